"""The Generator: each function of the catalogue (`catalogue.py`) a robot gets, built from its
algorithm and lowered to straight-line code (`lowering`).

The kinematics are rebuilt over trig symbols (`c2 = cos(q2 + offset)`) that every function
shares; adding a function touches the catalogue, this module and its algorithm.
"""

from dataclasses import replace
from functools import cached_property

import numpy
import sympy
from sympy.core.parameters import distribute

from jacgen.emission.catalogue import (EXTENTS, FUNCTION_NAMES, SECOND_ORDER, Argument, Call, Function, Loop,
                                       Output, Result, extent_of, in_catalogue_order, matrix, scalar, status,
                                       vector, with_callees)
from jacgen.emission import jacobian_uses
from jacgen.emission.lowering import Lowering
from jacgen.inputs.robot import EULER_ANGLES, Robot
from jacgen.model import kinematics
from jacgen.model.joint_ring import joint_atoms
from jacgen.model.js_rank import rank_determinant, singularity_jacobian
from jacgen.model.graph import elementwise
from jacgen.model.kinematics import generated_symbol
from jacgen.model.node import Node
from jacgen.model.singularities import Singularities
from jacgen.solvers import differential, general6r, general6r_target, ik, ik_limits
from jacgen.solvers.model import Model
from jacgen.solvers.subproblems import Subproblems, wrapped


# The functions the singularity analysis shapes (`Model.singularities`).
SINGULARITY_FUNCTIONS = ("singularity_factors", "manipulability", "jacobian_det")


class Generator:
    """Builds the emitted functions of one robot, sharing the symbolic chain between them:
    every function, or those of `selection` (names of FUNCTION_NAMES, callees included), whose
    derivation alone is done."""

    def __init__(self, robot: Robot, model: Model | None = None, selection=None):
        self.robot = robot
        self.model = model or Model(robot)
        self.selection = None if selection is None else with_callees(selection)
        self.q = kinematics.joint_symbols(robot)
        self.lowering = Lowering()
        self.named, self.lower, self.graph = self.lowering.named, self.lowering.lower, self.lowering.graph
        self.name_node = self.lowering.name_node
        self._trig: dict[tuple[int, ...], tuple[sympy.Symbol, sympy.Symbol]] = {}  # each defined once
        with distribute(False):  # keep 0.0825*(a - b) whole, for CSE to share a - b
            self.chain = kinematics.build_chain(robot, lambda i: self.cos_sin((i,)), self.q, simplify=self.named,
                                               angle_sum=self.cos_sin)

    def cos_sin(self, joints: tuple[int, ...]) -> tuple[sympy.Symbol, sympy.Symbol]:
        """Symbols for the cos and sin of a sum of joint angles, defined on first use:
        `c2 = cos(q2)` for one joint, `c23 = c2*c3 - s2*s3` for a run of parallel joints."""
        if joints not in self._trig:
            cos, sin = kinematics.trig_symbols(joints, self.robot.dof)
            if len(joints) == 1:
                angle = self.q[joints[0]] + self.robot.joints[joints[0]].offset.exact
                value = (sympy.cos(angle), sympy.sin(angle))
            else:
                value = kinematics.angle_sum_products(self.cos_sin(joints[:-1]), self.cos_sin(joints[-1:]))
            self.lowering.define(cos, value[0])
            self.lowering.define(sin, value[1])
            self._trig[joints] = (cos, sin)
        return self._trig[joints]

    def generates(self, name: str) -> bool:
        """Whether `name` is among the functions to generate (when the robot has it)."""
        return self.selection is None or name in self.selection

    @property
    def closed_form(self) -> "ik.ClosedForm | None":
        return self.model.closed_form

    def ik_functions(self) -> list[Function]:
        """ik_branches (every branch of the closed-form solver, whether the target allows it and
        whether it is inside the joint limits; for the general 6R solver, the parts its template
        loop runs, see `general_6r_functions`) and ik_nearest (the solution nearest a seed), from
        the target's symbols (none without a closed form)."""
        form = self.closed_form
        if form is None or not (self.generates("ik_branches") or self.generates("ik_nearest")):
            return []
        target = self._target(form.target == "pose")
        free, bindings, free_angle = (), {}, None
        if form.free is not None:  # the free joint's angle is an input; its cos and sin are the usual c_k, s_k
            free = (self._free_argument(),)
            free_angle = self.q[form.free]
            bindings = {free_angle: free[0].symbols[0]}
            self.cos_sin((form.free,))
        n = self.robot.dof
        seed = Argument("q_seed", sympy.Matrix([generated_symbol("qn", i + 1) for i in range(n)]))
        weights = Argument("weights", sympy.Matrix([generated_symbol("qw", i + 1) for i in range(n)]),
                           default="(1.0,) * DOF")
        sp = Subproblems(self.graph, self.name_node)
        if form.solver == "general_6r":
            parts, rows = self.general_6r_functions(target, free, bindings, sp), form.info.max_solutions
        else:
            q, valid, inside = ik.branches(self.robot, form, sp, target.symbols, free_angle)
            parts = [self.function("ik_branches", "every branch of the closed-form ik, whether the target allows "
                                   "it and whether it is inside the joint limits", matrix("q", q), vector("valid", valid),
                                   vector("in_limits", inside), arguments=(target, *free), bindings=bindings)]
            rows = q.shape[0]
        if not self.generates("ik_nearest"):
            return parts
        # ik_nearest reads ik_branches' results rather than lowering the solver a second time.
        table = Call("ik_branches", (target.name, *(a.name for a in free)), (
            Argument("branches_q", sympy.Matrix(rows, n, lambda r, c: generated_symbol("qb", r, c)),
                     vector=False),
            Argument("branches_valid", sympy.Matrix([generated_symbol("vb", r, real=None) for r in range(rows)])),
            Argument("branches_in_limits", sympy.Matrix([generated_symbol("lb", r, real=None) for r in range(rows)]))))
        table_q, table_valid, table_inside = (result.symbols for result in table.results)
        read = target.symbols[:3, :] if form.target == "pose" else target.symbols
        closest, outcome = ik_limits.nearest(self.robot, sp, table_q, list(table_valid), list(table_inside),
                                             list(seed.symbols), list(weights.symbols), form.free, list(read),
                                             self.lowering.called)
        nearest = self.function("ik_nearest", "the closed-form ik solution inside the joint limits nearest q_seed "
                                "(sum of weights_j (q_j - q_seed_j)^2), and the status", vector("q", closest),
                                status("status", outcome), arguments=(target, seed, *free, weights), calls=(table,))
        return [*parts, nearest]

    def general_6r_functions(self, target: Argument, free_input: tuple, bindings: dict,
                             sp: Subproblems) -> list[Function]:
        """The generated parts of the general 6R solver (`general6r`, `general6r_target`), which
        ik_branches runs around the eigenproblem kernel of its language: the equations at the
        target, the configuration of one root's loop angles, the pose error and Jacobian of a
        Newton step, ik's form of a configuration with its limits, and for a calibrated arm the
        branches of its nominal arm's closed form, which start the fast path. A 7R arm's free
        joint (`free_input`, bound by `bindings`) is in the chain's head or tail."""
        form = self.closed_form
        six = form.joints  # the robot's joint of each of the chain's six
        angles = Argument("angles", sympy.Matrix([generated_symbol("ga", k) for k in range(5)]))
        plans = [("", form.elimination, "")]
        if form.elimination.fallback is not None:
            plans.append(("_fallback", form.elimination.fallback, ", by the fallback elimination (for targets where "
                          "the first's leading matrix is singular to rounding)"))
        parts = []
        for suffix, plan, which in plans:
            n, stacked, q = general6r_target.equations_at(self.robot, form, plan, target.symbols, self.named)
            parts.append(self.function(
                f"ik_general_equations{suffix}", f"the general 6R solver's equations at T{which}: (P0 + s Ps + c Pc) "
                "v_bc = Q v_gh, P = [P0; Ps; Pc] (42 x 9)", matrix("P", stacked), matrix("Q", q),
                arguments=(target, *free_input), bindings=bindings, part_of="ik_branches"))
            q = general6r_target.loop_configuration(self.robot, form, plan, n, angles.symbols, self.q, self.named)
            parts.append(self.function(
                f"ik_general_start{suffix}", f"the configuration of one root's loop angles (a - shift, b, c, g, h; "
                f"the loop's free joint from the loop){which}", vector("q", q),
                arguments=(target, *free_input, angles), bindings=bindings, part_of="ik_branches"))
        dof = self.robot.dof
        target_pose = self.ik_target()
        given = Argument("q", sympy.Matrix([generated_symbol("qs", i + 1) for i in range(dof)]))
        error, jacobian = self.task_error(target_pose, None)
        step = self.function("ik_general_residual", "the pose error e at q (the position error and the rotation "
                             "vector of R_target R^T, world frame) and the geometric Jacobian J of the six joints "
                             "ik solves: the Newton step of the solver's polish is q + J^-1 e",
                             vector("e", error), matrix("J", jacobian[:, list(six)]),
                             arguments=(target_pose, given), bindings=dict(zip(self.q, given.symbols)),
                             part_of="ik_branches")
        given = Argument("q_solution", sympy.Matrix([generated_symbol("qg", i + 1) for i in range(dof)]))
        limited, inside = ik_limits.limited(self.robot, sp, list(given.symbols), six, form.free)
        limits = self.function("ik_general_limits", "ik's form of q (revolute angles wrapped, or into the limits) "
                               "and whether it is inside the joint limits", vector("q", limited),
                               scalar("in_limits", inside), arguments=(given,),
                               part_of="ik_branches")
        parts += [step, limits]
        if form.fast_path:
            free_angle = None if form.free is None else self.q[form.free]
            q, valid, certified = general6r_target.nominal_branches(form, sp, target.symbols, free_angle,
                                                                           self.lowering.value_of)
            parts.append(self.function("ik_general_nominal", "the fast path's starting points: every branch of the "
                                       "nearest special class's closed form (the nominal arm's), whether its target "
                                       "allows it, and whether its certificate holds", matrix("q", q),
                                       vector("valid", valid), status("certified", certified),
                                       arguments=(target, *free_input), bindings=bindings, part_of="ik_branches"))
        return parts

    def ik_numeric_step_function(self, task_jacobian: sympy.Matrix) -> Function:
        """ik_numeric_step: one damped least-squares step of ik_numeric from q (`differential`)."""
        robot, n = self.robot, self.robot.dof
        target = self.ik_target()
        given = Argument("q", sympy.Matrix([generated_symbol("qs", i + 1) for i in range(n)]))
        damping = self.damping_argument()
        limits = [joint.limits for joint in robot.joints]
        bindings = {qi: differential.clamp(given_i, bounds, self.graph)
                    for qi, given_i, bounds in zip(self.q, given.symbols, limits)}
        error, jacobian = self.task_error(target, task_jacobian)
        trial, cost = differential.ik_numeric_step(error, jacobian, list(self.q), damping.symbols[0], limits,
                                                   self.graph, self.name_node, self.lowering.called)
        read = target.symbols[:3, :] if len(robot.task) == 6 else target.symbols
        cost = differential.flagged_cost(cost, [*given.symbols, *read], self.graph, self.name_node)
        step = "J^T (J J^T + damping I)^-1 e" if jacobian.rows <= n else "(J^T J + damping I)^-1 J^T e"
        summary = (f"one step of ik_numeric: q clamped to the limits, then q + {step} clamped, and |e|^2 at "
                   "the clamped q (-1 when target or q is not finite)")
        return self.function("ik_numeric_step", summary, vector("q_start", self.q), vector("q_next", trial),
                             scalar("cost", cost), arguments=(target, given, damping), bindings=bindings)

    def _target(self, pose: bool, name: str | None = None) -> Argument:
        """An ik target: the 4x4 pose (named T unless `name`), or the task vector (mu)."""
        if pose:
            return Argument(name or "T", sympy.Matrix(4, 4, lambda r, c: generated_symbol("T", r, c, separator="")),
                            vector=False)
        return Argument(name or "mu", sympy.Matrix([generated_symbol("mu", i) for i in range(len(self.robot.task))]))

    def ik_target(self) -> Argument:
        """ik_numeric's target: the 4x4 pose for a six-component task, else the task vector."""
        return self._target(len(self.robot.task) == 6, "target")

    @staticmethod
    def damping_argument() -> Argument:
        """The damping of velocity_ik and its relatives and of ik_numeric's step, 0 by default."""
        return Argument("damping", sympy.Matrix([sympy.Symbol("damping", real=True)]), scalar=True, default="0.0")

    @staticmethod
    def _free_argument() -> Argument:
        """A 7-axis arm's free joint angle, an input of its closed form."""
        return Argument("q_free", sympy.Matrix([sympy.Symbol("q_free", real=True)]), scalar=True)

    def task_error(self, target: Argument, task_jacobian: sympy.Matrix | None) -> tuple[list, sympy.Matrix]:
        """The error e that ik's iterations drive to 0, at the chain's q, and its Jacobian: for a
        pose, the position error and the rotation vector of R_target R^T (world frame) with the
        geometric Jacobian; else the task error (Euler angles wrapped) with the task Jacobian."""
        with distribute(False):  # the error's sympy differences: numbers not distributed over sums
            if len(self.robot.task) == 6:
                tool, goal = self.chain.tool, target.symbols
                rotation = self.graph.values(goal[:3, :3]) @ self.graph.values(tool[:3, :3]).T
                return [goal[i, 3] - tool[i, 3] for i in range(3)] + differential.rotation_vector(
                    rotation, self.graph, self.name_node), self.jacobian
            mu = kinematics.task_vector(self.robot, self.chain.tool)
            return [wrapped(self.graph.value(goal - value)) if component in EULER_ANGLES else goal - value
                    for goal, value, component in zip(target.symbols, mu, self.robot.task)], task_jacobian

    @cached_property
    def jacobian(self) -> sympy.Matrix:
        return kinematics.column_jacobian(self.robot, self.chain)

    def second_order_functions(self) -> list[Function]:
        """fk_jacobian_dot, jacobian_dot, bias_acceleration, task_jacobian_dot and hessian, from
        the chain and the named columns of J (`kinematics`): O(1) per entry on top of J."""
        if not any(map(self.generates, SECOND_ORDER)):
            return []
        robot, n, m = self.robot, self.robot.dof, len(self.robot.task)
        q_dot = Argument("q_dot", sympy.Matrix([generated_symbol("qd", i + 1) for i in range(n)]))
        arguments = (Argument("q", sympy.Matrix(self.q)), q_dot)
        g = self.graph
        name = self.name_node
        columns = elementwise(name, g.values(self.jacobian))
        rates = g.values(q_dot.symbols).flatten()
        axes = [g.values(axis[:3, 2]).flatten() for axis in self.chain.axes]
        jacobian_dot = kinematics.jacobian_dot(robot, axes, columns, rates, name)
        bias = jacobian_dot @ rates
        task_jacobian_dot = kinematics.task_jacobian_dot(robot, g.values(self.chain.tool), columns,
                                                         elementwise(name, jacobian_dot), rates, name)
        hessian = numpy.concatenate(kinematics.hessian(robot, columns))
        return [
            self.function("fk_jacobian_dot", "fk, jacobian and bias_acceleration in one pass, sharing their terms",
                          matrix("T", self.chain.tool, result_of="fk"), matrix("J", self.jacobian, result_of="jacobian"),
                          vector("a", bias, result_of="bias_acceleration"), arguments=arguments),
            self.function("jacobian_dot", "time derivative dJ/dt of the world geometric Jacobian along q_dot (6 x DOF)",
                          matrix("Jd", jacobian_dot), arguments=arguments),
            self.function("bias_acceleration", "J' q_dot: the tool's classical linear and angular acceleration "
                          "at zero joint acceleration, world frame (6)", vector("a", bias), arguments=arguments),
            self.function("task_jacobian_dot", f"time derivative of the analytic Jacobian along q_dot ({m} x DOF): "
                          "mu'' = J_a q'' + J_a' q'", matrix("Jd", task_jacobian_dot), arguments=arguments),
            self.function("hessian", "partial derivatives dJ/dq_k of the world geometric Jacobian "
                          "(DOF x 6 x DOF, indexed [k, r, c])", matrix("H", hessian, layers=n)),
        ]

    @property
    def singularities(self) -> Singularities:
        return self.model.singularities

    def magnitude(self, value) -> Node:
        """|value|, of a named value."""
        return self.graph.call("Abs", self.name_node(value))

    @property
    def analyses_singularities(self) -> bool:
        """Whether a function generated reads the singularity analysis (the report describes it then)."""
        return any(map(self.generates, SINGULARITY_FUNCTIONS))

    def singularity_functions(self, js: sympy.Matrix) -> list[Function]:
        """singularity_factors, manipulability and (square Js) jacobian_det, from Js.

        The exact factors come first; where they are not the whole condition, the numeric
        rank determinant follows them. jacobian_det is the product of the exact factors
        when they are complete and cheaper to compute than the expansion of det(Js)."""
        if not self.analyses_singularities:
            return []
        singular, (m, n) = self.singularities, js.shape
        atoms = {}
        for i, symbols in enumerate(joint_atoms(self.robot)):
            if len(symbols) == 2:
                atoms.update(zip(symbols, self.cos_sin((i,))))
        numeric = self.graph.number(0) if singular.everywhere else rank_determinant(js, self.graph, self.name_node)
        factors = [f.polynomial.xreplace(atoms) for f in singular.factors]
        if not singular.complete or singular.everywhere:
            factors.append(numeric)
        what = "the robot is singular where one is 0" if factors else "never singular: the constant 1"
        functions = [self.function("singularity_factors", f"factors of {singular.kind}: {what}",
                                   vector("f", factors or [1]))]
        if m != n:
            return functions + [self.function("manipulability", f"manipulability sqrt({singular.kind})",
                                              scalar("w", self.graph.sqrt(self.magnitude(numeric))))]
        determinant = numeric
        if singular.complete and not singular.everywhere:
            rotation = self.chain.tool[:3, :3]
            cos_pitch = sympy.sqrt(rotation[0, 0] ** 2 + rotation[1, 0] ** 2)
            exact = self.graph.value(singular.constant.xreplace(atoms) * sympy.Mul(
                *(p.xreplace(atoms) ** k for p, k in singular.determinant)) / cos_pitch**singular.euler_power)
            if self.lower([exact]).operation_count <= self.lower([numeric]).operation_count:
                determinant = exact
        return functions + [
            self.function("manipulability", "manipulability |det(Js)|", scalar("w", self.magnitude(determinant))),
            self.function("jacobian_det", "det(Js)", scalar("d", determinant)),
        ]

    def function(self, name: str, summary: str, *results: Result, arguments: tuple[Argument, ...] | None = None,
                 bindings: dict | None = None, calls: tuple[Call, ...] = (), part_of: str | None = None
                 ) -> Function | None:
        """A function of one or more results (`matrix`, `vector`, `scalar`, `status`), lowered
        together so they share their terms; its arguments are q unless given. `bindings` define
        symbols (the joints) from the arguments for this function alone; `calls` are the
        generated functions whose results the body reads. None when `name` (or the function it
        is `part_of`) is not to be generated (nothing is lowered then)."""
        if not self.generates(part_of or name):
            return None
        outputs, values = [], []
        for output, entries in results:
            nodes = [self.graph.value(entry) for entry in entries]
            boolean = all(node.boolean for node in nodes)
            key = f"{name}.{output.name}"
            outputs.append(replace(output, vector=output.vector or boolean, boolean=boolean,
                                   extent=extent_of(key if key in EXTENTS else output.result_of or name, output.size)))
            values += nodes
        return Function(name, summary, tuple(outputs), arguments or (Argument("q", sympy.Matrix(self.q)),),
                        body=self.lower(values, bindings or {}), calls=calls, part_of=part_of or "")

    def functions(self) -> list[Function]:
        """Every straight-line function, in the catalogue's order (a loop's parts where the loop is)."""
        return list(self._functions)

    def signatures(self) -> list[Function | Loop]:
        """Every function a caller can call, in the catalogue's order: the straight-line ones
        (a loop's parts too) and the loops."""
        return in_catalogue_order((*self._functions, *self.loops))

    def without_loops(self) -> list[Function]:
        """The functions of CasADi, whose SX graphs run no loop of unknown length: without the
        parts of a loop it does not have, and without the functions that call such a loop (the
        general 6R solver's ik_nearest reads its ik_branches)."""
        absent = {loop.name for loop in self.loops if loop.casadi is None}
        return [f for f in self._functions
                if f.part_of not in absent and not any(call.function in absent for call in f.calls)]

    @cached_property
    def loops(self) -> list[Loop]:
        """The functions with control flow this robot gets, in the catalogue's order: ik_numeric
        around ik_numeric_step, ik around ik_branches, and the general 6R solver's ik_branches
        around the eigenproblem kernel of its language."""
        form, n = self.closed_form, self.robot.dof
        made = []
        if self.generates("ik_numeric"):
            defaults = differential.IK_NUMERIC_DEFAULTS
            arguments = (self.ik_target(), Argument("q0", sympy.Matrix(sympy.symbols(f"q0_:{n}", real=True))),
                         Argument("max_iter", sympy.Matrix([sympy.Symbol("max_iter")]), scalar=True,
                                  default=repr(defaults["max_iter"]), integer=True),
                         Argument("tol", sympy.Matrix([sympy.Symbol("tol")]), scalar=True, default=repr(defaults["tol"])))
            made.append(Loop("ik_numeric", "iterative inverse kinematics from q0: damped least squares on the task "
                             "error; (q, status)", (Output("q", n, 1, vector=True, extent=("DOF",)),
                                                    Output("status", 1, 1, scalar=True, integer=True)), arguments,
                             operations=differential.IK_NUMERIC_OPERATIONS, casadi="steps"))
        if form is None:
            return made
        target = self._target(form.target == "pose")
        free = (self._free_argument(),) * (form.free is not None)
        rows, solutions = form.info.max_solutions, ("MAX_IK_SOLUTIONS",)
        general = form.solver == "general_6r"
        if general and self.generates("ik_branches"):
            made.append(Loop("ik_branches", "every branch of the general 6R ik, whether the target allows it and "
                             "whether it is inside the joint limits",
                             (Output("q", rows, n, extent=(*solutions, "DOF")),
                              Output("valid", rows, 1, vector=True, boolean=True, extent=solutions),
                              Output("in_limits", rows, 1, vector=True, boolean=True, extent=solutions)),
                             (target, *free), operations=general6r.OPERATIONS))
        if self.generates("ik"):
            made.append(Loop("ik", "closed-form inverse kinematics: every joint solution that reaches the target, "
                             "inside the joint limits unless `limits` is False: one target gives them as (k, DOF), a "
                             "batch gives (q, keep), (..., MAX_IK_SOLUTIONS, DOF) and (..., MAX_IK_SOLUTIONS)",
                             (Output("q", rows, n, extent=(*solutions, "DOF")),
                              Output("count", 1, 1, scalar=True, integer=True)), (target, *free),
                             operations=general6r.OPERATIONS if general else 0, casadi=None if general else "graph"))
        return made

    def unavailable(self) -> list[str]:
        """The selected functions this robot does not have, each with why."""
        made = {f.name for f in (*self._functions, *self.loops)}
        why = {"ik": f"no closed form ({self.model.structure.reason})",
               "jacobian_det": f"Js is {len(self.robot.task)} x {self.robot.dof}, not square",
               "condition_number": "Js is singular at every configuration: sigma_min is 0 everywhere"}
        why["ik_branches"] = why["ik_nearest"] = why["ik"]
        return [f"{name}: {why.get(name, 'not generated for this robot')}"
                for name in FUNCTION_NAMES if name in (self.selection or ()) and name not in made]

    @cached_property
    def _functions(self) -> tuple[Function, ...]:
        robot, m = self.robot, len(self.robot.task)
        pose = self.chain.tool
        task_jacobian = kinematics.task_jacobian(robot, pose, self.jacobian)
        js = singularity_jacobian(robot, self.jacobian, task_jacobian)
        functions = (
            self.function("fk", "pose of the tool frame in the world frame (4x4 homogeneous)", matrix("T", pose)),
            self.function("jacobian", "geometric Jacobian in the world frame (6 x DOF, rows vx vy vz wx wy wz)",
                          matrix("J", self.jacobian)),
            self.function("fk_jacobian", "fk and jacobian in one pass, sharing their terms",
                          matrix("T", pose, result_of="fk"), matrix("J", self.jacobian, result_of="jacobian")),
            self.function("jacobian_tool", "geometric Jacobian in the tool frame (6 x DOF, rows vx vy vz wx wy wz)",
                          matrix("J", kinematics.tool_frame(self.jacobian, pose))),
            self.function("task", f"task vector mu = ({', '.join(robot.task)})",
                          vector("mu", kinematics.task_vector(robot, pose))),
            self.function("task_jacobian", f"analytic Jacobian d mu / d q ({m} x DOF)", matrix("J", task_jacobian)),
            *self.second_order_functions(),
            *self.singularity_functions(js),
            *jacobian_uses.functions(self, js, task_jacobian),
            self.ik_numeric_step_function(task_jacobian) if self.generates("ik_numeric_step") else None,
            *self.ik_functions(),
        )
        return tuple(in_catalogue_order(function for function in functions if function is not None))

