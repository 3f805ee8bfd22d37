"""Writing files atomically (a temporary file beside the target, then a rename) with the
permissions ``open(path, "w")`` would give (``tempfile.mkstemp``'s are 0600).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


def current_umask() -> int:
    """The process's umask (read from /proc where available, which changes nothing)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)  # no read-only query elsewhere: set and restore at once
    os.umask(mask)
    return mask


def make_folder_for(path: Path) -> Path:
    """Make ``path``'s folder (and its parents) and check that it can be written in;
    returns the folder.  An OSError saying which folder and why otherwise."""
    folder = Path(path).parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(f"the folder {folder} cannot be made ({exc.strerror})") from None
    if not os.access(folder, os.W_OK):
        raise OSError(f"the folder {folder} is not writable; choose another one")
    return folder


def atomic_write(path: Path, write, suffix: str | None = None) -> Path:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then rename it to
    ``path``; on any failure the temporary file is removed and ``path`` is untouched.  A
    missing folder is a FileNotFoundError naming it (not the temporary file)."""
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"the folder {path.parent} does not exist")
    fd, name = tempfile.mkstemp(
        prefix=f".{path.name}.", suffix=path.suffix if suffix is None else suffix, dir=path.parent
    )
    tmp = Path(name)
    try:
        os.fchmod(fd, 0o666 & ~current_umask())  # what a new file of open() gets
    finally:
        os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path
