"""URDF files: bytes -> the serial chain between two links, with exact numbers.

XML is hostile input. It is parsed by the standard library's expat with every DOCTYPE
refused, so no entity can be declared: neither entity expansion ("billion laughs") nor
external entities can happen, and an undeclared entity is an XML error. The tree is built
without recursion and the file size is capped. Every mistake is one RobotFileError naming
the file, line, column and element path.

Numbers keep their decimal text as exact rationals. An angle that is a multiple of pi/2 to the
digits it is written with (Snapper) and an axis within tolerances.ANGLE_SNAP of +-x/y/z become
exact, and the largest change this makes is recorded; everything else is a 30-digit float.
"""

import math
from dataclasses import dataclass, field
from decimal import Decimal
from pathlib import Path
from xml.parsers import expat

import numpy as np
import sympy
from sympy import Matrix

from jacgen.errors import RobotFileError
from jacgen.inputs import values
from jacgen.inputs.robot_file import MAX_JOINTS
from jacgen.inputs.transforms import xyz_rpy_transform
from jacgen.inputs.values import ExpressionError
from jacgen.tolerances import ANGLE_SNAP, WRITTEN_ANGLE_UNITS, WRITTEN_ANGLE_SNAP

MAX_URDF_BYTES = 16 << 20
DIGITS = 30  # of the numbers that are not exact (cos and sin of general angles)
MOVABLE = ("revolute", "continuous", "prismatic")
JOINT_TYPES = MOVABLE + ("fixed", "floating", "planar")


@dataclass
class Element:
    """An XML element: its tag, attributes, position (1-based) and children."""

    tag: str
    attributes: dict[str, str]
    line: int
    column: int
    children: list["Element"] = field(default_factory=list)

    def child(self, tag: str) -> "Element | None":
        return next((c for c in self.children if c.tag == tag), None)


@dataclass(frozen=True)
class UrdfJoint:
    """A joint of the chain: the transform from the parent link to the joint frame (exact
    4x4), the unit axis in the joint frame, and the URDF's limit text (None for none)."""

    name: str
    kind: str
    origin: Matrix
    axis: Matrix
    limits: tuple[str, str] | None


@dataclass(frozen=True)
class LinkChain:
    """The joints from `base` to `tip`: `start` is the transform from `base` to the first
    joint's parent link (the identity unless `base` hangs below it on fixed joints)."""

    robot_name: str
    base: str
    tip: str
    start: Matrix
    joints: tuple[UrdfJoint, ...]
    folded: tuple[str, ...]  # the fixed joints on the way, whose transforms are folded in


class Snapper:
    """Makes angles and directions that are nearly exact (a multiple of pi/2, a coordinate axis)
    exact, and remembers the largest change that made.

    With no `tolerance` (the default) a URDF angle is k*pi/2 (k != 0) when it is so to the digits
    it is written with: within WRITTEN_ANGLE_UNITS units of its last digit, and within
    WRITTEN_ANGLE_SNAP rad. `1.5708`, `1.57079632679` and `1.570796325` are pi/2; `1.6` is not, nor
    is a calibration's `1.6e-06`, whose digits are all significant. Any value within ANGLE_SNAP
    is exact too. An angle computed from the URDF's (a DH twist, the angle between two axes)
    is exact within the sum of the last-digit units of the general angles written on the chain:
    they are known to no better. With a `tolerance`, every test uses that tolerance alone."""

    def __init__(self, tolerance: float | None = None):
        self.tolerance, self.largest = tolerance, 0.0
        self.written_units = 0.0  # of the angles read that were not made exact

    def close(self, change: float, tolerance: float | None = None) -> bool:
        """Whether a value `change` away from exact is to be made exact (recorded if so): within
        `tolerance`, by default the one of values computed from the URDF's."""
        if change < (self.computed_tolerance() if tolerance is None else tolerance):
            self.largest = max(self.largest, change)
            return True
        return False

    def computed_tolerance(self) -> float:
        """The tolerance of a value computed from the URDF's."""
        return self.written_tolerance(min(self.written_units, WRITTEN_ANGLE_SNAP))

    def written_tolerance(self, digits: float = 0.0) -> float:
        """The tolerance of a value whose written digits allow it to be `digits` off exact."""
        return self.tolerance if self.tolerance is not None else max(ANGLE_SNAP, digits)

    def angle(self, value: sympy.Expr, text: str | None = None) -> sympy.Expr:
        """Exactly k*pi/2 when nearly so; otherwise the value itself. `text` is the decimal the
        URDF writes for it, if any."""
        quarter_turns = round(float(value) / (math.pi / 2))
        change = abs(float(value) - quarter_turns * math.pi / 2)
        tolerance = None
        if text is not None:
            unit = float(Decimal(1).scaleb(Decimal(text).as_tuple().exponent))
            tolerance = self.written_tolerance(min(WRITTEN_ANGLE_UNITS * unit, WRITTEN_ANGLE_SNAP) if quarter_turns else 0.0)
        if self.close(change, tolerance):
            return quarter_turns * sympy.pi / 2
        if text is not None and value != 0:
            self.written_units += unit
        return value


def parse_xml(data: bytes, path: str, what: str = "a URDF") -> Element:
    """The element tree of `data`, read as UTF-8 whatever encoding it declares (ROS reads URDFs
    so); refuses a DOCTYPE, so entities can never be declared."""
    parser = expat.ParserCreate(encoding="utf-8")
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    stack: list[Element] = []
    roots: list[Element] = []

    def position():
        return parser.CurrentLineNumber, parser.CurrentColumnNumber + 1

    def refuse_doctype(*_):
        raise RobotFileError(path, *position(), "", f"a DOCTYPE is not allowed in {what} (its entities "
                             "could expand without bound or read other files)")

    def start(tag, attributes):
        element = Element(tag, attributes, *position())
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    parser.StartDoctypeDeclHandler = refuse_doctype
    parser.StartElementHandler = start
    parser.EndElementHandler = lambda tag: stack.pop()
    try:
        parser.Parse(data, True)
    except expat.ExpatError as error:
        raise RobotFileError(path, error.lineno, error.offset + 1, "",
                             f"invalid XML: {expat.errors.messages[error.code]}") from None
    return roots[0]


def read_chain(path: str, base: str | None = None, tip: str | None = None, snapper: Snapper | None = None) -> LinkChain:
    """The chain of the URDF file at `path` from `base` (default: the root) to `tip`
    (default: the one leaf below `base`); `snapper` makes nearly exact angles and axes exact."""
    return _UrdfReader(path, snapper or Snapper()).chain(parse_xml(read_capped(path), path), base, tip)


def read_capped(path: str) -> bytes:
    """The bytes of the XML file at `path`, refused (RobotFileError) past MAX_URDF_BYTES."""
    try:
        data = Path(path).read_bytes()
    except OSError as error:
        raise RobotFileError(path, 1, 1, "", f"cannot read file: {error.strerror or error}") from None
    if len(data) > MAX_URDF_BYTES:
        raise RobotFileError(path, 1, 1, "", f"file larger than {MAX_URDF_BYTES} bytes")
    return data


class _UrdfReader:
    def __init__(self, path: str, snapper: Snapper):
        self.path, self.snapper = path, snapper

    def error(self, element: Element, key: str, message: str) -> RobotFileError:
        return RobotFileError(self.path, element.line, element.column, key, message)

    def name(self, element: Element, key: str) -> str:
        name = element.attributes.get("name", "")
        if not name:
            raise self.error(element, key, "missing attribute 'name'")
        return name

    def chain(self, root: Element, base: str | None, tip: str | None) -> LinkChain:
        if root.tag != "robot":
            raise self.error(root, root.tag, "expected a <robot> element (is this a URDF?)")
        links = self.declared(root, "link")
        joints = self.declared(root, "joint")
        parent_joint: dict[str, Element] = {}
        children: dict[str, list[Element]] = {name: [] for name in links}
        for name, joint in joints.items():
            key = f"joint[{name}]"
            parent, child = (self.link_of(joint, role, key, links) for role in ("parent", "child"))
            if child in parent_joint:
                raise self.error(joint, key, f"link {child!r} is already the child of joint "
                                 f"{parent_joint[child].attributes['name']!r}: a URDF is a tree")
            parent_joint[child] = joint
            children[parent].append(joint)
        roots = [name for name in links if name not in parent_joint]
        if len(roots) != 1:
            what = "no link" if not roots else f"{len(roots)} links ({listed(roots)})"
            raise self.error(root, "robot", f"{what} without a parent joint: a URDF has one root")
        reachable, pending = {roots[0]}, [roots[0]]
        while pending:
            for joint in children[pending.pop()]:
                child = joint.child("child").attributes["link"]
                reachable.add(child)
                pending.append(child)
        if len(reachable) != len(links):
            loop = sorted(set(links) - reachable)
            raise self.error(joints[parent_joint[loop[0]].attributes["name"]], "robot",
                             f"the joints of links {listed(loop)} form a loop")

        base = base or roots[0]
        for option, name in (("--base", base), ("--tip", tip)):
            if name is not None and name not in links:
                raise RobotFileError(self.path, root.line, root.column, option, f"no link named {name!r}")
        if tip is None:
            tip = self.only_leaf(root, base, children)
        up, down = self.route(base, tip, parent_joint)
        for joint in up:
            if joint.attributes.get("type") != "fixed":
                raise self.error(joint, f"joint[{joint.attributes['name']}]",
                                 f"link {base!r} is below joint {joint.attributes['name']!r}, which moves, "
                                 f"on the way to {tip!r}: choose a base on the tip's side of it")
        start = sympy.eye(4)
        for joint in up:  # base -> common ancestor: the fixed transforms, inverted
            start = inverse_transform(self.joint(joint).origin) * start
        chain = [self.joint(j) for j in down]
        moving = [j for j in down if j.attributes.get("type") in MOVABLE]
        if not moving:
            raise RobotFileError(self.path, root.line, root.column, "", f"no moving joint between "
                                 f"links {base!r} and {tip!r}")
        if len(moving) > MAX_JOINTS:
            raise self.error(moving[MAX_JOINTS], f"joint[{moving[MAX_JOINTS].attributes['name']}]",
                             f"the chain {base!r} -> {tip!r} has {len(moving)} moving joints; a robot file "
                             f"holds at most {MAX_JOINTS}")
        folded = tuple(j.attributes["name"] for j in up) + tuple(j.name for j in chain if j.kind == "fixed")
        return LinkChain(root.attributes.get("name", ""), base, tip, start, tuple(chain), folded)

    def declared(self, root: Element, tag: str) -> dict[str, Element]:
        found: dict[str, Element] = {}
        for element in root.children:
            if element.tag == tag:
                name = self.name(element, tag)
                if name in found:
                    raise self.error(element, f"{tag}[{name}]", f"duplicate {tag} name (also line "
                                     f"{found[name].line})")
                found[name] = element
        return found

    def link_of(self, joint: Element, role: str, key: str, links) -> str:
        element = joint.child(role)
        if element is None:
            raise self.error(joint, f"{key}.{role}", "missing element")
        link = element.attributes.get("link", "")
        if link not in links:
            raise self.error(element, f"{key}.{role}.link", f"no link named {link!r}" if link
                             else "missing attribute 'link'")
        return link

    def only_leaf(self, root: Element, base: str, children) -> str:
        leaves, pending = [], [base]
        while pending:
            link = pending.pop()
            below = [joint.child("child").attributes["link"] for joint in children[link]]
            if not below:
                leaves.append(link)
            pending.extend(below)
        if len(leaves) != 1:
            raise RobotFileError(self.path, root.line, root.column, "--tip",
                                 f"link {base!r} has {len(leaves)} leaves below it ({listed(sorted(leaves))}): "
                                 f"name the tool link with --tip")
        return leaves[0]

    @staticmethod
    def route(base: str, tip: str, parent_joint) -> tuple[list[Element], list[Element]]:
        """The joints from base up to the common ancestor, and from there down to tip."""

        def ancestry(link):
            joints = []
            while link in parent_joint:
                joints.append(parent_joint[link])
                link = parent_joint[link].child("parent").attributes["link"]
            return joints

        up, down = ancestry(base), ancestry(tip)
        while up and down and up[-1] is down[-1]:
            up.pop()
            down.pop()
        return up, down[::-1]

    def joint(self, element: Element) -> UrdfJoint:
        name = element.attributes["name"]
        key = f"joint[{name}]"
        kind = element.attributes.get("type", "")
        if kind not in JOINT_TYPES:
            raise self.error(element, f"{key}.type", f"expected one of {', '.join(JOINT_TYPES)}, got {kind!r}")
        if kind in ("floating", "planar"):
            raise self.error(element, f"{key}.type", f"a {kind} joint is on the chain: jacgen models "
                             "serial arms of revolute and prismatic joints")
        mimic = element.child("mimic")
        if mimic is not None:
            raise self.error(mimic, f"{key}.mimic", "a mimic joint is on the chain: its value follows "
                             "another joint's, and a DH row needs a joint of its own")
        origin = element.child("origin")
        xyz = self.numbers(origin, f"{key}.origin", "xyz")
        rpy_text = (origin.attributes.get("rpy", "0 0 0") if origin is not None else "0 0 0").split()
        rpy = [self.snapper.angle(value, text) for value, text in
               zip(self.numbers(origin, f"{key}.origin", "rpy"), rpy_text)]
        transform = xyz_rpy_transform(xyz, rpy, cos_sin)
        axis = Matrix([1, 0, 0])
        limits = None
        if kind in MOVABLE:
            axis_element = element.child("axis")
            if axis_element is not None:
                axis = self.axis(axis_element, f"{key}.axis")
            limit = element.child("limit")
            if kind != "continuous" and limit is not None and ("lower" in limit.attributes or "upper" in limit.attributes):
                lower, upper = (limit.attributes.get(side, "0") for side in ("lower", "upper"))
                low, high = (self.number(text, limit, f"{key}.limit.{side}") for side, text in
                             (("lower", lower), ("upper", upper)))
                if low > high:
                    raise self.error(limit, f"{key}.limit", f"lower limit {lower!r} is above upper limit {upper!r}")
                if low == high:
                    raise self.error(limit, f"{key}.limit", f"the limits are equal ({lower!r}): the joint could not "
                                     "move; give it a range, or make it a fixed joint")
                limits = (lower.strip(), upper.strip())
        return UrdfJoint(name, kind, transform, axis, limits)

    def number(self, text: str, element: Element, key: str) -> sympy.Rational:
        return number_of(text, lambda message: self.error(element, key, message))

    def numbers(self, element: Element | None, key: str, attribute: str) -> list[sympy.Rational]:
        if element is None or attribute not in element.attributes:
            return [sympy.Integer(0)] * 3
        parts = element.attributes[attribute].split()
        if len(parts) != 3:
            raise self.error(element, f"{key}.{attribute}", f"expected 3 numbers, got {len(parts)}")
        return [self.number(part, element, f"{key}.{attribute}") for part in parts]

    def axis(self, element: Element, key: str) -> Matrix:
        axis = snapped_axis(Matrix(self.numbers(element, key, "xyz")), self.snapper)
        if axis is None:
            raise self.error(element, f"{key}.xyz", "the axis is zero")
        return axis


def number_of(text: str, error) -> sympy.Rational:
    """A decimal, exact, by the robot files' bounded number parser; `error(message)` is raised."""
    try:
        return values.number(text.strip(" \t\r\n")).exact
    except ExpressionError as problem:
        hint = " (a xacro file? run xacro on it first)" if "$" in text else ""
        raise error(f"{problem}{hint}") from None


def snapped_axis(vector: Matrix, snapper: Snapper) -> Matrix | None:
    """The unit axis along `vector`: +-x, +-y or +-z exactly where it is within the snapper's
    written tolerance of one; None for a zero vector."""
    length = math.sqrt(sum(float(v) ** 2 for v in vector))
    if length < 1e-9:
        return None
    unit = [float(v) / length for v in vector]
    for k in range(3):
        for sign in (1, -1):
            if snapper.close(math.dist(unit, [sign * (i == k) for i in range(3)]), snapper.written_tolerance()):
                return Matrix([sign * int(i == k) for i in range(3)])
    return (vector / sympy.sqrt(sum(v**2 for v in vector))).evalf(DIGITS)


def listed(names: list[str], limit: int = 10) -> str:
    shown = ", ".join(repr(n) for n in names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


def cos_sin(angle: sympy.Expr) -> tuple[sympy.Expr, sympy.Expr]:
    """Exact for multiples of pi/2 (which snapping made exact), 30 digits otherwise."""
    if (angle / (sympy.pi / 2)).is_integer:
        return sympy.cos(angle), sympy.sin(angle)
    return sympy.cos(angle).evalf(DIGITS), sympy.sin(angle).evalf(DIGITS)


def inverse_transform(transform: Matrix) -> Matrix:
    rotation = transform[:3, :3].T
    inverse = sympy.eye(4)
    inverse[:3, :3] = rotation
    inverse[:3, 3] = -rotation * transform[:3, 3]
    return inverse


def joint_axes(chain: LinkChain, q) -> tuple[list[tuple[np.ndarray, np.ndarray]], np.ndarray]:
    """The URDF's own kinematics at q (n,) or a batch (..., n), its joint transforms multiplied
    out in floats (no DH involved): each moving joint's axis line (a point on it and its unit
    direction, (..., 3) each, in the base link's frame) and the tip link's pose (..., 4, 4)."""
    q = np.asarray(q, dtype=float)
    frame = np.broadcast_to(np.array(chain.start.evalf(), dtype=float), (*q.shape[:-1], 4, 4))
    movable, axes = iter(np.moveaxis(q, -1, 0)), []
    for joint in chain.joints:
        frame = frame @ np.array(joint.origin.evalf(), dtype=float)
        if joint.kind in MOVABLE:
            value = next(movable)[..., None, None]
            axis = np.array(joint.axis.evalf(), dtype=float).ravel()
            axes.append((frame[..., :3, 3], frame[..., :3, :3] @ axis))
            motion = np.broadcast_to(np.eye(4), frame.shape).copy()
            if joint.kind == "prismatic":
                motion[..., :3, 3] = value[..., 0] * axis
            else:  # Rodrigues
                skew = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
                motion[..., :3, :3] = np.eye(3) + np.sin(value) * skew + (1 - np.cos(value)) * skew @ skew
            frame = frame @ motion
    return axes, frame
