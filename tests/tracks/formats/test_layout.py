"""A folder of tool files (ballbat.tracks.formats.layout): its settings, the config that contradicts a file,
one scale per camera, every format giving the same tracks (docs/tracks.md).
"""

from __future__ import annotations

import helpers
import numpy as np
import pytest
from helpers import EXAMPLE
from track_files import (
    TOOL_NAMES,
    trk_text,
    write_lab_folder,
)

from ballbat.pipeline.config import checked_block
from ballbat.properties import InputError
from ballbat.tracks.data import with_found_settings
from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.layout import import_block, import_files

rows = helpers.rows  # a fixture of tests/helpers.py

CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}
POINTS = dict(TOOL_NAMES)
TABLE_UNITS = {"time": "ms", "length": "cm", "y": "up"}


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
