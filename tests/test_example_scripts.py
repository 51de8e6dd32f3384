"""The scripts that made the committed example datasets still make them, byte for byte."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "config" / "examples"


@pytest.mark.slow
def test_make_maple_regenerates_the_committed_table(tmp_path):
    """config/examples/make_maple.py (the forward model with its seed) gives maple_impacts.csv exactly."""
    out = tmp_path / "maple_impacts.csv"
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / "make_maple.py"), str(out)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == (EXAMPLES / "maple_impacts.csv").read_bytes()
