"""One row of `jacgen verify`'s table, and which backends run in float: shared by `verify` and
the checks it calls (`dexterity_checks`)."""

from dataclasses import dataclass


@dataclass(frozen=True)
class Result:
    """The largest error of one function of one robot, per backend (None: that backend not
    compared). A function verify does not compare at all fails: every function of the
    catalogue has a check (its note says why it has none)."""

    robot: str
    function: str
    errors: dict[str, float | None]
    tolerances: dict[str, float]
    note: str = ""
    compared: bool = True

    @property
    def above_tolerance(self) -> bool:
        return any(error is not None and not error <= self.tolerances[backend]
                   for backend, error in self.errors.items())

    @property
    def failed(self) -> bool:
        return self.above_tolerance or not self.compared


def is_float(backend: str) -> bool:
    return "float" in backend.split()
