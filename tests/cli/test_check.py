"""``ballbat check`` (ballbat.cli.check): a measured impacts file, raw tracks and a folder of tool files checked
as the workflow would read them, every problem listed, unit mistakes warned of (issues 13, 18, 35).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
import yaml
from conftest import ROOT
from helpers import BALLBAT
from helpers import ballbat_forked as ballbat
from helpers import ballbat_in_process as ballbat_cli
from track_files import (
    TOOL_NAMES,
    write_lab_folder,
)


def test_check_refuses_grams_as_ounces_and_b_outside_any_bat(tmp_path):
    """Issue 35's "Why": `ballbat check` accepted b = 60 in and M = 907 (grams typed as oz)."""
    bats = tmp_path / "bats.csv"
    bats.write_text("bat,name,M_oz,I0_oz_in2,Iz_oz_in2,b_in,R_in\nmaple,maple,907,2480,9.6,60,1.24\n")
    got = ballbat("check", "config/examples/maple_impacts.csv", "--bats", str(bats))
    assert got.returncode == 1
    assert f"{bats}: row 2, column M_oz: 907 oz" in got.stdout and "grams typed as ounces" in got.stdout
    assert f"{bats}: row 2, column b_in: 60 in is outside any bat's barrel" in got.stdout


MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"


def test_check_a_good_file_as_the_workflow_would():
    out = ballbat_cli("check", str(MAPLE), "--bats", str(MAPLE_BATS))
    assert out.returncode == 0, out.stdout + out.stderr
    # the example's one mis-read spin is excluded, as in results/maple/ingest.nc (README)
    assert "excluded: impact MP31" in out.stdout and "psi cannot be reconstructed" in out.stdout
    assert "usable: 31 impacts, 1 excluded" in out.stdout


def test_check_lists_every_problem(tmp_path):
    rows = MAPLE.read_text().splitlines()
    header = rows[0].split(",")
    bad = [header]
    for i, line in enumerate(rows[1:6]):
        cells = line.split(",")
        if i == 1:
            cells[header.index("v_ball_mph")] = "fast"
        if i == 3:
            cells[header.index("bat")] = "oak"
        bad.append(cells)
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(",".join(c) for c in bad) + "\n")
    out = ballbat_cli("check", str(path), "--bats", str(MAPLE_BATS))
    assert out.returncode == 1
    assert f"{path}" in out.stdout and "row 3, column v_ball_mph" in out.stdout and "fast" in out.stdout
    assert "row 5, column bat" in out.stdout and "oak" in out.stdout
    assert "not usable: 2 problem(s)" in out.stderr


def test_check_warns_of_unit_mistakes(tmp_path):
    rows = [line.split(",") for line in MAPLE.read_text().splitlines()]
    col = rows[0].index("omega_rpm")
    for r in rows[1:]:
        r[col] = f"{float(r[col]) * 2 * 3.141592653589793 / 60:.4f}"  # spin in rad/s
    path = tmp_path / "rads.csv"
    path.write_text("\n".join(",".join(r) for r in rows) + "\n")
    out = ballbat_cli("check", str(path), "--bats", str(MAPLE_BATS))
    assert out.returncode == 1  # most rows implausible: not usable (issue 10), the column and rows named
    assert "units are likely wrong" in out.stdout and "column omega_rpm" in out.stdout and "spin in rad/s" in out.stdout


def test_check_raw_tracks():
    """`--kind tracks` checks a tracks file as the reduce rule reads it (issue 11's format)."""
    tracks = ROOT / "config" / "examples" / "tracked_tracks.csv"
    impacts = ROOT / "config" / "examples" / "tracked_impacts.csv"
    out = ballbat_cli("check", str(tracks), "--kind", "tracks", "--impacts", str(impacts))
    assert out.returncode == 0, out.stdout + out.stderr
    assert "read and validated: 12 impacts tracked by the cameras spin, swing; not reduced" in out.stdout


def test_check_raw_tracks_lists_every_problem(tmp_path):
    lines = (ROOT / "config" / "examples" / "tracked_tracks.csv").read_text().splitlines()
    cells = lines[5].split(",")
    cells[1] = "side"  # an unknown camera
    lines[5] = ",".join(cells)
    path = tmp_path / "tracks.csv"
    path.write_text("\n".join([*lines, lines[2]]) + "\n")  # and a frame twice
    impacts = ROOT / "config" / "examples" / "tracked_impacts.csv"
    out = ballbat_cli("check", str(path), "--kind", "tracks", "--impacts", str(impacts))
    assert out.returncode == 1
    assert "row 6, column camera: unknown camera 'side'" in out.stdout and "appears twice" in out.stdout
    assert "not usable: 2 problem(s)" in out.stderr


EXAMPLE = ROOT / "config" / "examples"
CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}
POINTS = dict(TOOL_NAMES)


@pytest.mark.slow  # about 3 s: ballbat check imports and reduces a folder of tool files
def test_check_tracks_reads_a_folder_of_tool_files_as_the_workflow_does(tmp_path):
    """``ballbat check --kind tracks --config`` on a dataset naming a folder (``dir``) imports the files
    as the import_tracks rule does and then reduces them: the same verdict per impact as the long CSV.
    """
    lab = write_lab_folder(tmp_path / "lab", EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
    rig = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
    impacts = str(EXAMPLE / "tracked_impacts.csv")
    mirrors = {"swing": {"mirror": False, "m_per_px_err": 0.005}, "spin": {"mirror": True}}
    full = {c: {**mirrors[c], **CAMS[c]} for c in CAMS}
    outs = {}
    for name, block in {
        "csv": {"file": str(EXAMPLE / "tracked_tracks.csv"), "impacts": impacts, "cameras": full, "rig": rig},
        "dir": {"dir": str(lab), "points": POINTS, "impacts": impacts, "cameras": mirrors, "rig": rig},
    }.items():
        cfg = tmp_path / f"{name}.yaml"
        cfg.write_text(yaml.safe_dump({"datasets": {"lab": {"tracks": block}}}))
        res = subprocess.run([BALLBAT, "check", "--kind", "tracks", "--config", cfg], capture_output=True, text=True)
        assert res.returncode == 0, res.stdout + res.stderr
        outs[name] = [line for line in res.stdout.splitlines() if line.startswith("impact ")]
    assert len(outs["csv"]) == 12 and outs["dir"] == outs["csv"]
    assert sum(line.endswith(": used") for line in outs["dir"]) >= 9


# --------------------------------------------------------------------------------------
# ballbat check --kind tracks: the reduce rule's own reading, reduction and cross-checks


def check(capsys, *argv):
    from ballbat.cli import main

    rc = main(["check", "--kind", "tracks", *argv])
    out = capsys.readouterr()
    return rc, out.out, out.err


def test_check_tracks_says_what_the_workflow_does_with_every_impact(capsys):
    rc, out, err = check(capsys, "--config", "config/examples/tracked.yaml")
    assert rc == 0, out + err
    assert out.count("impact W") == 12 and "impact W01: used" in out
    assert "impact W04: excluded: reduce: dot_a's distance from the ball's centre varies" in out
    assert "cross-check: the ball's speed in swing / in spin" in out
    assert "11 of 12 impacts usable (per ball: baseball 11), 1 excluded, 0 tracking glitch(es) removed" in out


def _tracked_config(tmp_path, edit=None, keep=None):
    import yaml

    cfg = yaml.safe_load(Path("config/examples/tracked.yaml").read_text())
    block = cfg["datasets"]["tracked"]["tracks"]
    if keep is not None:  # a subset of the impacts
        lines = Path(block["file"]).read_text().splitlines()
        t = tmp_path / "tracks.csv"
        t.write_text("\n".join([lines[0], *[ln for ln in lines[1:] if ln.split(",")[0] in keep]]) + "\n")
        lines = Path(block["impacts"]).read_text().splitlines()
        i = tmp_path / "impacts.csv"
        i.write_text("\n".join([lines[0], *[ln for ln in lines[1:] if ln.split(",")[0] in keep]]) + "\n")
        block["file"], block["impacts"] = str(t), str(i)
    if edit:
        edit(block)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path


def test_check_tracks_exits_1_when_the_dataset_would_stop(tmp_path, capsys):
    def slow_spin(block):
        block["cameras"]["spin"]["fps"] = 500

    rc, out, err = check(capsys, "--config", str(_tracked_config(tmp_path, slow_spin)))
    assert rc == 1
    assert "the workflow would stop at reduce" in err
    assert "datasets.tracked.tracks: most likely cameras.spin.fps is 2x too low" in out


def test_check_tracks_exits_1_with_fewer_than_3_usable_impacts_per_ball(tmp_path, capsys):
    rc, out, err = check(capsys, "--config", str(_tracked_config(tmp_path, keep={"W01", "W02", "W04"})))
    assert rc == 1
    assert "2 of 3 impacts usable" in out + err and "with 3" in out + err, out + err
    assert "Excluded: dot_not_rotating_about_centre: 1" in out


def test_check_tracks_without_settings_does_not_call_files_usable(capsys):
    rc, out, _ = check(capsys, "config/examples/tracked_tracks.csv", "--impacts", "config/examples/tracked_impacts.csv")
    assert rc == 0 and "usable" not in out and "not reduced: give --config" in out
