"""The backends: one small config per language, as SymForce's codegen configs are.

A backend is an expression printer (for a real type; it holds the literal policy), the
templates it renders with the file each becomes, its comment syntax, the builder of what
its templates receive (types included), and the words it reserves.
Every algorithm reaches every backend as straight-line `Body`s (`lowering.py`); a backend
only prints and lays out. A new language is a printer in `printers.py` (for selects,
comparisons and `isfinite` too), a context builder in `context.py`, templates under
`templates/`, its reserved words (`names.py`), and one entry here.
"""

from dataclasses import dataclass
from typing import Callable

from . import context, names
from .printers import CasadiPrinter, CPrinter, PythonPrinter


@dataclass(frozen=True)
class Backend:
    """One target language."""

    name: str
    templates: tuple[tuple[str, str], ...]  # (template, output file pattern with {name})
    comment: str  # a one-line comment around {}
    printer: Callable[[str], object] | None  # real type ("double", "float") -> expression printer
    context: Callable  # (robot, generator, printer, real) -> the templates' data
    reserved: dict[str, frozenset[str]]  # words a parameter may not be (its name is an identifier there), by reason


BACKENDS = {
    "c": Backend("c", (("c/robot.h.jinja", "{name}.h"), ("c/robot.c.jinja", "{name}.c")), "/* {} */",
                 CPrinter, context.c_context, names.C_RESERVED),
    "python": Backend("python", (("python/robot.py.jinja", "{name}.py"),), "# {}",
                      lambda real: PythonPrinter(), context.python_context, names.PYTHON_RESERVED),
    "casadi": Backend("casadi", (("casadi/robot_casadi.py.jinja", "{name}_casadi.py"),), "# {}",
                      lambda real: CasadiPrinter(), context.casadi_context, names.PYTHON_RESERVED),
    "report": Backend("report", (("report/robot.md.jinja", "{name}.md"),), "<!-- {} -->", None, context.report_context, {}),
}
DEFAULT_LANGUAGES = tuple(BACKENDS)
