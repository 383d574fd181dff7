"""The documentation of the generated ik (its comment in C, docstring in Python): the target,
the result, the solver and the order of its branches, in words, from the closed form
(`solvers/ik.py`) and its class (`structure.SOLVERS`).
"""

import textwrap

from jacgen.solvers.ik import ClosedForm

DOC_WIDTH = 88  # characters per line of the generated documentation


def _chain_text(form: ClosedForm) -> list[str]:
    """How the solver's joints are the robot's: a free joint left out, a chain solved backwards."""
    if form.free is None and form.joints == tuple(range(len(form.joints))):
        return []
    text = []
    if form.free is not None:
        text.append(f"q_free: the angle of joint {form.free + 1} (rad); every solution keeps it as given "
                    "and solves the other six joints for it.")
    numbers = ", ".join(str(j + 1) for j in form.joints)
    if form.signs[0] < 0:
        text.append(f"The solver's joints 1-6 below are the robot's joints {numbers}, each turned the other way: "
                    "the chain is solved from the tool back to the base.")
    else:
        text.append(f"The solver's joints 1-6 below are the robot's joints {numbers}.")
    return text


def documentation(robot, form: ClosedForm, max_name: str) -> list[str]:
    """The generated ik's documentation: target, result, solver and the order of the branches."""
    if form.target == "pose":
        target = "target: the 4x4 tool pose in the world frame (rotation part orthonormal)."
    else:
        target = f"target: the task vector ({', '.join(robot.task)})" + (
            ", pitch in [-pi/2, pi/2]." if "pitch" in robot.task else ".")
    text = [
        target,
        f"Result: k <= {max_name} solutions inside the joint limits, revolute angles wrapped into "
        "(-pi, pi] or, where that is outside the limits, their lowest equivalent inside them; k = 0 "
        "when the target is out of reach or not finite. ik_branches also gives the solutions outside "
        "the limits (in_limits 0).",
        f"Solver: {form.info.title}.",
    ]
    if form.solver == "general_6r":
        text += _chain_text(form)[:1] if form.free is not None else []
        text.append(f"Order: {form.info.branches[0]}; each solution once (equal to 1e-6 rad).")
        return [line for paragraph in text for line in textwrap.wrap(paragraph, DOC_WIDTH)]
    text += [
        *_chain_text(form),
        "Order: nested loops over the branches, outermost first; where a subproblem has two roots "
        "phi +- alpha (alpha in (0, pi)), phi + alpha ('+') comes first:",
    ]
    lines = [line for paragraph in text for line in textwrap.wrap(paragraph, DOC_WIDTH)]
    lines += [f"  {line}" for branch in form.info.branches for line in textwrap.wrap(branch, DOC_WIDTH - 2)]
    notes = ("A branch the target does not allow is skipped; the others keep their order. A double "
             "root (a target on a singularity or on the workspace boundary) is returned once, and an "
             "angle the target leaves free (a singular wrist or shoulder) is set to 0.")
    return lines + textwrap.wrap(notes, DOC_WIDTH)
