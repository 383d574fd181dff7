"""jacgen: symbolic Jacobian code generator for robot arms.

Scripting entry points::

    import jacgen
    robot = jacgen.load_robot("robots/puma560.yaml")
    kin = jacgen.Kinematics(robot)          # readable sympy matrices: kin.fk, kin.jacobian, ...
    files = jacgen.render_robot(robot)      # {"puma560/puma560.py": text, ...}
"""

from .errors import JacgenError, RobotFileError
from .kinematics import Kinematics
from .render import render_robot
from .robot import Robot, load_robot
from .version import __version__

__all__ = ["JacgenError", "Kinematics", "Robot", "RobotFileError", "load_robot", "render_robot", "__version__"]
