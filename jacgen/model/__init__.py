"""The model of an arm: its structure (special classes), the kinematics as sympy matrices,
the exact singularity analysis, the DH chain in floating point, and the plain nodes
(selects, comparisons) every algorithm builds."""
