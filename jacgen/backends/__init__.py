"""The backends: one module per language, as SymForce's codegen has one per language.

A language module (`c.py`, `python.py`, `casadi.py`, `report.py`) holds its expression printer
(a subclass of `printers.Printer`: the literal policy, selects, comparisons, `isfinite`), the
builder of what its templates receive, the list of its templates under `templates/` (with
their runtime helpers), its comment syntax and its reserved words (`names.py`'s tables), in
one `BACKEND` record (`common.Backend`). Every algorithm reaches every language as
straight-line `Body`s (`lowering.py`): a backend only prints and lays out. Adding a language
is one module, its templates, and one line here.
"""

from . import c, casadi, native, python, report

BACKENDS = {module.BACKEND.name: module.BACKEND for module in (c, python, casadi, report, native)}
# `generate` without --lang: native is asked for by name (it is a package to build, and writes
# the C in both builds)
DEFAULT_LANGUAGES = ("c", "python", "casadi", "report")
