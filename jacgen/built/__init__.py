"""The modules `jacgen.arm` built, importable by name: `jacgen.built.k<key>.<module>`.

Each cache entry is a folder in one of this package's folders (`search_path()`: the arms/
folder of the default cache and those named in $JACGEN_ARM_FOLDERS), so that a process that
never called `jacgen.arm`, such as a spawned worker unpickling one of its functions, imports
it too.
"""

import os
from pathlib import Path

from jacgen import cache

ENTRY_FOLDERS = "JACGEN_ARM_FOLDERS"  # more folders of entries, for the spawned workers' imports


def default_folder() -> Path:
    """$JACGEN_CACHE_DIR, else `generate`'s cache folder ($XDG_CACHE_HOME/jacgen)."""
    return Path(os.environ.get("JACGEN_CACHE_DIR") or cache.folder())


def search_path() -> list[str]:
    """The folders whose entries this package imports."""
    folders = [str(default_folder() / "arms")]
    return folders + [f for f in os.environ.get(ENTRY_FOLDERS, "").split(os.pathsep) if f and f not in folders]


def add(folder: Path) -> None:
    """Imports the entries of `folder` too, here and in the processes started from now on."""
    folder = str(folder)
    if folder not in __path__:
        __path__.append(folder)
    if folder not in search_path():
        os.environ[ENTRY_FOLDERS] = os.pathsep.join(filter(None, [os.environ.get(ENTRY_FOLDERS), folder]))


__path__ = search_path()
