"""The Markdown report backend (`templates/report/`): the lines `jacgen show` prints, and each
function's size. It prints no expression and reserves no word."""

from jacgen.emission.backends.common import Backend, common_context, dimensions
from jacgen.emission import jacobian_uses
from jacgen.emission.generator import SINGULARITY_FUNCTIONS, Generator
from jacgen.inputs.robot import Robot
from jacgen.reports import description as words


def _report_context(robot: Robot, generator: Generator) -> dict:
    """The Markdown report: the lines `jacgen show` prints, and each function's size; the
    singularities only where a function generated reads their analysis (which takes a third
    of `generate --functions fk`'s time)."""
    singular = generator.singularities if generator.analyses_singularities else None
    operations = [{"name": f.name, "operations": f.body.operation_count,
                   "shape": "scalar" if f.scalar else " and ".join(dimensions(o) for o in f.outputs)}
                  for f in generator.functions()]
    return {
        "convention": robot.convention,
        "file_name": robot.file_name,
        "dh_header": words.DH_HEADER,
        "dh_rows": words.dh_table(robot),
        "singularity_kind": singular and singular.kind,
        "js_text": words.js_text(robot),
        "singularities": singular and words.singularity_lines(robot, singular),
        "euler": singular and words.euler_lines(robot, singular),
        "singularity_functions": SINGULARITY_FUNCTIONS,
        "dexterity": words.dexterity_lines(generator.model),
        "ik": words.ik_lines(generator.model),
        "operations": operations,
        "uses": [f for f in operations if f["name"] in jacobian_uses.NAMES],
    }


def report_context(robot: Robot, generator: Generator, printer: None, real: str) -> dict:
    """The Markdown report."""
    return dict(sorted((common_context(robot) | _report_context(robot, generator)).items()))


BACKEND = Backend("report", (("report/robot.md.jinja", "{name}.md"),), None, report_context)
