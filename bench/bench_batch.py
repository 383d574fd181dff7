"""Benchmark: the committed generated Python on large batches, per array library, beside
pytorch_kinematics.

    PYTHONPATH=. python bench/bench_batch.py [--sizes 1000,100000,1000000] [--rounds 3]

Optional peers, each row skipped (and said so) without it: JAX (`pip install jax`), PyTorch
(`pip install torch==2.13.0` takes this machine's CPU build) with array-api-compat, and
pytorch_kinematics (`pip install pytorch_kinematics`).

For ur5 and panda, the time per batch of `fk_jacobian` (the pose and the world Jacobian) for:
- numpy: the generated module on numpy arrays;
- JAX: the same module under `jax.jit`, compiled once per batch size before timing;
- PyTorch eager, and under `torch.compile` (compiled once per batch size before timing);
- pytorch_kinematics: `SerialChain.jacobian(q, ret_eef_pose=True)` (the same pose and world
  Jacobian) on the chain of the matching URDF in tests/data/urdf (ur5: base_link -> tool0; panda:
  panda_link0 -> panda_hand_tcp). Its pose is checked against jacgen.reference on the
  robot jacgen imports from that URDF, so both compute the same quantity.
Then the batched closed-form `ik` of ur5 (every branch, (q, keep) of fixed size) in numpy and
under `jax.jit`. All in double precision (jax_enable_x64), plus JAX in float32 for
fk_jacobian. Time is the median of `--rounds` after a warm-up call (common.py's timer
policy); the device of each library is printed (a GPU is used when JAX or PyTorch sees
one). Ratios are against numpy in the same run.
"""

import argparse
import contextlib
import io

import numpy as np

import common
from jacgen.checking import reference
from jacgen.urdf_import import import_urdf

URDFS = {"ur5": ("ur5_robot.urdf", "base_link", "tool0"), "panda": ("panda.urdf", "panda_link0", "panda_hand_tcp")}


jax = common.optional("jax")
torch = common.optional("torch")
pk = common.optional("pytorch_kinematics")
if jax:
    jax.config.update("jax_enable_x64", True)


def module(name):
    """The committed generated/NAME/NAME.py."""
    return common.load_module(common.ROOT / "generated" / name / f"{name}.py")


def seconds(function, rounds, ready=lambda result: result):
    """Median wall seconds of `function()` over `rounds` rounds, after a warm-up call."""
    return common.timed(function, rounds, ready).seconds


def torch_device():
    return "cuda" if torch.cuda.is_available() else "cpu"


def urdf_chain(name):
    """pytorch_kinematics' chain of the URDF, and the robot jacgen imports from it."""
    file, base, tip = URDFS[name]
    path = common.ROOT / "tests" / "data" / "urdf" / file
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):  # its parser's notes
        chain = pk.build_serial_chain_from_urdf(path.read_bytes(), tip, base)
    chain = chain.to(dtype=torch.float64, device=torch_device())
    return chain, import_urdf(str(path), base, tip).robot


def rows_fk_jacobian(name, sizes, rounds):
    generated = module(name)
    rng = np.random.default_rng(0)
    table = []
    for size in sizes:
        q = rng.uniform(-np.pi, np.pi, (size, generated.DOF))
        row = {"numpy": seconds(lambda: generated.fk_jacobian(q), rounds)}
        if jax:
            compiled = jax.jit(generated.fk_jacobian)
            q_jax, q_single = jax.numpy.asarray(q), jax.numpy.asarray(q, dtype=jax.numpy.float32)
            row["JAX jit"] = seconds(lambda: compiled(q_jax), rounds, jax.block_until_ready)
            row["JAX jit float32"] = seconds(lambda: compiled(q_single), rounds, jax.block_until_ready)
        if torch:
            q_torch = torch.from_numpy(q).to(torch_device())
            sync = (lambda result: torch.cuda.synchronize()) if torch_device() == "cuda" else (lambda result: result)
            row["PyTorch eager"] = seconds(lambda: generated.fk_jacobian(q_torch), rounds, sync)
            compiled = torch.compile(generated.fk_jacobian, fullgraph=True, dynamic=False)
            row["PyTorch compile"] = seconds(lambda: compiled(q_torch), rounds, sync)
            if pk:
                chain, imported = urdf_chain(name)
                row["pytorch_kinematics"] = seconds(lambda: chain.jacobian(q_torch, ret_eef_pose=True), rounds, sync)
                if size == sizes[0]:
                    _, pose = chain.jacobian(q_torch[:100], ret_eef_pose=True)
                    want = reference.fk(imported, q[:100])
                    print(f"{name}: pytorch_kinematics pose - jacgen.reference fk of the URDF import: "
                          f"{np.abs(pose.cpu().numpy() - want).max():.1e}")
        table.append((size, row))
    return table


def rows_ik(sizes, rounds):
    generated = module("ur5")
    rng = np.random.default_rng(1)
    table = []
    for size in sizes:
        targets = generated.fk(rng.uniform(-np.pi, np.pi, (size, generated.DOF)))
        row = {"numpy": seconds(lambda: generated.ik(targets), rounds)}
        if jax:
            compiled, targets_jax = jax.jit(generated.ik), jax.numpy.asarray(targets)
            row["JAX jit"] = seconds(lambda: compiled(targets_jax), rounds, jax.block_until_ready)
        table.append((size, row))
    return table


def print_table(title, table):
    print(f"\n{title}: seconds per batch (x: numpy's time / this one's)")
    columns = list(table[0][1])
    print("| batch | " + " | ".join(columns) + " |")
    print("|---:|" + "---:|" * len(columns))
    for size, row in table:
        cells = [f"{row[c]:.4g} (x{row['numpy'] / row[c]:.2f})" if c in row else "-" for c in columns]
        print(f"| {size:.0e} | " + " | ".join(cells) + " |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", default="1000,100000,1000000")
    parser.add_argument("--rounds", type=int, default=3)
    arguments = parser.parse_args()
    sizes = [int(size) for size in arguments.sizes.split(",")]
    print(f"numpy {np.__version__} on the CPU")
    if jax:
        print(f"JAX {jax.__version__} on {jax.devices()[0]}")
    if torch:
        print(f"PyTorch {torch.__version__} on {torch_device()}, {torch.get_num_threads()} threads")
    for name in URDFS:
        print_table(f"{name} fk_jacobian", rows_fk_jacobian(name, sizes, arguments.rounds))
    print_table("ur5 ik (every branch, batched)", rows_ik(sizes, arguments.rounds))


if __name__ == "__main__":
    main()
