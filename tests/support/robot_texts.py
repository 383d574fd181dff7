"""Robot files written out for the tests of the backends (tests/test_c_backend.py,
tests/test_casadi_backend.py)."""

# A robot with runtime parameters in the base translation only: fk and task read `p`, the
# Jacobians do not (they must still take it, and compile without an unused-parameter warning).
PARAMETRIC = """
name: lifted
convention: standard
angle_unit: deg
parameters:
  height: {value: 0.25, symbolic: true}
  shift: {value: -0.1, symbolic: true}
  a1: 0.4
joints:
  - {type: revolute, a: a1, alpha: 90, d: 0.1, offset: 30, limits: [-170, 170]}
  - {type: revolute, a: 0.3, alpha: 0, d: 0, offset: 0}
  - {type: prismatic, a: 0, alpha: 0, theta: 90, offset: 0.05, limits: [0, 0.2]}
base: {xyz: [shift, 0, height], rpy: [0, 0, 0]}
task: [x, y, z]
"""
