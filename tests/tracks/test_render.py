"""The tracks renderer (ballbat.tracks.render): a drawn calibration changes the renderer's scale, not the
reduction's (issue 22).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from ballbat.tracks.data import camera_block
from ballbat.tracks.render import drawn_calibration, settings_from_config

# ---------------------------------------------------------------------------------------
# drawn calibration


def _render_cfg(config, seed=5, **swing):
    cfg = copy.deepcopy(config["datasets"]["synthetic"]["render"])
    cfg["cameras"]["swing"].update(swing)
    return {**cfg, "seed": seed}


def test_drawn_calibration_changes_the_renderer_scale_not_the_reduction(config):
    cfg = _render_cfg(config)
    declared = settings_from_config(cfg)
    assert declared.swing.camera.m_per_px == cfg["cameras"]["swing"]["m_per_px"]  # off by default
    drawn = settings_from_config({**cfg, "draw_calibration": True})
    rel = drawn.swing.camera.m_per_px / declared.swing.camera.m_per_px - 1
    assert rel != 0 and abs(rel) < 5 * cfg["cameras"]["swing"]["m_per_px_err"]
    assert drawn.spin.camera.m_per_px == declared.spin.camera.m_per_px  # no uncertainty stated: not drawn
    assert drawn.swing.camera.fps == declared.swing.camera.fps and drawn.rig == declared.rig
    # the reduction reads the declared block
    block = camera_block({**cfg, "draw_calibration": True})
    assert block["cameras"]["swing"]["m_per_px"] == cfg["cameras"]["swing"]["m_per_px"]
    # reproducible from the render seed, another seed another draw
    again = settings_from_config({**cfg, "draw_calibration": True})
    assert again.swing.camera.m_per_px == drawn.swing.camera.m_per_px
    other = settings_from_config({**_render_cfg(config, seed=6), "draw_calibration": True})
    assert other.swing.camera.m_per_px != drawn.swing.camera.m_per_px


def test_drawn_scales_spread_as_stated():
    cfg = {
        "cameras": {  # every uncertainty given, as in the validated config (0: none stated)
            "swing": {"m_per_px": 1e-3, "m_per_px_err": 0.01, "fps_err": 0.0},
            "spin": {"m_per_px": 2e-3, "m_per_px_err": 0.0, "fps_err": 0.02},
        },
        "rig": {
            "pivot_to_tip_in": 34.0,
            "pivot_to_impact_in": 28.0,
            "pivot_to_tip_err_in": 0.0,
            "pivot_to_impact_err_in": 0.1,
        },
    }
    cfg["cameras"]["spin"]["fps"] = 1000.0
    cfg["cameras"]["swing"]["fps"] = 3000.0
    draws = [drawn_calibration({**cfg, "seed": k}) for k in range(2000)]
    rel = np.array([d["cameras"]["swing"]["m_per_px"] for d in draws]) / 1e-3 - 1
    assert abs(rel.mean()) < 4 * 0.01 / np.sqrt(2000) and rel.std() == pytest.approx(0.01, rel=0.1)
    fps = np.array([d["cameras"]["spin"]["fps"] for d in draws]) / 1000.0 - 1
    assert fps.std() == pytest.approx(0.02, rel=0.1)  # a stated frame-rate uncertainty is drawn (relative)
    rig = np.array([d["rig"]["pivot_to_impact_in"] for d in draws]) - 28.0
    assert rig.std() == pytest.approx(0.1, rel=0.1)  # a rig length's (absolute, inches)
    assert {d["cameras"]["swing"]["fps"] for d in draws} == {3000.0}  # nothing stated: not drawn
    assert {d["rig"]["pivot_to_tip_in"] for d in draws} == {34.0}
    assert cfg["cameras"]["swing"]["m_per_px"] == 1e-3  # the block itself is untouched


def test_rendered_tracks_scale_with_the_drawn_pixel_scale(config, balls):
    """Noise-free tracks drawn with the drawn scale: every swing-camera displacement from the tee is scaled by
    declared / drawn, while the impacts' own draws (contact time, swing plane...) are the same.
    """
    from ballbat.stages import render, simulate
    from ballbat.synthetic import SyntheticSettings

    syn = copy.deepcopy(config["datasets"]["synthetic"]["synthetic"])
    syn["impacts"] = {"baseball": {"wood": 4}}
    syn["e_x"] = {"baseball": {"wood": 0.46}}
    syn["e_y"] = {"baseball": 0.45}
    syn["psi_deg"] = {"baseball": [0.0, 30.0]}
    from ballbat.properties import load_bats

    bats = load_bats(__import__("pathlib").Path(__file__).resolve().parents[2] / "config" / "bats.csv")
    sim = simulate.run(SyntheticSettings(**{**syn, "seed": 3}), balls, bats)
    cfg = _render_cfg(config, seed=9)
    for cam in cfg["cameras"].values():
        cam["pixel_noise_px"] = 0.0
    plain = render.render(settings_from_config(cfg), sim, balls)
    drawn = render.render(settings_from_config({**cfg, "draw_calibration": True}), sim, balls)
    for k, v in plain.truth.items():
        np.testing.assert_array_equal(v, drawn.truth[k], err_msg=k)
    m0 = cfg["cameras"]["swing"]["m_per_px"]
    m1 = settings_from_config({**cfg, "draw_calibration": True}).swing.camera.m_per_px
    tee = cfg["cameras"]["swing"]["tee_px"][0]
    a = plain.cameras["swing"].x["ball"] - tee
    b = drawn.cameras["swing"].x["ball"] - tee
    both = np.isfinite(a) & np.isfinite(b) & (np.abs(a) > 1)
    assert both.sum() > 20
    np.testing.assert_allclose(b[both] / a[both], m0 / m1, rtol=1e-9)
