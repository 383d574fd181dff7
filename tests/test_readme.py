"""Every shell and Python block of the README runs as written, in a copy of the project with
the venv active (`jacgen`, `python` on PATH) and an empty jacgen.arm cache.

A block after `<!-- readme-test: skip (why) -->` is not run (the install commands; .ci/run
runs them), one after `<!-- readme-test: slow (why) -->` only with JACGEN_README_SLOW=1 (which
runs every block). A
YAML block whose first line is `# path` is written to that path first, as a reader would save
it. The Python blocks run in order in one interpreter, as a reader pastes them into one
session.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BLOCK = re.compile(r"(?:<!-- readme-test: (?P<mark>skip|slow) \((?P<why>[^)]*)\) -->\n)?```(?P<language>\w+)\n(?P<code>.*?)```",
                   re.S)
COPIED = ("robots", "generated", "examples", "tests/data", "docs")


def blocks() -> list[dict]:
    return [match.groupdict() for match in BLOCK.finditer((ROOT / "README.md").read_text())]


def test_the_readme_has_the_blocks_this_test_runs():
    found = blocks()
    assert sum(b["language"] == "python" and not b["mark"] for b in found) >= 4
    assert sum(b["language"] == "sh" and not b["mark"] for b in found) >= 1
    first_python = next(b for b in found if b["language"] == "python")
    assert 'arm = jacgen.arm("robots/ur5.yaml", backend="native")' in first_python["code"]


@pytest.mark.parametrize("slow", [False, True], ids=["quick", "slow"])
def test_every_block_runs_as_written(tmp_path, slow):
    if slow and not os.environ.get("JACGEN_README_SLOW"):
        pytest.skip("the slow blocks run with JACGEN_README_SLOW=1 (they build native modules and regenerate robots)")
    project = tmp_path / "project"
    for folder in COPIED:
        shutil.copytree(ROOT / folder, project / folder)
    environment = {**os.environ, "JACGEN_CACHE_DIR": str(tmp_path / "cache"), "MPLBACKEND": "Agg",
                   "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    python = []
    for block in blocks():
        code, language = block["code"], block["language"]
        if block["mark"] == "skip" or (block["mark"] == "slow" and not slow):
            continue
        if language == "yaml" and (path := re.match(r"# (\S+\.yaml)\n", code)):
            (project / path[1]).write_text(code)
        elif language == "sh":
            result = subprocess.run(["bash", "-e", "-c", code], cwd=project, env=environment, capture_output=True,
                                    text=True)
            assert result.returncode == 0, f"{code}\n{result.stdout[-2000:]}\n{result.stderr[-2000:]}"
        elif language == "python":
            python.append(code)
    script = "\n".join(python)
    result = subprocess.run([sys.executable, "-c", script], cwd=project, env=environment, capture_output=True, text=True)
    assert result.returncode == 0, f"{result.stdout[-2000:]}\n{result.stderr[-3000:]}"
