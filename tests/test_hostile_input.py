"""Hostile and extreme input (issue 35): the fuzz campaign's reproducers, every CLI command on
each of them, and a fuzzer of our own.

The contract on any input (docs/contract.md §1 "Numbers", §5): exit 0 with right results, or
exit 2 with one line that names the file, line, column and key; never "internal error", never
a traceback, within 10 s. Where generation succeeds, the C compiles under the contract's flags
and the Python and the C agree with `jacgen.reference`, at one q and batched.

The fuzzer is bounded for CI (FUZZ_EXAMPLES robot files through generation, compilation and
the comparison; URDF_EXAMPLES mutated URDFs through import-urdf). The release profile:

    JACGEN_FUZZ_EXAMPLES=10000 JACGEN_URDF_EXAMPLES=1000 .venv/bin/python -m pytest -q -p no:xdist \
        tests/test_hostile_input.py -k fuzz

Examples are random locally and fixed (derandomized) under CI.
"""

import os
import re
import sys
import time
from collections import Counter

import numpy as np
import pytest
import sympy
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from jacgen.inputs import names
from jacgen.checking import reference
from jacgen.emission.backends.c import CPrinter
from jacgen.cli import main
from jacgen.checking.c_library import compile_shared
from jacgen.errors import JacgenError
from jacgen.emission.generator import Generator
from jacgen.checking.generated_code import GeneratedCode
from jacgen.building import import_module
from jacgen.urdf_import import import_urdf
from jacgen.inputs.robot_file import load_robot, parse_robot

from conftest import ROOT
from support.graph_sympy import printed

FUZZ_EXAMPLES = int(os.environ.get("JACGEN_FUZZ_EXAMPLES", "40"))
URDF_EXAMPLES = int(os.environ.get("JACGEN_URDF_EXAMPLES", "60"))
ONE_LINE = re.compile(r"^jacgen: error: [^\n]+\n$")
UR5_URDF = ROOT / "tests" / "data" / "urdf" / "ur5_robot.urdf"


def arm(joints: str, task: str, extra: str = "", angle_unit: str = "rad") -> str:
    return (f"name: arm\nconvention: standard\nangle_unit: {angle_unit}\nlength_unit: m\n{extra}"
            f"joints:\n{joints}task: [{task}]\n")


def row(text: str, count: int = 1) -> str:
    return f"  - {{{text}}}\n" * count


PLANAR_12 = arm(row("type: revolute, a: 0.1, alpha: 0, d: 0", 12), "x, y, yaw")
PARAMETER_ONLY = arm(row("type: revolute, a: 1, alpha: L, d: 0"), "x", "parameters: {L: {value: 0.14, symbolic: true}}\n")

# The campaign's reproducers (issue 35's table), and what each must give: exit 0, or exit 2
# and the words of its reason.
ROBOT_FILES = {
    "F11_12_joints": (PLANAR_12, 0, None),
    "F14_tiny_arm": (arm(row("type: revolute, a: 1e-9, alpha: 0, d: 0", 2), "x, y"), 2, "the arm's size"),
    "F14_tiny_link": (arm(row("type: revolute, a: 1, alpha: 0, d: 0") + row("type: revolute, a: 1e-12, alpha: 0, d: 0"),
                          "x, y"), 2, "length 1e-12 is below"),
    "huge_arm": (arm(row("type: revolute, a: 1e5, alpha: 0, d: 0", 2), "x, y"), 2, "the arm's size"),
    "F12_parameter_only": (PARAMETER_ONLY, 0, None),
    "F10_power": (arm(row('type: revolute, a: "2**a1", alpha: 0, d: 0'), "x", "parameters: {a1: {value: 0.5, symbolic: true}}\n"),
                  2, "an exponent may not hold a symbolic parameter"),
    "F10_self_power": (arm(row('type: revolute, a: "a1**a1", alpha: 0, d: 0'), "x", "parameters: {a1: {value: 0.5, symbolic: true}}\n"),
                       2, "an exponent may not hold a symbolic parameter"),
    "F4_gimbal_lock": (arm(row("type: prismatic, a: 0, alpha: 0, theta: 0, limits: [0, 1]"), "z, roll",
                           "tool: {xyz: [0, 0, 0], rpy: [0, 90, 0]}\n", "deg"), 2, "roll and yaw are undefined"),
    "F13_equal_limits": (arm(row("type: revolute, a: 1, alpha: 0, d: 0, limits: [1, 1]") + row("type: revolute, a: 1, alpha: 0, d: 0"),
                             "x, y"), 2, "the limits are equal"),
    "F2_huge_exponent": (arm(row('type: revolute, a: "1e999999999999", alpha: 0, d: 0'), "x"), 2, "out of range"),
    "F2_tiny_exponent": (arm(row('type: revolute, a: "1e-999999999999", alpha: 0, d: 0'), "x"), 2, "too small for a double"),
    "many_digits": (arm(row(f'type: revolute, a: "0.{"1" * 150}", alpha: 0, d: 0'), "x"), 2, "more than 64 digits"),
    "F1_newline": (arm(row('type: revolute, a: 1, alpha: 0, d: 0, limits: ["\\n3", 2]'), "x"), 2, r"lower limit '\n3'"),
    "F9_next_line": (arm(row('type: revolute, a: 1, alpha: 0, d: 0, limits: [3, "2\\u0085"]'), "x"), 2, r"'2\x85'"),
    "unicode_digits": (arm(row('type: revolute, a: "\\u0661\\u0662", alpha: 0, d: 0'), "x"), 2, "unexpected character"),
    # found by test_fuzz_robot_files: `$` matched before a trailing newline, and "arm\n" named the C files
    "name_newline": (arm(row("type: revolute, a: 1, alpha: 0, d: 0"), "x").replace("name: arm", 'name: "arm\\n"'), 2,
                     "invalid name"),
    "fullwidth_digit": (arm(row('type: revolute, a: "\\uff11", alpha: 0, d: 0'), "x"), 2, "unexpected character"),
}


def run(*arguments) -> tuple:
    started = time.perf_counter()
    result = CliRunner().invoke(main, [str(a) for a in arguments])
    return result, time.perf_counter() - started


def assert_contract(result, seconds: float, exit_code: int | None = None, reason: str | None = None) -> None:
    """Exit 0, or exit 2 with one error line (with `reason` in it); never an internal error."""
    assert "internal error" not in result.stderr and "Traceback" not in result.output, result.stderr
    assert result.exit_code in (0, 2), (result.exit_code, result.stderr)
    if result.exit_code == 2:
        assert ONE_LINE.match(result.stderr), repr(result.stderr)
    if exit_code is not None:
        assert result.exit_code == exit_code, result.stderr
    if reason is not None:
        assert reason in result.stderr, result.stderr
    assert seconds < 10, f"{seconds:.1f} s"


@pytest.mark.parametrize("case", list(ROBOT_FILES))
@pytest.mark.parametrize("command", ["validate", "generate", "show", "verify"])
def test_every_command_on_every_reproducer(tmp_path, case, command):
    """Each reproducer through each command: its expected outcome, or (for a file that loads)
    exit 0; one line and no internal error either way."""
    text, exit_code, reason = ROBOT_FILES[case]
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    options = {"generate": ["-o", tmp_path / "out"], "verify": ["--samples", "5", "-j", "1"]}.get(command, [])
    if exit_code == 0 and command == "verify" and case == "F11_12_joints":
        pytest.skip("verify of the 12-joint arm takes longer than this test's budget; "
                    "test_twelve_joints_fk_is_right checks its code")
    result, seconds = run(command, path, *options)
    assert_contract(result, seconds, exit_code, reason)


def test_nothing_written_on_error(tmp_path):
    """A refused robot file leaves what is on disk as it was."""
    path = tmp_path / "arm.yaml"
    path.write_text(ROBOT_FILES["F13_equal_limits"][0])
    out = tmp_path / "out"
    (out / "arm").mkdir(parents=True)
    (out / "arm" / "arm.c").write_text("earlier")
    result, _ = run("generate", path, "-o", out)
    assert result.exit_code == 2
    assert [p.name for p in out.rglob("*") if p.is_file()] == ["arm.c"]
    assert (out / "arm" / "arm.c").read_text() == "earlier"


# -- right answers where the campaign found wrong ones ---------------------------------------
def test_twelve_joints_fk_is_right(generated):
    """F11: on 12 joints the sum of joints 1 and 2 is c1_2, joint 12 is c12: the C compiles
    (the contract's flags) and the Python and C fk equal the reference, one q and batched."""
    robot = parse_robot(PLANAR_12.encode(), "arm.yaml")
    assert names.trig((0, 1), 12) == ("c1_2", "s1_2") and names.trig((11,), 12) == ("c12", "s12")
    code = generated(robot, ("c", "python"), "double", functions=("fk",))
    q = np.random.default_rng(0).uniform(-3, 3, (8, 12))
    expected = reference.fk(robot, q)
    assert np.abs(code.python.fk(q) - expected).max() < 1e-12
    assert np.abs(code.python.fk(q[0]) - expected[0]).max() < 1e-12
    c = code.library("fk").evaluate("fk", q).reshape(expected.shape)
    assert np.abs(c - expected).max() < 1e-12


def test_parameter_only_entries_batch(generated):
    """F12: entries of fk that read only a symbolic parameter come back in the batch's shape
    and dtype, equal to the reference at the given parameter."""
    robot = parse_robot(PARAMETER_ONLY.encode(), "arm.yaml")
    code = generated(robot, ("c", "python"), "double", functions=("fk",))
    q = np.random.default_rng(1).uniform(-3, 3, (5, 1))
    expected = reference.fk(robot, q)
    assert np.abs(code.python.fk(q) - expected).max() < 1e-14
    assert np.abs(code.python.fk(q[2]) - expected[2]).max() < 1e-14
    assert code.python.fk(q.astype(np.float32)).dtype == np.float32
    other = reference.fk(parse_robot(PARAMETER_ONLY.replace("0.14", "0.3").encode(), "arm.yaml"), q)
    assert np.abs(code.python.fk(q, L=0.3) - other).max() < 1e-14
    assert np.abs(code.python.fk(q, L=np.full(5, 0.3)) - other).max() < 1e-14
    c = code.library("fk").evaluate("fk", q).reshape(expected.shape)
    assert np.abs(c - expected).max() < 1e-14


def test_large_integers_print_as_floating_literals():
    """F14: an integer too large for an int (10^36 = 1/a^4 for a = 1e-9) is a floating literal
    in C; small integers stay integers."""
    x = sympy.Symbol("x", real=True)
    assert printed(CPrinter("double"), sympy.Integer(10) ** 36 * x) == "1e+36*x"
    assert printed(CPrinter("double"), 2 * x) == "2*x"


def test_generated_prefixes_are_refused_as_parameter_names():
    """One owner of generated names: every prefix of names.GENERATED_PREFIXES with an index is
    refused as a parameter name (ga0 and qg1 were accepted before)."""
    for prefix in names.GENERATED_PREFIXES:
        for indices in ((0,), (3, 1)):
            assert names.parameter_name_problem(names.indexed(prefix, *indices), "arm") == "is used by the generated code"


# -- URDFs -----------------------------------------------------------------------------------
def ur5_with(old: str, new: str, count: int = 1) -> str:
    text = UR5_URDF.read_text()
    assert old in text
    return text.replace(old, new, count)


def long_chain(moving: int) -> str:
    joints = "".join(f'<joint name="j{k}" type="revolute"><parent link="l{k}"/><child link="l{k + 1}"/>'
                     f'<origin xyz="0.01 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>\n'
                     for k in range(moving))
    links = "".join(f'<link name="l{k}"/>' for k in range(moving + 1))
    return f'<?xml version="1.0"?>\n<robot name="chain">\n{links}\n{joints}</robot>\n'


URDF_CASES = {
    "F5_encoding": (ur5_with('encoding="utf-8"', 'encoding="bogus"'), (), 0, None),
    "F7_tiny_exponent": (ur5_with('xyz="0.0 0.0 0.089159"', 'xyz="1e-100000000 0.0 0.089159"'), (), 2, "too small"),
    "F8_5000_digits": (ur5_with('xyz="0.0 0.0 0.089159"', 'xyz="0.' + "1" * 5000 + ' 0.0 0.089159"'), (), 2, "digits"),
    "F3_long_chain": (long_chain(33), (), 2, "33 moving joints"),
    "F3_limit_underflow": (ur5_with('lower="-6.28318530718"', 'lower="1e-400"'), (), 2, "too small for a double"),
    "F3_far_origin": (ur5_with('xyz="0.0 0.0 0.089159"', 'xyz="0.0 0.0 999999"'), (), 2, "the arm's size"),
    "F3_subnormal_origin": (ur5_with('xyz="0.0 0.0 0.089159"', 'xyz="4.9e-324 0.0 0.089159"'), (), 2, "too small"),
    "F3_task_twice": (UR5_URDF.read_text(), ("--task", "x,x"), 2, "components must be distinct"),
    "equal_limits": (ur5_with('lower="-6.28318530718" upper="6.28318530718"', 'lower="1" upper="1"'), (), 2,
                     "the limits are equal"),
    "F9_newline_name": (ur5_with('name="shoulder_pan_joint"', 'name="shoulder&#10;pan"', 2), (), None, None),
}


@pytest.mark.parametrize("case", list(URDF_CASES))
def test_import_urdf_reproducers(tmp_path, case):
    text, options, exit_code, reason = URDF_CASES[case]
    path = tmp_path / "arm.urdf"
    path.write_text(text)
    tip = ("--tip", "l33") if case == "F3_long_chain" else ("--base", "base", "--tip", "tool0")
    result, seconds = run("import-urdf", path, *tip, *options, "-o", tmp_path / "arm.yaml")
    assert_contract(result, seconds, exit_code, reason)
    if result.exit_code == 0:
        load_robot(tmp_path / "arm.yaml")


# -- the fuzzer ------------------------------------------------------------------------------
OUTCOMES = {"robot files": Counter(), "urdfs": Counter()}


@pytest.fixture(scope="module", autouse=True)
def report_outcomes():
    """The fuzzers' outcomes on stderr (`-s` shows them): the release profile's record."""
    started = time.perf_counter()
    yield
    for kind, counts in OUTCOMES.items():
        if counts:
            print(f"\nfuzzed {kind}: {sum(counts.values())} in {time.perf_counter() - started:.0f} s: "
                  f"{dict(counts.most_common(12))}", file=sys.stderr)


def fuzz(examples: int):
    return settings(max_examples=examples, deadline=None, derandomize=bool(os.environ.get("CI")),
                    suppress_health_check=list(HealthCheck))


# Mostly valid, so that most files reach generation; one branch in four hostile.
numbers = st.floats(-0.6, 0.6, allow_nan=False).map(lambda v: f"{v:.6g}")
lengths = st.one_of(st.just("0"), numbers, numbers, st.sampled_from(["L", "0.1*L", "sqrt(2)/10", "1e-5", "-0.25"]),
                    st.sampled_from(["1e-9", "2e3", "1e-400", "1e999", "١٢", "0.1\n", "(0.2", "1/0", "2**L"]))
angles = st.one_of(st.sampled_from(["0", "90", "-90", "180", "pi", "45", "1e-12", "89.9999999999"]),
                   st.floats(-180, 180, allow_nan=False).map(lambda v: f"{v:.5g}"))
joints = st.one_of(
    st.builds(lambda a, alpha, d, off: f"type: revolute, a: {a!r}, alpha: {alpha!r}, d: {d!r}, offset: {off!r}",
              lengths, angles, lengths, angles),
    st.builds(lambda a, alpha, theta, lo, hi: f"type: prismatic, a: {a!r}, alpha: {alpha!r}, theta: {theta!r}, "
                                              f"limits: [{lo}, {hi}]",
              lengths, angles, angles, st.sampled_from(["0", "-0.2", "0", "0.1"]), st.sampled_from(["0.5", "0.3", "0.1", "0"])),
)
tasks = st.lists(st.sampled_from(["x", "y", "z", "roll", "pitch", "yaw"]), min_size=1, max_size=6, unique=True)


@st.composite
def robot_files(draw) -> str:
    """A robot file, usually valid, sometimes hostile: odd numbers, names, sizes and tasks."""
    rows = draw(st.lists(joints, min_size=1, max_size=12))
    order = ["x", "y", "z", "roll", "pitch", "yaw"]
    task = sorted(draw(tasks), key=order.index) if draw(st.booleans()) else draw(tasks)
    tool = draw(st.sampled_from(["", "tool: {xyz: [0, 0, 0.1], rpy: [0, 90, 0]}\n", "tool: {rpy: [10, 20, 30]}\n",
                                 "tool: {xyz: [0, 0, 1e6]}\n"]))
    parameters = draw(st.sampled_from(["parameters: {L: 0.2}\n"] * 3 + ["parameters: {L: {value: 0.2, symbolic: true}}\n"] * 3
                                      + ["parameters: {ga0: 0.2, L: 0.1}\n"]))
    name = draw(st.sampled_from(["arm"] * 6 + ["arm\n", "numpy", "a" * 60]))
    text = (f"name: {name!r}\nconvention: {draw(st.sampled_from(['standard', 'modified']))}\nangle_unit: deg\n"
            f"{parameters}joints:\n" + "".join(f"  - {{{r}}}\n" for r in rows) + tool + f"task: [{', '.join(task)}]\n")
    return text.replace("'", '"')


@fuzz(FUZZ_EXAMPLES)
@given(robot_files())
def test_fuzz_robot_files(tmp_path_factory, text):
    """Any robot file: refused in one line, or generated into C that compiles warning-free and
    Python and C whose fk and Jacobian equal the reference (one q and a batch)."""
    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / "arm.yaml"
    path.write_text(text)
    result, seconds = run("generate", path, "--functions", "fk,jacobian", "-o", folder / "out")
    assert_contract(result, seconds)
    OUTCOMES["robot files"][result.stderr.split(":")[-1].strip() if result.exit_code else "generated and agree"] += 1
    if result.exit_code:
        return
    robot = load_robot(path)
    built = folder / "out" / robot.name
    library = compile_shared([built / f"{robot.name}.c"], folder / f"lib{robot.name}.so")
    backends = GeneratedCode(robot, Generator(robot, selection=("fk", "jacobian")).signatures(), folder / "out",
                             {"double": library})
    ranges = np.array(robot.ranges)
    q = np.random.default_rng(0).uniform(ranges[:, 0], ranges[:, 1], (6, robot.dof))
    python = import_module(built / f"{robot.name}.py", f"fuzz_{robot.name}_{folder.name}")
    for name, expected in (("fk", reference.fk(robot, q)), ("jacobian", reference.jacobian(robot, q))):
        scale = 1 + np.abs(expected)
        for backend in ("python", "c double"):
            value = backends.evaluate(backend, name, q).reshape(expected.shape)
            assert np.all(np.abs(value - expected) <= 1e-9 * (1 + robot.reach) * scale), (backend, name, text)
        assert np.all(np.abs(getattr(python, name)(q[0]) - expected[0]) <= 1e-9 * (1 + robot.reach) * scale[0])


@fuzz(URDF_EXAMPLES)
@given(st.sampled_from(['xyz="0.0 0.0 0.089159"', 'lower="-6.28318530718"', 'name="shoulder_pan_joint"',
                        'encoding="utf-8"', '<axis xyz="0 0 1"/>', 'type="revolute"']),
       st.one_of(st.text(max_size=20), st.sampled_from(['xyz="1e6 0 0"', 'lower="nan"', 'name="a&#10;b"',
                                                        '<?xml version="1.0" encoding="latin-1"?>', 'type="fixed"',
                                                        '<axis xyz="0 0 0"/>', 'lower="6.3"', 'xyz="1e-17 0 0"'])))
def test_fuzz_urdfs(tmp_path_factory, old, new):
    """A mutated UR5 URDF: an imported robot file that loads, or one JacgenError line."""
    path = tmp_path_factory.mktemp("urdf") / "arm.urdf"
    path.write_bytes(UR5_URDF.read_text().replace(old, new, 1).encode("utf-8", "surrogatepass"))
    try:
        imported = import_urdf(str(path), "base", "tool0")
    except JacgenError:  # printed as one line by the CLI (test_import_urdf_reproducers)
        OUTCOMES["urdfs"]["refused"] += 1
        return
    parse_robot(imported.text.encode(), "imported.yaml")
    OUTCOMES["urdfs"]["imported"] += 1
