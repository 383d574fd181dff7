"""Generated code -> imported Python modules: `jacgen.arm`, the one loader of generated modules.

`arm(source)` returns the module `generate` writes for a robot (NAME.py, NAME_casadi.py, or
NAME_native built), rendered and built once and kept in a cache entry keyed by content:

- the key hashes what `generate`'s cache hashes (the robot file's bytes and name, the options,
  jacgen's code and templates and the versions of the libraries that shape the output,
  `sources.digest()`), the backend and, for native, the Python ABI (EXT_SUFFIX);
- an entry is a folder `<cache>/arms/k<key>/` with the robot file, the generated files, the
  built extension and `manifest.json`, the sha256 of each. A hit checks every hash, so a
  corrupt entry is rebuilt, never trusted; it imports no sympy and runs no compiler;
- an entry is built in a private folder and renamed into place, under a lock file, so that
  processes asking for the same arm at once build it once and all get it;
- the entries are the package `jacgen.built` (its `__path__` is the cache folders), so that
  a module is importable by name, `jacgen.built.k<key>.ur5`: its functions pickle into
  `multiprocessing`'s spawn workers and dask's workers on this machine.
"""

import atexit
import contextlib
import functools
import hashlib
import importlib
import json
import os
import shutil
import sys
import sysconfig
import tempfile
import types
import warnings
from pathlib import Path

from jacgen import built, cache, sources
from jacgen.building import BuildError, Progress, build_native, host_instruction_set
from jacgen.built import default_folder
from jacgen.errors import JacgenError
from jacgen.files import write_files

BACKENDS = ("python", "native", "casadi", "auto")
MODULES = {"python": "{name}", "casadi": "{name}_casadi", "native": "{name}_native"}
FORMAT = 1
# The robot descriptions jacgen.arm imports, by file suffix (urdf_import.FORMATS).
DESCRIPTIONS = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf"}
NO_BUILD = "JACGEN_NO_BUILD"
URDF_OPTIONS = ("base", "tip", "convention", "name", "task", "snap")


class ArmModule(types.ModuleType):
    """A module that `arm` returned: its repr names the robot, the backend and the functions."""

    def __repr__(self) -> str:
        functions = ", ".join(self.__jacgen__["functions"])
        return f"<jacgen arm {self.__jacgen__['robot']!r} ({self.__jacgen__['backend']}): {functions}>"


def arm(source, *, backend: str = "python", functions=None, base=None, tip=None, convention="standard",
        name=None, task=None, snap=None, cache_folder=None):
    """The generated module of a robot: `source` is a robot file, a URDF (the chain from `base`
    to `tip`, with import-urdf's other options), an MJCF file (.xml: the chain from the body `base` to
    the body or site `tip`, as import-mjcf) or the name of a shipped robot ("ur5").

    backend: "python" (NAME.py: numpy, JAX, PyTorch), "native" (NAME_native: the C, built
    here), "casadi", or "auto" (native where it builds, else python with one warning).
    functions: only those (and what they call), as `generate --functions`. cache_folder: the
    cache's place (default $JACGEN_CACHE_DIR, else generate's cache folder).
    """
    if backend not in BACKENDS:
        raise ValueError(f"backend must be one of {', '.join(BACKENDS)}, not {backend!r}")
    if backend == "auto":
        try:
            return arm(source, backend="native", functions=functions, base=base, tip=tip, convention=convention,
                       name=name, task=task, snap=snap, cache_folder=cache_folder)
        except BuildError as error:
            _warn_once(f"jacgen.arm: the Python module instead of the native one: {error}")
            backend = "python"
    path = robot_path(source)
    form = DESCRIPTIONS.get(path.suffix.lower())
    options = {form: {"base": base, "tip": tip, "convention": convention, "name": name,
                      "task": None if task is None else list(task), "snap": snap}} if form else {}
    if form is None and any(value is not None for value in (base, tip, name, task, snap)):
        raise JacgenError(f"{path}: base, tip, name, task and snap are options of a URDF or an MJCF file, "
                          "not of a robot file")
    functions = None if functions is None else [functions] if isinstance(functions, str) else list(functions)
    key = _key(path, {"backend": backend, "functions": functions, **options})
    folder = Path(cache_folder) if cache_folder is not None else default_folder()
    entry = _hit(folder, key)
    if entry is None:
        if os.environ.get(NO_BUILD, "") not in ("", "0"):
            raise BuildError(f"{path}: no cached {backend} module and {NO_BUILD} is set "
                             f"(fill the cache with `jacgen build {path} --backend {backend}`)")
        folder, entry = _build(folder, key, path, backend, functions, options)
    return _load(folder, entry)


def robot_path(source) -> Path:
    """The file of `source`: a path, or the name of a shipped robot."""
    path = Path(source)
    if path.suffix or os.sep in str(source) or path.exists():
        if not path.is_file():
            raise JacgenError(f"{path}: no such robot file")
        return path
    shipped = sources.robot_folder() / f"{source}.yaml"
    if not shipped.is_file():
        names = ", ".join(sorted(p.stem for p in sources.robot_folder().glob("*.yaml")))
        raise JacgenError(f"{source!r} is neither a file nor a shipped robot ({names})")
    return shipped


def _key(path: Path, options: dict) -> str:
    sha = hashlib.sha256(f"jacgen arm {FORMAT}\0{sources.digest()}\0".encode())
    if options["backend"] == "native":
        sha.update(f"{sysconfig.get_config_var('EXT_SUFFIX')}\0{sys.version}\0{host_instruction_set()}\0".encode())
    sha.update(json.dumps(options, sort_keys=True).encode() + b"\0")
    sha.update(path.name.encode() + b"\0" + path.read_bytes())
    return sha.hexdigest()[:32]


def _entry_name(key: str) -> str:
    return f"k{key}"


def _hit(folder: Path, key: str) -> dict | None:
    """The manifest of the entry for `key` in `folder` when every file it lists is intact."""
    entry = folder / "arms" / _entry_name(key)
    try:
        manifest = json.loads((entry / "manifest.json").read_text(encoding="utf-8"))
        if manifest.get("format") != FORMAT or manifest.get("key") != key:
            return None
        for relative, expected in manifest["files"].items():
            if Path(relative).name != relative or cache.file_hash((entry / relative).read_bytes()) != expected:
                return None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    return manifest


def _load(folder: Path, manifest: dict):
    """The entry's module, imported by its name under `jacgen.built`."""
    built.add(folder / "arms")
    module = importlib.import_module(f"jacgen.built.{_entry_name(manifest['key'])}.{manifest['module']}")
    if not isinstance(module, ArmModule):
        module.__class__ = ArmModule
        module.__jacgen__ = {key: manifest[key] for key in ("robot", "backend", "functions")}
    return module


@contextlib.contextmanager
def _locked(path: Path):
    """Holds an exclusive lock on the file `path` (no lock where the platform has none)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    with open(path, "a") as stream:
        fcntl.flock(stream, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(stream, fcntl.LOCK_UN)


def _build(folder: Path, key: str, path: Path, backend: str, functions, options: dict) -> tuple[Path, dict]:
    """Renders (and builds) the entry in a private folder and renames it into place, holding
    the key's lock; a folder that cannot be written is replaced by a temporary one, with a
    warning. Returns the folder used and the entry's manifest."""
    arms = folder / "arms"
    try:
        arms.mkdir(parents=True, exist_ok=True)
        lock = arms / f".{_entry_name(key)}.lock"
        lock.touch()
    except OSError as error:
        folder = _private_folder()
        _warn_once(f"jacgen.arm: cannot write the cache ({error.strerror or error}: {error.filename or arms}); "
                   f"building in {folder} for this process")
        arms = folder / "arms"
        lock = arms / f".{_entry_name(key)}.lock"
    with _locked(lock):
        manifest = _hit(folder, key)  # built by another process meanwhile
        if manifest is not None:
            return folder, manifest
        private = Path(tempfile.mkdtemp(prefix=f".{_entry_name(key)}.", dir=arms))
        try:
            with Progress(path.name) as progress:
                manifest = _render(private, key, path, backend, functions, options, progress)
            final = arms / _entry_name(key)
            if final.exists():  # a corrupt entry: out of the way first
                shutil.rmtree(final, ignore_errors=True)
            os.rename(private, final)
        finally:
            shutil.rmtree(private, ignore_errors=True)
    return folder, manifest


def _render(entry: Path, key: str, path: Path, backend: str, functions, options: dict, progress: "Progress"
            ) -> dict:
    """Writes the robot file, the generated files and (native) the built module into `entry`,
    then the manifest; returns it."""
    from jacgen.emission.generator import Generator
    from jacgen.emission.render import render_robot
    from jacgen.inputs.robot_file import load_robot

    progress.show("generating")
    if options:
        from jacgen import urdf_import

        (form, given), = options.items()
        given = {option: value for option, value in given.items() if value is not None}
        if "task" in given:
            given["task"] = tuple(given["task"])
        imported = urdf_import.import_description(urdf_import.FORMATS[form], str(path), **given)
        robot_file = entry / f"{imported.robot.name}.yaml"
        robot_file.write_text(imported.text, encoding="utf-8")
    else:
        robot_file = entry / path.name
        shutil.copyfile(path, robot_file)
    robot = load_robot(robot_file)
    generator = Generator(robot, selection=functions)
    files = render_robot(robot, ("native",) if backend == "native" else (backend,), generator=generator)
    write_files({relative.split("/", 1)[1]: text for relative, text in files.items()}, entry)
    module = MODULES[backend].format(name=robot.name)
    if backend == "native":
        progress.show(f"compiling {module}")
        build_native(entry, robot.name, progress)
    progress.show(f"built {module}")
    manifest = {"format": FORMAT, "key": key, "robot": robot.name, "backend": backend, "module": module,
                "functions": [f.name for f in generator.signatures()],
                "files": {p.name: cache.file_hash(p.read_bytes()) for p in sorted(entry.iterdir()) if p.is_file()}}
    (entry / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    return manifest


_warned: set[str] = set()


def _warn_once(message: str) -> None:
    """A warning, once per process for each kind (the words before the first parenthesis)."""
    kind = message.split("(")[0]
    if kind not in _warned:
        _warned.add(kind)
        warnings.warn(message, RuntimeWarning, stacklevel=3)


@functools.cache
def _private_folder() -> Path:
    """This process's cache folder where the cache cannot be written, removed at exit."""
    folder = Path(tempfile.mkdtemp(prefix="jacgen-arms-"))
    (folder / "arms").mkdir()
    atexit.register(shutil.rmtree, folder, True)
    return folder
