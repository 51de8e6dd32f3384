"""Sweeps (ballbat.studies.sweeps): sweep points of one parameter and of a grid, the contact sweep, the
scatter and spin-noise sweeps, bad values refused (issues 22, 36).
"""

from __future__ import annotations

import copy
import itertools
import math

import pytest

from ballbat.studies.settings import StudySettings
from ballbat.studies.sweeps import CONTACT_HALF_WIDTH_MS, point_dataset, sweep_points, truth_counts
from ballbat.tracks.render import settings_from_config


def _dataset():
    from ballbat.config_checks import load_config

    return load_config()["datasets"]["synthetic"]


def test_sweep_sets_scatter_psi_range_and_spin_noise():
    from ballbat.studies.sweeps import point_dataset

    base = _dataset()
    ds = point_dataset(base, ["e_x_scatter", "psi_max_scale", "spin_pixel_noise_px"], [0.02, 0.4, 3.5])
    assert ds["synthetic"]["e_x_scatter"] == 0.02
    for ball, (lo, hi) in base["synthetic"]["psi_deg"].items():
        assert ds["synthetic"]["psi_deg"][ball] == pytest.approx([lo, 0.4 * hi])
    assert ds["render"]["cameras"]["spin"]["pixel_noise_px"] == 3.5
    assert ds["render"]["cameras"]["swing"]["pixel_noise_px"] == base["render"]["cameras"]["swing"]["pixel_noise_px"]


@pytest.mark.parametrize(
    ("parameter", "value", "words"),
    [
        ("e_x_scatter", -0.01, "e_x_scatter must lie"),
        ("psi_max_scale", 0.0, "psi_max_scale must lie"),
        ("spin_pixel_noise_px", 0.0, "must be positive"),
    ],
)
def test_sweep_refuses_bad_values(parameter, value, words):
    from ballbat.studies.sweeps import check_sweep

    problems = check_sweep(_dataset(), parameter, [value], "studies.x")
    assert any(words in p for p in problems)


# ---------------------------------------------------------------------------------------
# the grid


def test_the_shipped_robustness_grid_expands_to_the_product(config):
    """27 points, the first setting slowest; each point's dataset has its noise, impacts and contact range."""
    s = StudySettings.from_config(config, "robustness")
    grid = config["studies"]["robustness"]["sweep"]["grid"]
    assert s.parameters == ("pixel_noise_px", "impacts_per_bat", "contact_ms") and s.is_grid
    assert s.values == tuple(itertools.product(*grid.values()))
    assert s.n_points == 27 and s.total == 27 * s.replicates
    assert s.point_settings().shape == (27, 3)
    for px, n, tc in s.values:
        ds = point_dataset(s.dataset, s.parameter, (px, n, tc))
        assert {c["pixel_noise_px"] for c in ds["render"]["cameras"].values()} == {px}
        assert {k for per in ds["synthetic"]["impacts"].values() for k in per.values()} == {int(n)}
        assert ds["render"]["contact_ms"] == pytest.approx([tc - 0.05, tc + 0.05])
        assert ds["render"]["draw_calibration"] is True  # the study draws its calibration
    # every replicate number maps to one point and replicate, each once
    seen = [divmod(g, s.replicates) for b in range(s.n_batches) for g in s.batch_range(b)]
    assert len(set(seen)) == s.total and max(p for p, _ in seen) == 26
    # one-parameter sweeps are as they were (the shipped design study)
    d = StudySettings.from_config(config, "design")
    assert d.parameter == "impacts_per_bat" and d.values == (5.0, 10.0, 20.0, 30.0, 50.0, 75.0, 100.0)
    assert not d.is_grid and d.point_settings()[:, 0].tolist() == list(d.values)
    assert StudySettings.from_config(config, "calibration").parameters == ()


def test_sweep_points_of_one_parameter_and_of_a_grid():
    assert sweep_points(None) == ((), [])
    assert sweep_points({"parameter": "e_x", "values": [0.3, 0.5]}) == (("e_x",), [(0.3,), (0.5,)])
    names, pts = sweep_points({"grid": {"e_x": [0.3, 0.5], "impacts_per_bat": [10, 20, 30]}})
    assert names == ("e_x", "impacts_per_bat") and len(pts) == 6 and pts[:3] == [(0.3, 10), (0.3, 20), (0.3, 30)]


def test_contact_sweep_sets_a_narrow_range_about_the_value(config):
    base = config["datasets"]["synthetic"]
    ds = point_dataset(base, "contact_ms", 0.8)
    assert ds["render"]["contact_ms"] == pytest.approx([0.8 - CONTACT_HALF_WIDTH_MS, 0.8 + CONTACT_HALF_WIDTH_MS])
    assert base["render"].get("contact_ms") != ds["render"]["contact_ms"]  # a copy
    assert settings_from_config(ds["render"]).contact_time == pytest.approx((0.75e-3, 0.85e-3))


def test_a_pair_of_no_impacts_stays_empty(config):
    ds = copy.deepcopy(config["datasets"]["synthetic"])
    ds["synthetic"]["impacts"]["baseball"]["wood"] = 0
    k, counts = truth_counts(ds, 1000)
    assert counts["baseball"]["wood"] == 0 and k == math.ceil(6 * 1000 / 88)
    ds["synthetic"]["impacts"] = {"baseball": {"wood": 0}}
    with pytest.raises(ValueError, match="no impacts"):
        truth_counts(ds, 1000)


@pytest.mark.parametrize(
    ("parameter", "value", "check"),
    [
        ("impacts_per_bat", 9, lambda d: {n for v in d["synthetic"]["impacts"].values() for n in v.values()} == {9}),
        ("e_x", 0.3, lambda d: {e for v in d["synthetic"]["e_x"].values() for e in v.values()} == {0.3}),
        ("pixel_noise_px", 3.5, lambda d: {c["pixel_noise_px"] for c in d["render"]["cameras"].values()} == {3.5}),
        ("spin_fps", 2000, lambda d: d["render"]["cameras"]["spin"]["fps"] == 2000),
        ("noise_scale", 2.0, lambda d: d["synthetic"]["noise"]["omega_rpm"] == 150.0),
    ],
)
def test_sweep_sets_the_dataset(config, parameter, value, check):
    base = config["datasets"]["synthetic"]
    before = copy.deepcopy(base)
    assert check(point_dataset(base, parameter, value))
    assert base == before  # a copy: the config is untouched
