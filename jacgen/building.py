"""Generated code -> a module in this process: the import of a generated Python file or built
extension by its path, and the build of the native module (`generate --lang native`'s
setup.py) for this machine. `jacgen.arm` (loading.py) and the checkers use them; neither
caches anything here.
"""

import functools
import importlib.machinery
import importlib.util
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from jacgen.errors import JacgenError


class BuildError(JacgenError):
    """The native module could not be built here (no compiler, no headers, no setuptools, or
    $JACGEN_NO_BUILD on a cache miss)."""


def import_module(path: Path, module_name: str):
    """The Python source or extension module at `path`, imported as `module_name` and put in
    sys.modules (so that its functions pickle by name). An extension module loads once per
    process: a second import of that name returns the first."""
    if module_name in sys.modules and str(path).endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES)):
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[module_name]
        raise
    return module


def build_native(folder: Path, name: str, progress: "Progress | None" = None) -> Path:
    """Builds NAME_native in `folder` (what `generate --lang native` wrote for the robot) with
    its setup.py, in place, for this machine's instruction set (host_instruction_set); the
    built file's path. BuildError with the first error."""
    try:
        import setuptools  # noqa: F401 (setup.py needs it)
    except ImportError:
        raise BuildError(f"building {name}_native needs setuptools: pip install 'jacgen[native]' "
                         "(backend='python' needs no compiler)") from None
    environment = dict(os.environ)
    if (instruction_set := host_instruction_set()) is not None:
        environment["JACGEN_INSTRUCTION_SET"] = instruction_set
    with tempfile.TemporaryDirectory() as scratch:
        command = [sys.executable, "setup.py", "-q", "build_ext", "--inplace", "--build-temp", scratch]
        with subprocess.Popen(command, cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                              env=environment) as run:
            output = _wait(run, progress)
    shutil.rmtree(folder / "build", ignore_errors=True)
    built = sorted(folder.glob(f"{name}_native.*.so")) + sorted(folder.glob(f"{name}_native.*.pyd"))
    if run.returncode != 0 or not built:
        raise BuildError(f"building {name}_native failed: {first_error(output)} (backend='python' needs no compiler)")
    return built[0]


@functools.cache
def host_instruction_set() -> str | None:
    """The widest of the native kernels' instruction sets (avx512f, avx2, default) that this
    x86-64 processor runs, from /proc/cpuinfo; None where it cannot tell or there is no choice
    (setup.py then builds what it builds for a package: the three clones on x86-64)."""
    if platform.machine() not in ("x86_64", "AMD64"):
        return None
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as cpuinfo:
            flags = next(line for line in cpuinfo if line.startswith("flags")).split()
    except (OSError, StopIteration):
        return None
    return "avx512f" if "avx512f" in flags else "avx2" if "avx2" in flags else "default"


def load_native(folder: Path, name: str):
    """NAME_native built in `folder` (build_native) and imported as NAME_native."""
    return import_module(build_native(folder, name), f"{name}_native")


def _wait(run: subprocess.Popen, progress: "Progress | None") -> str:
    """The output of `run` once it ends, showing its progress every second meanwhile."""
    chunks = []
    reader = threading.Thread(target=lambda: chunks.append(run.stdout.read()), daemon=True)
    reader.start()
    while run.poll() is None:
        if progress is not None:
            progress.tick()
        time.sleep(0.25)
    reader.join()
    return "".join(chunks)


def first_error(output: str) -> str:
    """The line of a compiler's (or tool's) output worth one error line: its first error."""
    lines = output.splitlines()
    return next((line for line in lines if " error: " in line or "cannot build: " in line),
                lines[0] if lines else "no output").strip()


class Progress:
    """One line on stderr that updates while an arm is built: its stage and the seconds so far."""

    def __init__(self, what: str):
        self.what, self.stage, self.start, self.shown = what, "", time.monotonic(), 0.0

    def show(self, stage: str) -> None:
        self.stage = stage
        self.tick(force=True)

    def tick(self, force: bool = False) -> None:
        now = time.monotonic()
        if force or now - self.shown >= 1:
            self.shown = now
            sys.stderr.write(f"\rjacgen: {self.what}: {self.stage} ({now - self.start:.0f} s)".ljust(72))
            sys.stderr.flush()

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exception) -> None:
        sys.stderr.write("\n")
