"""What `jacgen.arm` costs a Python user, against the ways before it and the peers' loaders.

    python bench/bench_arm.py [--robot ur5] [--rounds 5]

In an empty cache folder of its own: the first `jacgen.arm(robot, backend="native")` (generate
and compile, in this process), the same call again in this process, and a hit in a fresh process
(Python's start, `import jacgen`, the key, the entry's hashes and the module's import: the whole
process, timed from outside). Beside them, in the same run: the old way to the same module
(`jacgen generate --lang native` then `pip install --no-build-isolation` of it, into a temporary
target), and the peers' one-line loaders in a fresh process (Robotics Toolbox's
`rtb.models.DH.UR5()`, pytorch_kinematics' chain from the UR5's URDF), each median of
`--rounds`. Then one `fk_jacobian` call with the joint vector as a list, a tuple and an array.
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import common  # noqa: F401 (puts this checkout first on sys.path)

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
PEERS = {
    "jacgen.arm hit": "import jacgen; arm = jacgen.arm({robot!r}, backend='native')",
    "rtb.models.DH.UR5()": "import roboticstoolbox as rtb; robot = rtb.models.DH.UR5()",
    "pytorch_kinematics chain": ("import pytorch_kinematics as pk; "
                                 "chain = pk.build_serial_chain_from_urdf(open({urdf!r}).read(), 'tool0')"),
}


def fresh_process(program: str, environment: dict) -> float:
    """Seconds of a fresh interpreter running `program`, start to exit."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", program], env=environment, check=True, capture_output=True)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", default="ur5")
    parser.add_argument("--rounds", type=int, default=5)
    arguments = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        environment = {**os.environ, "JACGEN_CACHE_DIR": folder, "PYTHONPATH": str(ROOT)}
        os.environ["JACGEN_CACHE_DIR"] = folder
        import jacgen

        start = time.perf_counter()
        arm = jacgen.arm(arguments.robot, backend="native")
        first = time.perf_counter() - start
        start = time.perf_counter()
        jacgen.arm(arguments.robot, backend="native")
        again = time.perf_counter() - start
        print(f"\n{arguments.robot}: first jacgen.arm (generate + compile): {first:.1f} s; again in this process: "
              f"{again * 1e3:.1f} ms")

        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "jacgen", "generate", str(ROOT / "robots" / f"{arguments.robot}.yaml"),
                        "--lang", "native", "-o", f"{folder}/native", "--no-cache"], env=environment, check=True,
                       capture_output=True)
        subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-build-isolation", "--no-deps", "--target",
                        f"{folder}/installed", f"{folder}/native/{arguments.robot}"], env=environment, check=True,
                       capture_output=True)
        old_way = time.perf_counter() - start
        print(f"jacgen generate --lang native + pip install: {old_way:.1f} s ({old_way / first:.2f} x jacgen.arm's first call)")

        urdf = str(ROOT / "tests" / "data" / "urdf" / "ur5_robot.urdf")
        times = {name: [] for name in PEERS}
        for _ in range(arguments.rounds):  # interleaved
            for name, program in PEERS.items():
                if times[name] is None:
                    continue
                try:
                    times[name].append(fresh_process(program.format(robot=arguments.robot, urdf=urdf), environment))
                except subprocess.CalledProcessError as error:
                    times[name] = None
                    print(f"  {name}: {(error.stderr.decode().strip().splitlines() or ['no message'])[-1]}")
        ours = float(np.median(times["jacgen.arm hit"]))
        print(f"\nfresh process, start to exit (median of {arguments.rounds}):")
        for name, measured in times.items():
            if measured is None:
                print(f"  {name:26s}  failed (above)")
                continue
            print(f"  {name:26s} {np.median(measured):6.2f} s   / jacgen.arm hit: {np.median(measured) / ours:5.2f}")
        empty = float(np.median([fresh_process("pass", environment) for _ in range(arguments.rounds)]))
        print(f"  {'python -c pass':26s} {empty:6.2f} s")

        q = [0.1, -0.5, 0.3, 0.2, 0.4, 0.0][:arm.DOF] + [0.0] * max(0, arm.DOF - 6)
        calls = 100_000
        print(f"\none fk_jacobian from Python ({calls} calls, median of {arguments.rounds}):")
        array = None
        for name, value in (("array", np.array(q)), ("list", list(q)), ("tuple", tuple(q))):
            rounds = []
            for _ in range(arguments.rounds):
                start = time.perf_counter()
                for _ in range(calls):
                    arm.fk_jacobian(value)
                rounds.append((time.perf_counter() - start) / calls)
            measured = float(np.median(rounds))
            array = array or measured
            print(f"  {name:6s} {measured * 1e6:5.2f} us   / array: {measured / array:4.2f}")


if __name__ == "__main__":
    main()
