"""The eta^2 fit's derivatives from one stacked call of the model equal those from one call per point (issue 39).

:func:`ballbat.stronge.fit._jacobian`, :func:`ballbat.stronge.analysis.eiv_step` and
:func:`ballbat.stronge.analysis.finite_sample_bias` evaluate every point they difference in a
single call of :func:`ballbat.stronge.model.stronge_ex`. The references below are the
per-point code they replaced; the results must agree to round-off.
"""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.stronge.analysis import VtfData, eiv_step, finite_sample_bias
from ballbat.stronge.model import ContactParams, stronge_ex

NAMES = ("eta2", "e_y", "mu")


def _ex(d: VtfData, at: dict[str, float], dpsi: float = 0.0, **shift: float) -> np.ndarray:
    p = {k: at[k] + shift.get(k, 0.0) for k in NAMES}
    return stronge_ex(d.psi + dpsi, ContactParams(p["eta2"], p["e_y"], p["mu"], d.r_x, d.r_y, d.alpha))


def _eiv_step_per_point(d: VtfData, w, at, names, hp=1e-5, hk=1e-4):
    """eiv_step as it was: one call of the model per point."""
    nz = d.noise
    dpsi = nz.jx * (np.cos(d.psi) ** 2 * (1.0 + d.r_x))[:, None]
    e_psi = (_ex(d, at, hp) - _ex(d, at, -hp)) / (2 * hp)
    dr = (nz.jy - (1 + _ex(d, at))[:, None] * nz.jx - (e_psi * d.x)[:, None] * dpsi) / w[:, None]
    J, c = [], []
    for k in names:
        h = hk * max(abs(at[k]), 1e-3)
        e_k = (_ex(d, at, **{k: h}) - _ex(d, at, **{k: -h})) / (2 * h)
        up, down = (
            (_ex(d, at, hp, **{k: h}) - _ex(d, at, -hp, **{k: h})),
            (_ex(d, at, hp, **{k: -h}) - _ex(d, at, -hp, **{k: -h})),
        )
        e_k_psi = (up - down) / (4 * hp * h)
        dr_k = -((e_k_psi * d.x)[:, None] * dpsi + e_k[:, None] * nz.jx) / w[:, None]
        J.append(-e_k * d.x / w)
        c.append(np.sum(dr * dr_k * nz.sigma**2))
    J = np.stack(J, axis=1)
    return np.linalg.solve(J.T @ J, np.asarray(c))


@pytest.mark.parametrize("names", [["eta2"], ["eta2", "mu"], ["eta2", "e_y", "mu"]])
def test_eiv_step_equals_the_per_point_step(data, names):
    at = {"eta2": 5.3, "e_y": 0.55, "mu": 0.45}
    stacked = eiv_step(data, data.sigma, at, names)
    per_point = _eiv_step_per_point(data, data.sigma, at, names)
    assert np.all(stacked != 0.0)
    np.testing.assert_allclose(stacked, per_point, rtol=1e-9, atol=0.0)


def _row_by_row(psi, contact):
    """stronge_ex called once per row of a stacked (m, n) call, as the code did before stacking."""
    args = np.broadcast_arrays(np.asarray(psi, dtype=float), *(np.asarray(a, dtype=float) for a in contact.values()))
    if args[0].ndim < 2:
        return stronge_ex(psi, contact)
    return np.stack([stronge_ex(a[0], ContactParams(*a[1:])) for a in zip(*args, strict=True)])


def test_finite_sample_bias_equals_the_per_point_bias(data, monkeypatch):
    from ballbat.stronge import analysis

    at = {"eta2": 5.3, "e_y": 0.5, "mu": 0.5}
    stacked = finite_sample_bias(data, data.sigma, at)
    monkeypatch.setattr(analysis, "stronge_ex", _row_by_row)
    per_point = finite_sample_bias(data, data.sigma, at)
    assert np.isfinite(stacked) and stacked != 0.0
    assert stacked == pytest.approx(per_point, rel=1e-9)
