"""What `generate` last wrote for a robot file, so that an unchanged robot is not rendered again.

An entry's key is the sha256 of the robot file's bytes and name, the options that shape the
output (languages, real, functions, budget) and `sources.digest()` (jacgen's code, templates
and the libraries that shape the text). It maps to the robot's name and the sha256 of each
file written. A robot hits when its entry exists and every one of those files is on disk with
that hash, so a generated file edited by hand is still found stale. The entries live in
$XDG_CACHE_HOME/jacgen (~/.cache/jacgen), one small JSON file each; one that does not parse, is
for another key or names a path outside its robot's folder is ignored, never trusted.
"""

import hashlib
import json
import os
from pathlib import Path, PurePosixPath

from jacgen import sources
from jacgen.files import write_files

FORMAT = 1


def folder() -> Path:
    """$XDG_CACHE_HOME/jacgen, or ~/.cache/jacgen."""
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "jacgen"


def key(robot_file: Path, options: dict) -> str | None:
    """The key of `generate` for this robot file with these options (JSON-able values); None
    when the file cannot be read (loading it then says why)."""
    try:
        data = robot_file.read_bytes()
    except OSError:
        return None
    sha = hashlib.sha256(f"jacgen generate cache {FORMAT}\0{sources.digest()}\0".encode())
    sha.update(json.dumps(options, sort_keys=True).encode() + b"\0")
    sha.update(robot_file.name.encode() + b"\0")  # the generated header names the file
    sha.update(data)
    return sha.hexdigest()


def file_hash(text: str | bytes) -> str:
    return hashlib.sha256(text.encode("utf-8") if isinstance(text, str) else text).hexdigest()


def hit(entry_key: str, output: Path) -> dict | None:
    """The entry ({"robot": name, "files": {path: sha256}}) when it exists and every file it
    lists is in `output` unchanged."""
    entry = _read(entry_key)
    if entry is None:
        return None
    for relative, expected in entry["files"].items():
        path = output / relative
        if not path.is_file() or file_hash(path.read_bytes()) != expected:
            return None
    return entry


def store(entry_key: str, robot_name: str, files: dict[str, str]) -> None:
    """Records `files` ({path relative to the output folder: text}) as what this key writes.
    A cache that cannot be written is no error: the next run renders again."""
    entry = {"format": FORMAT, "key": entry_key, "robot": robot_name,
             "files": {relative: file_hash(text) for relative, text in sorted(files.items())}}
    try:
        write_files({f"{entry_key}.json": json.dumps(entry, indent=1) + "\n"}, folder())
    except OSError:
        pass


def _read(entry_key: str) -> dict | None:
    try:
        entry = json.loads((folder() / f"{entry_key}.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not (isinstance(entry, dict) and entry.get("format") == FORMAT and entry.get("key") == entry_key
            and isinstance(entry.get("robot"), str) and isinstance(entry.get("files"), dict) and entry["files"]):
        return None
    for relative, expected in entry["files"].items():
        parts = PurePosixPath(relative).parts if isinstance(relative, str) else ()
        if not (len(parts) == 2 and parts[0] == entry["robot"] and ".." not in parts and isinstance(expected, str)):
            return None
    return entry
