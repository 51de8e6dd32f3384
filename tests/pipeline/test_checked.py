"""Checked files (ballbat.pipeline.checked): what a damaged HDF5 file looks like, on small files in a
temporary folder. The same guards on a real run: tests/workflow/test_guards.py.
"""

from __future__ import annotations

import struct

import pytest
from helpers import product_file as product
from helpers import users_netcdf4

from ballbat.pipeline import checked

SIG = checked.HDF5_SIGNATURE


def superblock(version: int, size_of_offsets: int, base: int, eof: int, pad: int = 96) -> bytes:
    """An HDF5 superblock of ``version`` with its base and end-of-file addresses."""
    fmt = {4: "<I", 8: "<Q"}.get(size_of_offsets, "<Q")
    width = struct.calcsize(fmt)
    if version in (0, 1):
        head = bytearray(SIG + bytes([version, 0, 0, 0, 0, size_of_offsets, 8, 0]))
        head += bytes((24 if version == 0 else 28) - len(head))
    else:
        head = bytearray(SIG + bytes([version, size_of_offsets, 8, 0]))
    head += struct.pack(fmt, base) + bytes(width) + struct.pack(fmt, eof)
    return bytes(head) + bytes(max(0, pad - len(head)))


# --- hdf5_problem ------------------------------------------------------------------------


def test_hdf5_problem_of_a_whole_file(tmp_path):
    assert checked.hdf5_problem(product(tmp_path / "own.nc")) is None
    assert checked.hdf5_problem(users_netcdf4(tmp_path / "user.nc")) is None


def test_hdf5_problem_not_hdf5(tmp_path):
    path = tmp_path / "x.nc"
    path.write_bytes(b"CDF\x01" + bytes(96))  # NetCDF-3 classic
    assert checked.hdf5_problem(path) == "not a NetCDF-4/HDF5 file (100 bytes, no HDF5 signature)"
    path.write_bytes(b"")
    assert checked.hdf5_problem(path) == "not a NetCDF-4/HDF5 file (0 bytes, no HDF5 signature)"


def test_hdf5_problem_shorter_than_a_superblock(tmp_path):
    path = tmp_path / "x.nc"
    path.write_bytes(SIG + b"\x02")
    assert checked.hdf5_problem(path) == "truncated: 9 bytes, shorter than an HDF5 superblock"


def test_hdf5_problem_truncated_real_file(tmp_path):
    path = product(tmp_path / "own.nc")
    whole = path.stat().st_size
    with open(path, "r+b") as fh:
        fh.truncate(whole - 1)
    assert (
        checked.hdf5_problem(path)
        == f"truncated: {whole - 1} bytes, but its HDF5 superblock says it ends at byte {whole}"
    )


@pytest.mark.parametrize("version", [0, 1, 2, 3])
@pytest.mark.parametrize("size_of_offsets", [4, 8])
def test_hdf5_problem_reads_each_superblock_version(tmp_path, version, size_of_offsets):
    path = tmp_path / "x.nc"
    path.write_bytes(superblock(version, size_of_offsets, base=0, eof=96))
    assert checked.hdf5_problem(path) is None  # exactly as long as it says
    path.write_bytes(superblock(version, size_of_offsets, base=4, eof=96))  # the base address counts too
    assert checked.hdf5_problem(path) == "truncated: 96 bytes, but its HDF5 superblock says it ends at byte 100"
    path.write_bytes(superblock(version, size_of_offsets, base=0, eof=5000))
    assert checked.hdf5_problem(path) == "truncated: 96 bytes, but its HDF5 superblock says it ends at byte 5000"


def test_hdf5_problem_leaves_what_it_cannot_judge(tmp_path):
    path = tmp_path / "x.nc"
    path.write_bytes(superblock(4, 8, base=0, eof=10**9))  # a newer superblock: not judged
    assert checked.hdf5_problem(path) is None
    path.write_bytes(superblock(2, 2, base=0, eof=10**9))  # 2-byte offsets: not a layout it reads
    assert checked.hdf5_problem(path) is None
