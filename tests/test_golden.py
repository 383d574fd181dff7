"""Golden files: the committed generated/ is exactly what this version generates.

Every shipped robot is rendered in memory and compared byte for byte with generated/; a
mismatch prints the unified diff. This is `jacgen generate robots/*.yaml --check`, and it
also shows that the output does not depend on hashing: each test process has its own random
PYTHONHASHSEED, different from the one of the process that wrote generated/. `pytest tests/test_golden.py --update` rewrites the
files instead (then review the diff with git and commit it with the change that caused it).
"""

import sys

import pytest

from jacgen.files import stale_files, write_files
from jacgen.emission.render import render_robot

from conftest import GENERATED, ROBOT_NAMES, robot


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_generated_files_are_current(name, request):
    assert sys.flags.hash_randomization  # a fixed PYTHONHASHSEED would hide hash-order output
    files = render_robot(robot(name))
    if request.config.getoption("--update"):
        write_files(files, GENERATED)
        return
    diffs = stale_files(files, GENERATED)
    assert not diffs, "generated/ is stale; run pytest tests/test_golden.py --update:\n" + "".join(diffs)[:20_000]
