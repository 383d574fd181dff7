"""The generated float C run on an emulated Cortex-M4F: `jacgen verify --target cortex-m4f`.

The robot's C is cross-compiled for a Cortex-M4F (single-precision FPU, hard float, newlib's
libm) at -O2 with the contract's warning flags, linked with a harness rendered from the
function catalogue (`templates/target/`) and the board's runtime
(`templates/runtime/target_runtime.c`), and run on QEMU's MPS2 AN386 board. Inputs and
results pass through files on the host by semihosting; one QEMU run evaluates a batch.

Instruction counts: QEMU runs with `-icount shift=6`, so its virtual clock advances 64 ns per
instruction, and the SysTick counts the 25 MHz processor clock (40 ns): one tick is 40/64 of
an instruction. QEMU counts instructions; it is not cycle-accurate (no pipeline, wait
states or FPU latencies), so the counts compare code, not time.
"""

import re
import shutil
import subprocess
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from jacgen.checking import reference
from jacgen.checking.c_library import WARNING_FLAGS, first_error
from jacgen.emission.generator import Generator
from jacgen.emission.render import environment, render_robot
from jacgen.errors import JacgenError
from jacgen.files import write_files
from jacgen.inputs.robot import Robot
from jacgen.solvers.differential import IK_NUMERIC_DEFAULTS
from jacgen.sources import template_folder
from jacgen.tolerances import IK_NUMERIC_VERIFIED

TARGETS = ("cortex-m4f",)
INSTALL = "apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm"
CPU_FLAGS = ("-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16")
# -O2 as firmware builds it; one section per function for the per-function sizes; the stack
# frame of every function (-fstack-usage) and who calls whom (-fcallgraph-info).
BUILD_FLAGS = ("-O2", "-ffunction-sections", "-fstack-usage", "-fcallgraph-info=su")
QEMU = ("qemu-system-arm", "-M", "mps2-an386", "-nographic", "-monitor", "none",
        "-semihosting-config", "enable=on,target=native", "-icount", "shift=6", "-kernel")
INSTRUCTIONS_PER_TICK = 40 / 64
RUN_SECONDS = 300  # a run that takes longer is stopped (it hangs)
TEMPLATES = ("mps2_an386.ld", "harness.c")
RUNTIME = ("target_runtime.h", "target_runtime.c")  # copied from templates/runtime/


class TargetError(JacgenError):
    """The toolchain or QEMU is missing, or the target build or run failed."""


@dataclass(frozen=True)
class Call:
    """How the harness calls one generated C function, and what comes back."""

    name: str
    inputs: tuple[tuple[str, int, bool, bool], ...]  # per argument: name, values, passed by value, an int
    outputs: tuple[tuple[int, bool], ...]  # per output array: values, integers
    returns: str | None  # the C type of the returned value: "real", "int" or None

    @property
    def reads(self) -> int:
        return sum(size for _, size, _, _ in self.inputs)

    @property
    def reals(self) -> int:
        """Values of the real output arrays (the integer ones follow them in a result)."""
        return sum(size for size, integer in self.outputs if not integer)

    @property
    def integers(self) -> int:
        return sum(size for size, integer in self.outputs if integer)


@dataclass(frozen=True)
class Batch:
    """The results of one function at k inputs on the target."""

    returned: np.ndarray | None  # (k,)
    outputs: list[np.ndarray]  # per output array, (k, size), in declaration order
    ik_error: np.ndarray | None  # (k,) for ik: the largest |fk(solution) - target| found on the target
    instructions: np.ndarray  # (k,) per call
    stack: np.ndarray  # (k,) bytes of stack written during each call (libm included)


@dataclass(frozen=True)
class Resources:
    """What a function costs in the target build."""

    flash: int  # .text bytes of the function and the generated functions it calls (libm not counted)
    stack: int  # worst-case stack of the same, from the compiler's frame sizes
    bounded: bool  # every frame 'static' (no VLA, no alloca) and no recursion


def check_tools() -> None:
    """TargetError naming what is missing, in one line."""
    missing = [tool for tool in ("arm-none-eabi-gcc", "arm-none-eabi-nm", "qemu-system-arm") if shutil.which(tool) is None]
    if missing:
        raise TargetError(f"--target cortex-m4f needs {' and '.join(missing)} (Debian: {INSTALL})")


def calls(generator: Generator) -> list[Call]:
    """Every function of the contract the robot has, as the catalogue declares it (the general 6R
    solver's parts are measured through ik_branches)."""
    found = []
    for function in generator.signatures():
        if function.declaration is None:
            continue
        returned = function.returned
        outputs = tuple((o.size, o.boolean or o.integer) for o in function.outputs if o is not returned)
        kind = None if returned is None else "int" if returned.boolean or returned.integer else "real"
        found.append(Call(function.name, tuple((a.name, a.size, a.scalar, a.integer) for a in function.arguments),
                          outputs, kind))
    return found


def _arguments(call: Call, parameters: bool) -> list[str]:
    """The C arguments of a call: inputs from `inputs`, outputs into `reals` and `integers`."""
    arguments, offset = [], 0
    for _, size, by_value, integer in call.inputs:
        arguments.append(f"(int)inputs[{offset}]" if integer else f"inputs[{offset}]" if by_value else f"inputs + {offset}")
        offset += size
    counts = {False: 0, True: 0}
    for size, integer in call.outputs:
        arguments.append(f"{'integers' if integer else 'reals'} + {counts[integer]}")
        counts[integer] += size
    return arguments + ["&parameters"] * parameters


def harness_context(robot: Robot, found: list[Call]) -> dict:
    """What the harness template lays out: one case per function, the ik check."""
    real = f"{robot.name}_real"
    cases = [{"name": call.name, "reads": call.reads, "arguments": _arguments(call, bool(robot.symbolic_parameters)),
              "returns": {"real": real, "int": "int", None: None}[call.returns],
              "reals": call.reals, "integers": call.integers} for call in found]
    target = next((call.inputs[0][1] for call in found if call.name == "ik"), None)
    pose = target == 16
    return {
        "name": robot.name, "real": real, "dof": robot.dof, "cases": cases,
        "most_inputs": max(case["reads"] for case in cases),
        "most_reals": max(max(case["reals"] for case in cases), 1),
        "most_integers": max(max(case["integers"] for case in cases), 1),
        "parameters": [f"{p.value!r}f" for p in robot.symbolic_parameters],
        "ik_check": target and {"function": "fk" if pose else "task", "size": target,
                                "wrapped": [0] * 16 if pose else [int(name in ("roll", "pitch", "yaw")) for name in robot.task]},
    }


def _run(command: list[str], what: str, **options) -> subprocess.CompletedProcess:
    result = subprocess.run(command, capture_output=True, text=True, **options)
    if result.returncode != 0:
        raise TargetError(f"{what} failed (exit {result.returncode}): {first_error(result.stderr or result.stdout)}")
    return result


class Emulator:
    """One robot's float C built for the target, run on QEMU a batch at a time.

    `sources`: a folder holding NAME/NAME.h and NAME/NAME.c, as `jacgen generate --real float
    --lang c -o FOLDER` writes them, to run instead of generating them (the C you ship,
    checked as it is)."""

    def __init__(self, robot: Robot, generator: Generator, folder: Path, sources: Path | None = None):
        check_tools()
        self.robot, self.folder = robot, folder
        self.signatures = {f.name: f for f in generator.signatures() if f.declaration is not None}
        self.calls = {call.name: call for call in calls(generator)}
        self.index = {name: k for k, name in enumerate(self.calls)}
        code = folder / robot.name
        if sources is None:
            write_files(render_robot(robot, ("c",), "float", generator), folder)
        else:
            code.mkdir(parents=True, exist_ok=True)
            for suffix in (".h", ".c"):
                given = Path(sources) / robot.name / f"{robot.name}{suffix}"
                if not given.is_file():
                    raise TargetError(f"{given}: not found (--sources DIR holds NAME/NAME.h and NAME/NAME.c)")
                shutil.copyfile(given, code / f"{robot.name}{suffix}")
        context = harness_context(robot, list(self.calls.values()))
        templates = environment()
        for name in TEMPLATES:
            (folder / name).write_text(templates.get_template(f"target/{name}.jinja").render(context))
        for name in RUNTIME:
            shutil.copyfile(template_folder() / "runtime" / name, folder / name)
        self.sources = [code / f"{robot.name}.c", folder / "target_runtime.c", folder / "harness.c"]
        self.program = folder / f"{robot.name}.elf"
        self.measured: dict[str, Batch] = {}  # the last batch of each function run

    def build(self, warnings: tuple[str, ...] = WARNING_FLAGS) -> "Emulator":
        """Cross-compile (the robot's C with `warnings`: by default the contract's, any warning
        an error) and link."""
        objects = [self.folder / f"{source.stem}.o" for source in self.sources]
        for source, built in zip(self.sources, objects):
            # the robot's C with the general 6R solver's working memory static (contract §4)
            flags = [*warnings, f"-D{self.robot.name.upper()}_IK_STATIC_WORK"] if source is self.sources[0] \
                else WARNING_FLAGS
            _run(["arm-none-eabi-gcc", *flags, *CPU_FLAGS, *BUILD_FLAGS, f"-I{self.sources[0].parent}",
                  f"-I{self.folder}", "-c", str(source), "-o", str(built)],
                 f"arm-none-eabi-gcc on {source.name}", cwd=self.folder)
        _run(["arm-none-eabi-gcc", *CPU_FLAGS, "--specs=rdimon.specs", "-T", str(self.folder / "mps2_an386.ld"),
              "-Wl,--gc-sections", *map(str, objects), "-lm", "-o", str(self.program)], "linking for the target")
        return self

    def run(self, name: str, *inputs: np.ndarray) -> Batch:
        """`name` at each row of the inputs (one (k, size) array per argument, in order)."""
        call = self.calls[name]
        count = len(inputs[0])
        rows = np.hstack([np.reshape(np.asarray(array, dtype=np.float32), (count, -1)) for array in inputs])
        if rows.shape[1] != call.reads:
            raise ValueError(f"{name} reads {call.reads} values per call, got {rows.shape[1]}")
        (self.folder / "calls.bin").write_bytes(np.array([self.index[name], count], dtype="<i4").tobytes()
                                                + rows.astype("<f4").tobytes())
        try:
            _run([*QEMU, str(self.program)], f"{self.robot.name}_{name} on the emulated target", cwd=self.folder,
                 timeout=RUN_SECONDS)
        except subprocess.TimeoutExpired:
            raise TargetError(f"{self.robot.name}_{name} on the emulated target: no exit after {RUN_SECONDS} s") from None
        values = np.fromfile(self.folder / "results.bin", dtype="<f8")
        empty, values = values[0], values[1:]
        width = (call.returns is not None) + call.reals + call.integers + (name == "ik") + 2
        if values.size != count * width:
            raise TargetError(f"{self.robot.name}_{name} on the emulated target wrote {values.size} of "
                              f"{count * width} results")
        table = values.reshape(count, width)
        returned = table[:, 0] if call.returns else None
        column = call.returns is not None
        blocks = {False: column, True: column + call.reals}  # where the real and the integer outputs start
        outputs = []
        for size, integer in call.outputs:
            outputs.append(table[:, blocks[integer]:blocks[integer] + size])
            blocks[integer] += size
        batch = Batch(returned, outputs, table[:, -3] if name == "ik" else None,
                      (table[:, -2] - empty) * INSTRUCTIONS_PER_TICK, table[:, -1])
        self.measured[name] = batch
        return batch

    def call_with(self, name: str, values: dict[str, np.ndarray]) -> Batch:
        """`name` with each argument taken from `values` by its name (k rows each)."""
        return self.run(name, *(values[argument] for argument, _, _, _ in self.calls[name].inputs))

    def measure_remaining(self, q: np.ndarray, free: int | None) -> None:
        """Run each function not run yet at q, so that every one has instruction and stack
        figures: targets reached at q, seeds and starts 0.1 away, unit weights, damping 0.01, random
        rates and null-space motions, gains of 10."""
        rng = np.random.default_rng(2)
        target = reference.ik_target(self.robot, q)
        rates = rng.normal(size=(len(q), len(self.robot.task)))
        values = {"q": q, "q_dot": rng.normal(size=q.shape), "mu_dot": rates, "target_rate": rates,
                  "z": rng.normal(size=q.shape), "gain": np.full_like(rates, 10.0),
                  "damping": np.full(len(q), 0.01), "target": target, "T": target, "mu": target,
                  "q_seed": q + 0.1, "q0": q + 0.1, "weights": np.ones_like(q),
                  "max_iter": np.full(len(q), IK_NUMERIC_DEFAULTS["max_iter"]), "tol": np.full(len(q), IK_NUMERIC_VERIFIED["float"]), "q_free": q[:, free] if free is not None else None}
        for name in self.calls:
            if name not in self.measured:
                self.call_with(name, values)

    def results(self, name: str, *arguments) -> tuple[np.ndarray, ...]:
        """`name` at k rows of its arguments (a scalar may be one number for all): its results in
        the catalogue's order, each (k, *shape). `measured[name]` keeps the run, with ik's own
        check on the target."""
        signature = self.signatures[name]
        count = next(len(value) for value in arguments if np.ndim(value))
        batch = self.run(name, *(np.full(count, value) if np.ndim(value) == 0 else value for value in arguments))
        arrays = iter(batch.outputs)
        return tuple(batch.returned if output is signature.returned else next(arrays).reshape(count, *output.shape)
                     for output in signature.outputs)

    # -- flash and stack, from the compiler --------------------------------------------------
    @cached_property
    def resources(self) -> dict[str, Resources]:
        """Each function's flash and worst-case stack, with the generated functions it calls
        (read from the build: ask before its folder is removed)."""
        sizes = {}
        robot_object = self.folder / f"{self.robot.name}.o"
        for line in _run(["arm-none-eabi-nm", "-S", str(robot_object)], "arm-none-eabi-nm").stdout.splitlines():
            parts = line.split()
            if len(parts) == 4 and parts[2] in "tT":
                sizes[parts[3]] = int(parts[1], 16)
        frames, callees = _call_graph(self.folder / f"{self.robot.name}.ci")

        def reachable(symbol: str, seen: tuple = ()) -> tuple[set[str], int, bool]:
            """The generated functions `symbol` reaches, its deepest stack, and whether bounded."""
            if symbol in seen:  # recursion: unbounded
                return {symbol}, 0, False
            frame, bounded = frames[symbol]
            reached, deepest = {symbol}, 0
            for callee in callees.get(symbol, ()):
                if callee in frames:
                    more, depth, ok = reachable(callee, (*seen, symbol))
                    reached |= more
                    deepest, bounded = max(deepest, depth), bounded and ok
            return reached, frame + deepest, bounded

        found = {}
        for name in self.calls:
            symbol = f"{self.robot.name}_{name}"
            reached, stack, bounded = reachable(symbol)
            found[name] = Resources(sum(sizes.get(s, 0) for s in reached), stack, bounded)
        return found


_NODE = re.compile(r'node: \{ title: "([^"]+)" label: "[^"]*\\n(\d+) bytes \((\w+)\)')
_EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')


def _call_graph(path: Path) -> tuple[dict[str, tuple[int, bool]], dict[str, set[str]]]:
    """gcc's -fcallgraph-info=su file: {function: (frame bytes, static)} of the functions it
    compiled, and {caller: callees}, by their symbols (gcc titles a file-local function
    `file.c:name`)."""
    text = path.read_text()

    def symbol(title: str) -> str:
        return title.rsplit(":", 1)[-1]

    frames = {symbol(name): (int(size), kind == "static") for name, size, kind in _NODE.findall(text)}
    callees: dict[str, set[str]] = {}
    for source, target in _EDGE.findall(text):
        callees.setdefault(symbol(source), set()).add(symbol(target))
    return frames, callees



def format_resources(emulators: list[Emulator]) -> str:
    """Per robot and function: flash, worst-case stack, the stack measured and instructions per call."""
    header = ["robot", "function", "flash B", "stack B (gcc)", "stack B (measured)", "instructions/call (mean, max)"]
    rows = [header]
    for emulator in emulators:
        for name, cost in emulator.resources.items():
            batch = emulator.measured[name]
            rows.append([emulator.robot.name, name, str(cost.flash), f"{cost.stack}" + ("" if cost.bounded else " unbounded"),
                         f"{int(batch.stack.max())}", f"{batch.instructions.mean():.0f}, {batch.instructions.max():.0f}"])
    widths = [max(len(row[c]) for row in rows) for c in range(len(header))]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]
    return "\n".join(lines + [
        "flash: .text of the function and the generated functions it calls (libm not counted); stack (gcc): the",
        "deepest chain of their -fstack-usage frames; measured: the stack written during the calls, libm included;",
        "instructions: QEMU -icount (an instruction count, not cycles: QEMU is not cycle-accurate)"])
