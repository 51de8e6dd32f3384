"""``ballbat import-tracks`` (ballbat.cli.import_tracks): tool files into the long tracks CSV."""

from __future__ import annotations

import subprocess

import helpers
import pytest
import yaml
from helpers import BALLBAT, EXAMPLE
from helpers import same_tracks as _same
from track_files import (
    read_long_csv,
    write_lab_folder,
)

rows = helpers.rows  # a fixture of tests/helpers.py

CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}


@pytest.mark.slow  # about 3 s: the installed command on a folder of Tracker files
def test_cli_import_tracks(tmp_path, rows):
    """The command import-tracks writes the long CSV (the example's rows) and prints the settings found as YAML."""
    lab = write_lab_folder(tmp_path / "lab", EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
    out = tmp_path / "tracks.csv"
    pts = "--points=ball=ball,bat_tip=tip,dot_a=A,dot_b=B"
    res = subprocess.run([BALLBAT, "import-tracks", lab, pts, "-o", out], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    found = yaml.safe_load(res.stdout)
    assert found["cameras"]["swing"]["fps"] == pytest.approx(3000.0)
    assert found["cameras"]["spin"]["m_per_px"] == pytest.approx(0.00125)
    assert found["files"] == 24 and found["impacts"] == 12
    got = read_long_csv(out)
    assert set(got) == set(rows)
    for key, tracks in rows.items():
        _same(got[key], tracks)
    # a table with the wrong frame rate: exit 1, the rows named, nothing written
    tab = write_lab_folder(tmp_path / "tab", EXAMPLE / "tracked_tracks.csv", "kinovea_csv", CAMS)
    out2 = tmp_path / "t2.csv"
    res = subprocess.run(
        [
            BALLBAT,
            "import-tracks",
            tab,
            pts,
            "-o",
            out2,
            "--format",
            "kinovea_table",
            "--units",
            "time=ms,length=cm,y=up",
            "--camera",
            "swing:fps=1500,m_per_px=0.00074",
            "--camera",
            "spin:fps=1000,m_per_px=0.00125",
        ],
        capture_output=True,
        text=True,
    )
    assert res.returncode == 1 and not out2.exists()
    assert "W01_swing.csv: line 3, track 'tip': time Time is 0.500 frames, not a whole frame" in res.stderr
    res = subprocess.run(
        [BALLBAT, "import-tracks", lab, "--points", "ball", "-o", out2], capture_output=True, text=True
    )
    assert res.returncode == 2 and "argument --points: 'ball' is not NAME=VALUE" in res.stderr
    res = subprocess.run(
        [BALLBAT, "import-tracks", lab, pts, "-o", out2, "--camera", "cam1:fps=3000"], capture_output=True, text=True
    )
    assert res.returncode == 2 and "argument --camera: unknown camera 'cam1' (known: swing, spin)" in res.stderr
