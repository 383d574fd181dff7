"""How heavy the generated code is, against an earlier revision's, in one run (issue "Light
generated code"). Per robot, each tree's own jacgen generates (in a process of its own, run in
the tree), and this tree's tools measure both:

1. the float C: its source bytes, its `.text` on a Cortex-M4F (arm-none-eabi-gcc -O2) and on
   the host, and the seconds gcc -O2 takes for the host object;
2. on the emulated Cortex-M4F (`jacgen verify --target cortex-m4f --sources`, when
   arm-none-eabi-gcc and qemu-system-arm are installed): flash and instructions a call of the
   functions that loop, before -> after;
3. the double C on the host (gcc -O2, common.py's harness, one program per tree, the two run in
   turn): ns a call of fk_jacobian, velocity_ellipsoid, condition_number, velocity_ik and ik;
4. `jacgen generate` of every language (common.render_in_process: seconds, imports excluded);
5. with --native, the first `jacgen.arm(robot, backend="native")` on an empty cache, in a
   fresh process (seconds, start to exit).

    python bench/bench_light_code.py [--against REV] [--native] [ROBOT ...]

REV (default: 3f1a32c, the code of the issue's figures) is checked out into a temporary git
worktree.
"""

import argparse
import os
import re
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
LOOPED = ("condition_number", "velocity_ellipsoid", "manipulability_gradient", "velocity_ik", "ik_numeric_step",
          "ik_branches", "ik_nearest")
TIMED = ("fk_jacobian", "velocity_ellipsoid", "condition_number", "velocity_ik", "ik")
CALLS, ROUNDS = 100_000, 7


def generate(tree: Path, robot: str, folder: Path, real: str) -> Path:
    """The C of `robot` as the jacgen of `tree` writes it, in `real`; the path of NAME.c."""
    subprocess.run([sys.executable, "-c", "from jacgen.cli import main; main()", "generate",
                    str(common.ROOT / "robots" / f"{robot}.yaml"), "--real", real, "--lang", "c", "--no-cache",
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


def on_target(robot: str, sources: Path) -> dict[str, tuple[int, int]]:
    """{function: (flash bytes, mean instructions a call)} of the float C in sources/NAME/."""
    done = subprocess.run([sys.executable, "-m", "jacgen", "verify", str(common.ROOT / "robots" / f"{robot}.yaml"),
                           "--target", "cortex-m4f", "--sources", str(sources)], capture_output=True, text=True,
                          cwd=common.ROOT)
    figures = {}
    for line in done.stdout.splitlines():
        match = re.match(rf"{robot}\s+(\w+)\s+(\d+)\s+\d+\s+\d+\s+(\d+), \d+$", line)
        if match:
            figures[match[1]] = (int(match[2]), int(match[3]))
    return figures


def host_loops(robot) -> list[common.Loop]:
    """TIMED of jacgen's double C, each on the harness's joint vectors; ik on the poses fk
    gives at 1,024 of them (its free joint, if any, at their value)."""
    name, n, m = robot.name, robot.dof, len(robot.task)
    free = getattr(robot, "free_joint", None)
    poses = (f"static double poses[1024][16], frees[1024];\n"
             f"    for (long i = 0; i < 1024; ++i) {{ bench_configuration(q, {n}, i * 7); {name}_fk(q, poses[i]);"
             f" frees[i] = {f'q[{free}]' if free is not None else '0'}; }}")
    free_argument = "frees[i & 1023], " if free is not None else ""
    return [
        common.Loop(name, "fk_jacobian", n, f"{name}_fk_jacobian(q, T, J);", f"J[{6 * n - 1}]",
                    f"double T[16], J[{6 * n}];"),
        common.Loop(name, "velocity_ellipsoid", n, f"{name}_velocity_ellipsoid(q, U_v, s_v, U_w, s_w);", "s_v[2] + s_w[2]",
                    "double U_v[9], s_v[3], U_w[9], s_w[3];"),
        common.Loop(name, "condition_number", n, f"const double kappa = {name}_condition_number(q);", "kappa"),
        common.Loop(name, "velocity_ik", n, f"{name}_velocity_ik(q, mu_dot, 0.0, q_dot);", "q_dot[0]",
                    f"double q_dot[{n}], mu_dot[{m}];\n    for (int j = 0; j < {m}; ++j) mu_dot[j] = 0.1 * (j + 1);"),
        common.Loop(name, "ik", n, f"const int found = {name}_ik(poses[i & 1023], {free_argument}solutions);", "found",
                    f"double solutions[{name.upper()}_MAX_IK_SOLUTIONS * {n}];\n    {poses}"),
    ]


def host_times(robot, sources: dict[str, Path], folder: Path) -> dict[str, dict[str, float]]:
    """{tree: {function: ns a call}}: one harness program per tree's double NAME.c, run in turn
    twice, the median of all their rounds."""
    programs = {tree: common.build(folder / tree, "harness", common.harness(host_loops(robot),
                                                                         f'#include "{robot.name}.h"'), [source])
                for tree, source in sources.items()}
    rounds: dict[str, dict[str, list[float]]] = {tree: {} for tree in programs}
    for _ in range(2):
        for tree, program in programs.items():
            for line in common.run(program, CALLS, ROUNDS).splitlines():
                _, nanoseconds, _, variant = line.split(maxsplit=3)
                rounds[tree].setdefault(variant, []).append(float(nanoseconds))
    return {tree: {variant: common.median(values) for variant, values in times.items()}
            for tree, times in rounds.items()}


def first_native_arm(tree: Path, robot: str, cache: Path) -> float:
    """Seconds of a fresh process whose `jacgen.arm(robot, backend="native")` finds an empty cache."""
    environment = dict(os.environ, XDG_CACHE_HOME=str(cache))
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", f"import jacgen; jacgen.arm({robot!r}, backend='native')"], cwd=tree,
                   env=environment, check=True, capture_output=True)
    return time.perf_counter() - start


def ratio(now: float, then: float, unit: str = "") -> str:
    return f"{then:,.{0 if then >= 100 else 2}f} -> {now:,.{0 if now >= 100 else 2}f}{unit} ({now / then:.2f})"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", default="3f1a32c")
    parser.add_argument("--native", action="store_true", help="time the first native jacgen.arm too")
    parser.add_argument("robots", nargs="*", default=["ur5", "panda"])
    arguments = parser.parse_args()
    cross = shutil.which("arm-none-eabi-gcc") is not None
    emulated = cross and shutil.which("qemu-system-arm") is not None
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        trees = {"before": scratch / "before", "now": common.ROOT}
        subprocess.run(["git", "-C", str(common.ROOT), "worktree", "add", "--detach", "-q", str(trees["before"]),
                        arguments.against], check=True)
        try:
            print(f"before: {arguments.against}, now: this tree; each figure before -> now (now / before)")
            for robot in arguments.robots:
                print(f"\n{robot}")
                floats, doubles = {}, {}
                for name, tree in trees.items():
                    floats[name] = generate(tree, robot, scratch / name / "float", "float")
                    doubles[name] = generate(tree, robot, scratch / name / "double", "double")
                source = {name: path.stat().st_size / 1e3 for name, path in floats.items()}
                print(f"  float C source               {ratio(source['now'], source['before'], ' KB')}")
                if cross:
                    m4f = {name: text_size(M4F, path)[0] / 1e3 for name, path in floats.items()}
                    print(f"  M4F .text (-O2)              {ratio(m4f['now'], m4f['before'], ' KB')}")
                host = {name: text_size(HOST, path) for name, path in floats.items()}
                print(f"  host .text (-O2)             "
                      f"{ratio(host['now'][0] / 1e3, host['before'][0] / 1e3, ' KB')}")
                print(f"  host gcc -O2 of it           {ratio(host['now'][1], host['before'][1], ' s')}")
                if emulated:
                    target = {name: on_target(robot, path.parent.parent) for name, path in floats.items()}
                    for function in LOOPED:
                        if function in target["now"] and function in target["before"]:
                            (flash, count), (flash_then, count_then) = target["now"][function], target["before"][function]
                            print(f"  M4F {function:24} flash {ratio(flash, flash_then, ' B')}, "
                                  f"instructions {ratio(count, count_then)}")
                model = common.shipped(robot)
                times = host_times(model, doubles, scratch / robot)
                for function in TIMED:
                    print(f"  host C {function:21} {ratio(times['now'][function], times['before'][function], ' ns')}")
                rendered = {name: common.render_in_process(tree, common.ROOT / "robots" / f"{robot}.yaml", 600)
                            for name, tree in trees.items()}
                print(f"  generate, every language     "
                      f"{ratio(rendered['now']['seconds'], rendered['before']['seconds'], ' s')}")
                if arguments.native:
                    first = {name: first_native_arm(tree, robot, scratch / name / "cache") for name, tree in trees.items()}
                    print(f"  first native jacgen.arm      {ratio(first['now'], first['before'], ' s')}")
        finally:
            subprocess.run(["git", "-C", str(common.ROOT), "worktree", "remove", "--force", str(trees["before"])],
                           check=True)


if __name__ == "__main__":
    main()
