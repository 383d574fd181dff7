"""`jacgen import-urdf` and `import-mjcf`: a URDF's or an MJCF file's chain -> the text of a
robot file, checked before it is written.

Stages: urdf.read_chain or mjcf.read_mjcf_chain (XML -> exact joint transforms, one LinkChain),
dh_fit.fit (axes -> DH table), then this module writes the robot file, chooses the task of an
arm with fewer than six joints, and compares the file's fk with a plain walk of the chain.
"""

import hashlib
import re
import math
from dataclasses import dataclass, replace
from typing import Callable
from decimal import Context, Decimal
from pathlib import Path

import numpy as np
import sympy
import yaml

from jacgen.checking import reference
from jacgen.errors import JacgenError, RobotFileError
from jacgen.inputs.dh_fit import Axis, Table, exact_or_float, fit
from jacgen.inputs.names import robot_name_problem
from jacgen.inputs import values
from jacgen.inputs.values import ExpressionError
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.inputs.robot_file import (FORBIDDEN_IN_TEXT, IDENTIFIER_PATTERN, NAME_PATTERN, SMALLEST_LENGTH, parse_robot,
                                      task_problem)
from jacgen.inputs.mjcf import read_mjcf_chain
from jacgen.inputs.urdf import MOVABLE, LinkChain, Snapper, joint_axes, read_chain
from jacgen.version import __version__

CHECK_CONFIGURATIONS = 20
CHECK_SEED = 0
# Consecutive axes less than NEARLY_PARALLEL rad from parallel, whose common normal puts DH
# lengths more than FAR_NORMAL times the URDF chain's own extent away, are refused with the
# --snap that makes them parallel (docs/urdf.md). MAX_SNAP is --snap's largest value.
NEARLY_PARALLEL = 1e-3
FAR_NORMAL = 10
MAX_SNAP = 1e-2


@dataclass(frozen=True)
class Format:
    """A description format: its reader, command, the word for its frames, and its name."""

    read: Callable  # (path, base, tip, snapper) -> LinkChain
    command: str
    frames: str
    name: str
    fixed: str  # what of the chain does not move


URDF = Format(read_chain, "import-urdf", "links", "URDF", "fixed joints")
MJCF = Format(read_mjcf_chain, "import-mjcf", "bodies", "MJCF file", "bodies, frames and sites without a joint")
FORMATS = {"urdf": URDF, "mjcf": MJCF}


@dataclass(frozen=True)
class Imported:
    """A robot file made from a URDF: its text, the robot it reads as, the largest difference
    of its fk from the URDF's as written (entries of the 4x4 pose) at CHECK_CONFIGURATIONS
    random configurations, the largest change (radians) that making angles exact caused, and
    the lengths the fit computed at rounding level that were made 0 (key, value)."""

    text: str
    robot: Robot
    fk_difference: float
    snapped: float
    zeroed: tuple[tuple[str, float], ...] = ()


def import_urdf(path: str, base: str | None = None, tip: str | None = None, convention: str = "standard",
                name: str | None = None, task: tuple[str, ...] | None = None,
                snap: float | None = None) -> Imported:
    """The robot file for the chain of `path`, checked against the URDF's own fk. `snap` is the
    tolerance of the angles made exact (default: each URDF angle's own written digits, Snapper)."""
    return import_description(URDF, path, base, tip, convention, name, task, snap)


def import_mjcf(path: str, base: str | None = None, tip: str | None = None, convention: str = "standard",
                name: str | None = None, task: tuple[str, ...] | None = None,
                snap: float | None = None) -> Imported:
    """import_urdf for an MJCF file: the chain from the body `base` (default: the world) to the
    body or site `tip` (default: the one leaf body)."""
    return import_description(MJCF, path, base, tip, convention, name, task, snap)


def import_description(form: "Format", path: str, base: str | None = None, tip: str | None = None,
                       convention: str = "standard", name: str | None = None, task: tuple[str, ...] | None = None,
                       snap: float | None = None) -> Imported:
    """import_urdf or import_mjcf, by `form` (URDF, MJCF)."""
    return _import(form, path, base, tip, convention, name, task, snap, suggest=True)


def _import(form: Format, path, base, tip, convention, name, task, snap, suggest: bool) -> Imported:
    snapper = Snapper(snap)
    chain = form.read(path, base, tip, snapper)
    as_written = form.read(path, base, tip, Snapper(0.0))
    axes, tip_frame = _axes(chain)
    table = fit(axes, tip_frame, convention, snapper)
    name = name or _robot_name(chain.robot_name)
    problem = robot_name_problem(name) if NAME_PATTERN.fullmatch(name) else f"does not match {NAME_PATTERN.pattern}"
    if problem:
        raise JacgenError(f"{path}: robot name {name!r} {problem}; choose another with --name")
    if task is not None and (not task or any(component not in TASK_COMPONENTS for component in task)):
        raise JacgenError(f"--task: expected components of {', '.join(TASK_COMPONENTS)}, got {','.join(task)!r}")
    if task is not None and (problem := task_problem(list(task))):
        raise JacgenError(f"--task: {problem}")
    if far := _far_normal(chain, axes, table, snapper):
        raise _nearly_parallel_error(form, path, far, (base, tip, convention, name, task) if suggest else None)
    digest = hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]
    source = _text(Path(path).name)
    rule = (f"within {snap:g} rad of a multiple of 90 deg" if snap is not None
            else f"multiples of 90 deg to the digits the {form.name} writes them with")
    frames = f"{form.frames} {_text(chain.base)} -> {_text(chain.tip)}"
    description = f"{_text(chain.robot_name)} imported from {source} ({frames})"

    def text(table, zeroed, components, checked=""):
        header = [
            f"Imported by jacgen {__version__} {form.command} from {source} (sha256 {digest}), "
            f"robot {_text(chain.robot_name)!r}, {frames}.",
            f"{len(axes)} moving joint(s); {form.fixed} folded into the DH, base and tool transforms: "
            f"{_text(', '.join(chain.folded)) or 'none'}. DH frames as in docs/urdf.md.",
            f"Angles and axes {rule} were made exact; largest change {snapper.largest:.2g} rad.",
        ]
        if zeroed:
            header.append(f"Lengths the DH fit computed below {SMALLEST_LENGTH:g} of the arm's size were made 0: "
                          + ", ".join(f"{key} {value:.2g}" for key, value in zeroed) + ".")
        if checked:
            header.append(checked)
        return _robot_file(name, description, header, convention, table, components)

    fitted = _read_back(text(table, (), TASK_COMPONENTS), path, rounding_lengths=True)
    table, zeroed = _without_rounding_lengths(table, fitted.reach)
    if task is None:
        task = () if len(axes) >= 6 else _independent_task(_read_back(text(table, zeroed, TASK_COMPONENTS), path))
    difference = _fk_difference(_read_back(text(table, zeroed, task), path), as_written)
    result = text(table, zeroed, task, f"Its fk differs from the {form.name}'s as written by at most {difference:.2g} "
                  f"(an entry of the 4x4 pose) at {CHECK_CONFIGURATIONS} random configurations within the limits.")
    return Imported(result, _read_back(result, path), difference, snapper.largest, tuple(zeroed))


def _read_back(text: str, path: str, rounding_lengths: bool = False) -> Robot:
    """The robot of the file written for the URDF at `path`, validated as every robot file is:
    a rule the chain breaks there (its size, equal limits) is the URDF's, and named."""
    try:
        return parse_robot(text.encode(), "<imported robot file>", rounding_lengths)
    except RobotFileError as error:
        raise JacgenError(f"{path}: the chain makes no valid robot file: {error.key}: {error.message}") from None


def _without_rounding_lengths(table: Table, reach: float) -> tuple[Table, list[tuple[str, float]]]:
    """The table with every length (a, and a revolute row's d) below the robot files' smallest
    one (SMALLEST_LENGTH of the arm's size) made 0: the fit computed it from angles that are
    k*90 deg to their written digits, or from a pi/4 written in a double. Robot files refuse
    such a length, since the arm is singular everywhere to rounding there."""
    rows, zeroed = [], []
    for k, row in enumerate(table.rows):
        changes = {}
        for key in ("a", "d") if row.axis.kind == "revolute" else ("a",):
            value = float(getattr(row, key))
            if value and abs(value) < SMALLEST_LENGTH * reach:
                changes[key] = sympy.Integer(0)
                zeroed.append((f"joints[{k}].{key}", value))
        rows.append(replace(row, **changes))
    return replace(table, rows=tuple(rows)), zeroed


@dataclass(frozen=True)
class _FarNormal:
    """Consecutive axes that are not parallel but nearly so, whose common normal lies far
    outside the URDF's chain."""

    joints: tuple[str, str]
    angle: float  # rad, between the axes
    length: float  # the largest DH length of the two rows
    extent: float  # the URDF chain's own length: its joint origins' distances summed


def _far_normal(chain: LinkChain, axes: list[Axis], table: Table, snapper: Snapper) -> _FarNormal | None:
    """The nearly parallel axes whose common normal puts DH lengths more than FAR_NORMAL times
    the chain's extent away, if any (a URDF that writes pi/2 with too few digits for the default rule)."""
    extent = sum(math.hypot(*map(float, joint.origin[:3, 3])) for joint in chain.joints)
    lengths = [max(abs(float(row.a)), abs(float(row.d))) for row in table.rows]
    far = []
    for k, (here, there) in enumerate(zip(axes, axes[1:])):
        sine = math.hypot(*map(float, here.direction.cross(there.direction)))
        angle, length = math.asin(min(sine, 1.0)), max(lengths[k], lengths[k + 1])
        if snapper.computed_tolerance() <= sine and angle < NEARLY_PARALLEL and length > FAR_NORMAL * max(extent, 1e-3):
            far.append(_FarNormal((here.name, there.name), angle, length, extent))
    return min(far, key=lambda pair: pair.angle) if far else None


def _nearly_parallel_error(form: Format, path: str, far: _FarNormal, options) -> JacgenError:
    """The refusal of nearly parallel axes: which joints, how far from parallel, the DH length
    it would need, and the --snap value that imports the URDF with its effect on fk."""
    message = (f"{path}: joints {far.joints[0]!r} and {far.joints[1]!r}: their axes are {far.angle:.2g} rad from "
               f"parallel, so the DH common normal between them needs lengths of {far.length:.3g} m, where the "
               f"{form.name}'s chain spans {far.extent:.3g} m")
    snap = 10.0 ** math.ceil(math.log10(far.angle * 1.01))
    if options is not None and snap <= MAX_SNAP:
        try:
            effect = _import(form, path, *options, snap, suggest=False).fk_difference
            message += (f"; if they are meant to be parallel, import with --snap {snap:g}, which makes them so and "
                        f"moves fk by at most {effect:.2g} from the {form.name} as written")
        except JacgenError:
            message += f"; --snap {snap:g} does not import it either"
    return JacgenError(message)


def _axes(chain: LinkChain) -> tuple[list[Axis], sympy.Matrix]:
    """The moving joints' axis lines at q = 0 in the base link's frame, and the tip frame."""
    frame, axes = chain.start, []
    for joint in chain.joints:
        frame = (frame * joint.origin).applyfunc(exact_or_float)
        if joint.kind in MOVABLE:
            axes.append(Axis(joint.name, "prismatic" if joint.kind == "prismatic" else "revolute",
                             frame[:3, 3].applyfunc(exact_or_float), (frame[:3, :3] * joint.axis).applyfunc(exact_or_float),
                             joint.limits))
    return axes, frame


def _robot_name(urdf_name: str) -> str:
    """The URDF's name made a valid robot name; `_robot` is added to one that would hide
    a keyword, header or module ("random" -> "random_robot")."""
    name = re.sub(r"[^a-z0-9_]+", "_", urdf_name.lower()).strip("_")
    name = re.sub(r"^[^a-z]+", "", name)[:41] or "robot"
    return f"{name}_robot" if robot_name_problem(name) else name


def _joint_names(axes: list[Axis]) -> list[str]:
    """The URDF names, made identifiers and unique."""
    names: list[str] = []
    for axis in axes:
        name = re.sub(r"\W+", "_", axis.name, flags=re.ASCII).strip("_") or "joint"
        name = name if not name[0].isdigit() else f"j{name}"
        name, candidate, k = name[:44], name[:44], 2
        while candidate in names:
            candidate, k = f"{name}_{k}", k + 1
        assert IDENTIFIER_PATTERN.fullmatch(candidate)
        names.append(candidate)
    return names


def _text(text: str) -> str:
    """URDF text for a comment or the description: printable, one line, nothing that escapes."""
    text = "".join(c if c.isprintable() else "_" for c in text)
    for bad in FORBIDDEN_IN_TEXT:
        text = text.replace(bad, "_" * len(bad))
    return text


def literal(value: sympy.Expr) -> str:
    """A robot-file value: an exact decimal, "p/q", "r*sqrt(s)" or "k*pi/m" when exact and a
    robot file can hold it (contract §1 "Numbers"), else the shortest decimal that round-trips
    the double (rounding noise squared under a sqrt can need hundreds of digits)."""
    value = sympy.sympify(value)
    if not value.has(sympy.Float):
        text = _exact_literal(value)
        try:
            values.parse(text.strip('"'), lambda name: None)
            return text
        except ExpressionError:
            pass
    return repr(float(value)) if value != 0 else "0"


def _exact_literal(value: sympy.Expr) -> str:
    if value.is_Rational:
        return _rational(value)
    coefficient, rest = value.as_coeff_Mul()
    if rest is sympy.pi:
        p, q = coefficient.p, coefficient.q
        text = "pi" if abs(p) == 1 else f"{abs(p)}*pi"
        return f'"{"-" if p < 0 else ""}{text}{f"/{q}" if q != 1 else ""}"'
    radicand = _rational(coefficient**2 * rest.base).strip('"')  # r*sqrt(s) = sign(r)*sqrt(r**2*s)
    return f'"{"-" if coefficient < 0 else ""}sqrt({radicand})"'


def _rational(value: sympy.Rational) -> str:
    p, q = int(value.p), int(value.q)
    stripped = q
    for prime in (2, 5):
        while stripped % prime == 0:
            stripped //= prime
    if stripped != 1:
        return f'"{p}/{q}"'
    decimal = Context(prec=100).divide(Decimal(p), Decimal(q)).normalize()
    if -7 < decimal.adjusted() < 16:
        return format(decimal, "f")
    return str(decimal).lower().replace("e+", "e")


def _limits(text: tuple[str, str] | None) -> str | None:
    return None if text is None else f"[{_rational(sympy.Rational(text[0]))}, {_rational(sympy.Rational(text[1]))}]"


def _robot_file(name, description, header, convention, table, task) -> str:
    lines = [f"# {line}" for line in header]
    lines += [f"name: {name}", f"description: {_quoted(description)}", f"convention: {convention}",
              "angle_unit: rad", "length_unit: m", "joints:"]
    rows = []
    for joint_name, row in zip(_joint_names([r.axis for r in table.rows]), table.rows):
        fields = [("name", _quoted(joint_name)), ("type", row.axis.kind), ("a", literal(row.a)),
                  ("alpha", literal(row.alpha))]
        fields += ([("d", literal(row.d)), ("offset", literal(row.theta))] if row.axis.kind == "revolute"
                   else [("theta", literal(row.theta)), ("offset", literal(row.d))])
        if row.axis.limits is not None:
            fields.append(("limits", _limits(row.axis.limits)))
        rows.append([f"{key}: {value}" for key, value in fields])
    widths = [max(len(row[k]) for row in rows if k < len(row)) for k in range(max(map(len, rows)))]
    for row in rows:
        cells = [cell + ("," if k < len(row) - 1 else "") for k, cell in enumerate(row)]
        padded = " ".join(cell.ljust(widths[k] + 1) for k, cell in enumerate(cells)).rstrip()
        lines.append(f"  - {{{padded}}}")
    for key, (xyz, rpy) in (("base", table.base), ("tool", table.tool)):
        if any(v != 0 for v in xyz + rpy):
            lines.append(f"{key}: {{xyz: [{', '.join(map(literal, xyz))}], rpy: [{', '.join(map(literal, rpy))}]}}")
    if task:
        lines.append(f"task: [{', '.join(task)}]")
    return "\n".join(lines) + "\n"


def _quoted(text: str) -> str:
    """A YAML scalar that reads back as the string `text` (which _text has made safe)."""
    plain = re.fullmatch(r"[A-Za-z_]\w*", text, re.ASCII) and isinstance(yaml.safe_load(text), str)
    return text if plain else '"' + text.replace('"', "'") + '"'


def _independent_task(robot) -> tuple[str, ...]:
    """The first components in the order x, y, z, roll, pitch, yaw whose task-Jacobian rows are
    independent of those taken before, at two random configurations: one per joint at most."""
    rng = np.random.default_rng(CHECK_SEED)
    jacobians = [reference.task_jacobian(robot, rng.uniform(-1, 1, robot.dof)) for _ in range(2)]
    chosen: list[int] = []
    for k in range(len(TASK_COMPONENTS)):
        rows = chosen + [k]
        stacked = np.hstack([J[rows] for J in jacobians])
        if len(chosen) < robot.dof and np.linalg.matrix_rank(stacked, tol=1e-6 * max(1.0, np.abs(stacked).max())) == len(rows):
            chosen.append(k)
    return tuple(TASK_COMPONENTS[k] for k in chosen)


def _fk_difference(robot, chain: LinkChain) -> float:
    rng = np.random.default_rng(CHECK_SEED)
    low, high = np.array(robot.ranges).T
    worst = 0.0
    for _ in range(CHECK_CONFIGURATIONS):
        q = rng.uniform(low, high)
        worst = max(worst, float(np.abs(reference.fk(robot, q) - joint_axes(chain, q)[1]).max()))
    return worst
