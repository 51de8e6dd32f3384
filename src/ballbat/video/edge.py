"""The ball's sub-pixel edge and centre in one frame (docs/video.md, "The tracker").

The edge is found on 48 rays from a rough centre: first the peak of the radial gradient on a
wide window, until the circle moves by under a pixel; then a model of each ray's profile on a
±5 px window (a lit sphere, or where the ray lies past a single light's terminator the shading
clipped there), fitted at 61 tried edge positions, until the circle moves by under 0.01 px.
A circle is fitted to the edge points by least squares, points off it by more than 3 robust
standard deviations dropped (twice).

Speed (issue 38): the 48 rays' profiles are one bilinear gather from the frame, never the
whole frame; the 61 tried edges of every ray one matrix product per blur against the cached
orthonormal bases of the model; the circle's least squares are solved from their 3 x 3 normal
equations. Each pass runs compiled (:mod:`ballbat.video.kernels`, one call); the numpy
functions here are what the kernels do, and their reference (``fit_ball(compiled=False)``).
"""

from __future__ import annotations

import functools
import itertools

import numpy as np
from scipy import ndimage

N_RAYS = 48
#: How far inside the edge (px) the terminator models put the shading's terminator (:func:`edge_bases`).
_TERMINATOR = (1.0, 2.0, 3.0, 4.0)
#: The ray models' columns per tried edge: three terms shared (a constant, the slope outside, the constant inside),
#: the lit sphere's two, the lit fit's coefficient of its first, and one per terminator (:func:`edge_bases`).
N_TERMS = 6 + len(_TERMINATOR)
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


def _fixed_terms() -> np.ndarray:
    """Return the terms that do not depend on the radius: the slope outside, the constant inside: (2, 61, fine)."""
    e = _CAND[:, None]
    fine = _FINE[None, :]
    inside = (fine < e) * 1.0
    return np.stack([(1 - inside) * (fine - e), inside])


_TERMS_FIXED = _fixed_terms()


@functools.lru_cache(maxsize=32)
def _sphere(radius: float) -> np.ndarray:
    """Return the sphere's terms, of radius ``radius`` + e: (2 + terminators, 61, fine).

    Lit: sqrt(1 - rho^2) and rho inside. Past a terminator w px inside the edge: the Lambert
    shading that is 0 there and beyond, max(0, sqrt(1 - rho^2) - rho sqrt(1 - rho_t^2) / rho_t),
    rho_t = 1 - w / (radius + e); 0 where the terminator falls less than 1 px inside the
    samples' inner end (:func:`edge_bases`).
    """
    e = _CAND[:, None]
    fine = _FINE[None, :]
    rho = (radius + fine) / (radius + e)
    nz = np.sqrt(np.maximum(1 - rho * rho, 0))
    terms = [nz, _TERMS_FIXED[1] * rho]
    for w in _TERMINATOR:
        rt = np.maximum(1 - w / (radius + e), 1e-3)
        seen = (e - w >= _SAMPLES[0] + 1) & (w < radius + e)
        terms.append(np.maximum(nz - rho * np.sqrt(1 - rt * rt) / rt, 0) * seen)
    return np.stack(terms)


@functools.lru_cache(maxsize=64)
def _smoothing(blur: float) -> tuple[np.ndarray, np.ndarray]:
    """Return a blur's sampled smoothing K (:func:`_sampled_convolution`) and the three radius-free terms through it.

    The constant, the slope outside, the constant inside: (61, samples, 3); a new radius then
    smooths only the sphere's two terms.
    """
    k = _sampled_convolution(_kernel(blur))
    fixed = np.empty((_CAND.size, _SAMPLES.size, 3))
    fixed[:, :, 0] = k.sum(axis=0)
    fixed[:, :, 1:] = np.moveaxis(_TERMS_FIXED @ k, 0, 2)
    return k, fixed


@functools.lru_cache(maxsize=256)
def edge_bases(radius: float, blur: float = 0.0) -> np.ndarray:
    """For every tried edge position e, orthonormal bases of the ray models with their edge at e: (samples, 61 x 10).

    The models of a ray's profile about the radius ``radius`` (px, to 0.5 px), each linear in
    its coefficients: the background (a constant and a slope outside) and the ball inside as a
    Lambert sphere of radius ``radius`` + e under an even (ambient) light and one more. Lit (5
    terms): lit from anywhere in front, a constant, the normal's component towards the camera
    (sqrt(1 - (rho / R)^2)) and the one along the ray (rho / R). Past the terminator (4 terms
    each): on a ray facing away from a single light the shading is clipped at 0 from its
    terminator to the limb, a kink the lit model cannot follow (it put a 29-px ball's edge
    0.2 px in on those rays, the centre 0.03 px towards the light); one model per terminator
    1, 2, 3 or 4 px inside the edge, a constant and the shading that starts there
    (:func:`_sphere`). Such a ray's lit fit needs a light from behind (a negative coefficient of
    sqrt(1 - (rho / R)^2)): only those rays try the terminators (:func:`_edges_model`). Each
    term is smoothed as the pixels sample it (a 1-px box, then the bilinear interpolation of the
    rays: a triangle of half-width 1 px) and by the motion blur along the ray (a box of ``blur``
    px: the ball's travel during the exposure, projected on the ray).

    The columns of each e, term by term: Q of the lit model's QR factorisation (the three shared
    terms, then the lit two); the lit fit's coefficient of sqrt(1 - (rho / R)^2) (that row of its
    pseudo-inverse: its product with a profile is the coefficient); then each terminator's term
    made orthonormal to the three shared ones. A profile y's residual at e under a model is
    |y|^2 less the squares of y @ the shared columns and of the model's own. The lit terms are
    independent (their smallest singular value at least 2e-5 of the largest over radii of 5-80
    px and blurs of 0-12 px), and so are each terminator's with the shared three (at least
    2.7e-4) where it falls at least 1 px inside the samples' inner end; elsewhere its column is
    0 (the model is then the shared three alone, never a better fit than the lit model). So each
    spans what a pseudo-inverse's projector does. The terms that do not depend on the radius
    are smoothed once per blur (:func:`_smoothing`).
    """
    k, fixed = _smoothing(blur)
    d = np.empty((_CAND.size, _SAMPLES.size, N_TERMS - 1))  # each term smoothed and sampled
    d[:, :, :3] = fixed
    d[:, :, 3:] = np.moveaxis(_sphere(radius) @ k, 0, 2)
    q = np.empty((_CAND.size, _SAMPLES.size, N_TERMS))
    q[:, :, :5], rr = np.linalg.qr(d[:, :, :5])  # (61, samples, 5), (61, 5, 5)
    shared = q[:, :, :3]
    t = d[:, :, 5:] - shared @ (np.swapaxes(shared, 1, 2) @ d[:, :, 5:])
    norm = np.linalg.norm(t, axis=1, keepdims=True)
    # row 3 of the pseudo-inverse, R^-1 Q^T: (q_3 - R_34 / R_44 q_4) / R_33
    q[:, :, 5] = (q[:, :, 3] - (rr[:, 3, 4] / rr[:, 4, 4])[:, None] * q[:, :, 4]) / rr[:, 3, 3][:, None]
    q[:, :, 6:] = t / np.where(norm > 0, norm, 1.0)
    return np.ascontiguousarray(np.swapaxes(q, 0, 1).reshape(_SAMPLES.size, -1))


def profiles(
    img: np.ndarray, cx: float, cy: float, r: float, rad: np.ndarray, cos: np.ndarray = _COS, sin: np.ndarray = _SIN
) -> np.ndarray:
    """Return the frame on the rays (``cos``, ``sin``) at radii r + rad from (cx, cy), bilinear: (rays, rad).

    In float32, as the tracker has always sampled them (float64 moved marginal frames of lossy clips).
    """
    rr = r + rad
    at = np.empty((2, cos.size, rad.size))
    np.add(np.multiply.outer(sin, rr, out=at[0]), cy, out=at[0])
    np.add(np.multiply.outer(cos, rr, out=at[1]), cx, out=at[1])
    return ndimage.map_coordinates(img, at, output=np.float32, order=1, prefilter=False)


def _edges_gradient(prof: np.ndarray, rad: np.ndarray, sign: np.ndarray) -> np.ndarray:
    """Rough edge on each ray: the peak of the radial gradient, smoothed (offsets from the radius).

    ``sign``: +1 where the ray's inner end is the brighter.
    """
    d = np.diff(prof, axis=1)
    d *= -sign[:, None]  # the central gradient, smoothed by [1/4, 1/2, 1/4]
    g = np.concatenate([d[:, :1], d, d[:, -1:]], axis=1)
    g = g[:, :-1] + g[:, 1:]
    g = np.concatenate([g[:, :1], g, g[:, -1:]], axis=1)
    return rad[np.argmax(g[:, :-2] + 2 * g[:, 1:-1] + g[:, 2:], axis=1)]


def _edges_model(prof: np.ndarray, r: float, sigma, groups: list, models=None) -> tuple[np.ndarray, np.ndarray]:
    """Return the edge on each ray by the ray models (:func:`edge_bases`): offsets and the fit's chi-square per sample.

    ``sigma`` is the scale of the residuals (per ray or one); ``groups`` the rays (a slice) of each motion blur (px).
    One matrix product per blur into one array, the bases' columns ordered term by term (:func:`_term_bases`), so
    that each tried edge's sum over a model's terms adds contiguous rows. Each model's least residual over the tried
    edges (kept off the ends); where the lit fit there needs a light from behind (:func:`edge_bases`), the ray's edge
    is that of the model with the least (the lit model's on a tie), else the lit model's; parabolic between its
    neighbours. ``models`` (rays; 0 lit, j terminator j, -1 not yet chosen), where given, holds each ray's model
    once chosen: a later pass fits it alone (a ray that switched models from pass to pass kept its fit from settling).
    """
    n = prof.shape[0]
    y = prof.astype(np.float64)
    y -= np.add.reduce(y, axis=1, keepdims=True) / _SAMPLES.size  # the constant is in the model: residual unchanged
    p = np.empty((n, N_TERMS * _CAND.size))
    radius = round(2 * r) / 2
    for sel, b in groups:
        np.matmul(y[sel], _term_bases(radius, b), out=p[sel])
    sq = p.reshape(n, N_TERMS, _CAND.size)
    coef = sq[:, 5].copy()  # the lit fit's coefficient of sqrt(1 - rho^2)
    sq *= sq
    shared = sq[:, 0] + sq[:, 1] + sq[:, 2]
    fitted = np.concatenate([(shared + sq[:, 3] + sq[:, 4])[:, None], shared[:, None] + sq[:, 6:]], axis=1)
    rss = np.einsum("ij,ij->i", y, y)[:, None, None] - fitted  # (rays, models, tried edges)
    k = np.argmin(rss, axis=2)
    np.minimum(np.maximum(k, 1, out=k), _CAND.size - 2, out=k)  # np.clip's own overhead is several times these
    rows = np.arange(n)
    behind = coef[rows, k[:, 0]] < 0  # the lit fit's light from behind: past a terminator
    m = np.where(behind, np.argmin(np.take_along_axis(rss, k[:, :, None], axis=2)[:, :, 0], axis=1), 0)
    if models is not None:
        m = models[:] = np.where(models >= 0, models, m)
    k = k[rows, m]
    r0, r1, r2 = rss[rows, m][rows[None, :], k[None, :] + _TRIO[:, None]]
    den = r0 - 2 * r1 + r2
    off = np.minimum(np.maximum(0.5 * (r0 - r2) / np.where(den > 0, den, np.inf), -0.5), 0.5)
    return _CAND[k] + off * (_CAND[1] - _CAND[0]), r1 / (sigma**2 * (_SAMPLES.size - np.where(m == 0, 5, 4)))


@functools.lru_cache(maxsize=256)
def _term_bases(radius: float, blur: float) -> np.ndarray:
    """Return :func:`edge_bases` with its columns ordered term by term (10 x 61 tried edges), not edge by edge."""
    q = edge_bases(radius, blur).reshape(_SAMPLES.size, _CAND.size, N_TERMS)
    return np.ascontiguousarray(q.transpose(0, 2, 1).reshape(_SAMPLES.size, -1))


def _circle_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Least-squares circle (Kasa): centre and radius.

    About the points' mean the normal equations of x^2 + y^2 = a x + b y + c split: c is the
    mean of x^2 + y^2, and (a, b) solve a 2 x 2 system.
    """
    return _circle_of(np.stack([x, y]))


def _circle_of(pts: np.ndarray) -> tuple[float, float, float]:
    """:func:`_circle_fit` of the points ``pts`` (2 x n), its sums one matrix product."""
    n = pts.shape[1]
    m = np.add.reduce(pts, axis=1) / n
    uvz = np.empty((3, n))
    np.subtract(pts, m[:, None], out=uvz[:2])
    np.einsum("ij,ij->j", uvz[:2], uvz[:2], out=uvz[2])
    (suu, suv, suz), (_, svv, svz) = (uvz[:2] @ uvz.T).tolist()
    det = suu * svv - suv * suv
    a, b = (suz * svv - svz * suv) / det, (svz * suu - suz * suv) / det
    c = float(np.add.reduce(uvz[2])) / n
    mx, my = m.tolist()
    return a / 2 + mx, b / 2 + my, float(np.sqrt(max(c + a * a / 4 + b * b / 4, 0)))


def _median(v: np.ndarray) -> float:
    s = np.sort(v)
    n = s.size
    return float(s[n // 2]) if n % 2 else float(0.5 * (s[n // 2 - 1] + s[n // 2]))


def _fit_circle_robust(pts: np.ndarray, keep: np.ndarray):
    """Circle through the kept edge points (2 x rays), points off by more than 3 robust sigma dropped (twice)."""
    for _ in range(2):
        if np.count_nonzero(keep) < N_RAYS // 2:
            return None, keep
        fx, fy, fr = _circle_of(pts[:, keep])
        res = np.hypot(pts[0] - fx, pts[1] - fy)
        res -= fr
        kr = res[keep]
        mad = 1.4826 * _median(np.abs(kr - _median(kr))) + 0.05  # a clean edge: 0.15 px
        keep = keep & (np.abs(res) < 3 * mad)
    return (fx, fy, fr, res), keep


def _rays(blur: tuple[float, float]) -> tuple[np.ndarray, np.ndarray, list, np.ndarray]:
    """Return the rays' directions (cos, sin) ordered by the blur along them, each blur's rays, and where they start.

    Each blur's rays as (a slice, the blur), and their starts as an array (with the end). The
    blur is taken to 0.5 px (the model's bases are cached per blur); so is the order (per blur on
    each ray).
    """
    buckets = np.round(2 * np.abs(_COS * blur[0] + _SIN * blur[1])) / 2
    return _ray_order(buckets.tobytes())


@functools.lru_cache(maxsize=1024)
def _ray_order(key: bytes) -> tuple[np.ndarray, np.ndarray, list, np.ndarray]:
    buckets = np.frombuffer(key)
    order = np.argsort(buckets, kind="stable")
    b = buckets[order]
    cut = np.flatnonzero(np.diff(b)) + 1
    edges = [0, *cut.tolist(), N_RAYS]
    groups = [(slice(i, j), float(b[i])) for i, j in itertools.pairwise(edges)]
    return _COS[order], _SIN[order], groups, np.array(edges)


def fit_ball(
    img: np.ndarray,
    cx: float,
    cy: float,
    r: float,
    sigma: float,
    blur: tuple[float, float] = (0.0, 0.0),
    compiled: bool = True,
) -> tuple[tuple, str | None]:
    """Return the ball's sub-pixel centre near (cx, cy): ((x, y, r, rms, contrast), None) or ((), reason left out).

    ``r`` is where the edge is looked for first (the expected radius).
    The rough edges (gradient peaks on a wide window) until the circle moves by under a pixel,
    then the ray model (:func:`_edges_model`) until it moves by under 0.01 px (at most 8 passes).
    ``blur`` is the ball's travel during the exposure (px, x and y), where known.
    Each pass runs compiled (:mod:`ballbat.video.kernels`); ``compiled=False`` runs the numpy
    functions they are checked against (the same fit, to rounding).
    """
    cos, sin, groups, starts = _rays(blur)
    if compiled and not (img.flags.c_contiguous and img.dtype.isnative):  # one layout of the frame compiled
        img = np.ascontiguousarray(img, img.dtype.newbyteorder("="))
    h, w = img.shape
    wide, moved, kept = True, np.inf, np.ones(N_RAYS, bool)
    models = np.full(N_RAYS, -1)  # each ray's model, chosen in the first model pass (:func:`_edges_model`)
    one_pass = _pass_compiled if compiled else _pass_numpy
    for _ in range(8):
        rad = _WIDE if wide else _SAMPLES
        # not min(...) < ...: a centre that is not a number is outside too
        if not min(cx - r, cy - r, w - 1 - cx - r, h - 1 - cy - r) >= rad[-1] + 1 or not np.isfinite(cx + cy + r):
            return (), "ball touches the frame's border"
        fit, keep, step = one_pass(img, cx, cy, r, rad, cos, sin, (groups, starts), sigma, (kept, models), wide)
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


def _pass_numpy(img, cx, cy, r, rad, cos, sin, groups, sigma, kept, wide):
    """One pass of :func:`fit_ball` in numpy: ((x, y, r, residuals) or None, the rays kept, each ray's step).

    ``kept``: the rays kept by the last pass, and each ray's model (:func:`_edges_model`; updated in place).
    """
    kept, models = kept
    groups = groups[0]
    prof = profiles(img, cx, cy, r, rad, cos, sin)
    ends = np.add.reduce(prof[:, :4], axis=1) - np.add.reduce(prof[:, -4:], axis=1)
    step = np.abs(ends) / 4
    keep = step > 6 * sigma
    if wide:
        edge = _edges_gradient(prof, rad, np.sign(ends))
    else:
        # the model's own mismatch grows with the edge's contrast: 2 % of the step counts as noise
        edge, chi2 = _edges_model(prof, r, np.maximum(sigma, 0.02 * step), groups, models)
        keep &= (chi2 < 2.0) & kept  # a ray once dropped stays dropped: the passes settle
    at = r + edge
    pts = np.stack([cx + cos * at, cy + sin * at])
    fit, keep = _fit_circle_robust(pts, keep)
    return fit, keep, step


def _pass_compiled(img, cx, cy, r, rad, cos, sin, groups, sigma, kept, wide):
    """:func:`_pass_numpy` by the kernels of :mod:`ballbat.video.kernels` (the model's products by BLAS, as numpy's)."""
    kernels = _kernels()
    kept, models = kept
    if not kernels.inside(img, cx, cy, abs(r) + rad[-1]):  # what the border test keeps: never out of the frame
        raise ValueError(f"fit_ball: rays about ({cx}, {cy}), radius {r}, leave the frame")
    if wide:
        fitted, fx, fy, fr, res, keep, step = kernels.gradient_pass(img, cx, cy, r, rad, cos, sin, sigma, N_RAYS // 2)
    else:
        groups, starts = groups
        bases, past = _group_bases(round(2 * r) / 2, tuple(b for _, b in groups))
        fitted, fx, fy, fr, res, keep, step = kernels.model_pass(
            img, cx, cy, r, rad, cos, sin, bases, past, starts, _CAND, sigma, kept, models, N_RAYS // 2
        )
    return ((fx, fy, fr, res) if fitted else None), keep, step


@functools.lru_cache(maxsize=1)
def _kernels():
    """Return :mod:`ballbat.video.kernels`, imported where a ball is first fitted (numba: about 0.3 s of CPU, once)."""
    from . import kernels

    return kernels


@functools.lru_cache(maxsize=256)
def _group_bases(radius: float, blurs: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Return the bases (:func:`_term_bases`) of each group of rays (by its blur), stacked: six terms, and the rest.

    The kernel takes the products with the first six for every ray, with the terminators' for a few
    (:func:`ballbat.video.kernels.edges_model`).
    """
    q = np.stack([_term_bases(radius, b) for b in blurs])
    cut = 6 * _CAND.size
    return np.ascontiguousarray(q[:, :, :cut]), np.ascontiguousarray(q[:, :, cut:])
