"""Property tests of the robot file loader and the value grammar (hypothesis).

- Whatever the bytes (random bytes, random YAML documents, robot-shaped documents with
  garbage in them, mutations of the shipped robot files), `parse_robot` returns a Robot or
  raises RobotFileError whose message is one line `FILE:LINE:COL: ...`; nothing else.
- Random strings given to the expression parser give a Value or an ExpressionError.
- On generated well-formed expressions the parser agrees with Python: its float side equals
  Python's float arithmetic on the same text, its exact side equals the float side within
  the rounding error the float evaluation can have (bounded alongside, ~1e-16 relative
  without cancellation), and it refuses exactly the expressions whose evaluation leaves the
  grammar's limits.

Each test counts its outcomes; run with `-s` to see them (about 4,000 cases, ~30 s).
Examples are random locally and fixed (derandomized) under CI, so CI runs are reproducible.
"""

import math
import os
import re
import sys
from collections import Counter

import pytest
import sympy
import yaml
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from jacgen.inputs import values
from jacgen.errors import RobotFileError
from jacgen.inputs.values import ExpressionError, Value
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.inputs.robot_file import parse_robot

from conftest import ROBOT_FILES

MESSAGE = re.compile(r"^[^:\n]+:\d+:\d+: [^\n]*$")
OUTCOMES: dict[str, Counter] = {}


def fuzz(examples: int):
    return settings(max_examples=examples, deadline=None, derandomize=bool(os.environ.get("CI")),
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.fixture(scope="module", autouse=True)
def report_counts():
    yield
    total = sum(sum(counts.values()) for counts in OUTCOMES.values())
    print(f"\nfuzz cases: {total}", file=sys.stderr)
    for name, counts in sorted(OUTCOMES.items()):
        print(f"  {name}: {dict(sorted(counts.items()))}", file=sys.stderr)


def check_load(data: bytes, test: str) -> None:
    """The loader's contract on any input."""
    counts = OUTCOMES.setdefault(test, Counter())
    try:
        robot = parse_robot(data, "fuzz.yaml")
    except RobotFileError as error:
        assert MESSAGE.match(str(error)), str(error)
        counts["error"] += 1
        return
    assert isinstance(robot, Robot) and 1 <= robot.dof <= 32
    counts["robot"] += 1


# -- random input ----------------------------------------------------------------------------
@fuzz(500)
@given(st.binary(max_size=400))
def test_random_bytes(data):
    check_load(data, "random_bytes")


SCHEMA_WORDS = ("name", "description", "convention", "angle_unit", "length_unit", "parameters", "joints",
                "base", "tool", "task", "type", "a", "alpha", "d", "theta", "offset", "limits", "xyz", "rpy",
                "value", "symbolic", "revolute", "prismatic", "standard", "modified", "deg", "rad") + TASK_COMPONENTS
scalars = (st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=12)
           | st.sampled_from(SCHEMA_WORDS + ("pi/2", "-a1", "sqrt(2)", "1e300", "a1 +", "q1", "numpy")))
keys = st.sampled_from(SCHEMA_WORDS) | st.text(max_size=8)
documents = st.recursive(scalars, lambda children: st.lists(children, max_size=5)
                         | st.dictionaries(keys, children, max_size=6), max_leaves=25)


@fuzz(600)
@given(documents)
def test_random_yaml_documents(document):
    check_load(yaml.safe_dump(document, allow_unicode=True).encode(), "random_yaml")


def maybe(strategy, garbage=documents):
    """Mostly (19 times in 20) a plausible value, sometimes anything."""
    return st.integers(0, 19).flatmap(lambda pick: garbage if pick == 19 else strategy)


numbers = st.integers(-360, 360) | st.floats(-2, 2, allow_nan=False) | st.sampled_from(["pi/2", "-pi/4", "2*a1", "a1"])
limits = st.lists(st.integers(-360, 360) | st.floats(-2, 2, allow_nan=False), min_size=2, max_size=2).map(sorted)
common = {"a": maybe(numbers), "alpha": maybe(numbers)}
optional = {"name": maybe(st.from_regex(r"[a-z][a-z0-9_]{0,5}", fullmatch=True)), "offset": maybe(numbers),
            "limits": maybe(limits)}
joint = (st.fixed_dictionaries({"type": st.just("revolute"), "d": maybe(numbers), **common}, optional=optional)
         | st.fixed_dictionaries({"type": st.just("prismatic"), "theta": maybe(numbers), **common}, optional=optional))
vector = st.lists(numbers, min_size=3, max_size=3)
robot_documents = st.fixed_dictionaries(
    {"name": maybe(st.from_regex(r"[a-z][a-z0-9_]{0,7}", fullmatch=True)),
     "convention": maybe(st.sampled_from(["standard", "modified"])),
     "parameters": maybe(st.fixed_dictionaries({"a1": st.integers(-9, 9) | st.sampled_from(["pi/3", "sqrt(2)"])})),
     "joints": maybe(st.lists(maybe(joint), min_size=1, max_size=7)),
     "task": maybe(st.lists(st.sampled_from(TASK_COMPONENTS), min_size=1, max_size=6, unique=True)
                   .map(lambda task: sorted(task, key=TASK_COMPONENTS.index)))},
    optional={"angle_unit": maybe(st.sampled_from(["deg", "rad"])),
              "base": maybe(st.fixed_dictionaries({}, optional={"xyz": vector, "rpy": vector})),
              "tool": maybe(st.fixed_dictionaries({}, optional={"xyz": vector, "rpy": vector}))},
)


@fuzz(600)
@given(robot_documents)
def test_robot_shaped_documents(document):
    check_load(yaml.safe_dump(document, sort_keys=False).encode(), "robot_shaped")


# -- mutations of the shipped robot files ------------------------------------------------------
SHIPPED = [path.read_text() for path in ROBOT_FILES]


def paths(node, prefix=()):
    """Every path (tuple of keys and indices) to a value inside a loaded YAML document."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, child in items:
        yield prefix + (key,)
        yield from paths(child, prefix + (key,))


@fuzz(700)
@given(st.sampled_from(SHIPPED), st.data())
def test_mutated_shipped_robots(text, data):
    document = yaml.safe_load(text)
    path = data.draw(st.sampled_from(list(paths(document))))
    parent = document
    for key in path[:-1]:
        parent = parent[key]
    operation = data.draw(st.sampled_from(["delete", "replace", "insert"]))
    if operation == "delete":
        del parent[path[-1]]
    elif operation == "replace":
        parent[path[-1]] = data.draw(maybe(numbers, documents))
    elif isinstance(parent, dict):
        parent[data.draw(keys)] = data.draw(scalars)
    else:
        parent.insert(path[-1], data.draw(documents))
    check_load(yaml.safe_dump(document, sort_keys=False, allow_unicode=True).encode(), f"mutated_{operation}")


@fuzz(500)
@given(st.sampled_from(SHIPPED), st.data())
def test_garbage_in_shipped_robot_text(text, data):
    start = data.draw(st.integers(0, len(text)))
    end = data.draw(st.integers(start, min(len(text), start + 20)))
    garbage = data.draw(st.text(alphabet=st.sampled_from(list(":-[]{}&*!|>'\"#%@`,? \n\t.0123456789eapi")) | st.characters(),
                                max_size=10))
    check_load((text[:start] + garbage + text[end:]).encode("utf-8", "surrogatepass"), "text_garbage")


# -- expressions ---------------------------------------------------------------------------------
PARAMETER_VALUES = {"a1": Value(sympy.Rational(3, 10), 0.3), "d4": Value(sympy.Symbol("d4", real=True), 0.4318)}


def resolve(name: str) -> Value:
    if name not in PARAMETER_VALUES:
        raise ExpressionError(f"unknown parameter {name!r}")
    return PARAMETER_VALUES[name]


@fuzz(600)
@given(st.lists(st.sampled_from(list("0123456789.eE+-*/() ") + ["pi", "sqrt", "a1", "d4", "**", "x"]), max_size=30)
       .map("".join) | st.text(max_size=40))
def test_random_expression_strings(text):
    counts = OUTCOMES.setdefault("expression_strings", Counter())
    try:
        value = values.parse(text, resolve)
    except ExpressionError as error:
        assert "\n" not in str(error)
        counts["error"] += 1
        return
    assert math.isfinite(value.approx) and abs(value.approx) <= values.MAX_MAGNITUDE
    counts["value"] += 1


# Well-formed expression trees: (text, float the parser should compute, its error bound, valid)
EPSILON = sys.float_info.epsilon


class Invalid(Exception):
    """The expression leaves the grammar's limits, so the parser must refuse it."""


def evaluate(tree) -> tuple[float, float]:
    """(value, bound on its rounding error) of a tree, as Python floats; Invalid past the limits."""
    kind = tree[0]
    if kind == "number":
        value, error = float(tree[1]), EPSILON * abs(float(tree[1]))
    elif kind == "pi":
        value, error = math.pi, EPSILON * math.pi
    elif kind == "neg":
        value, error = evaluate(tree[1])
        return -value, error
    elif kind == "sqrt":
        (a, ea) = evaluate(tree[1])
        if a < 0:
            raise Invalid
        value = math.sqrt(a)
        error = (ea / (2 * value) if value > 0 else math.sqrt(ea)) + EPSILON * value
    else:
        (a, ea), (b, eb) = evaluate(tree[1]), evaluate(tree[2])
        if kind == "+":
            value, error = a + b, ea + eb
        elif kind == "-":
            value, error = a - b, ea + eb
        elif kind == "*":
            value, error = a * b, abs(a) * eb + abs(b) * ea + ea * eb
        elif kind == "/":
            if b == 0:
                raise Invalid
            value = a / b
            error = math.inf if eb >= abs(b) else (ea + abs(value) * eb) / (abs(b) - eb)
        else:  # "**" with a small integer exponent
            if abs(b) > values.MAX_EXPONENT or (a == 0 and b < 0):
                raise Invalid
            value = a**b
            error = abs(b) * abs(a) ** (b - 1) * ea * 1.01 if a else 0.0
        if value == 0 and kind in ("*", "/", "**") and a != 0 and (b != 0 or kind == "**"):
            raise Invalid  # a product, quotient or power of non-zero numbers underflowed
        error += EPSILON * abs(value)
    if abs(value) > values.MAX_MAGNITUDE or 0 < abs(value) < sys.float_info.min:
        raise Invalid
    return value, error


def text_of(tree, parenthesize: bool) -> str:
    """Source text, with parentheses where the grammar needs them or where `parenthesize`."""
    kind = tree[0]
    if kind == "number":
        return tree[1]
    if kind == "pi":
        return "pi"
    if kind == "sqrt":
        return f"sqrt({text_of(tree[1], parenthesize)})"
    if kind == "neg":
        return f"-({text_of(tree[1], parenthesize)})"
    left, right = (f"({text_of(child, parenthesize)})" if parenthesize or child[0] not in ("number", "pi", "sqrt")
                   else text_of(child, parenthesize) for child in tree[1:])
    return f"{left} {kind} {right}"


literals = st.one_of(
    st.integers(0, 1000).map(str),
    st.decimals(0, 100, places=3, allow_nan=False, allow_infinity=False).map(str),
    st.floats(1e-3, 1e3).map(lambda x: f"{x:.6e}"),
).map(lambda text: ("number", text)) | st.just(("pi",))
trees = st.recursive(
    literals,
    lambda children: st.one_of(
        st.tuples(st.sampled_from(["+", "-", "*", "/"]), children, children),
        st.tuples(st.just("**"), children, st.integers(-4, 4).map(lambda n: ("number", str(n)) if n >= 0
                                                                     else ("neg", ("number", str(-n))))),
        st.tuples(st.just("sqrt"), children),
        st.tuples(st.just("neg"), children),
    ),
    max_leaves=8,
)


@fuzz(700)
@given(trees, st.booleans())
def test_parser_agrees_with_python_arithmetic(tree, parenthesize):
    counts = OUTCOMES.setdefault("expression_oracle", Counter())
    text = text_of(tree, parenthesize)
    try:
        expected, error_bound = evaluate(tree)
    except Invalid:
        with pytest.raises(ExpressionError):
            values.parse(text, resolve)
        counts["refused"] += 1
        return
    value = values.parse(text, resolve)
    # Python reads the same text with the same precedence; float literals make it float arithmetic.
    python = eval(re.sub(r"(?<![\d.eE+-])(\d+)(?![\d.eE])", r"\1.0", text), {"pi": math.pi, "sqrt": math.sqrt})
    assert value.approx == pytest.approx(python, rel=1e-12, abs=1e-300)
    assert value.approx == pytest.approx(expected, rel=1e-12, abs=1e-300)
    exact = float(sympy.N(value.exact, 30))
    assume(math.isfinite(error_bound))
    assert abs(exact - value.approx) <= 1e-12 * abs(exact) + 4 * error_bound, (text, exact, value.approx)
    counts["agreed"] += 1
