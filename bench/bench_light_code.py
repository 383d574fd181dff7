"""How heavy the generated C is, against an earlier revision's, in one run (issue "Light
generated code"): per robot, the float C's source bytes, its `.text` on a Cortex-M4F
(arm-none-eabi-gcc -O2, when installed) and on the host, and the seconds gcc -O2 takes for
the host object.

    python bench/bench_light_code.py [--against REV] [ROBOT ...]

REV (default: 011aaff, the last commit with the Jacobi sweeps written out) is checked out
into a temporary git worktree, and each tree's own jacgen generates the code in a process of
its own (run in the tree, as common.render_in_process does), so that both are measured by the same compilers in the same run.
"""

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import common

M4F = ["arm-none-eabi-gcc", "-std=c99", "-O2", "-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard",
       "-mfpu=fpv4-sp-d16", "-c"]
HOST = ["gcc", "-std=c99", "-O2", "-c"]


def generate(tree: Path, robot: str, folder: Path) -> Path:
    """The float C of `robot` as the jacgen of `tree` writes it; the path of NAME.c."""
    subprocess.run([sys.executable, "-c", "from jacgen.cli import main; main()", "generate",
                    str(common.ROOT / "robots" / f"{robot}.yaml"), "--real", "float", "--lang", "c", "--no-cache",
                    "-o", str(folder)], check=True, capture_output=True, cwd=tree)
    return folder / robot / f"{robot}.c"


def text_size(command: list[str], source: Path) -> tuple[int, float]:
    """(.text bytes, compile seconds) of one object."""
    output = source.with_suffix(f".{command[0]}.o")
    start = time.perf_counter()
    subprocess.run([*command, f"-I{source.parent}", str(source), "-o", str(output)], check=True)
    seconds = time.perf_counter() - start
    size = "arm-none-eabi-size" if command[0].startswith("arm") else "size"
    return int(subprocess.run([size, str(output)], check=True, capture_output=True, text=True)
               .stdout.splitlines()[1].split()[0]), seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", default="011aaff")
    parser.add_argument("robots", nargs="*", default=["puma560", "ur5", "panda"])
    arguments = parser.parse_args()
    cross = shutil.which("arm-none-eabi-gcc") is not None
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        before = scratch / "before"
        subprocess.run(["git", "-C", str(common.ROOT), "worktree", "add", "--detach", "-q", str(before),
                        arguments.against], check=True)
        try:
            print(f"{'robot':8} {'source KB':>16} {'M4F .text KB':>16} {'host .text KB':>16} {'host gcc -O2 s':>16}"
                  f"   (this tree / {arguments.against}, ratio)")
            for robot in arguments.robots:
                figures = []
                for name, tree in (("now", common.ROOT), ("before", before)):
                    (scratch / name).mkdir(exist_ok=True)
                    source = generate(tree, robot, scratch / name / "out")
                    m4f = text_size(M4F, source)[0] if cross else None
                    host, seconds = text_size(HOST, source)
                    figures.append((source.stat().st_size, m4f, host, seconds))
                cells = []
                for k, (now, then) in enumerate(zip(*figures)):
                    if now is None:
                        cells.append(f"{'-':>16}")
                    elif k == 3:
                        cells.append(f"{f'{now:.1f}/{then:.1f} {now / then:.2f}':>16}")
                    else:
                        cells.append(f"{f'{now / 1e3:.0f}/{then / 1e3:.0f} {now / then:.2f}':>16}")
                print(f"{robot:8} " + " ".join(cells))
        finally:
            subprocess.run(["git", "-C", str(common.ROOT), "worktree", "remove", "--force", str(before)], check=True)


if __name__ == "__main__":
    main()
