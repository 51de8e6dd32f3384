"""The report's front page (ballbat.frontpage) from small in-memory results."""

from __future__ import annotations

import base64
import io
import subprocess

import numpy as np
import pytest
import xarray as xr
from docutils.core import publish_parts
from PIL import Image

from ballbat import frontpage as fp

BALLS = ["baseball", "softball"]
BATS = ["wood", "metal_rough"]
FLAG = {"flag_values": np.array([0, 1, 4], dtype=np.int8), "flag_meanings": "ok psi_undefined excluded_at_ingest"}
INGEST = {"flag_values": np.array([0, 1, 3], dtype=np.int8), "flag_meanings": "ok no_impact dot_not_rotating"}
STATUS = {"flag_values": np.array([0, 1, 2, 3], dtype=np.int8), "flag_meanings": "ok no_impacts too_few fit_failed"}


def impacts(flags=(0, 0, 1, 4, 0), ingest=(0, 0, 0, 3, 0), warnings="") -> xr.Dataset:
    n = len(flags)
    return xr.Dataset(
        {
            "flag": ("impact", np.array(flags, dtype=np.int8), FLAG),
            "ingest_flag": ("impact", np.array(ingest, dtype=np.int8), INGEST),
        },
        coords={
            "impact": np.arange(n),
            "impact_id": ("impact", [f"B{i:02d}" for i in range(n)]),
            "ball": ("impact", (["baseball", "softball"] * n)[:n]),
            "bat": ("impact", ["wood"] * n),
        },
        attrs={"ingest_warnings": warnings},
    )


def fit(systematic=True, truth=True) -> xr.Dataset:
    e_x = np.array([[0.4630408, 0.35943587], [0.2325132, np.nan]])
    ds = xr.Dataset(
        {
            "e_x": (("ball", "bat"), e_x),
            "e_x_err": (("ball", "bat"), np.array([[0.0115, 0.0063], [0.0064, np.nan]])),
            "e_x_status": (("ball", "bat"), np.array([[0, 0], [0, 2]], dtype=np.int8), STATUS),
            "e_x_pooled": ("ball", np.array([0.3976, 0.1520])),
            "e_x_pooled_err": ("ball", np.array([0.0067, 0.0061])),
            "e_y_implied": ("ball", np.array([0.4499, 0.3192])),
            "e_y_implied_err": ("ball", np.array([0.0015, 0.0014])),
            "mu_k_lower_bound": ("ball", np.array([0.1603, 0.2110])),
            "mu_k_lower_bound_err": ("ball", np.array([0.0012, 0.0012])),
        },
        coords={"ball": BALLS, "bat": BATS},
        attrs={"provenance_git": '{"commit": "0123456789abcdef", "dirty": false}'},
    )
    if systematic:
        ds["e_x_err_scale"] = (("ball", "bat"), np.array([[0.00524, 0.0049], [0.0046, np.nan]]))
        ds["e_x_pooled_err_scale"] = ("ball", np.array([0.0050, 0.0043]))
    if truth:
        ds["truth_e_x"] = (("ball", "bat"), np.array([[0.464, 0.356], [0.234, np.nan]]))
        ds["truth_e_x_pooled"] = ("ball", np.array([0.395, 0.148]))
    return ds


def stronge() -> xr.Dataset:
    return xr.Dataset(
        {
            "eta2": ("ball", np.array([4.68056658, 6.07470919])),
            "eta2_err": ("ball", np.array([0.02961735, 0.03269738])),
            "eta2_ci_low": ("ball", np.array([4.62003809, 6.00752382])),
            "eta2_ci_high": ("ball", np.array([4.7421, 6.1431])),
        },
        coords={"ball": BALLS},
    )


def scenario() -> xr.Dataset:
    return xr.Dataset(coords={"case": np.arange(3)}, attrs={"kind": "sweep", "ball": "baseball", "bat": "wood"})


def render(rst: str) -> str:
    """HTML of the fragment as the report renders it; any docutils warning fails the test."""
    return publish_parts(rst, writer="html", settings_overrides={"halt_level": 2, "report_level": 5})["html_body"]


def page(**kw) -> str:
    datasets = {"lab_1": {"kind": "measured", "impacts": impacts(**kw), "fit": fit(), "stronge": stronge()}}
    return fp.front_page(datasets, {"paper": scenario()}, [], {"commit": "0123456789abcdef", "dirty": False}, None)


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        ((0.35943587, 0.0063), ("0.3594", "0.0063")),
        ((4.68056658, 0.02961735), ("4.681", "0.030")),  # 0.0296 -> 0.030: two significant digits
        ((0.5, 0.0996), ("0.50", "0.10")),  # rounds up into the next decade
        ((1234.5, 123.0), ("1230", "120")),
        ((0.4630408, 0.0115, 0.00524), ("0.4630", "0.0115", "0.0052")),  # the smaller sets the place
        ((0.4630408, float("nan")), ("0.463", "n/a")),
        ((float("nan"), 0.01), ("n/a", "0.010")),
    ],
)
def test_round_pm(args, expected):
    assert fp.round_pm(*args) == expected


def test_pm_and_decimals():
    assert fp.pm(6.07470919, 0.03269738) == "6.075 ± 0.033"
    assert fp.pm(0.2, float("nan")) == "0.2"
    assert fp.decimals_for(float("nan"), 0.0, -1.0) is None  # none is a usable uncertainty
    assert fp.decimals_for(float("nan"), 0.02) == 3


def test_exclusion_reasons_group_and_take_the_ingest_reason():
    groups = fp.exclusion_reasons(impacts())
    assert groups == {"psi undefined": ["B02"], "dot not rotating": ["B03"]}
    assert fp.exclusion_reasons(impacts(flags=(0, 0), ingest=(0, 0))) == {}
    as_variable = impacts().reset_coords("impact_id")  # as ballbat's files hold it: a data variable
    assert fp.exclusion_reasons(as_variable) == {"psi undefined": ["B02"], "dot not rotating": ["B03"]}


def test_dataset_line_counts_and_names_exclusions():
    line = fp.dataset_line("lab", "measured", impacts())
    assert line.startswith("**lab** (measured): 5 impacts (3 baseball, 2 softball); 3 used, 2 excluded:")
    assert "psi undefined (1: impact B02)" in line and "dot not rotating (1: impact B03)" in line
    assert fp.dataset_line("lab", "measured", impacts(flags=(0,), ingest=(0,))).endswith("1 used, 0 excluded.")
    many = fp.dataset_line("lab", "measured", impacts(flags=(1,) * 11, ingest=(0,) * 11))
    assert "(11: impacts B00, B01" in many and "and 3 more" in many  # counted, never silently dropped


def test_e_x_rows_systematic_paper_truth():
    rows = fp.e_x_rows(fit())
    # softball on metal_rough has no value: no row; pooled rows follow each ball's bats
    assert [r[:2] for r in rows] == [
        ["baseball", "wood"],
        ["baseball", "metal rough"],
        ["baseball", "pooled (Eq. ex)"],
        ["softball", "wood"],
        ["softball", "pooled (Eq. ex)"],
    ]
    assert rows[0] == ["baseball", "wood", "**0.4630**", "± 0.0115", "± 0.0052", "0.464 ± 0.014", "0.464"]
    assert rows[2][5] == "0.405 ± 0.010"  # the paper's pooled value as published
    no_syst = fp.e_x_rows(fit(systematic=False, truth=False))
    assert no_syst[0] == ["baseball", "wood", "**0.463**", "± 0.011", "—", "0.464 ± 0.014"]  # 0.0115 is 0.01149...


def test_per_ball_rows():
    rows = fp.per_ball_rows(fit(), stronge())
    assert rows[0] == [
        "baseball",
        "**4.681 ± 0.030**",
        f"4.620 {fp.DASH} 4.742",
        "4.75",
        "0.4499 ± 0.0015",
        "≥ 0.1603 ± 0.0012",
        "≥ 0.15",
    ]
    assert rows[1][3] == "6.3"


def test_fit_warnings_name_the_fit_and_why():
    assert fp.fit_warnings(fit()) == ["e_x (softball, metal_rough): too few"]


def test_front_page_renders_numbers_before_warnings():
    rst = page(warnings="column v_bat_mph_ looks like km/h *twice*")
    html = render(rst)
    assert html.index("0.4630") < html.index("4.681 ± 0.030") < html.index("Warnings and provenance")
    assert "column v_bat_mph_ looks like km/h *twice*" in html  # escaped: shown literally
    assert "Scenario <strong>paper</strong> (D sweep): baseball on the wood bat; 3 cases." in html
    assert "e_x (softball, metal_rough): too few" in html
    assert "commit <tt" in html or "commit <code" in html
    assert "0123456789ab" in html and "clean tree" in html
    assert "calibration systematic" in html and "the synthetic experiment was drawn with" in html


def test_notes_follow_the_columns():
    text = "\n".join(fp.dataset_section("lab", fit(systematic=False, truth=False), stronge()))
    assert (
        "syst. —: no calibration uncertainty stated" in text
        and "truth:" not in text
        and "not in the standard error" not in text
    )


def test_front_page_does_not_repeat_a_logged_warning():
    logged = ["results/lab_1/logs/ingest.log: odd speeds"]
    datasets = {
        "lab_1": {"kind": "measured", "impacts": impacts(warnings="odd speeds"), "fit": fit(), "stronge": stronge()}
    }
    rst = fp.front_page(datasets, {}, logged, {"commit": "abc", "dirty": True}, "2026-01-02")
    assert rst.count("odd speeds") == 1
    assert "uncommitted changes in the tree, committed 2026-01-02" in rst
    quiet = fit()
    quiet["e_x_status"][:] = 0
    datasets = {"lab": {"kind": "synthetic", "impacts": impacts(), "fit": quiet, "stronge": stronge()}}
    assert "No warnings in this run." in fp.front_page(datasets, {}, [], {}, None)


def test_thumbnail_embeds_and_links(tmp_path):
    png = tmp_path / "fig5.png"
    Image.new("RGB", (1000, 600), (200, 30, 30)).save(png)
    uri = fp.thumbnail_uri(png, width=200)
    assert uri.startswith("data:image/png;base64,")
    with Image.open(io.BytesIO(base64.b64decode(uri.split(",", 1)[1]))) as im:
        assert im.size == (200, 120)
    lines = fp.dataset_section("lab", fit(), stronge(), "results/lab/figures/fig5.png", uri)
    html = render("\n".join(lines))
    assert "javascript:app.showResultInfo('results/lab/figures/fig5.png')" in html
    assert uri in html  # the data URI is split over source lines and joined again


def test_provenance_without_git():
    line = fp.provenance_line({"commit": "unknown", "dirty": "unknown"}, None)
    assert "not a git checkout" in line


def test_commit_date(root):
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, check=True)
    date = fp.commit_date(head.stdout.strip(), root)
    assert date is not None and len(date) == 10 and date[4] == "-"
    assert fp.commit_date("unknown", root) is None
    assert fp.commit_date("f" * 40, root) is None


def test_study_lines():
    cov = xr.Dataset(
        {"coverage_95": (("point", "quantity"), np.array([[0.93, 0.951], [np.nan, 0.96]]))},
        attrs={"replicates_per_point": 200},
    )
    des = xr.Dataset(
        {
            "impacts_required": (("point", "pair"), np.array([[50.0, 40.0, 20.0], [31.0, 27.0, 18.0]])),
            "setting": ("point", np.array([5.0, 10.0])),
        },
        coords={"ball": ("pair", ["baseball", "baseball", "softball"])},
        attrs={"delta_e_x": 0.02, "confidence": 0.95, "power": 0.8, "sweep_parameter": "impacts_per_bat"},
    )
    swept = cov.assign(setting=("point", [5.0, 10.0])).assign_attrs(sweep_parameter="impacts_per_bat")
    line = fp.study_line("design", swept, des)
    assert f"(200 replicates per point, impacts\\_per\\_bat 5{fp.DASH}10, 2 quantities)" in line
    assert f"95 % intervals cover the truth in 93.0{fp.DASH}96.0 % of replicates" in line
    assert (
        f"(95 % confidence, 80 % power, from the spread at impacts\\_per\\_bat = 10): baseball 27{fp.DASH}31,"
        " softball 18." in line
    )
    assert "impacts_per_bat 5" in render(line)
    assert fp.study_line("calibration", cov).endswith("(target 95 %).")
    assert "Replicate studies" in render(fp.studies_page({"calibration": (cov, None)}))


def test_names_render_literally():
    sc = xr.Dataset(coords={"case": np.arange(2)}, attrs={"kind": "launch", "ball": "ball_", "bat": "*odd*"})
    html = render(fp.scenario_line("my_run_", sc))
    assert "<strong>my_run_</strong> (launch conditions): ball_ on the *odd* bat; 2 cases." in html
