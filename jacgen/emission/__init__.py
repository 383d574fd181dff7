"""Emission: the catalogue of generated functions, the Generator that builds them, lowering
(CSE, constant folding), the printer core, one backend per language, and the renderer."""
