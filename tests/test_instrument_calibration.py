"""Issue #35, item 4: a measured impacts file's instruments state their calibration uncertainties.

``datasets.<name>.calibration`` (``speed_scale_pct``, ``spin_scale_pct``, ``angle_offset_deg``): each
stated one is a systematic source, every impact's values moved by +-1 sigma and refitted. The hand
computation rescales the file's columns itself. "syst. —" appears only where nothing is stated, and
then the text says so.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
import yaml

from ballbat import chain
from ballbat.compare import NO_SYSTEMATIC_NOTE, SYSTEMATIC_NOTE, systematic_note
from ballbat.config_checks import validate_config
from ballbat.pipeline.config import ConfigError
from ballbat.properties import load_balls, load_bats

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "config" / "examples"
IMPACTS, BATS, BALLS = EX / "maple_impacts.csv", EX / "maple_bats.csv", ROOT / "config" / "balls.csv"


def _fit(impacts: Path, calibration: dict | None = None):
    settings = chain.schema_settings({"impacts": str(impacts), "bats": str(BATS)}, "maple")
    ds = chain.ingest(impacts, BALLS, BATS, calibration)
    return chain.run(settings, ds, load_balls(BALLS), load_bats(BATS)).fit_ex


def _moved(tmp_path: Path, columns: tuple[str, ...], factor: float = 1.0, offset: float = 0.0) -> Path:
    """The impacts file with ``columns`` times ``factor`` plus ``offset`` (what a miscalibrated instrument gives)."""
    with IMPACTS.open() as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        for c in columns:
            if row[c] != "":
                row[c] = repr(float(row[c]) * factor + offset)
    out = tmp_path / f"moved_{'_'.join(columns)}_{factor}_{offset}.csv"
    with out.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return out


@pytest.fixture(scope="module")
def nominal():
    return _fit(IMPACTS)


CASES = {
    # source: (config, columns moved by hand, factor at +1 sigma, offset at +1 sigma)
    # (a scale moves the file's standard uncertainties of those values with them; an offset does not)
    "speed_scale": (
        {"speed_scale_pct": 1.0},
        ("v_bat_mph", "v_ball_mph", "v_bat_mph_err", "v_ball_mph_err"),
        0.01,
        0.0,
    ),
    "spin_scale": ({"spin_scale_pct": 0.5}, ("omega_rpm", "omega_rpm_err"), 0.005, 0.0),
    "angle_offset": ({"angle_offset_deg": 0.2}, ("theta_deg",), 0.0, 0.2),
}


@pytest.mark.parametrize("source", list(CASES))
def test_calibration_systematic_is_the_rescaled_file_refitted(tmp_path, nominal, source):
    """Speed scale 1 %: e_x's systematic is half of what rescaling every speed by +-1 % does to it; alike the others."""
    cal, columns, rel, off = CASES[source]
    fit = _fit(IMPACTS, cal)
    assert list(fit["systematic"].values) == [source]
    got = fit["e_x_syst_by_source"].sel(systematic=source).values
    plus = _fit(_moved(tmp_path, columns, 1 + rel, off))
    minus = _fit(_moved(tmp_path, columns, 1 - rel, -off))
    for q in ("e_x", "e_x_pooled", "tan_ratio_slope", "e_y_implied"):
        expect = 0.5 * np.abs(plus[q].values - minus[q].values)
        ok = np.isfinite(expect)
        # the file holds mph, deg and rpm to its own digits; the hand-moved file is written back with
        # repr, so the two agree to rounding (1e-9 relative) rather than bit for bit
        assert np.allclose(fit[f"{q}_syst_by_source"].values[0][ok], expect[ok], rtol=1e-6, atol=1e-12), q
    assert np.all(got[np.isfinite(got)] > 0)
    # the nominal numbers do not move; the systematic stands apart from the standard error
    assert np.array_equal(fit["e_x"].values, nominal["e_x"].values, equal_nan=True)
    assert np.array_equal(fit["e_x_err"].values, nominal["e_x_err"].values, equal_nan=True)
    assert np.allclose(fit["e_x_err_total"].values, np.hypot(fit["e_x_err"].values, got), equal_nan=True)


def test_speed_scale_size_and_direction(nominal):
    """A larger speed scale uncertainty gives a proportionally larger systematic (linear for small sigma)."""
    one = _fit(IMPACTS, {"speed_scale_pct": 1.0})["e_x_pooled_syst"].values
    two = _fit(IMPACTS, {"speed_scale_pct": 2.0})["e_x_pooled_syst"].values
    ok = np.isfinite(one)
    assert ok.any() and np.allclose(two[ok] / one[ok], 2.0, rtol=0.01)
    # size: both speeds scale, so the normalised spin's bracket (v_bat sin psi) scales by the same 1 %,
    # and psi moves a little with v_ball: 1 + e_x changes by about 1 %, i.e. e_x by about (1 + e_x) x 1 %
    e_x = nominal["e_x_pooled"].values[ok]
    assert np.allclose(one[ok], 0.01 * (1 + e_x), rtol=0.5)


def test_nothing_stated_no_source_and_the_text_says_so(nominal):
    from ballbat.reporting import fig5_numbers

    assert "systematic" not in nominal.coords and "e_x_syst" not in nominal
    assert systematic_note(nominal) == NO_SYSTEMATIC_NOTE
    assert "no calibration uncertainty stated" in NO_SYSTEMATIC_NOTE
    settings = chain.schema_settings({"impacts": str(IMPACTS), "bats": str(BATS)}, "maple")
    impacts = chain.reconstructed(settings, chain.ingest(IMPACTS, BALLS, BATS), load_balls(BALLS), load_bats(BATS))
    assert f"syst. —: {NO_SYSTEMATIC_NOTE}" in fig5_numbers(impacts, nominal)
    stated = _fit(IMPACTS, {"spin_scale_pct": 1.0})
    text = fig5_numbers(impacts, stated)
    assert "syst. —" not in text and "the instruments' calibrations" in text and "spin_scale" in text
    assert "(stat) ±" in text and "(syst)" in text


def test_front_page_and_summary_split_by_source(tmp_path, nominal):
    from ballbat.frontpage import dataset_section
    from ballbat.pipeline.config import checked_block
    from ballbat.stages import stronge

    settings = chain.schema_settings({"impacts": str(IMPACTS), "bats": str(BATS)}, "maple")
    c = chain.run(
        settings,
        chain.ingest(IMPACTS, BALLS, BATS, {"speed_scale_pct": 1.0, "angle_offset_deg": 0.2}),
        load_balls(BALLS),
        load_bats(BATS),
    )
    st = stronge.run(stronge.StrongeSettings.from_config({"stronge": checked_block({}, "stronge")}), c.reconstruct)
    page = "\n".join(dataset_section("maple", c.fit_ex, st))
    assert "syst. —" not in page and "By source, pooled e_x of the baseball: " in page
    assert "speed\\_scale" in page and "angle\\_offset" in page  # (escaped for reStructuredText)
    plain = "\n".join(dataset_section("maple", nominal, st))
    assert f"syst. —: {NO_SYSTEMATIC_NOTE}" in plain
    # camera-tracked data alone keeps its note as it was
    assert SYSTEMATIC_NOTE.startswith("every stated calibration uncertainty (pixel scale")


def test_config_calibration_keys(config):
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    maple = {"impacts": str(IMPACTS), "calibration": {"speed_scale_pct": 0.5}}
    good = {**config, "datasets": {**config["datasets"], "maple": maple}}
    assert validate_config(good, schema)["datasets"]["maple"]["calibration"] == {"speed_scale_pct": 0.5}
    for bad, words in (
        ({"impacts": str(IMPACTS), "calibration": {"speed_scale": 0.5}}, "speed_scale"),
        ({"impacts": str(IMPACTS), "calibration": {"spin_scale_pct": -1}}, "spin_scale_pct"),
        ({**config["datasets"]["synthetic"], "calibration": {"speed_scale_pct": 0.5}}, "'impacts' is a dependency"),
    ):
        with pytest.raises(ConfigError, match=words):
            validate_config({**config, "datasets": {**config["datasets"], "x": bad}}, schema)


def test_workbook_lists_each_source_or_says_none(tmp_path, nominal):
    from openpyxl import load_workbook

    from ballbat.pipeline.config import checked_block
    from ballbat.stages import stronge
    from ballbat.workbook import dataset_workbook

    settings = chain.schema_settings({"impacts": str(IMPACTS), "bats": str(BATS)}, "maple")
    sst = stronge.StrongeSettings.from_config({"stronge": checked_block({}, "stronge")})
    for cal, name in (({"angle_offset_deg": 0.2}, "with.xlsx"), (None, "without.xlsx")):
        c = chain.run(settings, chain.ingest(IMPACTS, BALLS, BATS, cal), load_balls(BALLS), load_bats(BATS))
        dataset_workbook(tmp_path / name, c.reconstruct, c.fit_ex, stronge.run(sst, c.reconstruct), [])
    rows = list(load_workbook(tmp_path / "with.xlsx")["systematics"].iter_rows(min_row=3, values_only=True))
    e_x = [r for r in rows if r[0] == "e_x_pooled"]
    assert e_x and all(r[3] == "angle_offset" and r[4] is None and r[5] > 0 for r in e_x)
    sheet = load_workbook(tmp_path / "with.xlsx")["e_x"]
    assert [c.value for c in sheet[1]][4] == "e_x_syst" and all(
        r[4] for r in sheet.iter_rows(min_row=3, values_only=True)
    )
    none = list(load_workbook(tmp_path / "without.xlsx")["systematics"].iter_rows(min_row=3, values_only=True))
    assert none == [("e_x", None, None, "none stated", None, None, NO_SYSTEMATIC_NOTE)]
