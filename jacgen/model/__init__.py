"""The model of an arm: its structure (special classes), the kinematics as sympy matrices,
the exact singularity analysis and Js (`js_rank.py`), the value graph every algorithm's
expressions end on (`graph.py`, its nodes `node.py`), and the tolerance symbols the solvers
compare with (`tolerance_symbols.py`)."""
