"""The single-frame glitch test's loops, compiled with numba (issue 39's speed).

:func:`ballbat.tracks.checks.glitch_mask` compares each point with the midpoint of its
neighbours and with the straight-line extrapolations from either side; in numpy that is some
forty whole-array operations (shifted copies, products, masks) and a sort of every track's
offsets for its robust noise, for each of the five points of both cameras. Here each track is
one pass of plain loops (:func:`midpoint_offsets`, :func:`track_noise`, :func:`glitches`): the
same arithmetic in the same order on the same values, and the medians of the same values
(numba's selection, the mean of the middle two as numpy takes it), so the flags are numpy's
(``tests/tracks/test_checks.py`` compares them on random tracks). 108 impacts of 120 frames:
0.86 -> 0.63 ms a point (the medians are most of what is left). The numpy code stays the
reference (``checks.GLITCH_COMPILED = False``).

Compiled once per machine (``cache=True``: kept in ``__pycache__`` beside this file or in
``NUMBA_CACHE_DIR``); imported where tracks are checked, never when the Snakefile is read.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")

#: The robust standard deviation's factor of the median absolute value (1.4826 MAD).
MAD = 1.4826

#: Fewest finite offset components for a track's own noise (fewer: the pooled noise alone).
OWN_NOISE_VALUES = 10


@_jit
def midpoint_offsets(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return each point's offset from the midpoint of its neighbours (rx, ry), NaN without two (``checks``')."""
    n, m = x.shape
    rx = np.full((n, m), np.nan)
    ry = np.full((n, m), np.nan)
    for i in range(n):
        for k in range(1, m - 1):
            rx[i, k] = x[i, k] - 0.5 * (x[i, k - 1] + x[i, k + 1])
            ry[i, k] = y[i, k] - 0.5 * (y[i, k - 1] + y[i, k + 1])
    return rx, ry


@_jit
def pooled_mad(rx: np.ndarray, ry: np.ndarray) -> float:
    """Return 1.4826 times the median |component| of every finite offset (NaN where there is none)."""
    v = np.empty(rx.size + ry.size)
    k = 0
    for a in (rx, ry):
        flat = a.ravel()
        for j in range(flat.size):
            if np.isfinite(flat[j]):
                v[k] = abs(flat[j])
                k += 1
    if k == 0:
        return np.nan
    return MAD * np.median(v[:k])


@_jit
def track_noise(rx: np.ndarray, ry: np.ndarray, pooled: float) -> np.ndarray:
    """Return each track's noise: 1.4826 MAD of its offsets' components where it has 10, at least ``pooled``."""
    n, m = rx.shape
    sd = np.empty(n)
    v = np.empty(2 * m)
    for i in range(n):
        k = finite = 0
        for a in (rx, ry):
            for j in range(m):
                if not np.isnan(a[i, j]):  # the median is of every value but NaN (batched.nanmedian_rows)
                    v[k] = abs(a[i, j])
                    k += 1
                    finite += np.isfinite(a[i, j])
        med = np.median(v[:k]) if finite >= OWN_NOISE_VALUES else 0.0
        sd[i] = max(MAD * med, pooled)
    return sd


@_jit
def _nan_to_num(v: float) -> float:
    """numpy.nan_to_num of one value: NaN 0, +inf the largest double (a distance is not negative)."""
    if np.isnan(v):
        return 0.0
    return 1.7976931348623157e308 if v == np.inf else v


@_jit
def _bends_back(x, y, i, k, d, rx, ry, rn) -> bool:
    """Whether the line through the two frames on side ``d`` (-1 before, +1 after) misses with r, past |r|/2."""
    m = x.shape[1]
    if k + 2 * d < 0 or k + 2 * d >= m:
        return False
    lx = x[i, k] - 2 * x[i, k + d] + x[i, k + 2 * d]
    ly = y[i, k] - 2 * y[i, k + d] + y[i, k + 2 * d]
    if not (np.isfinite(lx) and np.isfinite(ly)):
        return False
    return (lx * rx + ly * ry) / rn > 0.5 * rn


@_jit
def glitches(x, y, rx, ry, sd, z, skip, has_skip) -> np.ndarray:
    """Return the flags (impact, column) of :func:`ballbat.tracks.checks.glitch_mask` from the offsets and noise."""
    n, m = x.shape
    out = np.zeros((n, m), dtype=np.bool_)
    rn = np.empty(m)
    for i in range(n):
        for k in range(m):
            rn[k] = math.hypot(rx[i, k], ry[i, k])
        limit = z * sd[i]
        for k in range(m):
            r = rn[k]
            if not (r > limit) or (has_skip and skip[i, k]):
                continue
            if not (np.isfinite(x[i, k]) and np.isfinite(y[i, k])):
                continue
            before = _nan_to_num(rn[k - 1]) if k > 0 else 0.0
            after = _nan_to_num(rn[k + 1]) if k + 1 < m else 0.0
            if not (r >= before and r >= after):  # a glitch's neighbours stick out by half as much
                continue
            if _bends_back(x, y, i, k, -1, rx[i, k], ry[i, k], r) and _bends_back(x, y, i, k, 1, rx[i, k], ry[i, k], r):
                out[i, k] = True
    return out
