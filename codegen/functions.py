"""What to emit: every generated function as straight-line code over named temporaries.

The kinematics are rebuilt over trig symbols (`c2 = cos(q2 + offset)`), each function's
outputs are reduced by common-subexpression elimination, and the result is a `Body`
that every printer turns into its own language. Temporaries are numbered in a fixed
order, so the output does not depend on hashing.
"""

from dataclasses import dataclass
from functools import cached_property

import sympy

from . import kinematics
from .printers import fold_constants
from .robot import Robot


@dataclass(frozen=True)
class Body:
    """Straight-line code: input bindings, then definitions in order, then the outputs."""

    joints_used: tuple[int, ...]  # indices of q read by the body
    definitions: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    outputs: tuple[sympy.Expr, ...]  # row-major

    @cached_property
    def operation_count(self) -> int:
        return int(sympy.count_ops([e for _, e in self.definitions] + list(self.outputs)))


@dataclass(frozen=True)
class Function:
    """One generated function returning a rows x cols matrix (scalar when 1 x 1 and `scalar`)."""

    name: str
    summary: str
    output: str  # the output array's name in C
    rows: int
    cols: int
    body: Body
    scalar: bool = False


class Generator:
    """Builds the emitted functions of one robot, sharing the symbolic chain between them."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.q = kinematics.joint_symbols(robot)
        self.trig_definitions: list[tuple[sympy.Symbol, sympy.Expr]] = []
        self._trig: dict[tuple[int, ...], tuple[sympy.Symbol, sympy.Symbol]] = {}
        self.chain = kinematics.build_chain(robot, lambda i: self.cos_sin((i,)), self.q, angle_sum=self.cos_sin)

    def cos_sin(self, joints: tuple[int, ...]) -> tuple[sympy.Symbol, sympy.Symbol]:
        """Symbols for the cos and sin of a sum of joint angles, defined on first use:
        `c2 = cos(q2)` for one joint, `c23 = c2*c3 - s2*s3` for a run of parallel joints."""
        if joints not in self._trig:
            separator = "_" if any(i >= 9 for i in joints) else ""
            label = separator.join(str(i + 1) for i in joints)
            cos, sin = sympy.symbols(f"c{label} s{label}", real=True)
            if len(joints) == 1:
                angle = self.q[joints[0]] + self.robot.joints[joints[0]].offset.exact
                value = (sympy.cos(angle), sympy.sin(angle))
            else:
                value = kinematics.angle_sum_products(self.cos_sin(joints[:-1]), self.cos_sin(joints[-1:]))
            self.trig_definitions += [(cos, value[0]), (sin, value[1])]
            self._trig[joints] = (cos, sin)
        return self._trig[joints]

    @cached_property
    def jacobian(self) -> sympy.Matrix:
        return kinematics.column_jacobian(self.robot, self.chain)

    def lower(self, outputs: sympy.Matrix) -> Body:
        """CSE of the outputs, with the trig symbols they use defined first."""
        expressions = list(outputs)
        temporaries = sympy.numbered_symbols("t", real=True)
        replacements, reduced = sympy.cse(expressions, symbols=temporaries, order="canonical")
        needed = set().union(*(e.free_symbols for e in reduced), *(e.free_symbols for _, e in replacements))
        trig = []
        for symbol, value in reversed(self.trig_definitions):  # sums need their terms' symbols
            if symbol in needed:
                trig.insert(0, (symbol, value))
                needed |= value.free_symbols
        definitions = tuple((symbol, fold_constants(e)) for symbol, e in trig + replacements)
        reduced = tuple(fold_constants(e) for e in reduced)
        read = set().union(*(e.free_symbols for _, e in definitions), *(e.free_symbols for e in reduced))
        joints_used = tuple(i for i, symbol in enumerate(self.q) if symbol in read)
        return Body(joints_used, definitions, reduced)

    def functions(self) -> list[Function]:
        robot, n, m = self.robot, self.robot.dof, len(self.robot.task)
        pose = self.chain.tool
        return [
            Function("fk", "pose of the tool frame in the world frame (4x4 homogeneous)", "T", 4, 4, self.lower(pose)),
            Function("jacobian", "geometric Jacobian in the world frame (6 x DOF, rows vx vy vz wx wy wz)",
                     "J", 6, n, self.lower(self.jacobian)),
            Function("jacobian_tool", "geometric Jacobian in the tool frame (6 x DOF, rows vx vy vz wx wy wz)",
                     "J", 6, n, self.lower(kinematics.tool_frame(self.jacobian, pose))),
            Function("task", f"task vector mu = ({', '.join(robot.task)})", "mu", m, 1,
                     self.lower(kinematics.task_vector(robot, pose))),
            Function("task_jacobian", f"analytic Jacobian d mu / d q ({m} x DOF)", "J", m, n,
                     self.lower(kinematics.task_jacobian(robot, pose, self.jacobian))),
        ]
