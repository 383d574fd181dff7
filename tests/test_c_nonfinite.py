"""Generated C on NaN, infinite and huge inputs: no undefined behaviour (UBSan, including
float-to-int casts), statuses instead of garbage where the contract promises them."""

import shutil
import subprocess

import pytest

from jacgen.checking.c_library import WARNING_FLAGS
from jacgen.files import write_files
from jacgen.emission.render import render_robot

from conftest import robot

INPUTS = ("NAN", "INFINITY", "-INFINITY", "1e300", "-1e300", "0.0")


def harness(name: str, dof: int, task_dim: int, pose_target: bool) -> str:
    """Every generated function of robot `name`, on every input value in every slot."""
    target = 16 if pose_target else task_dim
    return f"""
#include <math.h>
#include <stdio.h>
#include "{name}.h"
int main(void) {{
    const double values[] = {{{", ".join(INPUTS)}}};
    int bad = 0;
    for (unsigned v = 0; v < sizeof values / sizeof values[0]; ++v) {{
        double q[{dof}], T[16], J[6 * {dof}], mu[{task_dim}], Jt[{task_dim} * {dof}], f[64], rates[{task_dim}];
        double target[{target}], solutions[64 * {dof}], found[{dof}];
        for (int i = 0; i < {dof}; ++i) q[i] = values[v];
        for (int i = 0; i < {task_dim}; ++i) rates[i] = values[v];
        for (int i = 0; i < {target}; ++i) target[i] = values[v];
        {name}_fk(q, T); {name}_jacobian(q, J); {name}_fk_jacobian(q, T, J); {name}_jacobian_tool(q, J);
        {name}_task(q, mu); {name}_task_jacobian(q, Jt); {name}_singularity_factors(q, f);
        (void){name}_manipulability(q);
        /* not finite: the documented status; finite (huge or zero): any status, no UB */
        int status = {name}_velocity_ik(q, rates, 0.0, found);
        if (!isfinite(values[v]) && status != 2) bad = 1;
        int count = {name}_ik(target, solutions);
        if (!isfinite(values[v]) && count != 0) bad = 1;
        for (int i = 0; i < {dof}; ++i) q[i] = 0.1;
        status = {name}_ik_numeric(target, q, 20, 1e-9, found);
        if (!isfinite(values[v]) && status != 3) bad = 1;
        (void)T; (void)J; (void)mu; (void)Jt; (void)f; (void)solutions;
    }}
    printf("%s\\n", bad ? "bad status" : "ok");
    return bad;
}}
"""


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not installed")
@pytest.mark.parametrize("name", ["planar_2r", "puma560", "stanford", "ur5"])
def test_nonfinite_inputs_are_defined_behaviour(name, tmp_path):
    arm = robot(name)
    write_files(render_robot(arm, ("c",), "double"), tmp_path)
    folder = tmp_path / name
    (folder / "main.c").write_text(harness(name, arm.dof, len(arm.task), len(arm.task) == 6))
    sanitize = ["-fsanitize=undefined,float-cast-overflow", "-fno-sanitize-recover=all"]
    subprocess.run(["gcc", *WARNING_FLAGS, "-O1", *sanitize, "-I", str(folder), "-o", str(folder / "run"),
                    str(folder / "main.c"), str(folder / f"{name}.c"), "-lm"], check=True)
    result = subprocess.run([str(folder / "run")], capture_output=True, text=True)
    assert result.returncode == 0 and result.stdout.strip() == "ok", result.stdout + result.stderr
