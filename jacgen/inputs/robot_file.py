"""Robot files (contract §1): YAML -> a validated, frozen Robot (`robot.py`).

The YAML is composed into nodes (never constructed into Python objects) so that every
error can name the file, line, column and key path of the offending value. The reader is
hardened against hostile files: bounded size and nesting, no aliases.
"""

import hashlib
import math
import re
from pathlib import Path

import numpy as np
import yaml

from jacgen.errors import RobotFileError
from jacgen.inputs import numeric_chain
from jacgen.inputs.names import PARAMETER_NAME_RULE, ROBOT_NAME_RULE, parameter_name_problem, robot_name_problem
from jacgen.inputs.robot import IDENTITY_POSE, TASK_COMPONENTS, ZERO, Joint, Parameter, Pose, Robot
from jacgen.inputs.values import ExpressionError, Value, combined, parse
from jacgen.tolerances import ANGLE_SNAP

MAX_JOINTS = 32
MAX_FILE_BYTES = 1 << 20
MAX_NESTING = 16  # a robot file needs 4 levels: file, joints, a joint, its limits
NAME_PATTERN = re.compile(r"^[a-z][a-z0-9_]{0,47}$")
IDENTIFIER_PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,47}$")
# Free text (description, length_unit) is copied into generated comments, docstrings and
# strings: printable lines (one for length_unit, any number for the description) without
# what could end or escape them there. Its length is bounded only by MAX_FILE_BYTES.
FORBIDDEN_IN_TEXT = ('\\', '"""', "/*", "*/", "??")
# The sizes jacgen is right for (contract §1, "Numbers"): the reach (Robot.reach) is 0 or within
# REACH, in the file's length unit, since the generated code's tolerances are absolute; a length
# of a link (a, d) that is not 0 is at least SMALLEST_LENGTH times the reach (below it the arm is singular everywhere
# to double rounding).
REACH = (1e-2, 1e3)
SMALLEST_LENGTH = 1e-7
# Below this, cos(pitch) is the rounding of 0 (check_euler_angles).
GIMBAL_LOCK = 1e-12


def load_robot(path: str | Path) -> Robot:
    """Read and validate a robot file; raises RobotFileError with the position of the mistake."""
    path = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise RobotFileError(path, 1, 1, "", f"cannot read file: {error.strerror or error}") from None
    return parse_robot(data, path)


def parse_robot(data: bytes, path: str = "<robot>", rounding_lengths: bool = False) -> Robot:
    """Validate the bytes of a robot file (`path` only names it in messages). With
    `rounding_lengths`, a length below SMALLEST_LENGTH of the arm's size is let through
    (import-urdf reads its fit so, to find such lengths and make them 0)."""
    if len(data) > MAX_FILE_BYTES:
        raise RobotFileError(path, 1, 1, "", f"file larger than {MAX_FILE_BYTES} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        column = error.start - data.rfind(b"\n", 0, error.start)  # in bytes
        raise RobotFileError(path, line, column, "", "file is not valid UTF-8") from None
    try:
        root = yaml.compose(text, Loader=_Composer)
    except _Refused as error:
        mark = error.problem_mark
        raise RobotFileError(path, mark.line + 1, mark.column + 1, "", error.problem) from None
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        raise RobotFileError(path, line, column, "", f"invalid YAML: {error.problem or error.context}") from None
    except yaml.reader.ReaderError as error:  # a character YAML does not allow, e.g. a control character
        line = text.count("\n", 0, error.position) + 1
        column = error.position - text.rfind("\n", 0, error.position)
        raise RobotFileError(path, line, column, "", f"invalid YAML: character U+{error.character:04X} "
                             "is not allowed") from None
    if root is None:
        raise RobotFileError(path, 1, 1, "", "file is empty")
    return _RobotReader(path, data, rounding_lengths).read(root)


class _Refused(yaml.MarkedYAMLError):
    """Valid YAML that robot files do not allow."""


class _Composer(yaml.SafeLoader):
    """PyYAML's safe parser and composer, refusing aliases (a value must be written where it
    is used, so every error has one position) and nesting deeper than any robot file needs
    (so that hostile input cannot exhaust the recursive composer)."""

    depth = 0

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            raise _Refused(problem="YAML aliases (*name) are not supported; write the value out",
                           problem_mark=event.start_mark)
        if self.depth >= MAX_NESTING:
            raise _Refused(problem=f"nested deeper than {MAX_NESTING} levels", problem_mark=event.start_mark)
        self.depth += 1
        try:
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1


class _RobotReader:
    def __init__(self, path: str, data: bytes, rounding_lengths: bool = False):
        self.path, self.data, self.rounding_lengths = path, data, rounding_lengths
        self.values: dict[str, Value] = {}
        self.angle_scale = Value(("integer", 1), 1.0)
        self.lengths: list[tuple[yaml.Node, str, Value]] = []  # the link lengths read, for check_sizes

    # -- errors and structure ------------------------------------------------------------
    def error(self, node, key: str, message: str) -> RobotFileError:
        mark = node.start_mark
        return RobotFileError(self.path, mark.line + 1, mark.column + 1, key, message)

    def mapping(self, node, key: str, allowed: tuple[str, ...], required: tuple[str, ...] = ()):
        """The entries of a mapping node as {key: value node}, checked against the schema."""
        if not isinstance(node, yaml.MappingNode):
            raise self.error(node, key or "file", f"expected a mapping, got {_describe(node)}")
        entries: dict[str, object] = {}
        for key_node, value_node in node.value:
            name = self.key(key_node, key)
            where = _key_path(key, name)
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

    def key(self, node, parent: str) -> str:
        """The text of a mapping key, which must be a plain scalar."""
        if not isinstance(node, yaml.ScalarNode):
            raise self.error(node, parent or "file", f"expected a name as key, got {_describe(node)}")
        return node.value

    def sequence(self, node, key: str, length: int | None = None):
        if not isinstance(node, yaml.SequenceNode):
            raise self.error(node, key, f"expected a list, got {_describe(node)}")
        if length is not None and len(node.value) != length:
            raise self.error(node, key, f"expected a list of {length} items, got {len(node.value)}")
        return node.value

    def string(self, node, key: str, choices: tuple[str, ...] | None = None, pattern=None) -> str:
        if not isinstance(node, yaml.ScalarNode) or node.tag != "tag:yaml.org,2002:str":
            raise self.error(node, key, f"expected a string, got {_describe(node)}")
        if choices is not None and node.value not in choices:
            raise self.error(node, key, f"expected one of {', '.join(choices)}, got {_shown(node.value)}")
        if pattern is not None and not pattern.fullmatch(node.value):
            raise self.error(node, key, f"invalid name {_shown(node.value)} (expected {pattern.pattern})")
        return node.value

    def text(self, node, key: str, paragraphs: bool = False) -> str:
        """Free text that is copied into generated files: printable lines (one unless
        `paragraphs`), nothing that escapes; trailing white space dropped."""
        text = self.string(node, key).rstrip()
        lines = text.split("\n") if paragraphs else [text]
        if not all(line.isprintable() for line in lines):
            raise self.error(node, key, "must be lines of printable characters" if paragraphs
                             else "must be one line of printable characters")
        bad = [part for part in FORBIDDEN_IN_TEXT if part in text]
        if bad:
            raise self.error(node, key, f"may not contain {bad[0]!r} (it is copied into generated "
                             f"comments and strings; not allowed: {' '.join(FORBIDDEN_IN_TEXT)})")
        return text

    def value(self, node, key: str, angle: bool = False, length: bool = False) -> Value:
        """A number, parameter name or expression; angles converted to radians and snapped,
        link lengths (a, d) kept for `check_sizes`."""
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
            raise self.error(node, key, f"{error} in {_shown(node.value)}") from None
        if length:
            self.lengths.append((node, key, value))
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
             "joints", "base", "tool", "task", "ik", "characteristic_length"),
            ("name", "convention", "joints"),
        )
        name = self.string(top["name"], "name", pattern=NAME_PATTERN)
        problem = robot_name_problem(name)
        if problem:
            raise self.error(top["name"], "name", f"{name!r} {problem}: {ROBOT_NAME_RULE}")
        description = self.text(top["description"], "description", paragraphs=True) if "description" in top else ""
        convention = self.string(top["convention"], "convention", ("standard", "modified"))
        if "angle_unit" in top and self.string(top["angle_unit"], "angle_unit", ("deg", "rad")) == "deg":
            self.angle_scale = Value(("div", ("pi",), ("integer", 180)), math.pi / 180)
        length_unit = self.text(top["length_unit"], "length_unit") if "length_unit" in top else "m"
        parameters = self.parameters(top["parameters"], name) if "parameters" in top else ()
        joints = self.joints(top["joints"])
        base = self.pose(top["base"], "base") if "base" in top else IDENTITY_POSE
        tool = self.pose(top["tool"], "tool") if "tool" in top else IDENTITY_POSE
        task = self.task(top.get("task"), root, len(joints))
        free_joint, nearest_class = self.ik_options(top["ik"], joints, task) if "ik" in top else (None, True)
        length = self.characteristic_length(top["characteristic_length"]) if "characteristic_length" in top else None
        robot = Robot(name, description, convention, length_unit, parameters, joints, base, tool,
                      task, self.path, hashlib.sha256(self.data).hexdigest()[:16], free_joint, nearest_class, length)
        self.check_sizes(robot, top["joints"])
        if "task" in top:
            self.check_euler_angles(robot, top["task"])
        return robot

    def check_euler_angles(self, robot: Robot, task_node) -> None:
        """Roll and yaw are defined somewhere: not when the tool's x axis stays along the world
        z axis (pitch +-90 deg) at every configuration, as it does when no joint turns it (at
        the symbolic parameters' values; checked at a few fixed random configurations)."""
        if not {"roll", "yaw"} & set(robot.task):
            return
        ranges = np.array(robot.ranges)
        q = np.random.default_rng(0).uniform(ranges[:, 0], ranges[:, 1], (4, robot.dof))
        x_axis = numeric_chain.link_frames(robot, q)[1][:, :3, 0]
        if np.all(np.hypot(x_axis[:, 0], x_axis[:, 1]) < GIMBAL_LOCK):
            raise self.error(task_node, "task", "roll and yaw are undefined at every configuration: the tool's x "
                             "axis stays along the world z axis (pitch +-90 deg), where ZYX Euler angles have no "
                             "roll or yaw; leave them out of the task, or turn the tool")

    def check_sizes(self, robot: Robot, joints_node) -> None:
        """The reach within REACH, and no link length (a, d) but 0 below SMALLEST_LENGTH of it."""
        reach = robot.reach
        if reach and not REACH[0] <= reach <= REACH[1]:
            raise self.error(joints_node, "joints", f"the arm's size (the sum of its lengths) is {reach:.3g} "
                             f"{robot.length_unit}: jacgen supports {REACH[0]:g} to {REACH[1]:g} (its tolerances "
                             f"are absolute); write the lengths in another unit")
        for node, key, value in self.lengths:
            if value.approx and abs(value.approx) < SMALLEST_LENGTH * reach and not self.rounding_lengths:
                raise self.error(node, key, f"length {value.approx:.3g} is below {SMALLEST_LENGTH:g} of the arm's "
                                 f"size {reach:.3g}, where the arm is singular everywhere to rounding: write 0")

    def parameters(self, node, robot_name: str) -> tuple[Parameter, ...]:
        if not isinstance(node, yaml.MappingNode):
            raise self.error(node, "parameters", f"expected a mapping, got {_describe(node)}")
        result = []
        for key_node, value_node in node.value:
            name = self.key(key_node, "parameters")
            key = _key_path("parameters", name)
            if not IDENTIFIER_PATTERN.fullmatch(name):
                raise self.error(key_node, key, f"invalid parameter name {_shown(name)} "
                                 f"(expected {IDENTIFIER_PATTERN.pattern})")
            problem = parameter_name_problem(name, robot_name)
            if problem:
                raise self.error(key_node, key, f"parameter name {name!r} {problem}: {PARAMETER_NAME_RULE}")
            if name in self.values:
                raise self.error(key_node, key, "duplicate parameter")
            symbolic = False
            if isinstance(value_node, yaml.MappingNode):
                entries = self.mapping(value_node, key, ("value", "symbolic"), ("value",))
                if "symbolic" in entries:
                    symbolic = self.flag(entries["symbolic"], f"{key}.symbolic")
                value = self.value(entries["value"], f"{key}.value")
            else:
                value = self.value(value_node, key)
            parameter = Parameter(name, value.approx, symbolic)
            self.values[name] = Value(("symbol", name), value.approx) if symbolic else value
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
            fixed = self.value(entries[constant], f"{key}.{constant}", angle=constant == "theta", length=constant == "d")
            joints.append(Joint(
                name=name, kind=kind,
                a=self.value(entries["a"], f"{key}.a", length=True),
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
        items = self.sequence(node, key, 2)
        lower, upper = (self.value(item, f"{key}[{i}]", angle) for i, item in enumerate(items))
        if lower.approx > upper.approx:
            raise self.error(node, key, f"lower limit {_shown(items[0].value)} is above upper limit {_shown(items[1].value)}")
        if lower.approx == upper.approx:
            raise self.error(node, key, f"the limits are equal ({_shown(items[0].value)}): the joint could not move; "
                             "give it a range, or fold it into the neighbouring rows")
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
        problem = task_problem(names)
        if problem:
            raise self.error(node, "task", problem)
        return tuple(names)


    def characteristic_length(self, node) -> float:
        """`characteristic_length`: a positive number (or expression) in the file's length unit,
        fixed at generation time (it is printed into the generated constant)."""
        value = self.value(node, "characteristic_length")
        if value.symbolic:
            raise self.error(node, "characteristic_length", f"may not hold a symbolic parameter (it is a constant "
                             f"of the generated code), got {_shown(node.value)}")
        if not value.approx > 0:
            raise self.error(node, "characteristic_length", f"expected a positive length, got {_shown(node.value)}")
        return value.approx

    def flag(self, node, key: str) -> bool:
        """A YAML boolean."""
        if not (isinstance(node, yaml.ScalarNode) and node.tag == "tag:yaml.org,2002:bool"):
            raise self.error(node, key, f"expected true or false, got {_describe(node)}")
        return node.value.lower() in ("true", "yes", "on")

    def ik_options(self, node, joints: tuple[Joint, ...], task: tuple[str, ...]) -> tuple[int | None, bool]:
        """`ik: {free_joint: k, nearest_class: false}`: the free joint (0-based) and whether a
        calibrated arm may take the nearest special class's fast path."""
        entries = self.mapping(node, "ik", ("free_joint", "nearest_class"))
        free = self.free_joint(entries["free_joint"], joints, task) if "free_joint" in entries else None
        nearest_class = self.flag(entries["nearest_class"], "ik.nearest_class") if "nearest_class" in entries else True
        return free, nearest_class

    def free_joint(self, item, joints: tuple[Joint, ...], task: tuple[str, ...]) -> int:
        """`ik.free_joint` (1-based, as the joint table is read): a revolute joint of a 7-joint
        arm with the full pose task. Returned 0-based."""
        number = item.value if isinstance(item, yaml.ScalarNode) and item.tag == "tag:yaml.org,2002:int" else ""
        if not number.isdigit():
            raise self.error(item, "ik.free_joint", f"expected a joint number 1 to {len(joints)}, got {_describe(item)}")
        number = int(number)
        if not 1 <= number <= len(joints):
            raise self.error(item, "ik.free_joint", f"expected a joint number 1 to {len(joints)}, got {number}")
        if len(joints) != 7 or task != TASK_COMPONENTS:
            raise self.error(item, "ik.free_joint", f"a free joint needs 7 joints and the full pose task "
                             f"(one joint more than the task), not {len(joints)} joints for {len(task)} components")
        if not joints[number - 1].revolute:
            raise self.error(item, "ik.free_joint", f"joint {number} is prismatic: the free joint must be revolute")
        return number - 1


def task_problem(components: list[str]) -> str | None:
    """Why `components` (each one of TASK_COMPONENTS) is not a task, None when it is."""
    if not components:
        return "expected at least one component"
    if len(set(components)) != len(components) or components != sorted(components, key=TASK_COMPONENTS.index):
        canonical = ", ".join(sorted(set(components), key=TASK_COMPONENTS.index))
        return f"components must be distinct and in the order x, y, z, roll, pitch, yaw: write [{canonical}]"
    return None


def _scaled(value: Value, scale: Value) -> Value:
    return combined("mul", value.approx * scale.approx, value, scale)


def _snap_angle(value: Value) -> Value:
    """Exact k*pi/2 for an angle written as a decimal within tolerances.ANGLE_SNAP of it."""
    if value.symbolic:
        return value
    quarter_turns = round(value.approx / (math.pi / 2))
    if abs(value.approx - quarter_turns * math.pi / 2) < ANGLE_SNAP:
        return Value(("mul", ("integer", quarter_turns), ("div", ("pi",), ("integer", 2))), quarter_turns * math.pi / 2)
    return value


def _describe(node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    kinds = {"bool": "a boolean", "null": "nothing", "int": "a number", "float": "a number", "str": "a string"}
    kind = kinds.get(node.tag.rsplit(":", 1)[-1], "a value")
    return f"{kind} ({_shown(node.value)})" if node.value != "" else kind


def _shown(text: str, limit: int = 60) -> str:
    """User text quoted for a one-line message: escaped, and cut when long."""
    return repr(text) if len(text) <= limit else repr(text[:limit]) + "..."


def _key_path(parent: str, name: str) -> str:
    """`parent.name`, with a name that is not a plain word quoted."""
    shown = name if re.fullmatch(r"[\w<>-]{1,48}", name, re.ASCII) else _shown(name)
    return f"{parent}.{shown}" if parent else shown
