"""The output folder: atomic writes that leave unchanged files alone, and diffs against disk.

Light on imports, so that a cached `generate` (`cache.py`) never loads the generator.
"""

import difflib
import os
import tempfile
from pathlib import Path


def stale_files(files: dict[str, str], folder: Path) -> list[str]:
    """Unified diffs of the files that differ from what is on disk (missing counts as empty)."""
    diffs = []
    for relative, text in sorted(files.items()):
        target = folder / relative
        current = target.read_text(encoding="utf-8") if target.is_file() else ""
        if current != text:
            diffs.append("".join(difflib.unified_diff(
                current.splitlines(keepends=True), text.splitlines(keepends=True),
                fromfile=f"a/{relative}", tofile=f"b/{relative}")))
    return diffs


def write_files(files: dict[str, str | bytes], folder: Path) -> list[Path]:
    """Write each file atomically (temporary file + rename); unchanged files are not touched.
    Text is written as UTF-8 with \\n line ends, bytes as they are (a drawing)."""
    written = []
    for relative, content in sorted(files.items()):
        target = folder / relative
        data = content if isinstance(content, bytes) else content.encode("utf-8")
        if target.is_file() and target.read_bytes() == data:
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as stream:
                stream.write(data)
            # mkstemp makes the file private (0600): give it the mode the file had, or a new file's
            os.chmod(temporary, target.stat().st_mode & 0o7777 if target.exists() else _new_file_mode())
            os.replace(temporary, target)
        except BaseException:
            os.unlink(temporary)
            raise
        written.append(target)
    return written


def _new_file_mode() -> int:
    """The mode `open` gives a new file: 0666 less the process's umask."""
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask
