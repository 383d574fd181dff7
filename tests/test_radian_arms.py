"""Random arms written in radians (issue 21): arbitrary twists such as 1.2001 rad are exact
rationals with no closed-form cosine, the arms whose structure detection once took minutes;
each generated for every language and checked by `jacgen verify` (a file of its own so that
the test workers share the stress suite)."""

import re

import pytest

from support.random_arms import generates_and_verifies, random_arm_text

RADIAN_ARMS = [(6, 6001), (11, 11000), (16, 16000)]  # (joints, seed): before the structure stage was bounded, 11 joints took minutes


@pytest.mark.parametrize("dof, seed", RADIAN_ARMS)
def test_arm_in_radians_generates_and_verifies(tmp_path, dof, seed):
    text = random_arm_text(seed, dof=dof, radians=True)
    assert "angle_unit: rad" in text and re.search(r"alpha: -?\d\.\d{4}", text)  # an arbitrary twist
    generates_and_verifies(tmp_path / f"arm{seed}.yaml", text)
