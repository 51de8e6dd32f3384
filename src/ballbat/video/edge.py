"""The ball's sub-pixel edge and centre in one frame (docs/video.md, "The tracker").

The edge is found on 48 rays from a rough centre: first the peak of the radial gradient on a
wide window, until the circle moves by under a pixel; then a model of each ray's profile on a
±5 px window, fitted at 61 tried edge positions, until the circle moves by under 0.01 px.
A circle is fitted to the edge points by least squares, points off it by more than 3 robust
standard deviations dropped (twice).

Speed (issue 38): every ray of a pass is one array operation (the 48 rays' profiles one
bilinear gather from the frame, never the whole frame; the 61 tried edges of every ray one
matrix product against the cached orthonormal bases of the model), and the circle's least
squares are solved from their 3 x 3 normal equations.
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
from scipy import ndimage

N_RAYS = 48
_ANGLES = np.linspace(0, 2 * np.pi, N_RAYS, endpoint=False)
_COS, _SIN = np.cos(_ANGLES), np.sin(_ANGLES)

#: Radial samples of a ray about the current edge (px) and the edge positions tried among them.
_SAMPLES = np.arange(-5.0, 5.01, 0.5)
_CAND = np.arange(-3.0, 3.0001, 0.1)
_WIDE = np.arange(-10.0, 10.01, 0.5)
_TRIO = np.array([-1, 0, 1])
#: The fine grid the model's terms are smoothed on (px), and where the samples fall on it.
_FINE = np.arange(-9.0, 9.0, 0.05)
_AT = np.round((_SAMPLES - _FINE[0]) / 0.05).astype(int)


def _kernel(blur: float) -> np.ndarray:
    """Return the smoothing of the model's terms on the fine grid: 1-px box, interpolation's triangle, blur's box."""
    box = np.ones(20) / 20
    kern = np.convolve(box, np.convolve(box, box))
    if blur >= 0.5:
        kern = np.convolve(kern, np.ones(round(blur / 0.05)))
    return kern / kern.sum()


def _sampled_convolution(kern: np.ndarray) -> np.ndarray:
    """Return the matrix K (fine grid x samples) with b @ K = np.convolve(b, kern, "same") at the samples."""
    j = np.arange(_FINE.size)[:, None]
    lag = _AT[None, :] + (kern.size - 1) // 2 - j
    return np.where((lag >= 0) & (lag < kern.size), kern[np.clip(lag, 0, kern.size - 1)], 0.0)


@functools.lru_cache(maxsize=32)
def _terms(radius: float) -> np.ndarray:
    """Return the ray model's four non-constant terms on the fine grid, for every tried edge: (4, 61, fine)."""
    e = _CAND[:, None]
    fine = _FINE[None, :]
    inside = (fine < e) * 1.0
    rho = (radius + fine) / (radius + e)
    return np.stack([(1 - inside) * (fine - e), inside, np.sqrt(np.clip(1 - rho * rho, 0, None)), inside * rho])


@functools.lru_cache(maxsize=256)
def edge_bases(radius: float, blur: float = 0.0) -> np.ndarray:
    """For every tried edge position e, an orthonormal basis of the ray model with its edge at e: (samples, 61 x 5).

    The model of a ray's profile about the radius ``radius`` (px, to 0.5 px), linear in its
    five coefficients: the background (a constant and a slope outside) and the ball inside as
    a Lambert sphere of radius ``radius`` + e lit from anywhere in front: a constant, the
    normal's component towards the camera (sqrt(1 - (rho / R)^2)) and the one along the ray
    (rho / R). Each is smoothed as the pixels sample it (a 1-px box, then the bilinear
    interpolation of the rays: a triangle of half-width 1 px) and by the motion blur along the
    ray (a box of ``blur`` px: the ball's travel during the exposure, projected on the ray).
    A profile y's residual at e is |y|^2 - |y @ basis_e|^2. The basis is the QR factorisation's
    Q: the five terms are independent (their smallest singular value at least 2e-5 of the
    largest over radii of 5-80 px and blurs of 0-12 px), so it spans what a pseudo-inverse's
    projector does.
    """
    k = _sampled_convolution(_kernel(blur))
    d = np.empty((_CAND.size, _SAMPLES.size, 5))  # each term smoothed and sampled
    d[:, :, 0] = k.sum(axis=0)
    d[:, :, 1:] = np.moveaxis(_terms(radius) @ k, 0, 2)
    q = np.linalg.qr(d)[0]  # (61, samples, 5)
    return np.ascontiguousarray(np.swapaxes(q, 0, 1).reshape(_SAMPLES.size, -1))


def profiles(
    img: np.ndarray, cx: float, cy: float, r: float, rad: np.ndarray, cos: np.ndarray = _COS, sin: np.ndarray = _SIN
) -> np.ndarray:
    """Return the frame on the rays (``cos``, ``sin``) at radii r + rad from (cx, cy), bilinear: (rays, rad).

    In float32, as the tracker has always sampled them (float64 moved marginal frames of lossy clips).
    """
    rr = r + rad
    xs, ys = cx + cos[:, None] * rr, cy + sin[:, None] * rr
    return ndimage.map_coordinates(img, [ys.ravel(), xs.ravel()], output=np.float32, order=1, prefilter=False).reshape(
        xs.shape
    )


def _edges_gradient(prof: np.ndarray, rad: np.ndarray) -> np.ndarray:
    """Rough edge on each ray: the peak of the radial gradient, smoothed (offsets from the radius)."""
    sign = np.sign(prof[:, :4].sum(axis=1) - prof[:, -4:].sum(axis=1))
    d = np.diff(prof, axis=1) * -sign[:, None]  # the central gradient, smoothed by [1/4, 1/2, 1/4]
    g = np.concatenate([d[:, :1], d, d[:, -1:]], axis=1)
    g = g[:, :-1] + g[:, 1:]
    g = np.concatenate([g[:, :1], g, g[:, -1:]], axis=1)
    return rad[np.argmax(g[:, :-2] + 2 * g[:, 1:-1] + g[:, 2:], axis=1)]


def _edges_model(prof: np.ndarray, r: float, sigma, groups: list) -> tuple[np.ndarray, np.ndarray]:
    """Return the edge on each ray by the ray model (:func:`edge_bases`): offsets and the fit's chi-square per sample.

    ``sigma`` is the scale of the residuals (per ray or one); ``groups`` the rays (a slice) of each motion blur (px).
    """
    y = prof.astype(np.float64)
    y -= y.mean(axis=1, keepdims=True)  # the constant is in the model: its residual is unchanged
    rss = np.empty((y.shape[0], _CAND.size))
    yy = np.einsum("ij,ij->i", y, y)[:, None]
    for sel, b in groups:
        p = y[sel] @ edge_bases(round(2 * r) / 2, b)
        p *= p
        np.subtract(yy[sel], p.reshape(-1, _CAND.size, 5).sum(axis=2), out=rss[sel])
    k = np.clip(np.argmin(rss, axis=1), 1, _CAND.size - 2)
    r0, r1, r2 = np.take_along_axis(rss, k[:, None] + _TRIO, axis=1).T
    den = r0 - 2 * r1 + r2
    off = np.clip(0.5 * (r0 - r2) / np.where(den > 0, den, np.inf), -0.5, 0.5)
    return _CAND[k] + off * (_CAND[1] - _CAND[0]), r1 / (sigma**2 * (_SAMPLES.size - 5))


def _circle_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares circle (Kasa): centre and radius.

    About the points' mean the normal equations of x^2 + y^2 = a x + b y + c split: c is the
    mean of x^2 + y^2, and (a, b) solve a 2 x 2 system.
    """
    mx, my = x.mean(), y.mean()
    u, v = x - mx, y - my
    z = u * u + v * v
    suu, suv, svv, suz, svz = u @ u, u @ v, v @ v, u @ z, v @ z
    det = suu * svv - suv * suv
    a, b = (suz * svv - svz * suv) / det, (svz * suu - suz * suv) / det
    c = z.mean()
    return a / 2 + mx, b / 2 + my, float(np.sqrt(max(c + a * a / 4 + b * b / 4, 0)))


def _median(v: np.ndarray) -> float:
    s = np.sort(v)
    n = s.size
    return float(s[n // 2]) if n % 2 else float(0.5 * (s[n // 2 - 1] + s[n // 2]))


def _fit_circle_robust(px, py, keep):
    """Circle through the kept edge points, points off by more than 3 robust sigma dropped (twice)."""
    for _ in range(2):
        if keep.sum() < N_RAYS // 2:
            return None, keep
        fx, fy, fr = _circle_fit(px[keep], py[keep])
        res = np.hypot(px - fx, py - fy) - fr
        kr = res[keep]
        mad = 1.4826 * _median(np.abs(kr - _median(kr))) + 0.05  # a clean edge: 0.15 px
        keep = keep & (np.abs(res) < 3 * mad)
    return (fx, fy, fr, res), keep


def _rays(blur: tuple[float, float]) -> tuple[np.ndarray, np.ndarray, list]:
    """Return the rays' directions (cos, sin), ordered by the motion blur along them, and each blur's rays (a slice).

    The blur is taken to 0.5 px (the model's bases are cached per blur).
    """
    buckets = np.round(2 * np.abs(_COS * blur[0] + _SIN * blur[1])) / 2
    order = np.argsort(buckets, kind="stable")
    b = buckets[order]
    cut = np.flatnonzero(np.diff(b)) + 1
    edges = [0, *cut.tolist(), N_RAYS]
    groups = [(slice(i, j), float(b[i])) for i, j in itertools.pairwise(edges)]
    return _COS[order], _SIN[order], groups


def fit_ball(
    img: np.ndarray, cx: float, cy: float, r: float, sigma: float, blur: tuple[float, float] = (0.0, 0.0)
) -> tuple[tuple, str | None]:
    """Return the ball's sub-pixel centre near (cx, cy): ((x, y, r, rms, contrast), None) or ((), reason left out).

    ``r`` is where the edge is looked for first (the expected radius).
    The rough edges (gradient peaks on a wide window) until the circle moves by under a pixel,
    then the ray model (:func:`_edges_model`) until it moves by under 0.01 px (at most 8 passes).
    ``blur`` is the ball's travel during the exposure (px, x and y), where known.
    """
    cos, sin, groups = _rays(blur)
    h, w = img.shape
    wide, moved, kept = True, np.inf, np.ones(N_RAYS, bool)
    for _ in range(8):
        rad = _WIDE if wide else _SAMPLES
        if min(cx - r, cy - r, w - 1 - cx - r, h - 1 - cy - r) < rad[-1] + 1:
            return (), "ball touches the frame's border"
        prof = profiles(img, cx, cy, r, rad, cos, sin)
        step = np.abs(prof[:, :4].mean(axis=1) - prof[:, -4:].mean(axis=1))
        keep = step > 6 * sigma
        if wide:
            edge = _edges_gradient(prof, rad)
        else:
            # the model's own mismatch grows with the edge's contrast: 2 % of the step counts as noise
            edge, chi2 = _edges_model(prof, r, np.maximum(sigma, 0.02 * step), groups)
            keep &= (chi2 < 2.0) & kept  # a ray once dropped stays dropped: the passes settle
        fit, keep = _fit_circle_robust(cx + cos * (r + edge), cy + sin * (r + edge), keep)
        if fit is None:
            return (), f"ball edge seen on {int(keep.sum())} of {N_RAYS} rays (occluded, blurred or on clutter)"
        moved = max(abs(fit[0] - cx), abs(fit[1] - cy), abs(fit[2] - r))
        cx, cy, r, res = fit
        if not wide and moved < 0.01:
            break
        kept = keep if not wide else kept
        wide = wide and moved > 1.0
    if wide or moved > 0.05:
        return (), f"ball edge fit did not settle (last step {moved:.2f} px)"
    rms = float(np.sqrt(np.mean(res[keep] ** 2)))
    if rms > 0.5:  # edge points that no circle fits: the ball half hidden, or an edge of the clutter taken
        return (), f"ball edge not round (residual {rms:.2f} px; occluded or on clutter)"
    return (cx, cy, r, rms, _median(step[keep])), None
