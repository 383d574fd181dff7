"""Checking generated code: the independent numpy reference, `jacgen verify`, the compiled C
through ctypes, the emulated Cortex-M4F, and the configurations checked at."""
