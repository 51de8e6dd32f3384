"""Atomic file writes: a failed job never leaves a half-written result behind.

The content is written to a temporary file in the target's directory, given the usual
permissions (0666 less the umask: ``mkstemp`` alone would make it private), and renamed
into place only when complete. On any error the temporary file is removed and whatever
was at the target before is left untouched. A write that fails on a full disk (netCDF says only
"NetCDF: HDF error") is reported as ``disk full``, naming the target (:func:`disk_full_error`).

The temporary file's name says who owns it: ``.<name>.<pid>@<host>.<random><suffix>``.
A job killed outright (SIGKILL, a lost node) cannot remove it; :func:`temporary_owner` reads
the owner back, so that only the temporaries of dead processes on this host are ever removed
(:func:`ballbat.pipeline.guards.remove_temporaries`), never those of another run's live job.
"""

from __future__ import annotations

import errno
import os
import re
import socket
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: ``.<target>.<pid>@<host>.<8 random characters of mkstemp><suffix>``
_OWNED = re.compile(
    r"^\.(?P<target>.+)\.(?P<pid>\d+)@(?P<host>[A-Za-z0-9_.-]+)\.[a-z0-9_]{8}(?P<suffix>\.[A-Za-z0-9]+)$"
)


def hostname() -> str:
    """Return this machine's name as temporaries carry it (only letters, digits, ``_``, ``.`` and ``-``)."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", socket.gethostname()) or "localhost"


def temporary_owner(name: str) -> tuple[int, str] | None:
    """Return ``(pid, host)`` of the job that made the temporary file ``name``; None if not one of ours."""
    m = _OWNED.match(name)
    return (int(m["pid"]), m["host"]) if m else None


@contextmanager
def atomic_target(path: str | os.PathLike[str], suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path to write; on success it replaces ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}@{hostname()}.", suffix=suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException as exc:
        full = disk_full_error(path, exc)  # judged before the temporary's space is freed
        Path(tmp).unlink(missing_ok=True)
        if full is not None:
            raise full from None
        raise


#: Free space (bytes) below which a failed write is put down to a full disk.
FULL_DISK_BYTES = 1 << 20


def disk_full_error(path: Path, exc: BaseException) -> OSError | None:
    """Return an error that says "disk full" and names ``path`` when ``exc`` met a full disk; None otherwise.

    netCDF/HDF5 report a full disk as "NetCDF: HDF error" (a RuntimeError or an OSError without
    errno): the free space of the target's folder tells.
    """
    if not isinstance(exc, (OSError, RuntimeError)):
        return None
    code = getattr(exc, "errno", None)
    if code not in (errno.ENOSPC, errno.EDQUOT):
        try:
            st = os.statvfs(path.parent)
        except OSError:
            return None
        if st.f_bavail * st.f_frsize >= FULL_DISK_BYTES:
            return None
    said = str(exc).splitlines()[0] if str(exc) else ""
    return OSError(
        errno.ENOSPC,
        f"disk full: {path} could not be written ({type(exc).__name__}: {said}); "
        "what was there is unchanged: free some space and run again",
    )
