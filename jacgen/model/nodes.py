"""The tolerances of the generated code: the symbols EPS, TINY and RANK, which the solvers
compare with (`subproblems`, `ik`, `differential`) and the printers replace by the numbers of
the build's real type.
"""

import sympy

EPS, TINY = sympy.symbols("EPS TINY", positive=True)
RANK = sympy.Symbol("RANK", positive=True)  # velocity_ik's singularity threshold (see `differential`)
# Their values by real type, replaced by the printers.
TOLERANCES = {"double": {EPS: sympy.Float(1e-12), TINY: sympy.Float(1e-24), RANK: sympy.Float(1e-12)},
              "float": {EPS: sympy.Float(1e-6), TINY: sympy.Float(1e-12), RANK: sympy.Float(1e-5)}}

TOLERANCE_SYMBOLS = frozenset(TOLERANCES["double"])
