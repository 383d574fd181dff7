"""jacgen: symbolic Jacobian code generator for robot arms.

Scripting entry points::

    import jacgen
    ur5 = jacgen.arm("ur5", backend="native")  # the generated module, built once and cached
    T, J = ur5.fk_jacobian([0.1, -0.5, 0.3, 0.2, 0.4, 0.0])
    robot = jacgen.load_robot("robots/puma560.yaml")
    kin = jacgen.Kinematics(robot)          # readable sympy matrices: kin.fk, kin.jacobian, ...
    files = jacgen.render_robot(robot)      # {"puma560/puma560.py": text, ...}

The names are imported when first used, so that `jacgen --help` and a cached
`jacgen generate --check` do not import sympy.
"""

from importlib import import_module

from jacgen.version import __version__

_HOMES = {"JacgenError": "errors", "RobotFileError": "errors", "Kinematics": "model.kinematics",
          "render_robot": "emission.render", "Robot": "inputs.robot", "load_robot": "inputs.robot_file",
          "arm": "loading", "BuildError": "building"}

__all__ = ["BuildError", "JacgenError", "Kinematics", "Robot", "RobotFileError", "load_robot", "render_robot", "__version__", "arm"]


def __getattr__(name: str):
    if name not in _HOMES:
        raise AttributeError(f"module 'jacgen' has no attribute {name!r}")
    return getattr(import_module(f".{_HOMES[name]}", __name__), name)
