"""The model of an arm: its structure (special classes), the kinematics as sympy matrices,
the exact singularity analysis, the value graph every algorithm's expressions end on
(`graph.py`), and the tolerance symbols the solvers compare with (`tolerance_symbols.py`)."""
