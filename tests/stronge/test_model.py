"""Stronge's lumped-parameter contact model (ballbat.stronge.model): the fast path against the general engine,
broadcasting and limits, energy, the paper's curves and time histories.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from ballbat.properties import recoil_factors
from ballbat.stronge.fit import _jacobian
from ballbat.stronge.model import ContactParams, omega_ratio, stronge_ex, stronge_solve
from ballbat.stronge.regimes import regime_boundaries

DEG = np.pi / 180
#: Paper, Sec. V.A: fitted eta^2 with e_y = mu = 0.5.
ETA2 = {"baseball": 4.75, "softball": 6.30}


def test_fast_path_matches_general_engine():
    """stronge_ex (fast path for Omega_t <= Omega_n) equals the phase machine everywhere."""
    rng = np.random.default_rng(1)
    n = 20000
    psi = rng.uniform(0, 89, n) * DEG
    eta2 = np.exp(rng.uniform(np.log(0.2), np.log(20), n))
    e_y, mu = rng.uniform(0.1, 1, n), rng.uniform(0.02, 2, n)
    r_x, r_y = rng.uniform(0, 0.5, n), rng.uniform(0, 0.5, n)
    np.testing.assert_allclose(
        stronge_ex(psi, ContactParams(eta2, e_y, mu, r_x, r_y)),
        stronge_solve(psi, ContactParams(eta2, e_y, mu, r_x, r_y)).e_x,
        atol=1e-12,
    )


def test_broadcasting_symmetry_and_psi_zero_limit():
    e = stronge_ex(np.array([[0.1], [0.2]]), ContactParams(np.array([4.0, 5.0, 6.0]), 0.5, 0.5))
    assert e.shape == (2, 3)
    assert isinstance(stronge_ex(0.3, ContactParams(4.75, 0.5, 0.5)), float)
    assert stronge_ex(-0.3, ContactParams(4.75, 0.5, 0.5)) == stronge_ex(0.3, ContactParams(4.75, 0.5, 0.5))
    # psi -> 0: stick lasts to separation, e_x = -cos(Omega_t t_f)
    rho = omega_ratio(4.75)
    assert stronge_ex(0.0, ContactParams(4.75, 0.5, 0.5)) == pytest.approx(-np.cos(rho * np.pi / 2 * 1.5), abs=1e-14)
    assert stronge_ex(1e-9, ContactParams(4.75, 0.5, 0.5)) == pytest.approx(-np.cos(rho * np.pi / 2 * 1.5), abs=1e-8)
    assert stronge_solve(0.0, ContactParams(4.75, 0.5, 0.5)).regime == "stick"
    # empty input
    assert stronge_ex(np.zeros((0, 3)), ContactParams(4.75, 0.5, 0.5)).shape == (0, 3)
    assert stronge_solve(np.array([]), ContactParams(4.75, 0.5, 0.5), histories=True, n_time=5).u.shape == (0, 5)


def test_invalid_inputs_raise_with_names():
    with pytest.raises(ValueError, match="e_y"):
        stronge_ex(0.3, ContactParams(4.75, 1.2, 0.5))
    with pytest.raises(ValueError, match="psi"):
        stronge_ex(np.pi / 2, ContactParams(4.75, 0.5, 0.5))
    with pytest.raises(ValueError, match="eta2"):
        stronge_solve(0.3, ContactParams(-1.0, 0.5, 0.5))


# ------------------------------------------------------------------------------------------
# published statements, Sec. V.A
# ------------------------------------------------------------------------------------------
def test_superball_ex_is_one():
    """Paper, Sec. V.A: superball, eta^2 = 3.5 and e_y = 1, initial stick -> e_x = 1."""
    psi = np.array([0.0, 5.0, 20.0, 40.0, 60.0]) * DEG
    sol = stronge_solve(psi, ContactParams(3.5, 1.0, 0.5))  # tan 60 deg = 1.73 < mu eta2 = 1.75
    np.testing.assert_allclose(sol.e_x, 1.0, atol=1e-12)
    assert set(sol.regime) == {"stick"}
    assert omega_ratio(3.5) == pytest.approx(1.0, abs=1e-15)
    # the tangential spring is back at equilibrium at separation
    h = stronge_solve(30 * DEG, ContactParams(3.5, 1.0, 0.5), histories=True, n_time=401)
    assert h.stretch[-1] == pytest.approx(0.0, abs=1e-12)
    assert h.u[-1] == pytest.approx(-np.tan(30 * DEG), abs=1e-12)
    # paper: "the initial kinetic energy is completely conserved"
    np.testing.assert_allclose(h.energy, 1.0, atol=1e-12)


@pytest.mark.parametrize("r", [(0.0, 0.0), (0.29, 0.27), (0.41, 0.38)])
def test_initial_stick_iff_tan_psi_below_mu_eta2(r):
    """Paper, Sec. V.A: the initial state is stick exactly when tan(psi) < mu eta^2."""
    rng = np.random.default_rng(7)
    eta2 = rng.uniform(2, 10, 50)
    mu = rng.uniform(0.05, 0.3, 50)  # keeps psi_stick below 90 deg
    e_y = rng.uniform(0.3, 1, 50)
    psi_b = np.arctan(mu * eta2)
    below = stronge_solve(psi_b * (1 - 1e-9), ContactParams(eta2, e_y, mu, *r))
    above = stronge_solve(psi_b * (1 + 1e-9), ContactParams(eta2, e_y, mu, *r))
    assert all(str(g).startswith("stick") for g in below.regime)
    assert all(str(g).startswith("slip") or g == "gross-slip" for g in above.regime)
    assert np.all(np.isfinite(below.t_stick_end) | (below.regime == "stick"))
    # e_x is continuous across the boundary
    np.testing.assert_allclose(below.e_x, above.e_x, atol=1e-6)


def test_contact_params_are_one_argument():
    """ContactParams broadcast like separate arguments; scalars() refuses arrays; omega_ratio agrees."""
    c = ContactParams(np.array([4.0, 5.0]), 0.5, np.array([[0.3], [0.5]]), 0.29, 0.27)
    arrays = c.broadcast(0.2)
    assert [a.shape for a in arrays] == [(2, 2)] * 7
    _, eta2, _, mu, _, _, alpha = arrays
    assert mu[1, 0] == 0.5 and eta2[1, 0] == 4.0 and alpha[0, 0] == 0.4
    ex = stronge_ex(0.2, c)
    assert ex[1, 0] == stronge_ex(0.2, ContactParams(4.0, 0.5, 0.5, 0.29, 0.27))
    assert c.omega_ratio() == pytest.approx(omega_ratio(np.array([4.0, 5.0]), 0.29, 0.27))
    assert ContactParams(np.float64(4.75), 0.5, 0.5).scalars() == ContactParams(4.75, 0.5, 0.5)
    with pytest.raises(TypeError):
        c.scalars()
    with pytest.raises(TypeError):
        regime_boundaries(c)


def test_omega_ratio_published():
    """Paper, Sec. V.A: Omega_t/Omega_n = 0.86 (eta^2 4.75) and 0.75 (6.30), given to 2 decimals."""
    assert omega_ratio(4.75) == pytest.approx(0.86, abs=0.005)
    assert omega_ratio(6.30) == pytest.approx(0.75, abs=0.005)
    # the paper's numbers are the rigid-surface formula sqrt(3.5/eta^2); in the bat frame
    # (wood bat) the ratio is 0.865 / 0.753
    assert omega_ratio(4.75) == pytest.approx(np.sqrt(3.5 / 4.75), rel=1e-15)


@pytest.mark.parametrize("ball,t_smax", [("baseball", 1.16), ("softball", 1.33)])
def test_fig10_timeline_bat_frame(ball, t_smax, wood):
    """Paper, Fig. 10 and Sec. V.A text at psi = 30 deg, e_y = mu = 0.5.

    "In the frame ... in which the ball is incident ... on a bat at rest": the bat recoils, so
    this is the bat frame (r_x, r_y of the wood bat, Table II). Published: stick until about
    1.4 t_c, separation at 1.5 t_c, stretch maximal at 1.16 t_c (baseball), 1.33 t_c
    (softball); the latter two are given to 2 decimals (tolerance 0.005).
    """
    r_x, r_y = wood[ball]
    sol = stronge_solve(30 * DEG, ContactParams(ETA2[ball], 0.5, 0.5, r_x, r_y), histories=True, n_time=3001)
    assert sol.regime == "stick-slip"
    assert sol.t_stick_end == pytest.approx(1.4, abs=0.03)  # "about 1.4" (1.415 / 1.422)
    assert sol.t_separation == pytest.approx(1.5, abs=1e-12)
    assert sol.t_stretch_max == pytest.approx(t_smax, abs=0.005)
    assert sol.t_stretch_max == pytest.approx(1 / sol.omega_ratio, rel=1e-9)  # stretch ~ sin(Omega_t t)
    # the sampled histories agree with the analytic maximum
    k = np.nanargmax(sol.stretch)
    assert sol.t[k] == pytest.approx(sol.t_stretch_max, abs=1e-3)
    # "over the period of stick, the transverse speed is proportional to cos(Omega_t t)"
    stick = sol.t < sol.t_stick_end
    expect = np.tan(30 * DEG) * np.cos(sol.omega_ratio * np.pi / 2 * sol.t[stick])
    np.testing.assert_allclose(sol.u[stick], expect, atol=1e-12)
    np.testing.assert_allclose(sol.c_velocity[stick], 0.0, atol=1e-12)
    # after the transition "the transverse force drops rapidly to zero": F = mu N -> 0
    slip = (sol.t > sol.t_stick_end) & (sol.t <= sol.t_separation)
    np.testing.assert_allclose(sol.tangential_force[slip], 0.5 * sol.normal_force[slip], atol=1e-12)
    assert sol.normal_force[sol.t <= 1.5][-1] == pytest.approx(0.0, abs=1e-12)
    assert np.nanmax(sol.normal_force) == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("ball,t_smax", [("baseball", 1.16), ("softball", 1.33)])
def test_fig10_timeline_rigid_frame_is_not_the_papers(ball, t_smax):
    """MODEL: on a rigid surface the stretch peaks at 1/Omega_t-ratio = 1.165 / 1.342 t_c.

    The softball's 1.342 misses the published 1.33 by more than the rounding; the bat frame
    (previous test) gives 1.156 / 1.328 and matches both. So Fig. 10 is the bat frame.
    """
    sol = stronge_solve(30 * DEG, ContactParams(ETA2[ball], 0.5, 0.5))
    assert sol.t_stick_end == pytest.approx(1.4, abs=0.03)
    assert sol.t_stretch_max == pytest.approx(1 / np.sqrt(3.5 / ETA2[ball]), rel=1e-9)
    if ball == "softball":
        assert abs(sol.t_stretch_max - t_smax) > 0.01


def test_energy_never_increases():
    """Kinetic + spring energy is non-increasing; |e_x| <= 1 (any frame, any regime)."""
    rng = np.random.default_rng(11)
    n = 300
    psi, eta2 = rng.uniform(0, 85, n) * DEG, rng.uniform(0.5, 10, n)
    e_y, mu = rng.uniform(0.3, 1, n), rng.uniform(0.05, 1.5, n)
    r_x, r_y = rng.uniform(0, 0.5, n), rng.uniform(0, 0.5, n)
    sol = stronge_solve(psi, ContactParams(eta2, e_y, mu, r_x, r_y), histories=True, n_time=801)
    E = sol.energy
    assert np.all(np.isfinite(E[:, 0]))
    np.testing.assert_allclose(E[:, 0], 1.0, atol=1e-14)
    dE = np.diff(E, axis=1)
    assert np.nanmax(dE) < 1e-12
    assert np.all(sol.e_x <= 1 + 1e-12) and np.all(sol.e_x >= -1 - 1e-12)
    # energy lost = the normal loss (1 - e_y^2 of the normal part) + friction >= 0
    assert np.all(np.isnan(E[:, -1]) | (E[:, -1] <= 1))


def test_small_psi_insensitive_to_mu():
    """Paper, Sec. V.A: "for small psi, the final speed is insensitive to the size of mu, as
    long as the initial stick criterion is satisfied". Model: over mu = 0.3..1 (all initial
    stick) e_x spreads by <= 0.02 at psi <= 10 deg, but by 0.065 at psi = 30 deg.
    """
    mu = np.linspace(0.3, 1.0, 15)
    for psi in (2.0, 5.0, 10.0):
        ex = stronge_ex(psi * DEG, ContactParams(4.75, 0.5, mu))
        assert np.ptp(ex) < 0.02
    assert np.ptp(stronge_ex(30 * DEG, ContactParams(4.75, 0.5, mu))) == pytest.approx(0.065, abs=0.005)


def test_ex_sensitive_to_e_y_at_fixed_eta2(wood):
    """ERRATA-like: the paper says the results are "insensitive to" e_y and mu over the
    experiment's psi. MODEL: at fixed eta2, e_y 0.4 -> 0.6 moves e_x(psi=10 deg) from
    0.30 to 0.54 (baseball, rigid); only after refitting eta2 (4.15 / 5.39) do the curves
    agree (tested in test_fit_absorbs_e_y).
    """
    ex = stronge_ex(10 * DEG, ContactParams(4.75, np.array([0.4, 0.5, 0.6]), 0.5))
    np.testing.assert_allclose(ex, [0.298, 0.421, 0.538], atol=0.002)


def test_curves_linear_then_flat_after_gross_slip(wood):
    """Paper, Sec. V.A / Fig. 9b: (v_t + r omega)/v_bat,n against tan psi/(1 + r_x) is "quite
    linear over a broad range of psi" and "eventually flatten[s] after the transition to
    gross slip". MODEL: in gross slip the ordinate is exactly constant,
    rho^2 mu eta2 (1 + e_y)/(1 + r_x).
    """
    for ball in ("baseball", "softball"):
        r_x, r_y = wood[ball]
        psi = np.linspace(0, 88, 881) * DEG
        ex = stronge_ex(psi, ContactParams(ETA2[ball], 0.5, 0.5, r_x, r_y))
        x = np.tan(psi) / (1 + r_x)
        y = (1 + ex) * x
        gross = np.tan(psi) >= 0.5 * ETA2[ball]
        rho = omega_ratio(ETA2[ball], r_x, r_y)
        np.testing.assert_allclose(y[gross], rho**2 * 0.5 * ETA2[ball] * 1.5 / (1 + r_x), rtol=1e-12)
        # linear: the local slope 1 + e_x stays within 10 % over psi <= 45 deg
        lin = psi <= 45 * DEG
        slope = 1 + ex[lin]
        assert np.ptp(slope) / slope.mean() < 0.10 if ball == "baseball" else np.ptp(slope) / slope.mean() < 0.15
        # y keeps rising until gross slip, then stays flat
        assert np.all(np.diff(y[~gross]) > 0)


@pytest.mark.parametrize("ball,published", [("baseball", 0.405), ("softball", 0.146)])
def test_ex_over_experiment_range(ball, published, balls, bats):
    """Paper, Secs. IV and V.A: at the fitted eta2 the model is "consistent with the constant
    value of e_x" (0.405 +- 0.010 baseball, 0.146 +- 0.009 softball, Eq. ex). MODEL (bat
    frame, each bat of Table II, psi from 0 to psi_max of Table I): e_x falls slowly with psi;
    its mean is within 0.05 of the published value and its spread below 0.08.
    """
    psi = np.linspace(0, balls[ball].psi_max, 61)
    means = []
    for bat in bats.values():
        r_x, r_y = recoil_factors(balls[ball], bat)
        ex = stronge_ex(psi, ContactParams(ETA2[ball], 0.5, 0.5, r_x, r_y))
        assert np.ptp(ex) < 0.08
        assert np.all(np.diff(ex) <= 1e-12)
        assert set(stronge_solve(psi[1:], ContactParams(ETA2[ball], 0.5, 0.5, r_x, r_y)).regime) == {"stick-slip"}
        means.append(ex.mean())
    assert np.mean(means) == pytest.approx(published, abs=0.05)


def test_histories_layout():
    sol = stronge_solve(
        np.array([10.0, 30.0]) * DEG, ContactParams(4.75, np.array([0.5, 0.8]), 0.5), histories=True, n_time=181
    )
    assert sol.t.shape == (181,) and sol.t[-1] == pytest.approx(1.8)
    for a in (sol.normal_force, sol.tangential_force, sol.stretch, sol.c_velocity, sol.u, sol.energy):
        assert a.shape == (2, 181)
    assert np.all(np.isnan(sol.u[0, sol.t > 1.5 + 1e-9]))
    assert np.all(np.isfinite(sol.u[1]))
    assert sol.u[1, -1] == pytest.approx(-sol.e_x[1] * np.tan(30 * DEG), abs=1e-12)
    assert stronge_solve(0.3, ContactParams(4.75, 0.5, 0.5)).t is None


def test_histories_common_grid():
    """t_max puts impacts solved apart on one grid; a grid ending before separation is refused."""
    sol = stronge_solve(30.0 * DEG, ContactParams(4.75, 0.5, 0.5), histories=True, n_time=181, t_max=1.8)
    assert sol.t[-1] == 1.8 and np.all(np.isnan(sol.u[sol.t > 1.5 + 1e-9]))
    same = stronge_solve(30.0 * DEG, ContactParams(4.75, 0.5, 0.5), histories=True, n_time=181, t_max=1.5)
    default = stronge_solve(30.0 * DEG, ContactParams(4.75, 0.5, 0.5), histories=True, n_time=181)
    assert np.array_equal(same.t, default.t) and np.array_equal(same.u, default.u, equal_nan=True)
    with pytest.raises(ValueError, match="ends before separation"):
        stronge_solve(30.0 * DEG, ContactParams(4.75, 0.8, 0.5), histories=True, t_max=1.5)


def test_import_is_light():
    """Importing the model and the fit module does not import lmfit or matplotlib."""
    code = (
        "import sys, ballbat.stronge, ballbat.stronge.fit; "
        "bad = [m for m in ('lmfit', 'matplotlib') if m in sys.modules]; "
        "assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


NAMES = ("eta2", "e_y", "mu")


def test_jacobian_rows_equal_one_call_per_point(data):
    def residual(eta2, e_y, mu):
        ex = stronge_ex(data.psi, ContactParams(eta2, e_y, mu, data.r_x, data.r_y, data.alpha))
        return (data.y - (1.0 + ex) * data.x) / data.sigma

    at = {"eta2": 4.9, "e_y": 0.5, "mu": 0.5}
    J, r = _jacobian(residual, at, list(NAMES))
    assert J.shape == (data.psi.size, 3)
    np.testing.assert_allclose(r, residual(4.9, 0.5, 0.5), rtol=1e-13, atol=1e-15)
    for i, k in enumerate(NAMES):
        h = 1e-6 * max(abs(at[k]), 1e-3)
        up, down = ({**at, k: at[k] + s} for s in (h, -h))
        col = (residual(*up.values()) - residual(*down.values())) / (2 * h)
        np.testing.assert_allclose(J[:, i], col, rtol=1e-8, atol=1e-6 * np.max(np.abs(col)))
        assert np.max(np.abs(J[:, i])) > 0.0


def _hard_batch(n, seed=7):
    """Impacts with Omega_t > Omega_n (eta2 < 3.5): the phase machine, not the fast path."""
    rng = np.random.default_rng(seed)
    psi = rng.uniform(0.05, 1.2, n)
    eta2 = rng.uniform(0.5, 3.4, n)
    r_x, r_y = rng.uniform(0, 0.5, n), rng.uniform(0, 0.5, n)
    return psi, ContactParams(eta2, 0.5, rng.uniform(0.1, 1.0, n), r_x, r_y)


def test_impact_geometry_is_stronge_ex():
    """ImpactGeometry(psi, r_x, r_y, alpha).e_x(eta2, e_y, mu) is stronge_ex's numbers, bit for bit, in any
    broadcast (a scan of eta2 against the impacts, one value, one per impact), and it names bad inputs.
    """
    from ballbat.stronge.model import ImpactGeometry

    psi, c = _hard_batch(40)
    geometry = ImpactGeometry(psi, c.r_x, c.r_y, c.alpha)
    for eta2, mu in ((np.geomspace(1, 30, 48)[:, None], 0.5), (4.75, 0.5), (c.eta2, c.mu)):
        want = stronge_ex(psi, ContactParams(eta2, 0.5, mu, c.r_x, c.r_y, c.alpha))
        np.testing.assert_array_equal(geometry.e_x(eta2, 0.5, mu), want)
    with pytest.raises(ValueError, match="psi must satisfy"):
        ImpactGeometry(np.array([0.1, 2.0]))
    with pytest.raises(ValueError, match="r_y must satisfy"):
        ImpactGeometry(psi, 0.1, -1.5)
    with pytest.raises(ValueError, match="eta2 must satisfy"):
        geometry.e_x(np.array([[4.0], [-1.0]]), 0.5, 0.5)
    with pytest.raises(ValueError, match="e_y must satisfy"):
        geometry.e_x(4.0, 1.5, 0.5)


def test_phase_machine_is_the_same_in_blocks_and_without_records(monkeypatch):
    """The stick grids sampled in blocks of GRID_BLOCK impacts, N computed once per shared grid row, the
    first stick of a batch with Omega_t >= Omega_n not sampled (it cannot end while loading) and the engine
    run without its piece records (stronge_ex's way) give the numbers of one block, every grid sampled,
    with every record, bit for bit.
    """
    from ballbat.stronge import model

    psi, c = _hard_batch(700)
    psi[:5] = 0.0  # stick to separation
    scan = ContactParams(np.geomspace(1, 3.4, 12)[:, None], 0.5, 0.5, c.r_x[:60], c.r_y[:60])
    prepared = [model._prepare(psi, c), model._prepare(psi[:60], scan)]
    blocked = [model._engine(p, np.arange(p.rho.size), record=False).uf for p in prepared]
    assert model.GRID_BLOCK < psi.size
    monkeypatch.setattr(model, "GRID_BLOCK", 10**6)
    monkeypatch.setattr(model, "_stuck_through_loading", lambda piece, end: False)
    monkeypatch.setattr(
        model, "_normal_on_grid", lambda grid, e, thf, end: model._normal(grid, e[:, None], thf[:, None])[:2]
    )
    whole = [model._engine(p, np.arange(p.rho.size)) for p in prepared]
    for a, b in zip(blocked, whole, strict=True):
        np.testing.assert_array_equal(a, b.uf)
    assert whole[0].start.shape[1] > 1  # the records are there, and several pieces deep
