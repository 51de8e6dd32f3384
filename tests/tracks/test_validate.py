"""A lab's tracks, impacts and camera settings: every problem reported at once, with file, row and column."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.pipeline.config import checked_block
from ballbat.properties import InputError, load_balls, load_bats
from ballbat.tracks.io import cameras_from_config, load_tracks

BALLS = load_balls("config/balls.csv")
BATS = load_bats("config/bats.csv")
HEADER = "impact_id,camera,point,frame,x_px,y_px\n"


def good_rows(iid="A1"):
    rows = []
    for cam, pts in (("swing", ("bat_tip", "ball")), ("spin", ("ball", "dot_a", "dot_b"))):
        for p in pts:
            for f in range(3):
                rows.append(f"{iid},{cam},{p},{100 + f},{10.0 + f},{20.0}\n")
    return rows


def write(tmp_path, rows, impacts="impact_id,bat,ball\nA1,wood,baseball\n"):
    t = tmp_path / "tracks.csv"
    t.write_text(HEADER + "".join(rows))
    i = tmp_path / "impacts.csv"
    i.write_text(impacts)
    return t, i


def problems(t, i):
    with pytest.raises(InputError) as exc:
        load_tracks(t, i, BALLS, BATS)
    return exc.value.problems


def test_good_file_reads(tmp_path):
    tr = load_tracks(*write(tmp_path, good_rows()), BALLS, BATS)
    assert tr.n == 1 and tr.cameras["swing"].frame0[0] == 100
    assert tr.cameras["spin"].x["dot_b"].shape == (1, 3)


def test_unknown_point_name(tmp_path):
    rows = good_rows()
    rows[0] = "A1,swing,dot_a,100,10.0,20.0\n"  # dot_a is a spin-camera point
    (p,) = [p for p in problems(*write(tmp_path, rows)) if "unknown point" in p]
    assert "tracks.csv: row 2, column point: unknown point 'dot_a' for the swing camera (known: bat_tip, ball)" in p


def test_unknown_camera(tmp_path):
    rows = [*good_rows(), "A1,camera3,ball,100,1,2\n"]
    ps = problems(*write(tmp_path, rows))
    assert any("row 17, column camera: unknown camera 'camera3' (known: swing, spin)" in p for p in ps)


def test_frame_twice(tmp_path):
    rows = [*good_rows(), "A1,spin,dot_a,101,5,5\n"]
    ps = problems(*write(tmp_path, rows))
    assert any(
        "row 17, column frame: frame 101 of dot_a in the spin camera of impact 'A1' appears twice (also row 12)" in p
        for p in ps
    )


def test_impact_with_no_tracks(tmp_path):
    ps = problems(*write(tmp_path, good_rows(), "impact_id,bat,ball\nA1,wood,baseball\nA2,wood,baseball\n"))
    assert any("impacts.csv: row 3: impact 'A2' has no tracks in" in p for p in ps)


def test_camera_missing(tmp_path):
    rows = [r for r in good_rows() if ",spin," not in r]
    ps = problems(*write(tmp_path, rows))
    assert any("impact 'A1'" in p and "the spin camera is missing" in p for p in ps)


def test_point_missing(tmp_path):
    rows = [r for r in good_rows() if "bat_tip" not in r]
    ps = problems(*write(tmp_path, rows))
    assert any("the swing camera has no rows of point(s) bat_tip" in p for p in ps)


def test_bad_cells_and_unknown_impact(tmp_path):
    rows = [*good_rows(), "A1,swing,ball,1.5,1,2\n", "A1,swing,ball,200,abc,2\n", "A9,swing,ball,300,1,2\n"]
    ps = problems(*write(tmp_path, rows))
    assert any("row 17, column frame: '1.5' is not a whole frame number" in p for p in ps)
    assert any("row 18, column x_px: 'abc' is not a number" in p for p in ps)
    assert any("row 19, column impact_id: impact 'A9' is not in" in p for p in ps)


def test_impacts_file_problems(tmp_path):
    impacts = "impact_id,bat,ball\nA1,wood,baseball\nA1,wood,baseball\nA3,oak,cricket\n"
    ps = problems(*write(tmp_path, good_rows(), impacts))
    assert any("impacts.csv: row 3, column impact_id: 'A1' duplicates row 2" in p for p in ps)
    assert any("impacts.csv: row 4, column bat: bat 'oak' is not in the bat table" in p for p in ps)
    assert any("impacts.csv: row 4, column ball: ball 'cricket' is not in the ball table" in p for p in ps)


def test_columns(tmp_path):
    t = tmp_path / "tracks.csv"
    t.write_text("impact_id,camera,point,frame,x,y_px\n")
    i = tmp_path / "impacts.csv"
    i.write_text("impact_id,bat,ball\nA1,wood,baseball\n")
    ps = problems(t, i)
    assert any("missing column(s) x_px" in p for p in ps)
    assert any("unknown column(s) 'x'" in p for p in ps)


def test_every_problem_at_once(tmp_path):
    rows = good_rows()
    rows[0] = "A1,swing,dot_z,100,10.0,20.0\n"
    rows.append("A1,spin,dot_a,101,5,5\n")
    ps = problems(*write(tmp_path, rows, "impact_id,bat,ball\nA1,wood,baseball\nA2,oak,baseball\n"))
    kinds = ("unknown point", "appears twice", "has no tracks", "not in the bat table")
    assert all(any(k in p for p in ps) for k in kinds), ps


def test_missing_file(tmp_path):
    ps = problems(tmp_path / "nope.csv", tmp_path / "nope_impacts.csv")
    assert any("nope_impacts.csv: file not found" in p for p in ps)
    assert any("nope.csv: file not found" in p for p in ps)


def test_camera_settings():
    cfg = {
        "cameras": {"swing": {"fps": -3000, "m_per_px": 0.00074, "mirror": "no", "zoom": 2}, "side": {}},
        "rig": {"pivot_to_tip_in": 28.0, "pivot_to_impact_in": 34.0},
    }
    camera_problems_named(
        cfg,
        "cameras.spin: camera missing",
        "cameras.side: unknown camera",
        "cameras.swing.fps: -3000 must be a positive number",
        "cameras.swing.mirror: 'no' must be true or false",
        "cameras.swing.zoom: unknown setting",
        "rig: pivot_to_impact_in 34.0 is beyond pivot_to_tip_in 28.0",
    )


def camera_problems_named(block: dict, *expected: str) -> list[str]:
    """The problems of a tracks ``block``'s cameras and rig: each expected one among them, with its key named."""
    with pytest.raises(InputError) as exc:
        cameras_from_config(block, "datasets.lab.tracks")
    ps = exc.value.problems
    for e in expected:
        assert any(f"datasets.lab.tracks.{e}" in p for p in ps), (e, ps)
    return ps


def tracks_block(swing: dict | None = None, spin: dict | None = None, **rig) -> dict:
    """A dataset's tracks block: the 3000 and 1000 fps cameras, with ``swing``/``spin``/``rig`` entries added."""
    return {
        "file": "tracks.csv",
        "impacts": "impacts.csv",
        "cameras": {
            "swing": {"fps": 3000, "m_per_px": 0.00074, "mirror": False, **(swing or {})},
            "spin": {"fps": 1000, "m_per_px": 0.00125, "mirror": False, **(spin or {})},
        },
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0, **rig},
    }


def test_calibration_uncertainties():
    """fps_err (relative) and the rig's length uncertainties (inches): read, and each wrong one named."""
    good = tracks_block(swing={"fps_err": 0.001}, pivot_to_impact_err_in=0.1)
    cams, rig = cameras_from_config(checked_block(good, "tracks"))  # the schema's defaults filled
    assert cams["swing"].fps_err == 0.001 and cams["spin"].fps_err == 0.0
    assert rig.pivot_to_impact_err == pytest.approx(0.1 * 0.0254) and rig.pivot_to_tip_err == 0.0
    bad = tracks_block(spin={"fps_err": 2}, pivot_to_tip_err_in=-1, pivot_to_impact_err_in=5)
    ps = camera_problems_named(
        bad,
        "cameras.spin.fps_err: 2 must be a relative uncertainty >= 0 and below 0.1",
        "rig.pivot_to_tip_err_in: -1 must be a number >= 0",
        "rig.pivot_to_impact_err_in: 5 in is 17.9 % of pivot_to_impact_in 28.0",
    )
    assert len(ps) == 3


def test_exposure_time():
    """exposure_us: microseconds into the Camera's seconds (0 by default: not known); one longer than the time
    between frames (1/2000 s typed as 500 us at 3000 fps), or negative, is named.
    """
    cams, _ = cameras_from_config(checked_block(tracks_block(swing={"exposure_us": 50}), "tracks"))
    assert cams["swing"].exposure_s == pytest.approx(50e-6) and cams["spin"].exposure_s == 0.0
    bad = tracks_block(swing={"exposure_us": 500}, spin={"exposure_us": -1})
    ps = camera_problems_named(
        bad,
        "cameras.swing.exposure_us: 500 us is longer than the 333.3 us between frames at 3000 fps",
        "cameras.spin.exposure_us: -1 must be a number >= 0",
    )
    assert len(ps) == 2


def test_camera_settings_good():
    block = tracks_block(swing={"mirror": True, "m_per_px_err": 0.005})
    cams, rig = cameras_from_config(checked_block(block, "tracks"))  # the schema's defaults filled
    assert cams["swing"].sign == -1 and cams["swing"].m_per_px_err == 0.005
    assert cams["spin"].m_per_px_err == 0.0  # the schema's default
    assert rig.pivot_to_impact == pytest.approx(28 * 0.0254)


def test_shipped_example_reduces():
    """config/examples/tracked.yaml: 12 impacts, the one with a tilted spin axis (W04) excluded."""
    import yaml

    from ballbat.properties import load_balls, load_bats
    from ballbat.stages import reduce
    from ballbat.tracks.io import load_tracks

    with open("config/examples/tracked.yaml") as fh:
        cfg = checked_block(yaml.safe_load(fh)["datasets"]["tracked"]["tracks"], "tracks")
    balls, bats = load_balls("config/balls.csv"), load_bats("config/bats.csv")
    tracks = load_tracks(cfg["file"], cfg["impacts"], balls, bats)
    settings = reduce.ReduceSettings.from_config(cfg, "tracked", systematics=True)
    ds = reduce.run(settings, tracks, balls, bats, source_file=cfg["file"])
    assert ds.attrs["source_file"] == cfg["file"]
    flagged = ds["impact_id"].values[ds["ingest_flag"].values != 0]
    assert list(flagged) == ["W04"]
    assert ds.sizes["impact"] == 12
    assert ds["v_bat_err_scale"].values[0] == pytest.approx(0.005 * ds["v_bat"].values[0])
    # the reduce rule's file carries the calibration shifts: the swing camera's scale (0.5 %) only
    sigma = dict(zip(ds["systematic"].values.astype(str), ds["systematic_rel_sigma"].values, strict=True))
    assert sigma["swing_m_per_px"] == 0.005 and sum(sigma.values()) == 0.005
    up = ds["v_ball_shift"].sel(systematic="swing_m_per_px", shift=1).values
    np.testing.assert_allclose(up, 0.005 * ds["v_ball"].values, rtol=0.01)  # the flight's gravity term aside
    assert not ds["v_bat_shift"].sel(systematic="swing_fps").values.any()


def test_one_limit_for_a_calibration_uncertainty(schema, raw):
    """The schema and the tracks' own check refuse a relative fps or pixel-scale uncertainty at the same value."""
    from ballbat.config_checks import validate_config
    from ballbat.tracks.checks import SCALE_ERR_MAX

    for camera in ("track_camera", "render_camera"):
        props = schema["$defs"][camera]["properties"]
        for k in ("m_per_px_err", "fps_err"):
            assert props[k]["exclusiveMaximum"] == SCALE_ERR_MAX and "maximum" not in props[k], (camera, k)
    raw["datasets"]["synthetic"]["render"]["cameras"]["swing"]["m_per_px_err"] = 0.3  # 0.3 % meant
    with pytest.raises(
        ValueError, match=r"m_per_px_err: 0.3 is greater than or equal to the maximum of 0.1 .*0.005 for 0.5 %"
    ):
        validate_config(raw, schema)
