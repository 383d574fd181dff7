"""The `jacgen` command line (contract §4). Exit codes: 0 ok, 1 check failed, 2 invalid input."""

import math
import sys
from pathlib import Path

import click

from jacgen import budget, cache
from jacgen.emission.backends import DEFAULT_LANGUAGES, LANGUAGES
from jacgen.errors import JacgenError
from jacgen.files import stale_files, write_files
from jacgen.parallel import usable_cpus
from jacgen.tolerances import URDF_AGREEMENT
from jacgen.version import __version__

# Each command imports what it needs when it runs: `jacgen --help`, `validate` and a cached
# `generate --check` start without sympy, casadi or matplotlib.

robot_files = click.argument("robot_files", nargs=-1, required=True, type=click.Path(dir_okay=False))
jobs_option = click.option("-j", "--jobs", default=usable_cpus(), show_default="the processors usable",
                           type=click.IntRange(min=1), help="Robots at once, each in a process of its own.")


def _languages(ctx, param, value: str) -> tuple[str, ...]:
    names = tuple(dict.fromkeys(part.strip() for part in value.split(",") if part.strip()))
    unknown = [name for name in names if name not in LANGUAGES]
    if unknown or not names:
        what = f"unknown language {unknown[0]!r}; " if unknown else ""
        raise click.BadParameter(f"{what}expected a comma-separated list of {', '.join(LANGUAGES)}")
    return names


def _functions(ctx, param, value: str | None) -> tuple[str, ...] | None:
    if value is None:
        return None
    names = tuple(dict.fromkeys(part.strip() for part in value.split(",") if part.strip()))
    if not names:
        raise click.BadParameter("expected a comma-separated list of function names")
    return names


def _check_functions(names: tuple[str, ...] | None) -> None:
    """--functions names the catalogue has, checked where something is rendered (the catalogue
    imports sympy: a cached `generate --check` needs neither)."""
    if names is None:
        return
    from jacgen.emission.catalogue import with_callees

    try:
        with_callees(names)
    except ValueError as error:
        raise click.BadParameter(str(error), param_hint="'--functions'") from None


def _error_line(message: str) -> None:
    """`jacgen: message` as one line on stderr, whatever the user's text in it holds: a
    character that is not printable (a newline, U+0085, a control) is escaped as Python would."""
    line = "".join(c if c.isprintable() else repr(c)[1:-1] for c in message)
    click.echo(f"jacgen: {line}", err=True)


class JacgenGroup(click.Group):
    """Turns every JacgenError, a file that cannot be written and a usage mistake into one
    line on stderr and exit code 2, and any other exception (a bug of jacgen's) into one
    line and exit code 1; `jacgen --debug ...` shows its traceback. Files are written only
    after everything has been generated, so an error leaves earlier output intact."""

    def main(self, *args, **kwargs):
        """click's main, except that a usage mistake is one line (click adds usage and a hint)."""
        try:
            code = super().main(*args, standalone_mode=False, **kwargs)
        except click.exceptions.NoArgsIsHelpError as error:
            error.show()
            code = error.exit_code
        except click.ClickException as error:
            _error_line(f"error: {error.format_message()}")
            code = error.exit_code
        except click.Abort:
            click.echo("jacgen: aborted", err=True)
            code = 1
        sys.exit(code if isinstance(code, int) else 0)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except JacgenError as error:
            _error_line(f"error: {error}")
            ctx.exit(2)
        except OSError as error:
            _error_line(f"error: {error.filename or ''}: {error.strerror or error}")
            ctx.exit(2)
        except (click.exceptions.Exit, click.ClickException, click.Abort):
            raise
        except Exception as error:  # noqa: BLE001 (a bug: one line, the traceback on request)
            if ctx.params.get("debug"):
                raise
            what = str(error)[:200]
            _error_line(f"internal error: {type(error).__name__}{': ' if what else ''}{what} "
                        f"(a bug in jacgen; run with --debug for the traceback)")
            ctx.exit(1)


@click.group(cls=JacgenGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="jacgen")
@click.option("--debug", is_flag=True, help="Show the traceback of an internal error.")
def main(debug):
    """Symbolic Jacobian code generator for robot arms."""


@main.command()
@robot_files
@click.option("-o", "--output", "output", default="generated", show_default=True,
              type=click.Path(file_okay=False), help="Folder that receives NAME/ for each robot.")
@click.option("--lang", "languages", default=",".join(DEFAULT_LANGUAGES), show_default=True,
              callback=_languages, help="Comma-separated targets, of c, python, casadi, report and native (a Python "
                                        "extension module of the C, to pip install).")
@click.option("--real", type=click.Choice(["double", "float"]), default="double", show_default=True,
              help="Floating-point type of the generated C (native has both).")
@click.option("--check", is_flag=True, help="Write nothing; exit 1 with a diff if a file would change.")
@click.option("--functions", "functions", default=None, callback=_functions, metavar="NAMES",
              help="Comma-separated functions to generate (with those they call), e.g. fk_jacobian,ik; "
                   "default: all.")
@click.option("--budget", "budget_seconds", default=budget.DEFAULT_SECONDS, show_default=True,
              type=click.FloatRange(min=0), metavar="SECONDS",
              help="Safety net on the exact singularity analysis of each robot, whose work is "
                   "bounded by size limits anyway: past it the numeric rank determinant stands as the "
                   "condition, with a warning (0: no limit).")
@click.option("--no-cache", "no_cache", is_flag=True,
              help="Render every robot, even one whose file, options and jacgen are unchanged since the files "
                   "were last written (cache: $XDG_CACHE_HOME/jacgen).")
@jobs_option
def generate(robot_files, output, languages, real, check, functions, budget_seconds, no_cache, jobs):
    """Generate code for each ROBOT_FILE."""
    if real == "float" and {"c", "native"} <= set(languages):
        raise click.UsageError("--lang native writes NAME.c in double beside NAME_float.c; with --real float, "
                               "write the float C of --lang c into another folder")
    folder = Path(output)
    options = {"languages": list(languages), "real": real, "functions": functions and list(functions),
               "budget": budget_seconds}
    paths = list(dict.fromkeys(Path(path) for path in robot_files))
    keys = {path: None if no_cache else cache.key(path, options) for path in paths}
    cached = {path: entry for path in paths if keys[path] and (entry := cache.hit(keys[path], folder))}
    robots, files = [], {}
    if len(cached) < len(paths):
        from jacgen.emission.render import render_robots
        from jacgen.inputs.robot_file import load_robot

        _check_functions(functions)
        budget.set_seconds(budget_seconds)
        robots = [load_robot(path) for path in paths if path not in cached]  # validate all before writing any
    _check_unique_names([(robot.name, robot.source) for robot in robots] +
                        [(entry["robot"], str(path)) for path, entry in cached.items()])
    if robots:
        files = render_robots(robots, languages, real, functions, jobs,
                              lambda robot: _progress(f"generated {robot.name}"))
    unchanged = sum(len(entry["files"]) for entry in cached.values())
    if check:
        diffs = stale_files(files, folder)
        for diff in diffs:
            click.echo(diff, nl=False)
        if diffs:
            click.echo(f"jacgen: {len(diffs)} generated file(s) out of date in {folder}", err=True)
            sys.exit(1)
        _remember(robots, files, keys)
        click.echo(f"jacgen: {len(files) + unchanged} generated file(s) up to date", err=True)
        return
    written = write_files(files, folder)
    _remember(robots, files, keys)
    click.echo(f"jacgen: wrote {len(written)} file(s), {len(files) + unchanged - len(written)} unchanged, in {folder}",
               err=True)


def _remember(robots: list, files: dict[str, str], keys: dict[Path, str | None]) -> None:
    """Records, per robot rendered, the files it has on disk now (cache.store)."""
    for robot in robots:
        if key := keys[Path(robot.source)]:
            cache.store(key, robot.name, {relative: text for relative, text in files.items()
                                          if relative.startswith(f"{robot.name}/")})


@main.command()
@click.argument("robots", nargs=-1, required=True)
@click.option("--backend", type=click.Choice(["native", "python", "casadi"]), default="native", show_default=True,
              help="The module to build.")
@click.option("--functions", "functions", default=None, callback=_functions, metavar="NAMES",
              help="Comma-separated functions to generate (with those they call); default: all.")
def build(robots, backend, functions):
    """Fill jacgen.arm's cache for each of ROBOTS (robot files, URDFs or shipped robots' names),
    ahead of time: for container images and CI. Exit 2 when a module cannot be built."""
    from jacgen.loading import arm

    _check_functions(functions)
    for robot in robots:
        module = arm(robot, backend=backend, functions=functions)
        click.echo(f"{robot}: {module.__name__} ({module.__file__})")


@main.command()
@robot_files
def validate(robot_files):
    """Check robot files only."""
    from jacgen.inputs.robot_file import load_robot

    for path in robot_files:
        robot = load_robot(path)
        click.echo(f"{path}: ok ({robot.name}, {robot.dof} joints)")


def _configuration(ctx, param, value: str | None):
    if value is None:
        return None
    try:
        q = [float(part) for part in value.split(",")]
    except ValueError:
        q = [math.nan]
    if not all(math.isfinite(x) for x in q):
        raise click.BadParameter(f"expected comma-separated finite numbers, got {value!r}")
    return q


@main.command()
@click.argument("robot_file", type=click.Path(dir_okay=False))
@click.option("--plot", "plot_file", type=click.Path(dir_okay=False), default=None, metavar="FILE.png",
              help="Also draw the arm (3D, at q, with the tool's velocity ellipsoid; planar arms: with the "
                   "manipulability map, workspace boundary and velocity ellipses) into FILE (.png, .svg, .pdf); "
                   "needs matplotlib.")
@click.option("--q", "q", callback=_configuration, default=None, metavar="q1,q2,...",
              help="The configuration to draw (radians, and lengths for prismatic joints; default: q = 0 "
                   "and the middle of the limits, or where that is q = 0, each joint halfway to its upper limit, "
                   "at most 45 deg).")
@click.option("--compare-urdf", "urdf_file", type=click.Path(dir_okay=False), default=None, metavar="FILE.urdf",
              help="Compare the joint axes and tool pose with a URDF's chain; exit 1 where they differ.")
@click.option("--base", default=None, metavar="LINK", help="--compare-urdf: first link (default: the root).")
@click.option("--tip", default=None, metavar="LINK", help="--compare-urdf: last link (default: the one leaf).")
@click.option("--tolerance", default=URDF_AGREEMENT, show_default=True, type=click.FloatRange(min=0),
              help="--compare-urdf: largest difference (radians, robot's length unit) that agrees.")
def show(robot_file, plot_file, q, urdf_file, base, tip, tolerance):
    """Describe a robot in words (DH table, task, singularities, inverse kinematics), draw it,
    compare it with a URDF."""
    from jacgen.inputs.robot_file import load_robot
    from jacgen.reports.description import describe
    from jacgen.solvers.model import Model

    robot = load_robot(robot_file)
    if q is not None and len(q) != robot.dof:
        raise JacgenError(f"--q: expected {robot.dof} values (one per joint of {robot.name}), got {len(q)}")
    if plot_file:
        from jacgen.reports.drawing import check_plot_format

        plot_format = Path(plot_file).suffix[1:].lower() or "png"
        check_plot_format(plot_format)  # before the text: a refused --plot prints one line only
    click.echo(describe(Model(robot)))
    if plot_file:
        import numpy as np

        from jacgen.reports.drawing import default_configurations, draw

        configurations = {"at --q": np.array(q)} if q is not None else default_configurations(robot)
        drawing = draw(robot, configurations, plot_format)
        write_files({Path(plot_file).name: drawing}, Path(plot_file).parent)
        click.echo(f"jacgen: wrote {plot_file}", err=True)
    if urdf_file:
        from jacgen.reports.urdf_comparison import compare_urdf, comparison_lines, first_difference

        comparison = compare_urdf(robot, urdf_file, base, tip)
        click.echo("\n" + "\n".join(comparison_lines(robot, urdf_file, comparison, tolerance)))
        if first_difference(comparison, tolerance) is not None:
            sys.exit(1)


@main.command()
@robot_files
@click.option("--samples", default=200, show_default=True, type=click.IntRange(min=1),
              help="Random configurations per robot, besides those near singularities.")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of the random configurations.")
@click.option("--target", type=click.Choice(["cortex-m4f"]), default=None,
              help="Check the float C on an emulated target instead of the host backends (needs "
                   "arm-none-eabi-gcc and qemu-system-arm), and print its flash, stack and instructions.")
@click.option("--sources", type=click.Path(file_okay=False, exists=True), default=None, metavar="DIR",
              help="With --target: run DIR/NAME/NAME.c and .h (the float C you ship, as `generate --real float -o DIR` "
                   "writes it) instead of generating them.")
@click.option("--native", is_flag=True,
              help="Build NAME_native too (generate --lang native, as pip builds it) and compare every function "
                   "of it, one call and batched, SIMD and scalar, double and float (about 20 s of compiling per robot).")
@jobs_option
def verify(robot_files, samples, seed, target, sources, native, jobs):
    """Compare every generated function of every backend with the numpy reference."""
    from jacgen.checking.verify import format_table
    from jacgen.checking.verify import verify as verify_robots
    from jacgen.inputs.robot_file import load_robot

    if sources and not target:
        raise click.UsageError("--sources needs --target")
    if native and target:
        raise click.UsageError("--native checks the host's native module; --target the emulated target's C")
    robots = [load_robot(path) for path in dict.fromkeys(robot_files)]
    _check_unique_names([(robot.name, robot.source) for robot in robots])
    emulators = []
    results = verify_robots(robots, samples, seed, _progress, target=target, sources=sources and Path(sources),
                            emulators=emulators, jobs=jobs, native=native)
    click.echo(format_table(results))
    if emulators:
        from jacgen.checking.cortex_m4f import format_resources

        click.echo("\n" + format_resources(emulators))
    if any(result.failed for result in results):
        sys.exit(1)


def _import_options(frames: str, frame: str, default_base: str, tip: str):
    """The options import-urdf and import-mjcf share."""
    def decorate(command):
        for option in reversed((
            click.option("--base", default=None, metavar=frame, help=f"First {frame.lower()} of the chain "
                         f"(default: {default_base})."),
            click.option("--tip", default=None, metavar=tip, help=f"Last {tip.lower()} of the chain (default: the one "
                         f"leaf {frame.lower()} below the base)."),
            click.option("--convention", type=click.Choice(["standard", "modified"]), default="standard",
                         show_default=True, help="DH convention of the robot file."),
            click.option("--name", default=None, help="Robot name (default: the file's, made a valid name)."),
            click.option("--task", default=None, metavar="x,y,...", help="Task components (default: all six, or for "
                         "fewer than six joints the first independent ones)."),
            click.option("--snap", default=None, type=click.FloatRange(0, 0.01), metavar="RADIANS",
                         help="Angles and axes this close to a multiple of 90 degrees become exact (default: an angle "
                         f"that is one to the digits it is written with, as 1.5708; docs/{frames}.md)."),
            click.option("-o", "--output", default=None, type=click.Path(dir_okay=False), metavar="FILE.yaml",
                         help="Write the robot file here (default: standard output)."),
        )):
            command = option(command)
        return command
    return decorate


@main.command("import-urdf")
@click.argument("urdf_file", type=click.Path(dir_okay=False))
@_import_options("urdf", "LINK", "the root", "LINK")
def import_urdf_command(urdf_file, base, tip, convention, name, task, snap, output):
    """Convert the serial chain of a URDF into a DH robot file, exactly."""
    from jacgen.urdf_import import URDF

    _import(URDF, urdf_file, base, tip, convention, name, task, snap, output)


@main.command("import-mjcf")
@click.argument("mjcf_file", type=click.Path(dir_okay=False))
@_import_options("mjcf", "BODY", "the world", "BODY|SITE")
def import_mjcf_command(mjcf_file, base, tip, convention, name, task, snap, output):
    """Convert the serial chain of an MJCF file (MuJoCo) into a DH robot file, exactly."""
    from jacgen.urdf_import import MJCF

    _import(MJCF, mjcf_file, base, tip, convention, name, task, snap, output)


def _import(form, path, base, tip, convention, name, task, snap, output) -> None:
    from jacgen.urdf_import import CHECK_CONFIGURATIONS, import_description

    components = tuple(part.strip() for part in task.split(",")) if task else None
    imported = import_description(form, path, base, tip, convention, name, components, snap)
    if output:
        write_files({Path(output).name: imported.text}, Path(output).parent)
        click.echo(f"jacgen: wrote {output}", err=True)
    else:
        click.echo(imported.text, nl=False)
    changes = [f"angles made exact by up to {imported.snapped:.1g} rad"] if imported.snapped else []
    changes += [f"{len(imported.zeroed)} length(s) of rounding level made 0"] if imported.zeroed else []
    changed = f" ({'; '.join(changes)})" if changes else ""
    click.echo(f"jacgen: {imported.robot.name}: {imported.robot.dof} joints; fk within "
               f"{imported.fk_difference:.1g} of the {form.name} as written, at {CHECK_CONFIGURATIONS} random "
               f"configurations{changed}", err=True)


def _check_unique_names(robots: list[tuple[str, str]]) -> None:
    """Each robot (name, source) writes NAME/: two files naming the same robot would overwrite
    each other."""
    first = {}
    for name, source in robots:
        other = first.setdefault(name, source)
        if other != source:
            raise JacgenError(f"{source}: name: robot name {name!r} is already used by "
                              f"{other} (each robot is written to its own folder NAME/)")


def _progress(message: str) -> None:
    """Progress on a terminal only, so pipes and CI logs stay clean."""
    if sys.stderr.isatty():
        click.echo(f"jacgen: {message}", err=True)
