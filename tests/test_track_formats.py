"""Reading the tracking tools' own files (docs/tracks.md, "Files of tracking tools").

The files are written by tests/track_files.py, shaped as Tracker and Kinovea write them, from
the tracks of config/examples/tracked_tracks.csv (rendered by ballbat's renderer).
"""

from __future__ import annotations

import copy
import subprocess
import sys
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest
import yaml

from ballbat.config_checks import validate_config
from ballbat.pipeline.config import ConfigError, checked_block
from ballbat.properties import InputError
from ballbat.tracks.data import with_found_settings
from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.kinovea import read_kva
from ballbat.tracks.formats.layout import import_block, import_files
from ballbat.tracks.formats.tables import read_kinovea_table, read_tracker_table
from ballbat.tracks.formats.tracker import read_trk, read_trz

sys.path.insert(0, str(Path(__file__).parent))
from track_files import (
    TOOL_NAMES,
    kinovea_csv_text,
    kva_text,
    read_long_csv,
    tracker_table_text,
    trk_text,
    write_lab_folder,
    write_trz,
)

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "config" / "examples"
CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}
POINTS = dict(TOOL_NAMES)
TABLE_UNITS = {"time": "ms", "length": "cm", "y": "up"}


def _written(path: Path, text: str) -> Path:
    """``path`` with ``text`` written to it."""
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def rows():
    return read_long_csv(EXAMPLE / "tracked_tracks.csv")


def _same(got, want, tol=0.0):
    assert set(got) == set(want)
    for name, (f, x, y) in want.items():
        gf, gx, gy = got[name]
        np.testing.assert_array_equal(gf - gf.min(), f - f.min())
        np.testing.assert_allclose(gx - gx[0], x - x[0], atol=tol, rtol=0)
        np.testing.assert_allclose(gy - gy[0], y - y[0], atol=tol, rtol=0)


def test_trk_gives_the_marks_frames_and_settings(tmp_path, rows):
    """Tracker's framedata [n] is the mark at video frame n (image pixels); fps from delta_t; scale from coords."""
    tracks = rows[("W01", "swing")]
    p = _written(tmp_path / "W01_swing.trk", trk_text(tracks, 3000.0, 0.00074, unit="cm"))
    ft = read_trk(p)
    for name, (f, x, y) in tracks.items():  # unrotated axes: the image pixels themselves, frames unchanged
        np.testing.assert_array_equal(ft.tracks[name][0], f)
        np.testing.assert_array_equal(ft.tracks[name][1], x)
        np.testing.assert_array_equal(ft.tracks[name][2], y)
    assert ft.fps == pytest.approx(3000.0, rel=1e-12)
    assert ft.m_per_px == pytest.approx(0.00074, rel=1e-12)
    assert "delta_t" in ft.source["fps"] and "px/cm" in ft.source["m_per_px"]


def test_trk_clip_with_a_step_size(tmp_path, rows):
    """Marks on every other frame of a clip with step size 2 keep their video frame numbers."""
    tracks = {n: tuple(a[::2] for a in t) for n, t in rows[("W01", "swing")].items()}
    f0 = min(t[0][0] for t in tracks.values())
    tracks = {n: t for n, t in tracks.items() if ((t[0] - f0) % 2 == 0).all()}
    assert tracks
    p = _written(tmp_path / "W01_swing.trk", trk_text(tracks, 3000.0, 0.00074, step=2))
    ft = read_trk(p)
    for name, (f, x, _) in tracks.items():
        np.testing.assert_array_equal(ft.tracks[name][0], f)
        np.testing.assert_array_equal(ft.tracks[name][1], x)
    p.write_text(trk_text(tracks, 3000.0, 0.00074, step=2, extra_mark=int(f0) + 1))
    off_step = rf"frame {int(f0) + 1}: the mark is not on a step of the clip \(frames {int(f0)}, "
    with pytest.raises(FormatError, match=off_step):
        read_trk(p)


def test_trk_turned_axes_are_undone(tmp_path, rows):
    """A coordinate system turned by 7 deg: ballbat's x-axis is the lab's, as set in Tracker."""
    tracks = rows[("W02", "spin")]
    p = _written(tmp_path / "a.trk", trk_text(tracks, 1000.0, 0.00125, angle_deg=7.0, origin=(512.5, 300.25)))
    ft = read_trk(p)
    _same(ft.tracks, tracks, tol=1e-9)
    assert "angle 7" in ft.source["axes"]


def test_trk_mark_off_the_clip_is_named(tmp_path, rows):
    p = _written(tmp_path / "W01_swing.trk", trk_text(rows[("W01", "swing")], 3000.0, 0.00074, extra_mark=2))
    with pytest.raises(FormatError) as exc:
        read_trk(p)
    msg = "\n".join(exc.value.problems)
    assert f"{p}: track 'ball', frame 2: the mark is not on a step of the clip" in msg


def test_trk_changing_coordinate_system_is_refused(tmp_path, rows):
    """A key frame of the coordinate system with another scale: one fixed system per file is needed."""
    root = ET.fromstring(trk_text(rows[("W01", "swing")], 3000.0, 0.00074))
    coords = next(p for p in root.findall("property") if p.get("name") == "coords").find("object")
    frames = next(p for p in coords.findall("property") if p.get("name") == "framedata")
    key = copy.deepcopy(frames.find("property"))
    key.set("name", "[40]")
    next(p for p in key.iter("property") if p.get("name") == "xscale").text = "1400.0"
    frames.append(key)
    p = tmp_path / "W01_swing.trk"
    p.write_bytes(ET.tostring(root))
    with pytest.raises(FormatError, match=r"W01_swing.trk: the coordinate system changes at frame 40"):
        read_trk(p)


def test_trz_holds_exactly_one_project(tmp_path, rows):
    tracks = rows[("W03", "swing")]
    p = tmp_path / "W03_swing.trz"
    write_trz(p, trk_text(tracks, 3000.0, 0.00074), "W03_swing.trk")
    ft = read_trz(p)
    _same(ft.tracks, tracks)
    assert ft.path.endswith("W03_swing.trz:W03_swing.trk")
    two = tmp_path / "two.trz"
    with zipfile.ZipFile(two, "w") as z:
        z.writestr("a.trk", "<x/>")
        z.writestr("b.trk", "<x/>")
    not_one = r"two.trz: a .trz must hold exactly one .trk project \(found: a.trk, b.trk\)"
    with pytest.raises(FormatError, match=not_one):
        read_trz(two)


def test_kva_timestamps_calibration(tmp_path, rows):
    """Kinovea: frame = (t - FirstTimeStamp) / AverageTimeStampsPerFrame; fps = CaptureFramerate; scale: a line."""
    tracks = rows[("W04", "spin")]
    p = _written(
        tmp_path / "W04_spin.kva", kva_text(tracks, 1000.0, 0.00125, per_frame=1001, first=123456, video_fps=29.97)
    )
    ft = read_kva(p)
    _same(ft.tracks, tracks)
    assert ft.fps == 1000.0
    assert ft.m_per_px == pytest.approx(0.00125, rel=1e-6)
    p.write_text(kva_text(tracks, 1000.0, None, mirror=True))
    with pytest.raises(FormatError, match="Mirror is true"):
        read_kva(p)
    root = ET.fromstring(kva_text(tracks, 1000.0, None))
    point = root.findall("Tracks/Track")[0].findall("TrackPointList/TrackPoint")[1]
    x, y, t, r = point.text.split(";")
    point.text = f"{x};{y};{int(t) + 200};{r}"  # a point between two frames
    p.write_bytes(ET.tostring(root))
    between = rf"track 'ball', point 2 \(t = {int(t) + 200}\): its timestamp is [0-9]+\.391 "
    with pytest.raises(FormatError, match=between):
        read_kva(p)


def test_exported_tables_become_pixels(tmp_path, rows):
    """World units, y up, time in s or ms: back to the pixels (y down) at the stated scale and frame rate."""
    tracks = rows[("W05", "swing")]
    k = _written(tmp_path / "W05_swing.csv", kinovea_csv_text(tracks, 3000.0, 0.00074))
    _same(read_kinovea_table(k, TABLE_UNITS, 3000.0, 0.00074).tracks, tracks, tol=1e-3)
    t = _written(tmp_path / "W05_swing.txt", tracker_table_text(tracks, 3000.0, 0.00074))
    got = read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 3000.0, 0.00074).tracks
    _same(got, tracks, tol=1e-3)
    # y stated the wrong way round: the motion comes out mirrored (not silently the same)
    flipped = read_tracker_table(t, {"time": "s", "length": "m", "y": "down"}, 3000.0, 0.00074).tracks
    dy = flipped["ball"][2] - flipped["ball"][2][0]
    np.testing.assert_allclose(dy, -(tracks["ball"][2] - tracks["ball"][2][0]), atol=1e-3)


def test_tracker_table_with_a_decimal_comma(tmp_path, rows):
    """A European locale: semicolons and decimal commas, as Tracker writes them there."""
    tracks = rows[("W06", "spin")]
    text = tracker_table_text(tracks, 1000.0, 0.00125, delim=";").replace(".", ",")
    t = _written(tmp_path / "W06_spin.txt", text)
    got = read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 1000.0, 0.00125).tracks
    _same(got, tracks, tol=1e-3)


def test_table_at_the_wrong_frame_rate_names_rows(tmp_path, rows):
    """The frame rate off by 2x (too low): times fall between frames and the rows are named."""
    k = _written(tmp_path / "W05_swing.csv", kinovea_csv_text(rows[("W05", "swing")], 3000.0, 0.00074))
    with pytest.raises(FormatError) as exc:
        read_kinovea_table(k, TABLE_UNITS, 1500.0, 0.00074)
    msg = "\n".join(exc.value.problems)
    assert f"{k}: line 3, track 'tip': time Time is 0.500 frames, not a whole frame" in msg
    assert "times are not whole frames at 1500 fps (units.time 'ms'): is the frame rate or the time unit wrong?" in msg


def test_exported_tables_name_cells_that_are_not_finite_numbers(tmp_path, rows):
    """Both exported tables name the line and track of a cell that is not a finite number."""
    k = tmp_path / "W05_swing.csv"
    lines = kinovea_csv_text(rows[("W05", "swing")], 3000.0, 0.00074).splitlines()
    cells = lines[2].split(",")
    cells[1], cells[2] = "inf", "abc"
    lines[2] = ",".join(cells)
    lines[3] = ",".join([lines[3].split(",")[0], "nan", "1.0", *lines[3].split(",")[3:]])
    k.write_text("\n".join(lines) + "\n")
    with pytest.raises(FormatError) as exc:
        read_kinovea_table(k, TABLE_UNITS, 3000.0, 0.00074)
    msg = "\n".join(exc.value.problems)
    assert f"{k}: line 3, track " in msg and "X 'inf', Y 'abc' are not numbers" in msg
    assert f"{k}: line 4, track " in msg and "X 'nan', Y '1.0' are not finite" in msg
    t = tmp_path / "W05_swing.txt"
    text = tracker_table_text(rows[("W05", "swing")], 3000.0, 0.00074).splitlines()
    first = next(i for i, ln in enumerate(text) if ln[:1].isdigit() or ln[:1] == "-")
    t.write_text("\n".join([*text[:first], "abc" + text[first][text[first].index("\t") :], *text[first + 1 :]]))
    with pytest.raises(FormatError, match=rf"line {first + 1}, column t: 'abc' is not a number"):
        read_tracker_table(t, {"time": "s", "length": "m", "y": "up"}, 3000.0, 0.00074)


def test_tables_need_units_and_settings(tmp_path, rows):
    write_lab_folder(tmp_path, EXAMPLE / "tracked_tracks.csv", "kinovea_csv", CAMS)
    with pytest.raises(FormatError) as exc:
        import_files([tmp_path], POINTS, fmt="kinovea_table", units={"time": "ms"}, cameras={"swing": {"fps": 3000}})
    msg = "\n".join(exc.value.problems)
    for want in (
        "tracks.units.length: missing",
        "tracks.units.y: missing",
        "tracks.cameras.swing.m_per_px: missing",
        "tracks.cameras.spin.fps: missing",
    ):
        assert want in msg


def test_config_that_contradicts_a_file_names_both(tmp_path):
    write_lab_folder(tmp_path, EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
    cams = {"swing": {"m_per_px": 0.00148, "fps": 3000}, "spin": {"fps": 500}}
    with pytest.raises(FormatError) as exc:
        import_files([tmp_path], POINTS, cameras=cams)
    msg = "\n".join(exc.value.problems)
    assert (
        f"tracks.cameras.swing.m_per_px: the config says 0.00148 but {tmp_path / 'W01_swing.trk'} says 0.00074 "
        "(coords xscale 1351.35 px/m)" in msg
    )
    assert f"tracks.cameras.spin.fps: the config says 500 but {tmp_path / 'W01_spin.trk'} says 1000" in msg
    assert "tracks.cameras.swing.fps" not in msg  # agrees
    with pytest.raises(FormatError, match=r"tracks.units: given, but only a table .* needs it"):
        import_files([tmp_path], POINTS, units={"time": "s", "length": "m", "y": "up"})


def test_files_of_one_camera_calibrated_apart_share_one_scale(tmp_path, rows):
    """Two swing files whose scales differ by 1 %: both brought to the median scale, the range reported."""
    for iid, mpp in (("W01", 0.00074), ("W02", 0.0007474)):
        (tmp_path / f"{iid}_swing.trk").write_text(trk_text(rows[(iid, "swing")], 3000.0, mpp))
        (tmp_path / f"{iid}_spin.trk").write_text(trk_text(rows[(iid, "spin")], 1000.0, 0.00125))
    imp = import_files([tmp_path], POINTS)
    sw = imp.cameras["swing"]
    assert sw["m_per_px"] == pytest.approx((0.00074 + 0.0007474) / 2)
    assert sw["m_per_px_range"] == pytest.approx([0.00074, 0.0007474])
    c = imp.columns
    sel = (c["impact_id"] == "W02") & (c["camera"] == "swing") & (c["point"] == "ball")
    want = rows[("W02", "swing")]["ball"][1] * 0.0007474 / sw["m_per_px"]  # same metres at the common scale
    np.testing.assert_allclose(np.sort(c["x_px"][sel]), np.sort(want), rtol=1e-12)


def test_layout_problems_are_named(tmp_path, rows):
    write_lab_folder(tmp_path, EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
    (tmp_path / "W03_spin.trk").unlink()
    (tmp_path / "W01_swing.trk").rename(tmp_path / "W01-swing.trk")
    (tmp_path / "notes.md").write_text("left alone")
    with pytest.raises(FormatError) as exc:
        import_files([tmp_path], {**POINTS, "bat_tip": "stick"})
    msg = "\n".join(exc.value.problems)
    assert (
        f"{tmp_path / 'W01-swing.trk'}: the name does not match the pattern '{{impact_id}}_{{camera}}.{{ext}}'" in msg
    )
    assert f"{tmp_path / 'W02_swing.trk'}: track 'stick' (ballbat's bat_tip, swing camera) is not in the file " in msg
    assert "notes.md" not in msg
    cfg = {
        "dir": str(tmp_path),
        "points": POINTS,
        "impacts": str(EXAMPLE / "tracked_impacts.csv"),
        "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    }
    cfg = checked_block(cfg, "tracks")  # the schema's defaults (pattern), as the workflow's config has them
    (tmp_path / "W01-swing.trk").rename(tmp_path / "W01_swing.trk")
    (tmp_path / "W99_swing.trk").write_text((tmp_path / "W02_swing.trk").read_text())
    with pytest.raises(InputError) as exc:
        import_block(cfg, "datasets.lab.tracks")
    msg = "\n".join(exc.value.problems)
    assert f"{tmp_path / 'W99_swing.trk'}: impact 'W99' is not in {EXAMPLE / 'tracked_impacts.csv'}" in msg
    assert "impact 'W03' has no file of the spin camera in" in msg and "(W03_spin.{ext})" in msg


def test_import_block_gives_the_example_tracks(tmp_path, rows):
    write_lab_folder(tmp_path, EXAMPLE / "tracked_tracks.csv", "kva", CAMS)
    cfg = {
        "dir": str(tmp_path),
        "points": POINTS,
        "impacts": str(EXAMPLE / "tracked_impacts.csv"),
        "cameras": {"swing": {"mirror": False, "m_per_px_err": 0.005}, "spin": {"mirror": True}},
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    }
    tracks, imp = import_block(checked_block(cfg, "tracks"), "datasets.lab.tracks")
    assert tracks.n == 12 and list(tracks.bat) == ["wood"] * 12
    merged = with_found_settings({"cameras": cfg["cameras"], "rig": cfg["rig"]}, imp.settings_yaml())
    assert merged["cameras"]["swing"]["fps"] == 3000.0 and merged["cameras"]["swing"]["m_per_px_err"] == 0.005
    assert merged["cameras"]["spin"]["m_per_px"] == pytest.approx(0.00125, rel=1e-6)
    assert "fps" not in cfg["cameras"]["swing"]  # the config block itself is left as it was


def test_schema_takes_a_folder_and_still_wants_settings_of_a_long_file():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    rig = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
    lab = {
        "dir": "data/trk",
        "points": POINTS,
        "impacts": "i.csv",
        "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
        "rig": rig,
    }
    cfg = validate_config({"datasets": {"lab": {"tracks": lab}}}, schema, available=10**12)
    assert cfg["datasets"]["lab"]["tracks"]["pattern"] == "{impact_id}_{camera}.{ext}"
    long = {
        "file": "t.csv",
        "impacts": "i.csv",
        "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
        "rig": rig,
    }
    with pytest.raises(ConfigError, match="fps"):
        validate_config({"datasets": {"lab": {"tracks": long}}}, schema, available=10**12)
    no_points = {k: v for k, v in lab.items() if k != "points"}
    with pytest.raises(ConfigError, match=r"datasets\.lab\.tracks: 'points' is a required property"):
        validate_config({"datasets": {"lab": {"tracks": no_points}}}, schema, available=10**12)
    with pytest.raises(ConfigError, match="units"):
        validate_config({"datasets": {"lab": {"tracks": {**lab, "units": {"time": "ms"}}}}}, schema, available=10**12)


BALLBAT = Path(sys.executable).parent / "ballbat"


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


@pytest.mark.slow
def test_tool_files_run_end_to_end_with_the_long_csvs_e_x(lab_run):
    """A folder of Tracker projects (.trk, one file per impact and camera) runs through snakemake (the
    lab run's tools.yaml, conftest.lab_run) and gives the long CSV's e_x (every other format reads the
    same tracks: :func:`test_every_format_imports_the_same_tracks`).
    """
    import xarray as xr

    res = lab_run / "results"
    ref = xr.open_dataset(res / "tracked" / "fit_ex.nc")
    ref_flags = xr.open_dataset(res / "tracked" / "reduce.nc")["ingest_flag"].values
    assert np.isfinite(ref["e_x"].values).all()
    got = xr.open_dataset(res / "trk" / "fit_ex.nc")
    np.testing.assert_allclose(got["e_x"].values, ref["e_x"].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got["e_x_err"].values, ref["e_x_err"].values, rtol=1e-6)
    flags = xr.open_dataset(res / "trk" / "reduce.nc")["ingest_flag"].values
    np.testing.assert_array_equal(flags, ref_flags)  # the same impact excluded (tilted spin axis)
    assert (res / "trk" / "figures" / "tracks_impacts.png").is_file()
    found = yaml.safe_load((res / "trk" / "imported_cameras.yaml").read_text())
    assert found["cameras"]["swing"]["fps"] == pytest.approx(3000.0)
    assert found["cameras"]["spin"]["m_per_px"] == pytest.approx(0.00125, rel=1e-6)
    assert found["cameras"]["swing"]["fps_from"].startswith("12 file(s)")


@pytest.mark.parametrize("fmt, tol", [("trz", 0.0), ("kva", 1e-6), ("kinovea_csv", 1e-6)])
def test_every_format_imports_the_same_tracks(tmp_path, fmt, tol):
    """A folder of each tool's files gives the tracks of the same folder of .trk files (the workflow's
    import_tracks: :func:`import_block`), frames equal and pixels within the format's rounding.
    """
    from ballbat.tracks.data import to_long

    def imported(f):
        cfg = {
            "dir": str(write_lab_folder(tmp_path / f, EXAMPLE / "tracked_tracks.csv", f, CAMS)),
            "points": POINTS,
            "impacts": str(EXAMPLE / "tracked_impacts.csv"),
            "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
            "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
        }
        if f == "kinovea_csv":
            cfg.update(format="kinovea_table", cameras={c: {**cfg["cameras"][c], **CAMS[c]} for c in CAMS})
            cfg["units"] = TABLE_UNITS
        tracks, imp = import_block(checked_block(cfg, "tracks"), f"datasets.{f}.tracks")
        found = imp.settings_yaml()["cameras"]["swing"]
        assert found["fps"] == pytest.approx(3000.0)  # a table holds no frame rate; the tools' projects do
        assert found["fps_from"].startswith("config" if f == "kinovea_csv" else "12 file(s)"), found
        return to_long(tracks)

    def relative(rows):
        """Frames and pixels from each clip's first mark (a table's time and origin are its own)."""
        clip = np.char.add(rows["impact_id"].astype(str), rows["camera"].astype(str))
        out = {k: np.asarray(v) for k, v in rows.items()}
        for c in np.unique(clip):
            at = clip == c
            first = np.flatnonzero(at)[np.argmin(out["frame"][at])]
            for col in ("x_px", "y_px"):
                out[col] = np.where(at, out[col] - out[col][first], out[col])
            out["frame"] = np.where(at, out["frame"] - out["frame"][first], out["frame"])
        return out

    want, got = imported("trk"), imported(fmt)
    if fmt == "kinovea_csv":
        want, got = relative(want), relative(got)
    for col in ("impact_id", "camera", "point", "frame"):
        np.testing.assert_array_equal(got[col], want[col], err_msg=col)
    for col in ("x_px", "y_px"):
        np.testing.assert_allclose(got[col], want[col], rtol=0, atol=tol, err_msg=col)


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
        cfg = _written(tmp_path / f"{name}.yaml", yaml.safe_dump({"datasets": {"lab": {"tracks": block}}}))
        res = subprocess.run([BALLBAT, "check", "--kind", "tracks", "--config", cfg], capture_output=True, text=True)
        assert res.returncode == 0, res.stdout + res.stderr
        outs[name] = [line for line in res.stdout.splitlines() if line.startswith("impact ")]
    assert len(outs["csv"]) == 12 and outs["dir"] == outs["csv"]
    assert sum(line.endswith(": used") for line in outs["dir"]) >= 9
