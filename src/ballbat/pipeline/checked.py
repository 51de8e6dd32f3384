"""Products that carry their own check: every byte of a result is verified before it is used.

NetCDF: :func:`seal_netcdf` adds the global attribute ``ballbat_content_sha256``, the sha256 of
the file's whole contents as netCDF stores them (every dimension, variable, value and attribute
but this one); :func:`verify_netcdf` recomputes it. A file damaged anywhere (not only its
header) is refused with a message naming it, never an HDF traceback inside a later job.

CSV tables: :func:`sealed_csv` ends the table with one comment line,
``# ballbat table: N rows, sha256 HEX`` (of every byte above it); :func:`read_sealed_csv`
refuses a table whose rows or bytes do not match, so that a truncated table never reaches the
HTML or the workbook. Read such a table elsewhere with ``pandas.read_csv(path, comment="#")``.
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
import re
import struct
from pathlib import Path

import numpy as np

CHECKSUM_ATTR = "ballbat_content_sha256"
_TRAILER = re.compile(r"# ballbat table: (\d+) rows, sha256 ([0-9a-f]{64})\n?\Z")


class DamagedFileError(ValueError):
    """A workflow product is damaged, or is not one (its check does not hold)."""

    def __init__(self, path: str | os.PathLike[str], problem: str) -> None:
        self.path = str(path)
        self.problem = problem
        super().__init__(f"{path}: {problem}")


# --- CSV -------------------------------------------------------------------------------------


HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def hdf5_problem(path: str | os.PathLike[str]) -> str | None:
    """Return why ``path`` is not a whole HDF5 (NetCDF-4) file, or None when it is.

    Reads the superblock (versions 0-3 of the HDF5 format): the file must start with the HDF5
    signature and be at least as long as the end-of-file address it records. A file whose
    header is whole can still be damaged inside: :func:`ballbat.pipeline.checked.verify_netcdf`
    checks every byte of its contents.
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


def _count_rows(body: str) -> int:
    return max(0, sum(1 for _ in csv.reader(io.StringIO(body))) - 1)  # the header is not a row


def sealed_csv(text: str) -> str:
    """Return CSV ``text`` (header and rows, ending in a newline) with its checked last line."""
    if text and not text.endswith("\n"):
        text += "\n"
    digest = hashlib.sha256(text.encode()).hexdigest()
    return f"{text}# ballbat table: {_count_rows(text)} rows, sha256 {digest}\n"


def _split(data: bytes) -> tuple[str, str | None]:
    return split_check_line(data.decode("utf-8", errors="replace"))


def split_check_line(text: str) -> tuple[str, str | None]:
    """Split ``text`` into the table and its check line (None when it has none)."""
    cut = text.rfind("# ballbat table: ", 0, len(text))
    if cut < 0 or (cut > 0 and text[cut - 1] != "\n"):
        return text, None
    return text[:cut], text[cut:]


def csv_problem(path: str | os.PathLike[str]) -> str | None:
    """Return why the table at ``path`` is not whole (its checked last line does not hold); None if it is."""
    data = Path(path).read_bytes()
    body, trailer = _split(data)
    if trailer is None:
        return (
            f"no check line ('# ballbat table: ...') at its end ({len(data)} bytes): "
            "cut short, or not a table this workflow wrote"
        )
    m = _TRAILER.match(trailer)
    if m is None:
        return f"its last line is not a whole check line: {trailer.strip()!r}"
    rows, digest = int(m[1]), m[2]
    found = _count_rows(body)
    if found != rows:
        return f"{found} rows, but it was written with {rows}"
    if hashlib.sha256(body.encode()).hexdigest() != digest:
        return "its bytes differ from those it was written with (sha256 mismatch)"
    return None


def read_sealed_csv(path: str | os.PathLike[str]) -> str:
    """Return the CSV text of a checked table (without its check line), or raise :class:`DamagedFileError`."""
    problem = csv_problem(path)
    if problem:
        raise DamagedFileError(path, problem)
    return _split(Path(path).read_bytes())[0]


# --- NetCDF ----------------------------------------------------------------------------------


def _value_bytes(value: object) -> bytes:
    arr = np.asarray(value)
    if arr.dtype.kind in "OUS":
        return repr([str(v) for v in arr.ravel().tolist()]).encode() + repr(arr.shape).encode()
    arr = np.ascontiguousarray(arr)
    return arr.dtype.str.encode() + repr(arr.shape).encode() + arr.tobytes()


def _content_sha256(nc: object) -> str:
    """sha256 of an open netCDF4.Dataset's dimensions, variables (raw values) and attributes."""
    h = hashlib.sha256()

    def put(tag: str, payload: bytes) -> None:
        h.update(tag.encode() + b"\0" + payload + b"\0")

    nc.set_auto_maskandscale(False)
    for name in sorted(nc.dimensions):
        put(f"dim {name}", str(len(nc.dimensions[name])).encode())
    for key in sorted(nc.ncattrs()):
        if key != CHECKSUM_ATTR:
            put(f"attr {key}", _value_bytes(nc.getncattr(key)))
    for name in sorted(nc.variables):
        var = nc.variables[name]
        put(f"var {name}", repr((var.dimensions, str(var.dtype))).encode())
        for key in sorted(var.ncattrs()):
            put(f"var {name} attr {key}", _value_bytes(var.getncattr(key)))
        put(f"var {name} data", _value_bytes(var[...]))
    if nc.groups:
        raise ValueError("groups are not written by this workflow")
    return h.hexdigest()


def seal_netcdf(path: str | os.PathLike[str]) -> str:
    """Add the content checksum to the NetCDF file ``path`` (just written, not yet in place); return it."""
    import netCDF4

    with netCDF4.Dataset(path, "a") as nc:
        digest = _content_sha256(nc)
        nc.setncattr(CHECKSUM_ATTR, digest)
    return digest


def netcdf_problem(path: str | os.PathLike[str]) -> str | None:
    """Return why the NetCDF file ``path`` is not whole, reading every byte of it; None when it is.

    A file without the checksum (written before files were sealed, or not by the workflow) is
    judged by its header alone; :func:`ballbat.pipeline.guards.written_by_workflow` says whether
    the workflow wrote it (a run never replaces, and a job never removes, a file it did not write).
    """
    problem = hdf5_problem(path)
    if problem:
        return problem
    import netCDF4

    try:
        with netCDF4.Dataset(path, "r") as nc:
            recorded = nc.getncattr(CHECKSUM_ATTR) if CHECKSUM_ATTR in nc.ncattrs() else None
            if recorded is None:  # not sealed: an older result, or a file the workflow did not write
                return None
            found = _content_sha256(nc)
    except (OSError, RuntimeError, ValueError, KeyError, IndexError, TypeError) as err:
        return f"damaged: netCDF cannot read it ({type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''})"
    if found != recorded:
        return "damaged: its contents differ from those it was written with (sha256 mismatch)"
    return None


def verify_netcdf(path: str | os.PathLike[str]) -> None:
    """Raise :class:`DamagedFileError` when the NetCDF file ``path`` is not whole."""
    problem = netcdf_problem(path)
    if problem:
        raise DamagedFileError(path, problem)
