"""jacgen's own sources: where its templates are, and one digest of its code and templates.

The digest keys the `generate` cache (`cache.py`): an editable install whose code or
templates changed, or another version of the libraries that shape the output, gives another
digest. Reading and hashing them takes a few milliseconds and imports nothing heavy.
"""

import functools
import hashlib
from importlib import metadata
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
TEMPLATE_FOLDER_CANDIDATES = (
    PACKAGE.parent / "templates",  # a source checkout
    PACKAGE / "templates",  # an installed package
)
# The libraries whose version can change the generated text (sympy's printing and
# simplification, jinja2's rendering, numpy's numbers in the report).
OUTPUT_LIBRARIES = ("sympy", "jinja2", "numpy")


def template_folder() -> Path:
    return next(path for path in TEMPLATE_FOLDER_CANDIDATES if path.is_dir())


def robot_folder() -> Path:
    """The shipped robot files: robots/ of a source checkout, or of the installed package."""
    return next((path for path in (PACKAGE.parent / "robots", PACKAGE / "robots") if path.is_dir()),
                PACKAGE / "robots")


@functools.cache
def digest() -> str:
    """sha256 of jacgen's modules, its templates and the versions of OUTPUT_LIBRARIES."""
    sha = hashlib.sha256()
    for root, pattern in ((PACKAGE, "*.py"), (template_folder(), "*")):
        for path in sorted(p for p in root.rglob(pattern) if p.is_file() and "__pycache__" not in p.parts):
            sha.update(f"{path.relative_to(root).as_posix()}\0{path.stat().st_size}\0".encode())
            sha.update(path.read_bytes())
    for library in OUTPUT_LIBRARIES:
        sha.update(f"{library} {metadata.version(library)}\0".encode())
    return sha.hexdigest()
