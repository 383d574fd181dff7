"""`python -m jacgen` runs the same CLI as `jacgen`."""

from jacgen.cli import main

main(prog_name="jacgen")
