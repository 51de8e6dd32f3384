"""The fit_stronge products on the default synthetic experiment (Sec. V.A, Figs. 9-10)."""

import numpy as np
import pytest

from ballbat.analysis import normalize, reconstruct
from ballbat.compare import stronge_rows
from ballbat.stronge.analysis import stronge_dataset
from ballbat.stronge.model import Regime
from ballbat.synthetic import SyntheticSettings, simulate_experiment


@pytest.fixture(scope="module")
def products(config, balls, bats):
    s = SyntheticSettings(**config["datasets"]["synthetic"]["synthetic"])
    rec = reconstruct(normalize(simulate_experiment(s, balls, bats), config["normalize"]["v_ref_mph"]), balls, bats)
    return stronge_dataset(rec, **{**config["stronge"], "n_time": 201})


def test_eta2_near_published(products):
    # The synthetic e_x follow Table II, whose pooled values (0.405, 0.146) the paper's eta^2
    # (4.75, 6.30; Sec. V.A) reproduce; our fit of the synthetic data lands within 5 % of them.
    for ball, pub in (("baseball", 4.75), ("softball", 6.30)):
        f = products.sel(ball=ball)
        assert float(f.eta2) == pytest.approx(pub, rel=0.05)
        assert 0 < float(f.eta2_err) < 0.3
        assert float(f.eta2_ci_low) < float(f.eta2) < float(f.eta2_ci_high)
        assert float(f.eta2_published) == pub


def test_curves_are_consistent(products):
    for ball in products.ball.values:
        f = products.sel(ball=ball)
        np.testing.assert_allclose(f.vtf_y_model, (1 + f.e_x_model) * f.vtf_x_model, rtol=1e-12)
        # Sec. V.A calls the curves "quite linear" and consistent with a constant e_x. The model
        # does not hold e_x constant: over 0-30 deg it falls steadily, by 0.05 (baseball) and
        # 0.046 (softball) at the fitted eta^2 (docs/stronge.md). The test states what it does.
        inside = products.psi_grid.values <= np.radians(30)
        ex = f.e_x_model.values[inside]
        assert np.all(np.diff(ex) < 0)
        assert 0.03 < ex[0] - ex[-1] < 0.06


def test_fig10_timeline(products):
    # Sec. V.A / Fig. 10 at psi = 30 deg: stick to ~1.4 t_c, separation 1.5 t_c, stretch largest
    # at 1.16 t_c (baseball) and 1.33 t_c (softball). The paper quotes two decimals for the
    # latter, one for the former; tolerances follow.
    for ball, t_s in (("baseball", 1.16), ("softball", 1.33)):
        f = products.sel(ball=ball)
        assert float(f.t_stretch_max) == pytest.approx(t_s, abs=0.02)
        assert float(f.t_stick_end) == pytest.approx(1.4, abs=0.05)
        assert float(f.t_separation) == pytest.approx(1.5, abs=1e-12)
        assert int(f.regime_history) == Regime.STICK_SLIP
        n = f.normal_force.values
        assert np.nanmax(n) == pytest.approx(1.0, abs=1e-2)
        stick = f.stick.values
        t = products.t_over_tc.values
        assert np.all(stick[(t > 0.05) & (t < 1.35)] == 1) and np.all(stick[(t > 1.45) & (t < 1.49)] == 0)


def test_comparison_rows(products):
    rows = {(r["quantity"], r["ball"]): r for r in stronge_rows(products)}
    assert rows[("omega_t_over_omega_n", "baseball")]["value"] == pytest.approx(0.86, abs=0.01)
    assert rows[("omega_t_over_omega_n", "softball")]["value"] == pytest.approx(0.75, abs=0.01)
    assert rows[("eta2", "baseball")]["uncertainty"] > 0


def test_published_eta2_gives_the_published_pooled_e_x(products):
    """Sec. V.A: the model at eta^2 = 4.75 / 6.30 (e_y = mu = 0.5) accounts for the data, whose
    pooled e_x is 0.405 / 0.146 (Sec. IV, Fig. 5). Its e_x averaged over the experiment's psi
    range (Table I: psi_max 30 / 41 deg) lies within 0.03 of those values.
    """
    for ball, psi_max, pooled in (("baseball", 30.0, 0.405), ("softball", 41.0, 0.146)):
        f = products.sel(ball=ball)
        inside = (products.psi_grid.values > 0) & (products.psi_grid.values <= np.radians(psi_max))
        assert float(np.mean(f.e_x_published.values[inside])) == pytest.approx(pooled, abs=0.03)
