"""The compiled fast path of Stronge's model (rho <= 1) against the numpy one."""

from __future__ import annotations

import numpy as np

from ballbat.stronge import model
from ballbat.stronge.model import ContactParams, ImpactGeometry, stronge_ex
from ballbat.stronge.soft_kernel import uf_soft


def _soft_impacts(rng, n):
    """Impacts on the fast path: every case (gross slip, stick ending loading or unloading, stick to separation)."""
    psi = rng.uniform(-1.4, 1.4, n)
    psi[::17] = 0.0  # stick to separation
    psi[1::23] = rng.choice([1e-9, -1e-7, 1e-5], psi[1::23].size)  # stick ending just before separation
    geo = ImpactGeometry(psi, rng.uniform(0, 0.2, n), rng.uniform(0, 0.1, n), rng.uniform(0.3, 0.7, n))
    eta2 = rng.uniform(1.0, 40.0, n)
    eta2[5::29] = 3.5  # rho = 1 on a rigid surface with alpha = 0.4 (the superball) where r_x = r_y = 0
    p = geo.params(eta2, rng.uniform(0.05, 1.0, n), rng.choice([0.0, 0.05, 0.3, 0.5, 2.0, 10.0], n))
    soft = p.rho <= 1.0
    return p.rho[soft], p.Lam[soft], p.e[soft], p.thf[soft]


def test_the_compiled_fast_path_is_numpy_s_to_round_off():
    """20 000 impacts of every fast-path case: the final U agrees with numpy's within 1e-13."""
    rho, Lam, e, thf = _soft_impacts(np.random.default_rng(3), 40_000)
    assert rho.size > 15_000
    want, got = model._uf_soft(rho, Lam, e, thf), uf_soft(rho, Lam, e, thf, model.NEWTON_TOL)
    assert np.array_equal(np.isfinite(want), np.isfinite(got)) and np.isfinite(want).all()
    assert np.max(np.abs(got - want)) < 1e-13
    # every case is there: gross slip, stick ending while loading, while unloading, and to separation
    gross = ~(Lam > 1)
    loading = ~gross & (np.sin(rho * np.pi / 2) / rho > Lam)
    assert gross.sum() > 100 and loading.sum() > 100 and (~gross & ~loading).sum() > 100


def test_e_x_is_the_same_either_way(monkeypatch):
    """stronge_ex on a mix of impacts on and off the fast path: compiled or not, the same to 1e-13."""
    rng = np.random.default_rng(4)
    psi = rng.uniform(-1.2, 1.2, 3000)
    c = ContactParams(rng.uniform(0.5, 30.0, 3000), 0.5, 0.5, 0.05, 0.02)
    got = stronge_ex(psi, c)
    monkeypatch.setattr(model, "COMPILED_SOFT", False)
    want = stronge_ex(psi, c)
    assert np.max(np.abs(got - want)) < 1e-13
    assert (c.omega_ratio() <= 1).sum() > 1000 and (c.omega_ratio() > 1).sum() > 200
