"""Robot files (SPEC §1): YAML -> a validated, frozen Robot.

The YAML is composed into nodes (never constructed into Python objects) so that every
error can name the file, line, column and key path of the offending value.
"""

import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path

import sympy
import yaml

from .errors import RobotFileError
from .expr import ExpressionError, Value, parse

TASK_COMPONENTS = ("x", "y", "z", "roll", "pitch", "yaw")
MAX_JOINTS = 32
MAX_FILE_BYTES = 1 << 20
NAME_PATTERN = re.compile(r"^[a-z][a-z0-9_]{0,47}$")
IDENTIFIER_PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,47}$")
# Names a parameter may not take: the grammar's own words and the generated code's arguments.
RESERVED_PARAMETER_NAMES = {"pi", "sqrt", "q", "p", "T", "J", "mu", "f", "damping", "target"}
# Within this many radians of a multiple of pi/2, an angle becomes that multiple exactly.
ANGLE_SNAP_TOLERANCE = 1e-9
ZERO = Value(sympy.Integer(0), 0.0)


@dataclass(frozen=True)
class Parameter:
    name: str
    value: float
    symbolic: bool

    @property
    def symbol(self) -> sympy.Symbol:
        return sympy.Symbol(self.name, real=True)


@dataclass(frozen=True)
class Joint:
    """One DH row. Angles in radians; `theta` is None for revolute, `d` None for prismatic."""

    name: str
    kind: str  # "revolute" | "prismatic"
    a: Value
    alpha: Value
    d: Value | None
    theta: Value | None
    offset: Value
    limits: tuple[float, float] | None

    @property
    def revolute(self) -> bool:
        return self.kind == "revolute"


@dataclass(frozen=True)
class Pose:
    """A fixed transform: translation xyz, then R = Rz(yaw) Ry(pitch) Rx(roll)."""

    xyz: tuple[Value, Value, Value]
    rpy: tuple[Value, Value, Value]

    @property
    def is_identity(self) -> bool:
        return all(v.exact == 0 for v in self.xyz + self.rpy)


IDENTITY_POSE = Pose((ZERO,) * 3, (ZERO,) * 3)


@dataclass(frozen=True)
class Robot:
    name: str
    description: str
    convention: str  # "standard" | "modified"
    length_unit: str
    parameters: tuple[Parameter, ...]
    joints: tuple[Joint, ...]
    base: Pose
    tool: Pose
    task: tuple[str, ...]
    source: str  # the path as given, for messages
    digest: str  # sha256 of the file's bytes, first 16 hex digits

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def symbolic_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.symbolic)


def load_robot(path: str | Path) -> Robot:
    """Read and validate a robot file; raises RobotFileError with the position of the mistake."""
    path = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise RobotFileError(path, 1, 1, "", f"cannot read file: {error.strerror or error}") from None
    return parse_robot(data, path)


def parse_robot(data: bytes, path: str = "<robot>") -> Robot:
    """Validate the bytes of a robot file (`path` only names it in messages)."""
    if len(data) > MAX_FILE_BYTES:
        raise RobotFileError(path, 1, 1, "", f"file larger than {MAX_FILE_BYTES} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise RobotFileError(path, line, 1, "", "file is not valid UTF-8") from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise RobotFileError(path, line, column, "", f"invalid YAML: {error.problem or error.context}") from None
    except yaml.YAMLError as error:
        raise RobotFileError(path, 1, 1, "", f"invalid YAML: {error}") from None
    except RecursionError:
        raise RobotFileError(path, 1, 1, "", "invalid YAML: nested too deeply") from None
    if root is None:
        raise RobotFileError(path, 1, 1, "", "file is empty")
    return _RobotReader(path, data).read(root)


class _RobotReader:
    def __init__(self, path: str, data: bytes):
        self.path, self.data = path, data
        self.seen_nodes: set[int] = set()
        self.values: dict[str, Value] = {}
        self.angle_scale = Value(sympy.Integer(1), 1.0)

    # -- errors and structure ------------------------------------------------------------
    def error(self, node, key: str, message: str) -> RobotFileError:
        mark = node.start_mark
        return RobotFileError(self.path, mark.line + 1, mark.column + 1, key, message)

    def visit(self, node, key: str):
        if id(node) in self.seen_nodes:
            raise self.error(node, key, "YAML aliases are not supported; write the value out")
        self.seen_nodes.add(id(node))
        return node

    def mapping(self, node, key: str, allowed: tuple[str, ...], required: tuple[str, ...] = ()):
        """The entries of a mapping node as {key: value node}, checked against the schema."""
        self.visit(node, key)
        if not isinstance(node, yaml.MappingNode):
            raise self.error(node, key or "file", f"expected a mapping, got {_describe(node)}")
        entries: dict[str, object] = {}
        for key_node, value_node in node.value:
            name = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
            where = f"{key}.{name}" if key else str(name)
            if name not in allowed:
                hint = f"; expected one of: {', '.join(allowed)}"
                raise self.error(key_node, where, f"unknown key{hint}")
            if name in entries:
                raise self.error(key_node, where, "duplicate key")
            entries[name] = value_node
        for name in required:
            if name not in entries:
                raise self.error(node, f"{key}.{name}" if key else name, "missing required key")
        return entries

    def sequence(self, node, key: str, length: int | None = None):
        self.visit(node, key)
        if not isinstance(node, yaml.SequenceNode):
            raise self.error(node, key, f"expected a list, got {_describe(node)}")
        if length is not None and len(node.value) != length:
            raise self.error(node, key, f"expected a list of {length} items, got {len(node.value)}")
        return node.value

    def string(self, node, key: str, choices: tuple[str, ...] | None = None, pattern=None) -> str:
        self.visit(node, key)
        if not isinstance(node, yaml.ScalarNode) or node.tag != "tag:yaml.org,2002:str":
            raise self.error(node, key, f"expected a string, got {_describe(node)}")
        if choices is not None and node.value not in choices:
            raise self.error(node, key, f"expected one of {', '.join(choices)}, got {node.value!r}")
        if pattern is not None and not pattern.match(node.value):
            raise self.error(node, key, f"invalid name {node.value!r} (expected {pattern.pattern})")
        return node.value

    def value(self, node, key: str, angle: bool = False) -> Value:
        """A number, parameter name or expression; angles converted to radians and snapped."""
        self.visit(node, key)
        numeric_tags = ("tag:yaml.org,2002:int", "tag:yaml.org,2002:float", "tag:yaml.org,2002:str")
        if not isinstance(node, yaml.ScalarNode) or node.tag not in numeric_tags:
            raise self.error(node, key, f"expected a number or expression, got {_describe(node)}")
        text = node.value
        if node.tag != "tag:yaml.org,2002:str":
            if text.lower().lstrip("+-") in (".inf", ".nan"):
                raise self.error(node, key, f"expected a finite number, got {text}")
            text = text.replace("_", "")
        try:
            value = parse(text, self.resolve)
        except ExpressionError as error:
            raise self.error(node, key, f"{error} in {node.value!r}") from None
        return _snap_angle(_scaled(value, self.angle_scale)) if angle else value

    def resolve(self, name: str) -> Value:
        if name not in self.values:
            raise ExpressionError(f"unknown parameter {name!r}")
        return self.values[name]

    # -- the schema ----------------------------------------------------------------------
    def read(self, root) -> Robot:
        top = self.mapping(
            root, "",
            ("name", "description", "convention", "angle_unit", "length_unit", "parameters",
             "joints", "base", "tool", "task"),
            ("name", "convention", "joints"),
        )
        name = self.string(top["name"], "name", pattern=NAME_PATTERN)
        description = self.string(top["description"], "description") if "description" in top else ""
        convention = self.string(top["convention"], "convention", ("standard", "modified"))
        if "angle_unit" in top and self.string(top["angle_unit"], "angle_unit", ("deg", "rad")) == "deg":
            self.angle_scale = Value(sympy.pi / 180, math.pi / 180)
        length_unit = self.string(top["length_unit"], "length_unit") if "length_unit" in top else "m"
        parameters = self.parameters(top["parameters"]) if "parameters" in top else ()
        joints = self.joints(top["joints"])
        base = self.pose(top["base"], "base") if "base" in top else IDENTITY_POSE
        tool = self.pose(top["tool"], "tool") if "tool" in top else IDENTITY_POSE
        task = self.task(top.get("task"), root, len(joints))
        return Robot(name, description, convention, length_unit, parameters, joints, base, tool,
                     task, self.path, hashlib.sha256(self.data).hexdigest()[:16])

    def parameters(self, node) -> tuple[Parameter, ...]:
        self.visit(node, "parameters")
        if not isinstance(node, yaml.MappingNode):
            raise self.error(node, "parameters", f"expected a mapping, got {_describe(node)}")
        result = []
        for key_node, value_node in node.value:
            name = key_node.value if isinstance(key_node, yaml.ScalarNode) else ""
            key = f"parameters.{name}"
            if not IDENTIFIER_PATTERN.match(name) or name in RESERVED_PARAMETER_NAMES or re.match(r"^q\d+$", name):
                raise self.error(key_node, key, f"invalid parameter name {name!r}")
            if name in self.values:
                raise self.error(key_node, key, "duplicate parameter")
            symbolic = False
            if isinstance(value_node, yaml.MappingNode):
                entries = self.mapping(value_node, key, ("value", "symbolic"), ("value",))
                if "symbolic" in entries:
                    flag = entries["symbolic"]
                    self.visit(flag, f"{key}.symbolic")
                    if not (isinstance(flag, yaml.ScalarNode) and flag.tag == "tag:yaml.org,2002:bool"):
                        raise self.error(flag, f"{key}.symbolic", f"expected true or false, got {_describe(flag)}")
                    symbolic = flag.value.lower() in ("true", "yes", "on")
                value = self.value(entries["value"], f"{key}.value")
            else:
                value = self.value(value_node, key)
            parameter = Parameter(name, value.approx, symbolic)
            self.values[name] = Value(parameter.symbol, value.approx) if symbolic else value
            result.append(parameter)
        return tuple(result)

    def joints(self, node) -> tuple[Joint, ...]:
        rows = self.sequence(node, "joints")
        if not 1 <= len(rows) <= MAX_JOINTS:
            raise self.error(node, "joints", f"expected 1 to {MAX_JOINTS} joints, got {len(rows)}")
        joints, names = [], {}
        for index, row in enumerate(rows):
            key = f"joints[{index}]"
            entries = self.mapping(row, key, ("name", "type", "a", "alpha", "d", "theta", "offset", "limits"),
                                   ("type", "a", "alpha"))
            kind = self.string(entries["type"], f"{key}.type", ("revolute", "prismatic"))
            constant, variable = ("d", "theta") if kind == "revolute" else ("theta", "d")
            if variable in entries:
                raise self.error(entries[variable], f"{key}.{variable}",
                                 f"not allowed for a {kind} joint ({variable} = q + offset)")
            if constant not in entries:
                raise self.error(row, f"{key}.{constant}", "missing required key")
            name = (self.string(entries["name"], f"{key}.name", pattern=IDENTIFIER_PATTERN)
                    if "name" in entries else f"joint{index + 1}")
            if name in names:
                raise self.error(entries.get("name", row), f"{key}.name",
                                 f"duplicate joint name {name!r} (also joints[{names[name]}])")
            names[name] = index
            fixed = self.value(entries[constant], f"{key}.{constant}", angle=constant == "theta")
            joints.append(Joint(
                name=name, kind=kind,
                a=self.value(entries["a"], f"{key}.a"),
                alpha=self.value(entries["alpha"], f"{key}.alpha", angle=True),
                d=fixed if kind == "revolute" else None,
                theta=fixed if kind == "prismatic" else None,
                offset=self.value(entries["offset"], f"{key}.offset", angle=kind == "revolute")
                if "offset" in entries else ZERO,
                limits=self.limits(entries["limits"], f"{key}.limits", kind == "revolute")
                if "limits" in entries else None,
            ))
        return tuple(joints)

    def limits(self, node, key: str, angle: bool) -> tuple[float, float]:
        lower, upper = (self.value(item, f"{key}[{i}]", angle) for i, item in
                        enumerate(self.sequence(node, key, 2)))
        if lower.approx > upper.approx:
            raise self.error(node, key, f"lower limit {lower.approx:g} is above upper limit {upper.approx:g}")
        return (lower.approx, upper.approx)

    def pose(self, node, key: str) -> Pose:
        entries = self.mapping(node, key, ("xyz", "rpy"))
        xyz = tuple(self.value(item, f"{key}.xyz[{i}]") for i, item in
                    enumerate(self.sequence(entries["xyz"], f"{key}.xyz", 3))) if "xyz" in entries else (ZERO,) * 3
        rpy = tuple(self.value(item, f"{key}.rpy[{i}]", angle=True) for i, item in
                    enumerate(self.sequence(entries["rpy"], f"{key}.rpy", 3))) if "rpy" in entries else (ZERO,) * 3
        return Pose(xyz, rpy)

    def task(self, node, root, dof: int) -> tuple[str, ...]:
        if node is None:
            if dof < 6:
                raise self.error(root, "task", f"missing required key (a robot with {dof} joints "
                                 f"must declare its task, e.g. [x, y])")
            return TASK_COMPONENTS
        items = self.sequence(node, "task")
        names = [self.string(item, f"task[{i}]", TASK_COMPONENTS) for i, item in enumerate(items)]
        if not names:
            raise self.error(node, "task", "expected at least one component")
        if len(set(names)) != len(names) or names != sorted(names, key=TASK_COMPONENTS.index):
            canonical = ", ".join(sorted(set(names), key=TASK_COMPONENTS.index))
            raise self.error(node, "task", f"components must be distinct and in the order "
                             f"x, y, z, roll, pitch, yaw: write [{canonical}]")
        return tuple(names)


def _scaled(value: Value, scale: Value) -> Value:
    return Value(value.exact * scale.exact, value.approx * scale.approx)


def _snap_angle(value: Value) -> Value:
    """Exact k*pi/2 for an angle written as a decimal within ANGLE_SNAP_TOLERANCE of it."""
    if value.exact.free_symbols:
        return value
    quarter_turns = round(value.approx / (math.pi / 2))
    if abs(value.approx - quarter_turns * math.pi / 2) < ANGLE_SNAP_TOLERANCE:
        return Value(quarter_turns * sympy.pi / 2, quarter_turns * math.pi / 2)
    return value


def _describe(node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    kinds = {"bool": "a boolean", "null": "nothing", "int": "a number", "float": "a number", "str": "a string"}
    kind = kinds.get(node.tag.rsplit(":", 1)[-1], "a value")
    return f"{kind} ({node.value!r})" if node.value != "" else kind
