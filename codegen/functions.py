"""What to emit: every generated function as straight-line code over named temporaries.

The kinematics are rebuilt over trig symbols (`c2 = cos(q2 + offset)`), each function's
outputs are reduced by common-subexpression elimination, and the result is a `Body`
that every printer turns into its own language. Temporaries are numbered in a fixed
order, so the output does not depend on hashing.
"""

from dataclasses import dataclass
from functools import cached_property

import sympy
from sympy.core.parameters import distribute

from . import analysis, kinematics
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
class Output:
    """One result of a generated function: a rows x cols matrix, or a scalar returned by value."""

    name: str  # the array's name in C
    rows: int
    cols: int
    scalar: bool = False
    equals: str = ""  # the function whose result this is, when the function fuses several

    @property
    def size(self) -> int:
        return self.rows * self.cols

    @property
    def shape(self) -> tuple[int, ...]:
        """numpy shape: matrices (rows, cols), column vectors (rows,), scalars ()."""
        if self.scalar:
            return ()
        return (self.rows,) if self.cols == 1 else (self.rows, self.cols)


@dataclass(frozen=True)
class Function:
    """One generated function; its body's outputs are those of `outputs`, concatenated."""

    name: str
    summary: str
    outputs: tuple[Output, ...]
    body: Body

    @property
    def scalar(self) -> bool:
        """Returns its one result by value."""
        return self.outputs[0].scalar

    def parts(self, values: tuple[sympy.Expr, ...]):
        """The body's outputs split per output: (Output, its values row-major)."""
        start = 0
        for output in self.outputs:
            yield output, values[start:start + output.size]
            start += output.size


class Generator:
    """Builds the emitted functions of one robot, sharing the symbolic chain between them."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.q = kinematics.joint_symbols(robot)
        # Trig symbols, each defined once, in an order that defines before use.
        self.definitions: list[tuple[sympy.Symbol, sympy.Expr]] = []
        self._trig: dict[tuple[int, ...], tuple[sympy.Symbol, sympy.Symbol]] = {}
        with distribute(False):  # keep 0.0825*(a - b) whole, for CSE to share a - b
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
            self.definitions += [(cos, value[0]), (sin, value[1])]
            self._trig[joints] = (cos, sin)
        return self._trig[joints]

    @cached_property
    def jacobian(self) -> sympy.Matrix:
        # Built with distribution on: p - o_i then cancels the terms the two origins share.
        return kinematics.column_jacobian(self.robot, self.chain)

    @cached_property
    def singularities(self) -> analysis.Singularities:
        return analysis.analyse(self.robot)

    def singularity_functions(self, js: sympy.Matrix) -> list[Function]:
        """singularity_factors, manipulability and (square Js) jacobian_det, from Js."""
        singular, (m, n) = self.singularities, js.shape
        atoms = {}
        for i, symbols in enumerate(analysis.joint_atoms(self.robot)):
            if len(symbols) == 2:
                atoms.update(zip(symbols, self.cos_sin((i,))))
        factors = [f.polynomial.xreplace(atoms) for f in singular.factors]
        minors = analysis.maximal_minors(js.tolist(), sympy.Integer(0), sympy.Integer(1))
        gram = sympy.Add(*(minor**2 for minor in minors))
        if not singular.complete:
            factors.append(gram)
        what = "the robot is singular where one is 0" if factors else "never singular: the constant 1"
        functions = [self.function("singularity_factors", f"factors of {singular.kind}: {what}",
                                   ("f", sympy.Matrix(factors or [1])))]
        if m != n:
            return functions + [self.function("manipulability", f"manipulability sqrt({singular.kind})",
                                              ("w", sympy.Matrix([sympy.sqrt(gram)])), scalar=True)]
        rotation = self.chain.tool[:3, :3]
        cos_pitch = sympy.sqrt(rotation[0, 0] ** 2 + rotation[1, 0] ** 2)
        determinant = singular.constant.xreplace(atoms) * sympy.Mul(
            *(p.xreplace(atoms) ** k for p, k in singular.determinant)) / cos_pitch**singular.euler_power
        return functions + [
            self.function("manipulability", "manipulability |det(Js)|", ("w", sympy.Matrix([sympy.Abs(determinant)])),
                          scalar=True),
            self.function("jacobian_det", "det(Js)", ("d", sympy.Matrix([determinant])), scalar=True),
        ]

    def function(self, name: str, summary: str, *results: tuple[str, sympy.Matrix], scalar: bool = False,
                 equals: tuple[str, ...] = ()) -> Function:
        """A function of one or more named results, lowered together so they share their terms."""
        outputs = tuple(Output(output, matrix.rows, matrix.cols, scalar, equal)
                        for (output, matrix), equal in zip(results, equals or ("",) * len(results)))
        return Function(name, summary, outputs, self.lower(sympy.Matrix.vstack(*(m.reshape(m.rows * m.cols, 1)
                                                                                 for _, m in results))))

    def lower(self, outputs: sympy.Matrix) -> Body:
        """The outputs as straight-line code: the trig symbols they need, then common
        subexpressions (t0, t1, ...), then the outputs."""
        with distribute(False):
            replacements, reduced = sympy.cse([fold_constants(e) for e in outputs],
                                              symbols=sympy.numbered_symbols("t", real=True), order="canonical")
        needed = set().union(*(e.free_symbols for e in reduced), *(e.free_symbols for _, e in replacements))
        trig = []
        for symbol, value in reversed(self.definitions):  # sums of angles need their terms
            if symbol in needed:
                trig.insert(0, (symbol, fold_constants(value)))
                needed |= value.free_symbols
        definitions = tuple(trig + replacements)
        read = set().union(*(e.free_symbols for _, e in definitions), *(e.free_symbols for e in reduced))
        joints_used = tuple(i for i, symbol in enumerate(self.q) if symbol in read)
        return Body(joints_used, definitions, reduced)

    def functions(self) -> list[Function]:
        """Every straight-line function, in the order the backends emit them."""
        return list(self._functions)

    @cached_property
    def _functions(self) -> tuple[Function, ...]:
        robot, m = self.robot, len(self.robot.task)
        pose = self.chain.tool
        task_jacobian = kinematics.task_jacobian(robot, pose, self.jacobian)
        return (
            self.function("fk", "pose of the tool frame in the world frame (4x4 homogeneous)", ("T", pose)),
            self.function("jacobian", "geometric Jacobian in the world frame (6 x DOF, rows vx vy vz wx wy wz)",
                          ("J", self.jacobian)),
            self.function("fk_jacobian", "fk and jacobian in one pass, sharing their terms",
                          ("T", pose), ("J", self.jacobian), equals=("fk", "jacobian")),
            self.function("jacobian_tool", "geometric Jacobian in the tool frame (6 x DOF, rows vx vy vz wx wy wz)",
                          ("J", kinematics.tool_frame(self.jacobian, pose))),
            self.function("task", f"task vector mu = ({', '.join(robot.task)})",
                          ("mu", kinematics.task_vector(robot, pose))),
            self.function("task_jacobian", f"analytic Jacobian d mu / d q ({m} x DOF)", ("J", task_jacobian)),
            *self.singularity_functions(analysis.singularity_jacobian(robot, self.jacobian, task_jacobian)),
        )
