"""The ball's edge fit (ballbat.video.edge; issue 38's speed, docs/video.md) against the slow ways it replaced."""

from __future__ import annotations

import numpy as np
import pytest
from video_clips import still_balls

from ballbat.video.edge import _CAND, _SAMPLES, _TERMINATOR, N_TERMS, _circle_fit, edge_bases, fit_ball
from ballbat.video.render import _LIGHT


def _designs(radius: float, blur: float, terminator: float | None = None) -> list[np.ndarray]:
    """D of a ray model at each tried edge, built term by term (np.convolve, np.interp).

    The lit model, or the one past a terminator ``terminator`` px inside the edge (its term left out where the
    terminator is not 1 px inside the samples).
    """
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
        nz = np.sqrt(np.clip(1 - rho * rho, 0, None))
        if terminator is None:
            basis += [nz, inside * rho]
        elif e - terminator >= _SAMPLES[0] + 1:
            rt = 1 - terminator / (radius + e)
            basis.append(np.clip(nz - rho * np.sqrt(1 - rt * rt) / rt, 0, None))
        out.append(np.column_stack([np.interp(_SAMPLES, fine, np.convolve(b, kern, mode="same")) for b in basis]))
    return out


def _residual_makers(radius: float, blur: float, terminator: float | None = None) -> np.ndarray:
    """I - D pinv(D) of a ray model at each tried edge (:func:`_designs`)."""
    return np.array([np.eye(_SAMPLES.size) - d @ np.linalg.pinv(d) for d in _designs(radius, blur, terminator)])


@pytest.mark.parametrize(("radius", "blur"), [(14.5, 0.0), (24.5, 1.5), (49.5, 3.0)])
def test_edge_bases_give_the_pseudo_inverse_residual_of_every_tried_edge(radius, blur):
    y = np.random.default_rng(1).normal(100, 30, (48, _SAMPLES.size))
    y -= y.mean(axis=1, keepdims=True)
    p = y @ edge_bases(radius, blur)
    sq = (p * p).reshape(48, _CAND.size, N_TERMS)
    yy = (y * y).sum(axis=1)[:, None]
    fast = yy - sq[:, :, :5].sum(axis=2)
    slow = np.einsum("ij,ejk,ik->ie", y, _residual_makers(radius, blur), y)
    np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-6 * slow.max())
    for j, w in enumerate(_TERMINATOR):
        fast = yy - sq[:, :, :3].sum(axis=2) - sq[:, :, 6 + j]
        slow = np.einsum("ij,ejk,ik->ie", y, _residual_makers(radius, blur, w), y)
        np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-6 * slow.max())
    # the last column: the lit fit's coefficient of sqrt(1 - rho^2)
    coef = np.stack([np.linalg.lstsq(d, y.T, rcond=None)[0][3] for d in _designs(radius, blur)], axis=1)
    got = p.reshape(48, _CAND.size, N_TERMS)[:, :, 5]
    np.testing.assert_allclose(got, coef, rtol=1e-7, atol=1e-9 * np.abs(coef).max())


def test_circle_fit_recovers_a_circle():
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    cx, cy, r = _circle_fit(512.3 + 30.7 * np.cos(a), 201.9 + 30.7 * np.sin(a))
    assert (cx, cy, r) == pytest.approx((512.3, 201.9, 30.7), abs=1e-9)


@pytest.mark.parametrize("radius", [29.28, 49.46])
def test_a_ball_under_one_hard_light_is_not_pulled_towards_it(radius):
    """Noise-free frames of the spin (29 px) and swing (49 px) cameras' balls: the centre within 0.025 px of the truth
    along the light, on average over 24 places. The lit model alone (before the terminator models) put the 29-px ball
    0.030 px towards it (its rays past the terminator, on the dark side, 0.2 px in); now 0.011 px and 0.017 px the
    other way (29 and 49 px; 0.002 px before for the 49-px ball).
    """
    toward = _LIGHT[:2] / np.hypot(*_LIGHT[:2])
    errors = []
    for img, x, y in still_balls(radius, 24, seed=5):
        fit, why = fit_ball(img, x + 0.7, y - 0.5, radius, 0.008 * 65535)
        assert why is None
        errors.append((fit[0] - x, fit[1] - y))
    errors = np.array(errors)
    assert abs(errors.mean(axis=0) @ toward) < 0.025
    assert np.sqrt(np.mean((errors**2).sum(axis=1))) < 0.05
