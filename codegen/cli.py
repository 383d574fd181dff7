"""The `jacgen` command line (SPEC §4). Exit codes: 0 ok, 1 check failed, 2 invalid input."""

import sys
from pathlib import Path

import click

from . import __version__
from .errors import JacgenError
from .render import DEFAULT_LANGUAGES, LANGUAGES, render_robot, stale_files, write_files
from .report import describe
from .robot import load_robot

robot_files = click.argument("robot_files", nargs=-1, required=True, type=click.Path(dir_okay=False))


def _languages(ctx, param, value: str) -> tuple[str, ...]:
    names = tuple(dict.fromkeys(part.strip() for part in value.split(",") if part.strip()))
    unknown = [name for name in names if name not in LANGUAGES]
    if unknown or not names:
        raise click.BadParameter(f"expected a comma-separated list of {', '.join(LANGUAGES)}")
    return names


class JacgenGroup(click.Group):
    """Turns every JacgenError into one line on stderr and exit code 2."""

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except JacgenError as error:
            click.echo(f"jacgen: error: {error}", err=True)
            ctx.exit(2)


@click.group(cls=JacgenGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="jacgen")
def main():
    """Symbolic Jacobian code generator for robot arms."""


@main.command()
@robot_files
@click.option("-o", "--output", "output", default="generated", show_default=True,
              type=click.Path(file_okay=False), help="Folder that receives NAME/ for each robot.")
@click.option("--lang", "languages", default=",".join(DEFAULT_LANGUAGES), show_default=True,
              callback=_languages, help="Comma-separated targets.")
@click.option("--real", type=click.Choice(["double", "float"]), default="double", show_default=True,
              help="Floating-point type of the generated C.")
@click.option("--check", is_flag=True, help="Write nothing; exit 1 with a diff if a file would change.")
def generate(robot_files, output, languages, real, check):
    """Generate code for each ROBOT_FILE."""
    robots = [load_robot(path) for path in robot_files]  # validate every file before writing any
    files = {}
    for robot in robots:
        _progress(f"generating {robot.name}")
        files.update(render_robot(robot, languages, real))
    folder = Path(output)
    if check:
        diffs = stale_files(files, folder)
        for diff in diffs:
            click.echo(diff, nl=False)
        if diffs:
            click.echo(f"jacgen: {len(diffs)} generated file(s) out of date in {folder}", err=True)
            sys.exit(1)
        click.echo(f"jacgen: {len(files)} generated file(s) up to date", err=True)
        return
    written = write_files(files, folder)
    click.echo(f"jacgen: wrote {len(written)} file(s), {len(files) - len(written)} unchanged, in {folder}", err=True)


@main.command()
@robot_files
def validate(robot_files):
    """Check robot files only."""
    for path in robot_files:
        robot = load_robot(path)
        click.echo(f"{path}: ok ({robot.name}, {robot.dof} joints)")


@main.command()
@click.argument("robot_file", type=click.Path(dir_okay=False))
def show(robot_file):
    """Describe a robot in words: DH table and task."""
    click.echo(describe(load_robot(robot_file)))


def _progress(message: str) -> None:
    """Progress on a terminal only, so pipes and CI logs stay clean."""
    if sys.stderr.isatty():
        click.echo(f"jacgen: {message}", err=True)
