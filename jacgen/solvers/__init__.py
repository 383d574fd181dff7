"""The solvers, as expressions: the closed-form IK classes and their subproblems, the general
6R solver's per-robot part, joint limits, and the differential (velocity_ik, ik_numeric's step)."""
