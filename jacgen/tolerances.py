"""jacgen's tolerances, each named for what it decides. This module imports nothing, so the
command line reads it before it loads a stage. The tolerances of one algorithm's inner
working stay beside it: the structure stage's 1e-40 on 60-digit numbers, the generated code's
EPS and TINY (`model/tolerance_symbols.py`), the general 6R solver's convergence (`solvers/general6r.py`).

Most are 1e-9, in rad and in the robot's length unit (times 1 + reach where poses are
compared): a few hundred roundings of double arithmetic on numbers of order 1 stay far below
it, and the 4-6 digits of a robot file or a URDF far above it.
"""

# The arm's geometry: what is made exact, or counts as equal
ANGLE_SNAP = 1e-9  # an angle this close to a multiple of pi/2 is that multiple (robot files, import-urdf --snap)
# import-urdf: a URDF angle within this many units of its last written digit of k*pi/2 (k != 0),
# and within WRITTEN_ANGLE_SNAP rad, is k*pi/2 (urdf.Snapper). A rounded or truncated pi/2 is
# within one unit; rtb-data's Puma 560 writes 1.570796325, 1.8 units off.
WRITTEN_ANGLE_UNITS = 2
WRITTEN_ANGLE_SNAP = 1e-3
PARALLEL = 1e-9  # |z_a x z_b| below which two unit axes are parallel
ROOT = 1e-9  # |factor| (relative to its scale) at a numerically found root of a singularity factor
URDF_AGREEMENT = 1e-9  # `show --compare-urdf`: a difference that agrees

# The generated code: what it must meet, times 1 + reach
REACHED = {"double": 1e-9, "float": 1e-3}  # |pose error| of an ik solution: the general 6R solver drops a root above it
# `jacgen verify`: the largest error of any function against the reference. float32 keeps 24
# bits (relative rounding 6e-8). An output is a sum of products along a chain of at most 32
# links, so its rounding error is a few tens of roundings of values no larger than the reach
# (positions, Jacobian entries) or 1 (rotations): ~1e-6 (1 + reach) for the shipped arms.
# 1e-4 leaves a margin of ~100 for long chains and cancellation, and is still far below any
# modelling error (a wrong term is >= 1e-3). Each error is divided by 1 + |expected|: float and
# double round relative to the value.
VERIFIED = {"double": 1e-9, "float": 1e-4}
# ik_numeric's `tol` (|pose error| at which it stops): the generated functions' default, and
# what `verify` asks of each build (the float step cannot reach below about 1e-5).
IK_NUMERIC_DEFAULT = 1e-10
IK_NUMERIC_VERIFIED = {"double": 1e-12, "float": 1e-5}
