"""A body in free flight filmed: its acceleration from tracked centres (docs/video.md, "A real clip").

The tracked positions along one image axis, ``y(t) = y0 + v0 t + a t^2 / 2``, are fitted by
weighted least squares in pixels; the acceleration's standard error comes from the
residual scatter about the parabola (the weights are relative: their scale is the scatter's).
The scale (metres per pixel) and the frame interval are known to within their own errors,
which move every point of the clip together: each is a systematic error of ``a``, carried
beside the statistical one and combined with it in quadrature (``a`` scales as the metres per
pixel, and as the inverse square of the frame interval).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class FallFit:
    """The fitted parabola: ``a`` (m/s^2, along the axis's direction) and its errors; y0, v0 at t = 0."""

    a: float
    se_stat: float  # from the residual scatter (m/s^2)
    se_scale: float  # from the scale's error (m/s^2)
    se_time: float  # from the frame interval's error (m/s^2)
    y0_px: float
    v0_px_s: float
    a_px_s2: float  # the acceleration in the image (px/s^2), before the scale
    rms_px: float  # the residuals' root mean square (px), unweighted
    n: int

    @property
    def se(self) -> float:
        """Return the combined standard error (m/s^2): the statistical and the systematic ones in quadrature."""
        return float(np.sqrt(self.se_stat**2 + self.se_scale**2 + self.se_time**2))

    def z(self, g: float, g_err: float = 0.0) -> float:
        """Return (a - g) over the combined error of both (``g_err``: the reference's own standard error)."""
        return float((self.a - g) / np.hypot(self.se, g_err))

    def residuals_px(self, t_s: np.ndarray, y_px: np.ndarray) -> np.ndarray:
        """Return the points' offsets from the fitted parabola (px)."""
        t = np.asarray(t_s, float)
        return np.asarray(y_px, float) - (self.y0_px + self.v0_px_s * t + 0.5 * self.a_px_s2 * t * t)


def fit_fall(
    t_s: ArrayLike,
    y_px: ArrayLike,
    m_per_px: float,
    *,
    m_per_px_err: float = 0.0,
    dt_rel_err: float = 0.0,
    sigma_px: ArrayLike | None = None,
) -> FallFit:
    """Fit y(t) = y0 + v0 t + a t^2 / 2 to tracked positions (px) at times ``t_s`` (s); ``a`` in m/s^2.

    ``sigma_px``: each point's relative uncertainty (weights 1 / sigma^2; their scale is set by
    the residual scatter), equal when not given. ``m_per_px_err`` is the scale's standard error
    (m/px), ``dt_rel_err`` the frame interval's relative one: systematic errors of ``a``
    (``se_scale = |a| m_per_px_err / m_per_px``, ``se_time = 2 |a| dt_rel_err``). At least 4
    points (one degree of freedom for the scatter); bad input is a ValueError saying which.
    """
    t, y = np.asarray(t_s, float).ravel(), np.asarray(y_px, float).ravel()
    s = np.ones_like(y) if sigma_px is None else np.broadcast_to(np.asarray(sigma_px, float), y.shape)
    _check_fall_input(t, y, s, m_per_px, m_per_px_err, dt_rel_err)
    tc = t.mean()  # centred: a well-conditioned design
    design = np.column_stack([np.ones_like(t), t - tc, 0.5 * (t - tc) ** 2]) / s[:, None]
    coef, *_ = np.linalg.lstsq(design, y / s, rcond=None)
    res = y - (design * s[:, None]) @ coef
    chi2 = float(np.sum((res / s) ** 2))
    cov = np.linalg.inv(design.T @ design) * chi2 / (t.size - 3)
    c, b, a_px = coef
    a = float(a_px * m_per_px)
    return FallFit(
        a=a,
        se_stat=float(np.sqrt(cov[2, 2]) * m_per_px),
        se_scale=abs(a) * m_per_px_err / m_per_px,
        se_time=2 * abs(a) * dt_rel_err,
        y0_px=float(c - b * tc + 0.5 * a_px * tc * tc),
        v0_px_s=float(b - a_px * tc),
        a_px_s2=float(a_px),
        rms_px=float(np.sqrt(np.mean(res**2))),
        n=int(t.size),
    )


def _check_fall_input(t, y, s, m_per_px, m_per_px_err, dt_rel_err) -> None:
    if t.shape != y.shape:
        raise ValueError(f"fit_fall: {t.size} times but {y.size} positions")
    if t.size < 4:
        raise ValueError(f"fit_fall: {t.size} points; at least 4 are needed (3 parameters and the scatter)")
    for name, v in (("t_s", t), ("y_px", y), ("sigma_px", s)):
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise ValueError(f"fit_fall: {name} has a non-finite value at index {int(bad[0])}")
    if np.any(s <= 0):
        raise ValueError(f"fit_fall: sigma_px must be positive (index {int(np.flatnonzero(s <= 0)[0])})")
    if np.unique(t).size < 3:
        raise ValueError("fit_fall: fewer than 3 distinct times")
    if not m_per_px > 0 or not m_per_px_err >= 0 or not dt_rel_err >= 0:
        raise ValueError(
            f"fit_fall: m_per_px must be positive, its error and dt_rel_err not negative "
            f"(got {m_per_px}, {m_per_px_err}, {dt_rel_err})"
        )


@dataclass(frozen=True)
class MarkAgreement:
    """Tracked centres against hand marks of the same clip, frame by frame (px): tracked minus marked."""

    frames: np.ndarray
    dx: np.ndarray
    dy: np.ndarray

    @property
    def offset(self) -> tuple[float, float]:
        """Return the mean difference (x, y): a constant one is where each method puts the centre, not noise."""
        return float(self.dx.mean()), float(self.dy.mean())

    @property
    def rms(self) -> tuple[float, float]:
        """Return the differences' root mean square about their mean (x, y)."""
        return float(self.dx.std()), float(self.dy.std())


def mark_agreement(
    tracked: tuple[ArrayLike, ArrayLike, ArrayLike],
    marks: tuple[ArrayLike, ArrayLike, ArrayLike],
    pixel_shift: float = 0.0,
) -> MarkAgreement:
    """Return the differences of tracked centres and hand marks in the frames both have.

    ``tracked`` and ``marks`` are (frames, x, y) arrays; ``pixel_shift`` is added to the tracked
    coordinates first: a tool whose pixel i spans [i, i + 1) (Tracker, Java's images) puts a pixel's
    centre at i + 0.5 where ballbat puts it at i, so 0.5 for Tracker's marks. Fewer than 2
    frames in common is a ValueError.
    """
    ft, xt, yt = (np.asarray(v) for v in tracked)
    fm, xm, ym = (np.asarray(v) for v in marks)
    common, it, im = np.intersect1d(ft, fm, return_indices=True)
    if common.size < 2:
        raise ValueError(f"mark_agreement: {common.size} frames in common (tracked {ft.size}, marked {fm.size})")
    return MarkAgreement(common, xt[it] + pixel_shift - xm[im], yt[it] + pixel_shift - ym[im])
