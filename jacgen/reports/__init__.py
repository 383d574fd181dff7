"""What a person reads: the words of `jacgen show` and the report, the generated ik's
documentation, the drawing, and the comparison with a URDF."""
