"""`python -m jacgen` runs the same CLI as `jacgen`."""

from .cli import main

main(prog_name="jacgen")
