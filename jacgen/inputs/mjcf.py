"""MJCF files (MuJoCo's XML): bytes -> the serial chain between two bodies, with exact numbers,
as the same `LinkChain` a URDF gives (urdf.py), so that one DH fit serves both.

What is read (docs/mjcf.md): `<compiler angle eulerseq autolimits>`, `<include file>`,
`<default>` classes (nested, `class` and `childclass`), and in `<worldbody>` the bodies' and
frames' `pos` and orientation (`quat`, `axisangle`, `euler`, `xyaxes`, `zaxis`), their hinge
and slide joints (`pos`, `axis`, `range`, `limited`, `ref`) and sites. A body's frame follows
its parent's by its pose; its joint turns (or slides) it about the joint's axis through the
joint's position, by q - ref. A site is a tool frame. Anything else jacgen cannot represent
exactly on the chain (a body with two joints, a ball or free joint) is one RobotFileError.

The XML is read as URDFs are (urdf.parse_xml: no DOCTYPE, no entities, a size cap); an
include that includes itself, or more than MAX_INCLUDES files, is refused. Numbers keep their
decimal text as exact rationals: a quaternion's rotation is exact (its entries are rational in
the quaternion's, over its squared norm, as MuJoCo normalises it), and one within its written
digits of a quarter-turn rotation is that rotation (Snapper, as a URDF's rpy).
"""

from decimal import Decimal
from pathlib import Path

import sympy
from sympy import Matrix

from jacgen.errors import RobotFileError
from jacgen.inputs.robot_file import MAX_JOINTS
from jacgen.inputs.transforms import translation
from jacgen.inputs.urdf import (DIGITS, Element, LinkChain, Snapper, UrdfJoint, cos_sin, listed, number_of,
                                parse_xml, read_capped, snapped_axis)
from jacgen.tolerances import WRITTEN_ANGLE_SNAP, WRITTEN_ANGLE_UNITS

MAX_INCLUDES = 100
GENERATING = ("replicate", "attach", "composite", "flexcomp")  # elements that make bodies: refused
ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
DEFAULTED = ("joint", "site")  # the elements whose <default> settings the reader takes
JOINTS = ("joint", "freejoint")


def read_mjcf_chain(path: str, base: str | None = None, tip: str | None = None,
                    snapper: Snapper | None = None) -> LinkChain:
    """The chain of the MJCF file at `path` from the body `base` (default: the world) to the
    body or site `tip` (default: the one leaf body below `base`)."""
    reader = _MjcfReader(path, snapper or Snapper())
    return reader.chain(reader.model(path), base, tip)


class _MjcfReader:
    def __init__(self, path: str, snapper: Snapper):
        self.path, self.snapper = path, snapper
        self.angle_unit, self.sequence, self.autolimits = "degree", "xyz", True
        self.defaults: dict[str, tuple[str | None, dict[str, dict]]] = {}  # class -> (parent, attributes by tag)
        self.included = 0
        self.source: dict[int, str] = {}  # id(element) -> its file, for messages

    def error(self, element: Element, key: str, message: str) -> RobotFileError:
        return RobotFileError(self.source.get(id(element), self.path), element.line, element.column, key, message)

    # -- the file, its includes, compiler and defaults ------------------------------------------
    def model(self, path: str) -> Element:
        root = self.parse(path, ())
        if root.tag != "mujoco":
            raise self.error(root, root.tag, "expected a <mujoco> element (is this an MJCF file?)")
        for compiler in (c for c in root.children if c.tag == "compiler"):
            self.read_compiler(compiler)
        for default in (c for c in root.children if c.tag == "default"):
            self.read_default(default)
        return root

    def parse(self, path: str, including: tuple[str, ...], include: Element | None = None) -> Element:
        """The file's tree with every include replaced by the included file's elements."""
        if include is not None and not Path(path).is_file():
            raise self.error(include, "include.file", f"cannot read {include.attributes['file']!r}: no such file")
        root = parse_xml(read_capped(path), path, "an MJCF file")
        pending = [root]
        while pending:
            element = pending.pop()
            self.source[id(element)] = path
            children = []
            for child in element.children:
                if child.tag != "include":
                    children.append(child)
                    pending.append(child)
                    continue
                self.source[id(child)] = path
                name = child.attributes.get("file", "")
                if not name:
                    raise self.error(child, "include.file", "missing attribute 'file'")
                target = str(Path(self.path).parent / name)
                if Path(target).resolve() in {Path(p).resolve() for p in (*including, path)}:
                    raise self.error(child, "include.file",
                                     f"{name!r} includes itself (through {listed([*including, path])})")
                self.included += 1
                if self.included > MAX_INCLUDES:
                    raise self.error(child, "include.file", f"more than {MAX_INCLUDES} included files")
                included = self.parse(target, (*including, path), child)
                children.extend(included.children)  # the included file's <mujoco> is dropped
            element.children = children
        return root

    def read_compiler(self, compiler: Element) -> None:
        attributes = compiler.attributes
        self.angle_unit = attributes.get("angle", self.angle_unit)
        if self.angle_unit not in ("degree", "radian"):
            raise self.error(compiler, "compiler.angle", f"expected degree or radian, got {self.angle_unit!r}")
        self.sequence = attributes.get("eulerseq", self.sequence)
        if len(self.sequence) != 3 or any(c not in "xyzXYZ" for c in self.sequence):
            raise self.error(compiler, "compiler.eulerseq", f"expected 3 of x, y, z, X, Y, Z, got {self.sequence!r}")
        self.autolimits = attributes.get("autolimits", "true") == "true"

    def read_default(self, top: Element) -> None:
        """A top-level <default> and the classes nested in it (no recursion: a hostile file may
        nest them deeply). The top-level one of every file, an included one's too, is the class
        main, whose settings the later ones add to."""
        pending: list[tuple[Element, str | None]] = [(top, None)]
        while pending:
            element, parent = pending.pop()
            name = element.attributes.get("class", "main") if parent is not None else "main"
            if name in self.defaults and name != "main":
                raise self.error(element, f"default[{name}]", "duplicate default class")
            settings = self.defaults.setdefault(name, (parent, {}))[1]
            for child in element.children:
                if child.tag in DEFAULTED:
                    settings[child.tag] = settings.get(child.tag, {}) | child.attributes
                elif child.tag == "default":
                    pending.append((child, name))

    def attribute(self, element: Element, name: str, class_name: str) -> str | None:
        """The element's attribute, else its class's default, else the class's parents'."""
        if name in element.attributes:
            return element.attributes[name]
        class_name = element.attributes.get("class", class_name)
        if class_name not in self.defaults and class_name != "main":
            raise self.error(element, f"{element.tag}.class", f"no default class {class_name!r}")
        while class_name is not None and class_name in self.defaults:
            parent, settings = self.defaults[class_name]
            if name in settings.get(element.tag, {}):
                return settings[element.tag][name]
            class_name = parent
        return None

    # -- the tree of bodies ----------------------------------------------------------------------
    def chain(self, root: Element, base: str | None, tip: str | None) -> LinkChain:
        worlds = [c for c in root.children if c.tag == "worldbody"]
        if not worlds:
            raise self.error(root, "mujoco", "no <worldbody>")
        world = Element("worldbody", {}, worlds[0].line, worlds[0].column,
                        [child for w in worlds for child in w.children])  # a file's worldbody sections are one
        parent: dict[int, Element] = {}
        bodies: dict[str, Element] = {}
        sites: dict[str, Element] = {}
        pending = [world]
        while pending:
            element = pending.pop()
            for child in element.children:
                if child.tag in GENERATING:
                    raise self.error(child, child.tag, f"<{child.tag}> makes bodies that jacgen does not read: save "
                                     "the model without it (MuJoCo's mj_saveLastXML writes it out) and import that")
                if child.tag in ("body", "frame"):
                    parent[id(child)] = element
                    pending.append(child)
                    name = child.attributes.get("name", "") if child.tag == "body" else ""
                    if name in bodies:
                        raise self.error(child, f"body[{name}]", f"duplicate body name (also line {bodies[name].line})")
                    if name:
                        bodies[name] = child
                elif child.tag == "site" and child.attributes.get("name"):
                    parent[id(child)] = element
                    sites[child.attributes["name"]] = child
        start = world
        if base is not None:
            if base not in bodies:
                raise RobotFileError(self.path, root.line, root.column, "--base", f"no body named {base!r}")
            start = bodies[base]
        if tip is None:
            leaves = self.leaves(start)
            if len(leaves) != 1:
                names = sorted(leaf.attributes.get("name", f"line {leaf.line}") for leaf in leaves)
                above = "the world" if base is None else f"body {base!r}"
                raise RobotFileError(self.path, root.line, root.column, "--tip",
                                     f"{above} has {len(leaves)} leaf bodies below it ({listed(names)}): name the "
                                     "tool body or site with --tip")
            end = leaves[0]
        elif tip in bodies:
            end = bodies[tip]
        elif tip in sites:
            end = sites[tip]
        else:
            raise RobotFileError(self.path, root.line, root.column, "--tip", f"no body or site named {tip!r}")
        route, element = [], end
        while element is not start:
            if id(element) not in parent:
                raise RobotFileError(self.path, root.line, root.column, "--base",
                                     f"body {base!r} is not above {tip!r}: choose one of the tip's ancestors")
            route.append(element)
            element = parent[id(element)]
        above, class_name = start, "main"  # the class the start's children default to: its own or an ancestor's
        while class_name == "main" and above is not None:
            class_name = above.attributes.get("childclass", "main")
            above = parent.get(id(above))
        tip = tip or end.attributes.get("name", f"the body at line {end.line}")
        moving = sum(c.tag in JOINTS for e in route if e.tag == "body" for c in e.children)
        if not moving:  # counted before any pose is computed: a hostile chain is refused at once
            raise RobotFileError(self.path, root.line, root.column, "", "no hinge or slide joint between "
                                 f"{'the world' if base is None else repr(base)} and {tip!r}")
        if moving > MAX_JOINTS:
            raise RobotFileError(self.path, root.line, root.column, "", f"the chain has {moving} joints; "
                                 f"a robot file holds at most {MAX_JOINTS}")
        joints: list[UrdfJoint] = []
        for element in reversed(route):
            joints += self.frame(element, class_name)
            class_name = element.attributes.get("childclass", class_name)
        folded = tuple(e.attributes.get("name", f"{e.tag}@{e.line}") for e in reversed(route)
                       if not any(c.tag in JOINTS for c in e.children))
        return LinkChain(root.attributes.get("model", ""), base or "world", tip, sympy.eye(4), tuple(joints), folded)

    @staticmethod
    def leaves(start: Element) -> list[Element]:
        found, pending = [], [start]
        while pending:
            element = pending.pop()
            below = [c for c in element.children if c.tag in ("body", "frame")]
            if not below and element is not start and element.tag == "body":
                found.append(element)
            pending.extend(below)
        return found

    def frame(self, element: Element, class_name: str) -> list[UrdfJoint]:
        """The chain's entries of one body, frame or site below its parent: its pose (a fixed
        entry), then its joint, turning or sliding about the joint's axis through its `pos`."""
        name = element.attributes.get("name", f"{element.tag}@{element.line}")
        key = f"{element.tag}[{name}]"
        own_class = element.attributes.get("childclass", class_name)  # its joint's
        pose = translation(*self.vector(element, key, "pos", class_name)) * self.orientation(element, key, class_name)
        entries = [UrdfJoint(name, "fixed", pose, Matrix([1, 0, 0]), None)]
        if element.tag != "body":
            return entries
        joints = [c for c in element.children if c.tag in JOINTS]
        if len(joints) > 1:
            raise self.error(joints[1], key, f"body {name!r} has {len(joints)} joints: a DH row moves one joint "
                             "per body; give each joint a body of its own")
        if not joints:
            return entries
        joint = joints[0]
        joint_name = joint.attributes.get("name", f"{name}_joint")
        joint_key = f"{key}.joint[{joint_name}]"
        kind = "free" if joint.tag == "freejoint" else self.attribute(joint, "type", own_class) or "hinge"
        if kind not in ("hinge", "slide"):
            raise self.error(joint, f"{joint_key}.type", f"a {kind} joint is on the chain: jacgen models serial arms "
                             "of hinge (revolute) and slide (prismatic) joints")
        at = translation(*self.vector(joint, joint_key, "pos", own_class))
        axis = self.axis(joint, joint_key, own_class)
        written = self.attribute(joint, "ref", own_class)
        reference = self.number(written or "0", joint, f"{joint_key}.ref")
        limits = self.limits(joint, joint_key, kind, own_class)
        if kind == "hinge":
            reference = self.angle(reference, written)
            moved = rotation_about(axis, -reference) if reference != 0 else sympy.eye(4)
        else:
            moved = translation(*(-reference * axis))
        kind = "prismatic" if kind == "slide" else "revolute" if limits is not None else "continuous"
        return [*entries, UrdfJoint(f"{joint_name}@", "fixed", at * moved, axis, None),
                UrdfJoint(joint_name, kind, sympy.eye(4), axis, limits),
                UrdfJoint(f"{joint_name}@back", "fixed", translation(*(-v for v in at[:3, 3])), axis, None)]

    # -- numbers -----------------------------------------------------------------------------------
    def number(self, text: str, element: Element, key: str) -> sympy.Rational:
        return number_of(text, lambda message: self.error(element, key, message))

    def numbers(self, element: Element, key: str, name: str, class_name: str, count: int) -> list | None:
        text = self.attribute(element, name, class_name)
        if text is None:
            return None
        parts = text.split()
        if len(parts) != count:
            raise self.error(element, f"{key}.{name}", f"expected {count} numbers, got {len(parts)}")
        return [self.number(part, element, f"{key}.{name}") for part in parts]

    def vector(self, element: Element, key: str, name: str, class_name: str) -> list:
        return self.numbers(element, key, name, class_name, 3) or [sympy.Integer(0)] * 3

    def angle(self, value: sympy.Expr, text: str | None) -> sympy.Expr:
        """An angle in the compiler's unit, in radians (exact k*pi/2 when so to its digits)."""
        if self.angle_unit == "degree":  # exact: a multiple of pi
            return self.snapper.angle(value * sympy.pi / 180, None)
        return self.snapper.angle(value, text)

    def axis(self, joint: Element, key: str, class_name: str) -> Matrix:
        vector = Matrix(self.numbers(joint, key, "axis", class_name, 3) or [0, 0, 1])
        axis = snapped_axis(vector, self.snapper)
        if axis is None:
            raise self.error(joint, f"{key}.axis", "the axis is zero")
        return axis

    def limits(self, joint: Element, key: str, kind: str, class_name: str) -> tuple[str, str] | None:
        limited = self.attribute(joint, "limited", class_name) or "auto"
        given = self.numbers(joint, key, "range", class_name, 2)
        if limited not in ("true", "false", "auto"):
            raise self.error(joint, f"{key}.limited", f"expected true, false or auto, got {limited!r}")
        if limited == "false" or (limited == "auto" and (not self.autolimits or given is None)):
            return None
        if given is None:
            raise self.error(joint, f"{key}.range", "limited without a range: give the range")
        low, high = given
        if low >= high:
            raise self.error(joint, f"{key}.range", f"the range's low end {float(low):g} is not below its high end "
                             f"{float(high):g}: give it a range, or no joint")
        if kind == "hinge" and self.angle_unit == "degree":
            return tuple(repr(float(v * sympy.pi / 180)) for v in (low, high))
        return tuple(str(Decimal(v.p) / Decimal(v.q)) for v in (low, high))

    def orientation(self, element: Element, key: str, class_name: str) -> Matrix:
        """The rotation of the element's frame (4 x 4), from the one orientation it gives."""
        given = [name for name in ORIENTATIONS if self.attribute(element, name, class_name) is not None]
        if len(given) > 1:
            raise self.error(element, key, f"{' and '.join(given)} both orient it: give one")
        if not given:
            return sympy.eye(4)
        name = given[0]
        text = self.attribute(element, name, class_name)
        place = f"{key}.{name}"
        if name == "quat":
            w, x, y, z = self.numbers(element, key, name, class_name, 4)
            norm = w**2 + x**2 + y**2 + z**2
            if norm == 0:
                raise self.error(element, place, "the quaternion is zero")
            rotation = Matrix([[w**2 + x**2 - y**2 - z**2, 2 * (x * y - w * z), 2 * (x * z + w * y)],
                               [2 * (x * y + w * z), w**2 - x**2 + y**2 - z**2, 2 * (y * z - w * x)],
                               [2 * (x * z - w * y), 2 * (y * z + w * x), w**2 - x**2 - y**2 + z**2]]) / norm
            return self.snapped(rotation, text)
        if name == "axisangle":
            *direction, angle = self.numbers(element, key, name, class_name, 4)
            axis = snapped_axis(Matrix(direction), self.snapper)
            if axis is None:
                raise self.error(element, place, "the axis is zero")
            return rotation_about(axis, self.angle(angle, text.split()[3]))
        if name == "euler":
            angles = self.numbers(element, key, name, class_name, 3)
            result = sympy.eye(4)
            for letter, angle, written in zip(self.sequence, angles, text.split()):
                turn = rotation_about(Matrix([int(letter.lower() == c) for c in "xyz"]), self.angle(angle, written))
                result = result * turn if letter.islower() else turn * result
            return result
        if name == "xyaxes":
            values = self.numbers(element, key, name, class_name, 6)
            x, y = Matrix(values[:3]), Matrix(values[3:])
            if x.norm() == 0:
                raise self.error(element, place, "the x axis is zero")
            x = x / x.norm()
            y = y - x * x.dot(y)
            if y.norm() == 0:
                raise self.error(element, place, "the y axis is parallel to the x axis")
            y = y / y.norm()
            return self.snapped(Matrix.hstack(x, y, x.cross(y)), text)
        z = Matrix(self.numbers(element, key, name, class_name, 3))
        if z.norm() == 0:
            raise self.error(element, place, "the z axis is zero")
        z = z / z.norm()
        turn = Matrix([0, 0, 1]).cross(z)
        if turn.norm() == 0:
            return sympy.eye(4) if z[2] > 0 else rotation_about(Matrix([1, 0, 0]), sympy.pi)
        return self.snapped(rotation_about(turn / turn.norm(), sympy.acos(z[2]))[:3, :3], text)

    def snapped(self, rotation: Matrix, text: str) -> Matrix:
        """A rotation (3 x 3) that is a quarter-turn one to the digits its numbers are written
        with (as Snapper.angle) made exactly that one; others to DIGITS digits unless exact."""
        rounded = Matrix(3, 3, lambda r, c: int(round(float(rotation[r, c]))))
        change = max(abs(float(rotation[r, c]) - rounded[r, c]) for r in range(3) for c in range(3))
        # The finest digit written: MuJoCo writes 6 significant digits and drops trailing zeros,
        # so "0.5" beside "0.499998" is 0.500000.
        decimals = [part for part in text.split() if Decimal(part).as_tuple().exponent < 0]  # not "0", "1"
        unit = min((float(Decimal(1).scaleb(Decimal(part).as_tuple().exponent)) for part in decimals), default=0.0)
        quarter_turns = rounded * rounded.T == sympy.eye(3) and rounded.det() == 1
        if quarter_turns and self.snapper.close(change, self.snapper.written_tolerance(
                min(WRITTEN_ANGLE_UNITS * unit, WRITTEN_ANGLE_SNAP))):
            rotation = rounded
        elif rotation.has(sympy.Float) or any(not e.is_Rational for e in rotation):
            rotation = rotation.evalf(DIGITS)
        result = sympy.eye(4)
        result[:3, :3] = rotation
        return result


def rotation_about(axis: Matrix, angle: sympy.Expr) -> Matrix:
    """The 4 x 4 rotation by `angle` about the unit `axis` (Rodrigues), exact where cos and sin are."""
    c, s = cos_sin(angle)
    x, y, z = axis
    skew = Matrix([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    result = sympy.eye(4)
    result[:3, :3] = sympy.eye(3) + s * skew + (1 - c) * skew * skew
    return result
