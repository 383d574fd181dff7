"""The backends: one module per language, as SymForce's codegen has one per language.

A language module (`c.py`, `python.py`, `casadi.py`, `report.py`) holds its expression printer
(a subclass of `printers.Printer`: the literal policy, selects, comparisons, `isfinite`), the
builder of what its templates receive and the list of its templates under `templates/` (with
their runtime helpers, fixed C under `templates/runtime/`), in one `BACKEND` record
(`common.Backend`). Every algorithm reaches every language as straight-line `Body`s
(`lowering.py`): a backend only prints and lays out. Adding a language is one module, its
templates, and its name with its reserved words in `inputs/names.py`'s RESERVED, whose keys
are LANGUAGES.
"""

from importlib import import_module

from jacgen.inputs.names import RESERVED

LANGUAGES = tuple(RESERVED)  # each the module of its name
# `generate` without --lang: native is asked for by name (it is a package to build, and writes
# the C in both builds)
DEFAULT_LANGUAGES = ("c", "python", "casadi", "report")


def backend(language: str):
    """The `common.Backend` of a language of LANGUAGES, its module imported on first use (so
    that the command line starts without the printers and sympy)."""
    return import_module(f".{language}", __name__).BACKEND
