"""Guards of the results folder: broken results are rebuilt, left-over temporary files removed.

Results are written atomically (:mod:`.atomic`): a finished file is complete. A file can still
be broken afterwards (a full disk, a copy cut short, a hand edit); Snakemake, which judges by
timestamps, would then keep it and every later job would fail on it. :func:`remove_broken`
finds NetCDF files that are not whole, by the HDF5 superblock's end-of-file address against the
file's size (no library, a few bytes read per file), and removes them so that the run rebuilds
them. A job killed while writing leaves its temporary file (``.name.XXXX.tmp``) behind:
:func:`remove_temporaries` removes those.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import os

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def hdf5_problem(path: str | os.PathLike[str]) -> str | None:
    """Return why ``path`` is not a whole HDF5 (NetCDF-4) file, or None when it is.

    Reads the superblock (versions 0-3 of the HDF5 format): the file must start with the HDF5
    signature and be at least as long as the end-of-file address it records.
    """
    path = Path(path)
    size = path.stat().st_size
    with open(path, "rb") as fh:
        head = fh.read(96)
    if not head.startswith(HDF5_SIGNATURE):
        return f"not a NetCDF-4/HDF5 file ({size} bytes, no HDF5 signature)"
    if len(head) < 12:
        return f"truncated: {size} bytes, shorter than an HDF5 superblock"
    version = head[8]
    if version in (0, 1):
        size_of_offsets = head[13]
        base_at = 24 if version == 0 else 28
    elif version in (2, 3):
        size_of_offsets = head[9]
        base_at = 12
    else:
        return None  # a newer superblock: not judged here
    fmt = {4: "<I", 8: "<Q"}.get(size_of_offsets)
    if fmt is None or len(head) < base_at + 3 * size_of_offsets:
        return None
    base = struct.unpack_from(fmt, head, base_at)[0]
    eof = struct.unpack_from(fmt, head, base_at + 2 * size_of_offsets)[0]
    if size < base + eof:
        return f"truncated: {size} bytes, but its HDF5 superblock says it ends at byte {base + eof}"
    return None


def remove_broken(results: str | os.PathLike[str]) -> list[str]:
    """Remove the NetCDF files under ``results`` that are not whole; return a message for each."""
    messages = []
    for path in sorted(Path(results).rglob("*.nc")):
        if path.name.startswith("."):
            continue
        problem = hdf5_problem(path)
        if problem:
            path.unlink()
            messages.append(f"{path}: {problem}; removed, so that this run rebuilds it")
    return messages


def remove_temporaries(results: str | os.PathLike[str]) -> list[str]:
    """Remove temporary files that killed jobs left under ``results``; return a message for each."""
    messages = []
    for path in sorted(Path(results).rglob(".*.tmp")):
        if path.is_file():
            size = path.stat().st_size
            path.unlink()
            messages.append(f"{path}: temporary file of a job that did not finish ({size} bytes); removed")
    return messages


def warnings_summary(
    results: str | os.PathLike[str], datasets: list[str], others: list[str] | tuple[str, ...] = ()
) -> list[str]:
    """Return the warnings in the job logs of the given results folders, each with its log file."""
    lines = []
    for name in [*datasets, *others]:
        for log in sorted((Path(results) / name / "logs").glob("*.log")):
            for line in log.read_text(errors="replace").splitlines():
                if " WARNING " in line or line.startswith("WARNING"):
                    lines.append(f"{log}: {line.split('WARNING', 1)[1].strip(' :')}")
    return lines
