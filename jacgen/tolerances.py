"""Tolerances the command line needs before it imports the stage that applies them (this
module imports nothing, so that `jacgen --help` starts fast)."""

URDF_AGREEMENT = 1e-9  # `show --compare-urdf`: a difference that agrees, in rad and the robot's length unit
