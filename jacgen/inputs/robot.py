"""A robot as jacgen knows it (contract §1): the frozen Robot, its joints (DH rows), poses and
parameters, as `robot_file.py` reads them from a robot file and `urdf_import.py` writes them.
Every later stage takes a Robot.
"""

import math
from dataclasses import dataclass
from pathlib import Path

from jacgen.inputs.values import Value

TASK_COMPONENTS = ("x", "y", "z", "roll", "pitch", "yaw")
EULER_ANGLES = TASK_COMPONENTS[3:]  # ZYX Euler angles of the tool: R = Rz(yaw) Ry(pitch) Rx(roll)
ZERO = Value(("integer", 0), 0.0)


@dataclass(frozen=True)
class Parameter:
    name: str
    value: float
    symbolic: bool

    @property
    def symbol(self):
        """The sympy symbol of a parameter kept symbolic."""
        return Value(("symbol", self.name), self.value).exact


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
    free_joint: int | None = None  # `ik: {free_joint: k}`, 0-based: the joint the closed-form ik takes as input
    nearest_class: bool = True  # `ik: {nearest_class: false}` turns off the calibrated arms' fast path
    characteristic_length: float | None = None  # Angeles' L from the file (model/dexterity.py); None: computed

    @property
    def dof(self) -> int:
        return len(self.joints)

    @property
    def symbolic_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.symbolic)

    @property
    def file_name(self) -> str:
        """The robot file's name without its folder, unprintable characters as '?' (it goes
        into one-line comments and the report's commands)."""
        return "".join(c if c.isprintable() else "?" for c in Path(self.source).name)

    @property
    def reach(self) -> float:
        """An upper bound of the distance of any frame origin from the world origin: the sum of
        every length of the file (a, d, the base's and tool's xyz, prismatic travel)."""
        total = sum(abs(v.approx) for pose in (self.base, self.tool) for v in pose.xyz)
        for joint in self.joints:
            total += abs(joint.a.approx)
            if joint.revolute:
                total += abs(joint.d.approx)
            else:
                lo, hi = joint.limits or (-math.pi, math.pi)
                total += max(abs(lo), abs(hi)) + abs(joint.offset.approx)
        return total

    @property
    def ranges(self) -> tuple[tuple[float, float], ...]:
        """Each joint's range: its limits, or [-pi, pi] for a joint without."""
        return tuple(joint.limits or (-math.pi, math.pi) for joint in self.joints)
