"""What jacgen derives from a robot file once, before any code exists: the end of the model
and solver stages.

The structure (and with it the closed-form solver and its exact constants), the singularity
analysis and the dexterity are computed at most once per robot and read by every backend, the
report and `jacgen show`/`verify`. Each is computed when first asked for.
"""

from functools import cached_property

from jacgen import budget
from jacgen.inputs.robot import Robot
from jacgen.model.dexterity import Dexterity, dexterity
from jacgen.model.singularities import Singularities, analyse, unanalysed
from jacgen.model.structure import Geometry, Structure, classify
from jacgen.solvers import ik


class Model:
    """One robot's derived facts, each computed on first use."""

    def __init__(self, robot: Robot):
        self.robot = robot

    @cached_property
    def geometry(self) -> Geometry:
        """Every joint axis as a line at q = 0, exactly."""
        return Geometry(self.robot)

    @cached_property
    def structure(self) -> Structure:
        """The structure class and why (or why no closed form applies)."""
        return classify(self.robot, self.geometry)

    @cached_property
    def closed_form(self) -> ik.ClosedForm | None:
        """The closed-form solver and its constants, None without one."""
        return ik.closed_form(self.robot, self.geometry, self.structure)

    @cached_property
    def singularities(self) -> Singularities:
        """The exact singularity analysis, under its work limits and the --budget safety net."""
        return budget.within_budget(lambda: analyse(self.robot), lambda: unanalysed(self.robot),
                                    f"the singularity analysis of {self.robot.name}")

    @cached_property
    def dexterity(self) -> Dexterity:
        """Angeles' characteristic length, the best condition number of Js and where (numeric)."""
        return dexterity(self.robot)
