"""The scripts that made the committed example datasets still make them, byte for byte."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "config" / "examples"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["maple", "hickory"])
def test_example_script_regenerates_the_committed_table(tmp_path, name):
    """config/examples/make_<name>.py (the forward model with its seed) gives <name>_impacts.csv exactly."""
    out = tmp_path / f"{name}_impacts.csv"
    run = subprocess.run(
        [sys.executable, str(EXAMPLES / f"make_{name}.py"), str(out)], capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    assert out.read_bytes() == (EXAMPLES / f"{name}_impacts.csv").read_bytes()
