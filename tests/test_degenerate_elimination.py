"""The general 6R solver where its elimination degenerates (contract §2, "The fallback
elimination"): at targets on the set where the leading matrix of an arm's elimination plan is
singular (sampled by `general6r_plan.degenerate_set`, bisected to rounding), the solver takes its
fallback plan, and finds every solution that a multi-start search on the reference fk finds,
in numpy and in C. Each arm runs without its calibrated fast path, which would decide many of
these targets first. The Puma's pose is the one where the first plan's pencil is singular at
every angle of its hidden joint (issue 60): 2 to 4 of its 8 solutions were lost."""

import dataclasses

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.inputs.robot_file import load_robot
from jacgen.solvers import general6r, general6r_plan

from conftest import ROOT
from support.general6r_arms import multi_start
from support.generated import model
from support.ik import wrapped

ARMS = {name: ROOT / "robots" / f"{name}.yaml" for name in ("jaco", "mico", "manocha_canny", "ur5_calibrated",
                                                             "panda_calibrated", "sawyer")}
ARMS |= {name: ROOT / "tests" / "data" / "calibrated" / f"{name}.yaml"
         for name in ("kr5_calibrated", "puma560_calibrated", "puma560_perturbed", "ur5_perturbed")}
POSES = 3  # degenerate targets per arm
IN_C = ("puma560_calibrated", "jaco")  # the C compiled for these (the native module runs the same C)
# puma560_calibrated at the first plan's singular pencil (any last joint; issue 60, part 3)
SINGULAR_PENCIL = np.array([-2.12031, -2.24255, 1.54876, 1.19133, -2.16188, 0.7])


def degenerate_configurations(arm, form, count: int) -> np.ndarray:
    """Configurations whose loop angles lie on the first plan's degenerate set; a free joint at 0.3."""
    plan = form.elimination
    _, links, _ = general6r.chain_form(arm, form.free)
    theta = general6r_plan.degenerate_set(plan, links, 12 * count, np.random.default_rng(7))[:count]
    assert len(theta) == count
    offsets = np.array([arm.joints[j].offset.approx for j in form.joints])
    q = np.full((count, arm.dof), 0.3)
    q[:, list(form.joints)] = theta - offsets
    return q


@pytest.mark.parametrize("name", list(ARMS))
def test_degenerate_targets_lose_no_solution(name, generated):
    arm = dataclasses.replace(load_robot(ARMS[name]), nearest_class=False)
    form = model(arm).closed_form
    assert form.solver == "general_6r" and form.elimination.fallback is not None
    q = degenerate_configurations(arm, form, POSES)
    if name == "puma560_calibrated":
        q = np.vstack([q, SINGULAR_PENCIL])
    _, links, _ = general6r.chain_form(arm, form.free)
    loop = q[:, list(form.joints)] + [arm.joints[j].offset.approx for j in form.joints]
    first, fallback = form.elimination, form.elimination.fallback
    assert (general6r_plan.leading_condition(first.equations, links, first.shift, loop) > general6r_plan.DEGENERATE).all()
    assert (general6r_plan.leading_condition(fallback.equations, links, fallback.shift, loop) < general6r_plan.DEGENERATE).all()
    code = generated(arm, ("python", "c") if name in IN_C else ("python",), functions=("ik_branches",))
    free = () if form.free is None else (0.3,)
    rng = np.random.default_rng(3)
    for configuration in q:
        pose = reference.fk(arm, configuration)
        solutions, valid, _ = code.python.ik_branches(pose, *free)
        found = {"numpy": solutions[valid]}
        if name in IN_C:
            c_solutions, c_valid, _ = code.library("ik_branches").call("ik_branches", pose, *free)
            found["c"] = c_solutions[c_valid.astype(bool)]
        # every solution of a multi-start search (a 6R arm), or the generating one (a free joint)
        expected = multi_start(arm, pose, 60, rng) if form.free is None else [configuration]
        assert len(expected) >= 1
        for language, ours in found.items():
            assert max(np.abs(reference.fk(arm, s) - pose).max() for s in ours) < 1e-9, language
            for solution in expected:
                assert min(np.abs(wrapped(solution - s)).max() for s in ours) < 1e-6, (language, configuration)
