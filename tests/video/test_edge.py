"""The ball's edge fit (ballbat.video.edge; issue 38's speed, docs/video.md) against the slow ways it replaced."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.video.edge import _CAND, _SAMPLES, _circle_fit, edge_bases


def _residual_makers(radius: float, blur: float) -> np.ndarray:
    """I - D pinv(D) of the ray model at each tried edge, built term by term (np.convolve, np.interp)."""
    fine = np.arange(-9.0, 9.0, 0.05)
    box = np.ones(20) / 20
    kern = np.convolve(box, np.convolve(box, box))
    if blur >= 0.5:
        kern = np.convolve(kern, np.ones(round(blur / 0.05)))
    kern /= kern.sum()
    out = []
    for e in _CAND:
        inside = fine < e
        rho = (radius + fine) / (radius + e)
        basis = [np.ones_like(fine), np.where(inside, 0.0, fine - e), inside * 1.0]
        basis += [np.sqrt(np.clip(1 - rho * rho, 0, None)), inside * rho]
        d = np.column_stack([np.interp(_SAMPLES, fine, np.convolve(b, kern, mode="same")) for b in basis])
        out.append(np.eye(_SAMPLES.size) - d @ np.linalg.pinv(d))
    return np.array(out)


@pytest.mark.parametrize(("radius", "blur"), [(14.5, 0.0), (24.5, 1.5), (49.5, 3.0)])
def test_edge_bases_give_the_pseudo_inverse_residual_of_every_tried_edge(radius, blur):
    y = np.random.default_rng(1).normal(100, 30, (48, _SAMPLES.size))
    y -= y.mean(axis=1, keepdims=True)
    p = y @ edge_bases(radius, blur)
    fast = (y * y).sum(axis=1)[:, None] - (p * p).reshape(48, _CAND.size, 5).sum(axis=2)
    slow = np.einsum("ij,ejk,ik->ie", y, _residual_makers(radius, blur), y)
    np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-6 * slow.max())


def test_circle_fit_recovers_a_circle():
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    cx, cy, r = _circle_fit(512.3 + 30.7 * np.cos(a), 201.9 + 30.7 * np.sin(a))
    assert (cx, cy, r) == pytest.approx((512.3, 201.9, 30.7), abs=1e-9)
