"""jacgen: symbolic Jacobian code generator for robot arms.

Scripting entry points::

    import jacgen
    robot = jacgen.load_robot("robots/puma560.yaml")
    kin = jacgen.Kinematics(robot)          # readable sympy matrices: kin.fk, kin.jacobian, ...
    files = jacgen.render_robot(robot)      # {"puma560/puma560.py": text, ...}
"""

__version__ = "0.1.0"

from .errors import JacgenError, RobotFileError  # noqa: E402
from .kinematics import Kinematics  # noqa: E402
from .render import render_robot  # noqa: E402
from .robot import Robot, load_robot  # noqa: E402

__all__ = ["JacgenError", "Kinematics", "Robot", "RobotFileError", "load_robot", "render_robot", "__version__"]
