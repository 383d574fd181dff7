"""The tolerances of the generated code: the symbols EPS, TINY and RANK, which the solvers
compare with (`subproblems`, `ik`, `differential`) and the printers replace by the numbers of
the build's real type.
"""

import sympy

EPS, TINY = sympy.symbols("EPS TINY", positive=True)
RANK = sympy.Symbol("RANK", positive=True)  # velocity_ik's singularity threshold (see `differential`)
# Their values by real type, replaced by the printers.
# TINY bounds the product of two sines squared (`subproblems.sp1`): an angle is taken as free only
# where the distances from its axis are below 1e-10 (double) or 1e-5 (float) of the vectors, so
# that any angle moves the pose by less than the generated code's tolerance there.
TOLERANCES = {"double": {EPS: sympy.Float(1e-12), TINY: sympy.Float(1e-40), RANK: sympy.Float(1e-12)},
              "float": {EPS: sympy.Float(1e-6), TINY: sympy.Float(1e-20), RANK: sympy.Float(1e-5)}}

TOLERANCE_SYMBOLS = frozenset(TOLERANCES["double"])
