"""What a person reads: the words of `jacgen show` and the report, the drawing, and the
comparison with a URDF."""
