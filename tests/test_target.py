"""The generated float C on an emulated Cortex-M4F: `make -C examples/firmware check-m4`, which
runs `jacgen verify --target cortex-m4f` (jacgen/checking/cortex_m4f.py), passes on the C jacgen generates,
fails when one constant of it is wrong, and reports the resources the contract bounds."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from jacgen.cli import main
from jacgen.inputs.robot_file import load_robot
from jacgen.checking.cortex_m4f import INSTALL

ROOT = Path(__file__).resolve().parent.parent
MISSING = [tool for tool in ("arm-none-eabi-gcc", "arm-none-eabi-nm", "qemu-system-arm") if shutil.which(tool) is None]
needs_target = pytest.mark.skipif(bool(MISSING), reason=f"emulated Cortex-M4F: {', '.join(MISSING)} not installed "
                                                         f"({INSTALL})")
STACK_LIMIT = 4096  # bytes, any generated function (issue 23)
FK_JACOBIAN_STACK_LIMIT = 1024


def check_m4(sources: Path) -> subprocess.CompletedProcess:
    """check-m4 on the Puma 560's float C in `sources`/puma560/, as a user runs it."""
    return subprocess.run(["make", "-s", "-C", str(ROOT / "examples" / "firmware"), "check-m4", "M4_ROBOTS=puma560",
                           "M4_SAMPLES=60", f"M4_SOURCES={sources}", f"JACGEN={sys.executable} -m jacgen"],
                          capture_output=True, text=True, timeout=600)


@pytest.fixture(scope="module")
def float_c(generated) -> Path:
    """The folder `jacgen generate robots/puma560.yaml --real float --lang c -o` writes."""
    return generated(load_robot(ROOT / "robots" / "puma560.yaml"), ("c",), "float").folder


def declared(folder: Path) -> set[str]:
    """The functions puma560.h in `folder`/puma560/ declares, without the puma560_ prefix."""
    return set(re.findall(r"(?m)^\w+ puma560_(\w+)\(", (folder / "puma560" / "puma560.h").read_text()))


def rows(output: str, table: int) -> dict[str, list[str]]:
    """The puma560 rows of the errors (0) or the resources table (1), by function: the cells
    after the function's name."""
    text = output.split("\n\n")[table]
    return {cells[1]: cells[2:] for cells in (re.split(r"\s{2,}", line.strip()) for line in text.splitlines())
            if cells[0] == "puma560"}


@needs_target
def test_check_m4_passes_and_bounds_the_stack(float_c):
    """Every function of the header compared and none above tolerance; every one measured,
    within the stack bounds."""
    result = check_m4(float_c)
    assert result.returncode == 0, result.stdout + result.stderr
    functions = declared(float_c)
    errors = rows(result.stdout, 0)
    assert set(errors) == functions, sorted(set(errors) ^ functions)
    assert f"0 of {len(errors)} functions above tolerance" in result.stdout
    assert "checked on the target too" in errors["ik"][-1]
    # flash, stack (gcc), stack (measured), instructions (mean, max)
    resources = rows(result.stdout, 1)
    assert set(resources) == functions, sorted(set(resources) ^ functions)
    for name, (flash, stack, measured, instructions) in resources.items():
        assert int(flash) > 0 and int(stack) > 0, name
        assert int(stack) <= STACK_LIMIT and int(measured) <= STACK_LIMIT, (name, stack, measured)
        assert float(instructions.split(",")[0]) > 0, name
    assert int(resources["fk_jacobian"][1]) <= FK_JACOBIAN_STACK_LIMIT
    assert int(resources["fk_jacobian"][2]) <= FK_JACOBIAN_STACK_LIMIT


@needs_target
def test_check_m4_fails_on_one_wrong_constant(float_c, tmp_path):
    """One length of puma560_fk 1 % off (the 0.4318 m upper arm: 4.3 mm): check-m4 fails, and
    names fk and no function that does not read it."""
    shutil.copytree(float_c, tmp_path / "copy")
    source = tmp_path / "copy" / "puma560" / "puma560.c"
    text = source.read_text()
    start = text.index("void puma560_fk(")
    literal = next(found for found in re.finditer(r"\b\d+\.\d+F\b", text[start:])
                   if float(found.group()[:-1]) > 0.1)
    wrong = f"{float(literal.group()[:-1]) * 1.01!r}f"
    source.write_text(text[:start + literal.start()] + wrong + text[start + literal.end():])
    result = check_m4(tmp_path / "copy")
    assert result.returncode != 0 and "make" in result.stderr, result.stdout + result.stderr  # verify exited 1
    table = rows(result.stdout, 0)
    assert "FAIL" in table["fk"][0]
    assert "FAIL" not in table["jacobian"][0] and "FAIL" not in table["fk_jacobian"][0]


def test_missing_toolchain_is_one_line(monkeypatch, tmp_path):
    monkeypatch.setenv("PATH", str(tmp_path))  # nothing on it
    result = CliRunner().invoke(main, ["verify", str(ROOT / "robots" / "scara.yaml"), "--target", "cortex-m4f"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and "arm-none-eabi-gcc" in lines[0] and "qemu-system-arm" in lines[0], result.output


@needs_target
def test_general_6r_float_verifies_within_the_stack_bound():
    """The Jaco (general 6R: the eigenproblem, in double on the float build) on the target: ik,
    ik_branches and ik_nearest reach their targets, and with its working memory static (as the
    target build compiles it) no function's stack is over 4 KB."""
    result = subprocess.run([sys.executable, "-m", "jacgen", "verify", str(ROOT / "robots" / "jaco.yaml"),
                             "--target", "cortex-m4f", "--samples", "12"], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout + result.stderr
    output = result.stdout.split("\n\n")
    errors = {cells[1]: cells[2:] for cells in (re.split(r"\s{2,}", line.strip()) for line in output[0].splitlines())
              if cells[0] == "jaco"}
    assert "checked on the target too" in errors["ik"][-1] and "0 of" in result.stdout
    resources = {cells[1]: cells[2:] for cells in (re.split(r"\s{2,}", line.strip()) for line in output[1].splitlines())
                 if cells[0] == "jaco"}
    for name in ("ik", "ik_nearest"):
        flash, stack, measured, instructions = resources[name]
        assert int(stack) <= STACK_LIMIT and int(measured) <= STACK_LIMIT, (name, stack, measured)
