"""The bats league table (issue 37, section 2; docs/league.md): every bat's e_x over test sessions,
pairwise differences whose shared systematics cancel within a session and add across sessions,
Holm's adjustment, the consistency test of a bat in several sessions, the equivalence test (TOST),
``ballbat compare FOLDER...`` and the workflow's league rule.

The fit_ex.nc files here are built by hand (the variables the league reads, written by the
workflow's writer), so every expected number is a hand computation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from helpers import league_fit_file as fit_file
from helpers import league_pair as pair
from helpers import league_row as row
from helpers import league_settings as settings
from scipy import stats

from ballbat import league


def table(*folders: Path, **kw) -> xr.Dataset:
    return league.league([s for f in folders for s in league.read_folder(f)], settings(**kw))


# ---------------------------------------------------------------------------------------
# the pairwise standard error and the cancellation rule


def test_within_session_shared_systematic_cancels(tmp_path):
    """Two bats of one session: var = a^2 + b^2 + (s_A - s_B)^2 (the shared calibration moves both)."""
    fit_file(tmp_path / "s1", "d1", {"A": (0.45, 0.006, 20, 0.005), "B": (0.40, 0.008, 20, 0.004)})
    p = pair(table(tmp_path / "s1"), "A", "B")
    assert p["difference"] == pytest.approx(0.05, abs=1e-12)
    assert p["stat"] == pytest.approx(math.hypot(0.006, 0.008), rel=1e-12)
    assert p["syst"] == pytest.approx(0.001, rel=1e-9)
    assert p["se"] == pytest.approx(math.sqrt(0.006**2 + 0.008**2 + 0.001**2), rel=1e-12)


def test_across_sessions_systematics_add_in_quadrature(tmp_path):
    """Two bats of two sessions: var = a^2 + b^2 + s_A^2 + s_B^2 (independent calibrations)."""
    fit_file(tmp_path / "s1", "d1", {"A": (0.45, 0.006, 20, 0.005)})
    fit_file(tmp_path / "s2", "d2", {"B": (0.40, 0.008, 20, 0.004)})
    ds = table(tmp_path / "s1", tmp_path / "s2")
    p = pair(ds, "A", "B")
    assert p["syst"] == pytest.approx(math.hypot(0.005, 0.004), rel=1e-12)
    assert p["se"] == pytest.approx(math.sqrt(0.006**2 + 0.008**2 + 0.005**2 + 0.004**2), rel=1e-12)
    # Student t on Welch-Satterthwaite's dof: each stat. variance on n - 1 = 19, the systematics known
    dof = p["se"] ** 4 / (0.006**4 / 19 + 0.008**4 / 19)
    assert p["dof"] == pytest.approx(dof, rel=1e-9)
    assert p["p"] == pytest.approx(2 * stats.t.sf(0.05 / p["se"], dof), rel=1e-9)
    # the session: the dataset's folder as given
    assert sorted(ds["entry_session"].values) == [str(tmp_path / "s1" / "d1"), str(tmp_path / "s2" / "d2")]
    # a source calibrated once for every session (sharing: lab) cancels across sessions too
    lab = table(tmp_path / "s1", tmp_path / "s2", sharing={"swing_m_per_px": "lab"})
    assert pair(lab, "A", "B")["syst"] == pytest.approx(0.001, rel=1e-9)


def test_a_property_tables_uncertainty_is_shared_by_every_session(tmp_path):
    """A bat's property uncertainty (issue 35: ``bat:<bat>:<column>``) is the same table's in every
    session: it does not average down over sessions, and a ball's is shared by every entry of it.
    """
    assert settings().kind("bat:A:M_oz") == "bat" and settings().kind("ball:baseball:m_oz") == "lab"
    assert settings().kind("swing_m_per_px") == "session"
    sources = ["bat:A:M_oz"]
    fit_file(tmp_path / "s1", "d1", {"A": (0.45, 0.006, 20, 0.004)}, sources=sources)
    fit_file(tmp_path / "s2", "d2", {"A": (0.46, 0.006, 20, 0.004)}, sources=sources)
    r = row(table(tmp_path / "s1", tmp_path / "s2"), "A")
    assert r["e_x_syst"] == pytest.approx(0.004, rel=1e-9)  # not 0.004 / sqrt(2)
    assert r["e_x_stat"] == pytest.approx(0.006 / math.sqrt(2), rel=1e-9)


def test_a_session_label_joins_datasets_into_one_session(tmp_path):
    """Two datasets labelled one test session (config datasets.<name>.session) share its calibrations."""
    fit_file(tmp_path / "a", "d1", {"A": (0.45, 0.006, 20, 0.005)})
    fit_file(tmp_path / "b", "d2", {"B": (0.40, 0.008, 20, 0.004)})
    sessions = league.read_folder(tmp_path / "a", session="day1") + league.read_folder(tmp_path / "b", session="day1")
    p = pair(league.league(sessions, settings()), "A", "B")
    assert p["syst"] == pytest.approx(0.001, rel=1e-9)


# ---------------------------------------------------------------------------------------
# Holm, consistency, TOST


def test_holm_against_a_hand_computation():
    """P = (0.01, 0.04, 0.03, 0.005): sorted 0.005 x 4, 0.01 x 3, 0.03 x 2, 0.04 x 1, made monotone."""
    assert league.holm(np.array([0.01, 0.04, 0.03, 0.005])) == pytest.approx([0.03, 0.06, 0.06, 0.02])
    assert league.holm(np.array([0.5, 0.9])) == pytest.approx([1.0, 1.0])  # capped at 1
    out = league.holm(np.array([0.02, np.nan, 0.04]))  # no value, no test: m = 2
    assert out[0] == pytest.approx(0.04) and np.isnan(out[1]) and out[2] == pytest.approx(0.04)


def test_consistency_of_a_bat_in_three_sessions(tmp_path):
    """X = 0.40, 0.42, 0.44 with 0.01 each: mean 0.42, chi2 = 8 on 2 dof, p = exp(-4)."""
    for k, x in enumerate((0.40, 0.42, 0.44)):
        fit_file(tmp_path / f"s{k}", "d", {"A": (x, 0.01, 20, 0.0), "B": (0.3, 0.01, 20, 0.0)})
    r = row(table(*(tmp_path / f"s{k}" for k in range(3))), "A")
    assert r["e_x"] == pytest.approx(0.42, abs=1e-12)
    assert r["e_x_stat"] == pytest.approx(0.01 / math.sqrt(3), rel=1e-12)
    assert r["consistency_chi2"] == pytest.approx(8.0, rel=1e-9) and r["consistency_dof"] == 2
    assert r["consistency_p"] == pytest.approx(math.exp(-4), rel=1e-9)
    assert r["n"] == 60 and r["n_sessions"] == 3


def test_consistency_with_systematics_is_the_hand_formula(tmp_path):
    """Two sessions, independent calibrations: chi2 = (x1 - x2)^2 / (a1^2 + s1^2 + a2^2 + s2^2)."""
    fit_file(tmp_path / "s1", "d", {"A": (0.40, 0.006, 20, 0.004), "B": (0.3, 0.01, 20, 0.0)})
    fit_file(tmp_path / "s2", "d", {"A": (0.43, 0.008, 20, 0.005), "B": (0.3, 0.01, 20, 0.0)})
    r = row(table(tmp_path / "s1", tmp_path / "s2"), "A")
    assert r["consistency_chi2"] == pytest.approx(0.03**2 / (0.006**2 + 0.004**2 + 0.008**2 + 0.005**2), rel=1e-9)


@pytest.mark.parametrize(
    ("d", "se", "equivalent"),
    [
        (0.0, 0.005, True),  # clearly equivalent: the 90 % interval +-0.008 inside +-0.02
        (0.03, 0.005, False),  # clearly not: outside the margin
        (0.02 - 1.6448536 * 0.005, 0.005, None),  # borderline: p = 0.05 exactly
    ],
)
def test_tost(d, se, equivalent):
    p, p_lower, p_upper = league.tost(d, se, 0.02)
    assert p == max(p_lower, p_upper)
    assert p_lower == pytest.approx(stats.norm.sf((d + 0.02) / se))
    if equivalent is None:
        assert p == pytest.approx(0.05, abs=1e-6)
    else:
        assert (p < 0.05) == equivalent


def test_tost_in_the_table_uses_the_reference_bat(tmp_path):
    """The configured reference bat; the other bat's TOST is the hand p of its difference."""
    fit_file(tmp_path / "s1", "d", {"ref": (0.450, 0.004, 30, 0.0), "near": (0.455, 0.004, 30, 0.0)})
    fit_file(tmp_path / "s2", "d", {"far": (0.40, 0.004, 30, 0.0)})
    ds = table(tmp_path / "s1", tmp_path / "s2", reference_bat="ref", margin=0.02)
    near, far = row(ds, "near"), row(ds, "far")
    se = math.hypot(0.004, 0.004)
    assert near["tost_dof"] == pytest.approx(se**4 / (2 * 0.004**4 / 29), rel=1e-9)
    assert near["tost_p"] == pytest.approx(stats.t.cdf((0.005 - 0.02) / se, near["tost_dof"]), rel=1e-9)
    assert near["tost_equivalent"] == 1 and far["tost_equivalent"] == 0 and row(ds, "ref")["tost_equivalent"] == -1
    with pytest.raises(ValueError, match=r"league\.reference_bat: 'oak' has no e_x here"):
        table(tmp_path / "s1", reference_bat="oak")
