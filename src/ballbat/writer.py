"""The one writer of the ``ballbat`` command line: it never replaces what it did not write.

Every file a command writes (``-o FILE``) goes through :func:`write_output`. It refuses, with one
line naming the path and saying why (:class:`OutputRefused`):

* a path that is an input of the same command (a file it reads, or a path inside a folder it reads);
* anything existing that is not a regular file: a folder, a device (``/dev/null``, ``/dev/full``),
  a pipe, a socket, a symbolic link;
* an existing regular file that ballbat did not write: only a file that ends in ballbat's check
  line (``# ballbat table: N rows, sha256 ...``, :func:`ballbat.pipeline.checked.sealed_csv`) is
  replaced, so a lab's own file is never lost;
* a folder that does not exist, unless ``parents`` is given (``--parents``).

``-`` means standard output. The write is atomic (:func:`ballbat.pipeline.atomic.atomic_target`:
a temporary file in the same folder, renamed into place), so a failure (a full disk) leaves the
file that was there, whole.
"""

from __future__ import annotations

import errno
import os
import stat
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from collections.abc import Iterable

STDOUT = "-"


class OutputRefused(Exception):
    """The output path is refused (a usage error: exit status 2); the message is one line naming the path."""


class OutputFailed(OutputRefused):
    """The write itself failed (a full disk: exit status 1); what was at the path is unchanged."""


def _kind(mode: int) -> str:
    """Name the kind of a file that is not a regular file."""
    if stat.S_ISDIR(mode):
        return "a folder: give a file name inside it"
    if stat.S_ISLNK(mode):
        return "a symbolic link: give the file it points to, or another name"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device, not a regular file (use '-' for standard output)"
    return "not a regular file (a pipe or socket; use '-' for standard output)"


def _inside(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def _input_clash(target: Path, inputs: Iterable[str | os.PathLike[str]]) -> str | None:
    """Return the input ``target`` is, or lies in (None when it is none of them)."""
    real = Path(os.path.realpath(target))
    for given in inputs:
        src = Path(os.path.realpath(given))
        if src.is_dir() and _inside(real, src):
            return f"inside the input folder {given} (this command reads it; the next run would too)"
        if real == src:
            return f"an input of this command ({given})"
    return None


def output_problem(path: str | os.PathLike[str], inputs: Iterable[str | os.PathLike[str]], parents: bool) -> str | None:
    """Return why ``path`` cannot be written by a command that reads ``inputs``; None when it can."""
    from .pipeline.checked import csv_problem

    target = Path(path)
    clash = _input_clash(target, inputs)
    if clash:
        return f"{path}: is {clash}; nothing written"
    try:
        mode = os.lstat(target).st_mode
    except FileNotFoundError:
        mode = None
    if mode is not None and not stat.S_ISREG(mode):
        return f"{path}: is {_kind(mode)}; nothing written"
    if mode is not None and csv_problem(target) is not None:
        return (
            f"{path}: exists and was not written by ballbat (no check line at its end); it is left alone: "
            "remove it or give another name; nothing written"
        )
    parent = target.parent
    if not parent.is_dir() and not parents:
        what = "is not a folder" if parent.exists() else "does not exist"
        return f"{path}: the folder {parent} {what} (give --parents to create it); nothing written"
    return None


def write_output(path: str, text: str, inputs: Iterable[str | os.PathLike[str]] = (), *, parents: bool = False) -> str:
    """Write ``text`` to ``path`` (``-``: standard output) as described above; return where it went.

    Raises :class:`OutputRefused` (one line) when the path is refused, :class:`OutputFailed` when
    the write fails.
    """
    if path == STDOUT:
        sys.stdout.write(text)
        sys.stdout.flush()
        return "standard output"
    from .pipeline.atomic import atomic_target

    inputs = list(inputs)
    problem = output_problem(path, inputs, parents)
    if problem:
        raise OutputRefused(problem)
    try:
        if parents:
            Path(path).parent.mkdir(parents=True, exist_ok=True)
        with atomic_target(path) as tmp:
            with open(tmp, "w", newline="", encoding="utf-8") as fh:
                fh.write(text)
                fh.flush()
                os.fsync(fh.fileno())
    except OSError as exc:
        raise OutputFailed(f"{path}: {write_failure(exc)}; nothing written, what was there is unchanged") from None
    return str(path)


def write_failure(exc: OSError) -> str:
    """Say what a failed write met, in words (a full disk, a read-only folder, a missing permission)."""
    if exc.errno == errno.ENOSPC:
        return "disk full"
    if exc.errno == errno.EDQUOT:
        return "disk quota exceeded"
    if exc.errno in (errno.EACCES, errno.EPERM):
        return "no permission to write there"
    if exc.errno == errno.EROFS:
        return "read-only file system"
    return exc.strerror or str(exc)
