"""The tracker's innermost loops, compiled with numba (issue 38's speed; docs/video.md, "Speed").

Each kernel does what numpy and scipy functions of :mod:`ballbat.video.edge` and
:mod:`ballbat.video.search` do, as plain loops: those functions stay the reference
(``compiled=False``), and ``tests/video/test_kernels.py`` checks each kernel against them on
random inputs and rendered frames. A pass of the ball's edge fit is one call
(:func:`gradient_pass`, :func:`model_pass`), and so are the marker's and the dots' searches in
their regions (:func:`marker_search`, :func:`dots_search`) and a dot's refinement
(:func:`dot_refine`).

Why compiled: a pass of the edge fit is about 25 numpy calls on arrays of 48 x 21, so numpy's
per-call overhead, not the arithmetic, set its cost (about 130 us a pass; here 14 us a
gradient pass, 35 us a model pass, 20 of them the model's matrix product, left to BLAS; with
the models past a single light's terminator, tried on the rays that need them, about 60 us on
the bench's clips, measured under cProfile against 40 before).

Compiled once per machine and type of frame (``cache=True``: numba keeps the machine code in
``__pycache__`` beside this file, or in ``NUMBA_CACHE_DIR``), about 17 s the first time; a
process loads it from there (numba's import and the load: about 0.3 s of CPU, once, see
:func:`load`). Only the tracker imports this module, where it first fits a ball or searches.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Compiled once per machine and type of arguments, kept on disk (``cache=True``); a float divided by zero
#: gives inf or NaN as in numpy (``error_model="numpy"``), not an exception.
_jit = njit(cache=True, nogil=True, error_model="numpy")


@_jit
def profiles(
    img: np.ndarray, cx: float, cy: float, r: float, rad: np.ndarray, cos: np.ndarray, sin: np.ndarray
) -> np.ndarray:
    """Return the frame on the rays at radii r + rad from (cx, cy), bilinear, float32 (:func:`.edge.profiles`).

    As ``scipy.ndimage.map_coordinates(order=1, prefilter=False)`` computes it (its weights
    1 - t and 1 - (1 - t), its sum's order, in float64, then float32). Every sample must be
    inside the frame with a pixel to spare (the caller's border test).
    """
    n, m = cos.size, rad.size
    out = np.empty((n, m), np.float32)
    for i in range(n):
        for j in range(m):
            rr = r + rad[j]
            x = cx + cos[i] * rr
            y = cy + sin[i] * rr
            fx, fy = np.floor(x), np.floor(y)
            ix, iy = int(fx), int(fy)
            wx0 = 1.0 - (x - fx)
            wy0 = 1.0 - (y - fy)
            wx1, wy1 = 1.0 - wx0, 1.0 - wy0
            t = 0.0
            t += img[iy, ix] * wy0 * wx0
            t += img[iy, ix + 1] * wy0 * wx1
            t += img[iy + 1, ix] * wy1 * wx0
            t += img[iy + 1, ix + 1] * wy1 * wx1
            out[i, j] = t
    return out


@_jit
def ends_step(prof: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return each ray's inner four samples' sum less its outer four's (float32), and the step: that over 4, >= 0."""
    n, m = prof.shape
    ends = np.empty(n, np.float32)
    step = np.empty(n, np.float32)
    for i in range(n):
        a = prof[i, 0] + prof[i, 1] + prof[i, 2] + prof[i, 3]
        b = prof[i, m - 4] + prof[i, m - 3] + prof[i, m - 2] + prof[i, m - 1]
        ends[i] = a - b
        step[i] = abs(ends[i]) / np.float32(4.0)
    return ends, step


@_jit
def edges_gradient(prof: np.ndarray, rad: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Return each ray's rough edge, the peak of its radial gradient (:func:`.edge._edges_gradient`, in float32)."""
    n, m = prof.shape
    out = np.empty(n)
    d = np.empty(m + 1, np.float32)  # the differences, their first and last repeated
    g = np.empty(m + 2, np.float32)
    for i in range(n):
        s = np.float32(-1.0) if ends[i] > 0 else (np.float32(1.0) if ends[i] < 0 else np.float32(0.0))
        for j in range(m - 1):
            d[j + 1] = (prof[i, j + 1] - prof[i, j]) * s
        d[0], d[m] = d[1], d[m - 1]
        for j in range(m):
            g[j + 1] = d[j] + d[j + 1]
        g[0], g[m + 1] = g[1], g[m]
        best, at = g[0] + (g[1] + g[1]) + g[2], 0
        for j in range(1, m):
            v = g[j] + (g[j + 1] + g[j + 1]) + g[j + 2]
            if v > best:
                best, at = v, j
        out[i] = rad[at]
    return out


@_jit
def centred(prof: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the profiles in float64 less each ray's mean, and each ray's sum of squares after."""
    n, m = prof.shape
    y = np.empty((n, m))
    yy = np.empty(n)
    for i in range(n):
        s = 0.0
        for j in range(m):
            s += prof[i, j]
        mean = s / m
        q = 0.0
        for j in range(m):
            v = prof[i, j] - mean
            y[i, j] = v
            q += v * v
        yy[i] = q
    return y, yy


@_jit
def _least(rss: np.ndarray, shared: np.ndarray, yy: float, own: np.ndarray, own2: np.ndarray) -> int:
    """Fill ``rss`` with a model's residual at each tried edge and return its least's (kept off the ends).

    The residual is |y|^2 less the squares of the three shared terms (``shared``, summed) and of the model's own
    products (``own``, and ``own2`` for the lit model's second), in numpy's order.
    """
    nc = rss.size
    for e in range(nc):
        s = shared[e] + own[e] * own[e]
        if own2.size:
            s += own2[e] * own2[e]
        rss[e] = yy - s
    k = 0
    for e in range(1, nc):
        if rss[e] < rss[k]:
            k = e
    return min(max(k, 1), nc - 2)


@_jit
def _past_products(y: np.ndarray, past: np.ndarray, starts: np.ndarray, behind: np.ndarray) -> np.ndarray:
    """Return the products of the rays ``behind`` with their group's terminator columns (one BLAS product a group).

    (rays x 4 * tried edges); the other rays' rows are left unset.
    """
    out = np.empty((y.shape[0], past.shape[2]))
    for g in range(starts.size - 1):
        rays = np.flatnonzero(behind[starts[g] : starts[g + 1]]) + starts[g]
        if rays.size:
            sub = np.empty((rays.size, y.shape[1]))
            for a in range(rays.size):
                sub[a] = y[rays[a]]
            prod = np.dot(sub, past[g])
            for a in range(rays.size):
                out[rays[a]] = prod[a]
    return out


@_jit
def edges_model(
    p: np.ndarray,
    y: np.ndarray,
    yy: np.ndarray,
    past: np.ndarray,
    starts: np.ndarray,
    cand: np.ndarray,
    step: np.ndarray,
    sigma: float,
    n_samples: int,
    models: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Return the edges and chi-squares per sample of :func:`.edge._edges_model`, after the lit model's product.

    ``p`` (rays x 6 * tried edges, term by term: three shared, the lit model's two, the lit fit's
    coefficient of sqrt(1 - rho^2)) is the centred profiles' ``y`` products with the bases'
    first six terms; ``past`` (groups x samples x 4 * tried edges) the terminators' columns of
    each group of rays (rays ``starts[g]`` to ``starts[g + 1]``). The lit model's least residual
    over the tried edges (:func:`_least`); where the coefficient there is negative (a light from
    behind), each terminator's too (their products taken for those rays alone), and the edge is
    that of the model with the least (the lit model's on a tie), parabolic between its
    neighbours. The residuals' scale is the noise ``sigma`` or 2 % of the ray's ``step``,
    whichever is more, in float32 as numpy takes them. ``models`` (0 lit, j terminator j, -1 not
    yet chosen) holds each ray's model once chosen, a later pass fitting it alone (in place).
    """
    n, nc = p.shape[0], cand.size
    rss, none = np.empty(nc), np.empty(0)
    shared = p[:, : 3 * nc] * p[:, : 3 * nc]
    shared = shared[:, :nc] + shared[:, nc : 2 * nc] + shared[:, 2 * nc :]
    kb, terms, trio = np.empty(n, np.int64), np.full(n, 5), np.empty((n, 3))
    behind = np.zeros(n, np.bool_)
    for i in range(n):
        k = _least(rss, shared[i], yy[i], p[i, 3 * nc : 4 * nc], p[i, 4 * nc : 5 * nc])
        kb[i], trio[i, 0], trio[i, 1], trio[i, 2] = k, rss[k - 1], rss[k], rss[k + 1]
        behind[i] = models[i] > 0 if models[i] >= 0 else p[i, 5 * nc + k] < 0
    own = _past_products(y, past, starts, behind)
    for i in np.flatnonzero(behind):
        best = 0
        for m in range(past.shape[2] // nc):
            k = _least(rss, shared[i], yy[i], own[i, m * nc : (m + 1) * nc], none)
            if (rss[k] < trio[i, 1] and models[i] < 0) or models[i] == m + 1:
                kb[i], terms[i], trio[i, 0], trio[i, 1], trio[i, 2] = k, 4, rss[k - 1], rss[k], rss[k + 1]
                best = m + 1
        models[i] = best
    for i in range(n):
        models[i] = max(models[i], 0)
    edge, chi2 = np.empty(n), np.empty(n)
    for i in range(n):
        r0, r1, r2 = trio[i, 0], trio[i, 1], trio[i, 2]
        den = r0 - 2 * r1 + r2
        off = 0.5 * (r0 - r2) / den if den > 0 else 0.0
        off = min(max(off, -0.5), 0.5)
        edge[i] = cand[kb[i]] + off * (cand[1] - cand[0])
        scale = max(np.float32(sigma), np.float32(0.02) * step[i])
        chi2[i] = r1 / ((scale * scale) * np.float64(n_samples - terms[i]))
    return edge, chi2


@_jit
def _median(v):
    """Return ``np.median`` of float64 values."""
    s = np.sort(v)
    n = s.size
    return s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2])


@_jit
def circle_fit(x: np.ndarray, y: np.ndarray) -> tuple[float, float, float]:
    """Return the least-squares circle (Kasa) about the points' mean (:func:`.edge._circle_fit`): centre, radius."""
    n = x.size
    mx = 0.0
    my = 0.0
    for i in range(n):
        mx += x[i]
        my += y[i]
    mx /= n
    my /= n
    suu = suv = svv = suz = svz = sz = 0.0
    for i in range(n):
        u, v = x[i] - mx, y[i] - my
        z = u * u + v * v
        suu += u * u
        suv += u * v
        svv += v * v
        suz += u * z
        svz += v * z
        sz += z
    det = suu * svv - suv * suv
    a, b = (suz * svv - svz * suv) / det, (svz * suu - suz * suv) / det
    c = sz / n
    return a / 2 + mx, b / 2 + my, np.sqrt(max(c + a * a / 4 + b * b / 4, 0.0))


@_jit
def circle_robust(px: np.ndarray, py: np.ndarray, keep: np.ndarray, min_kept: int) -> tuple:
    """Return the circle through the kept points, less those 3 robust sigma off, twice.

    :func:`.edge._fit_circle_robust`: (fitted, x, y, r, residuals, keep); ``fitted`` False where
    fewer than ``min_kept`` are kept.
    """
    n = px.size
    keep = keep.copy()
    res = np.empty(n)
    fx = fy = fr = 0.0
    for _ in range(2):
        nk = 0
        for i in range(n):
            nk += keep[i]
        if nk < min_kept:
            return False, fx, fy, fr, res, keep
        kx, ky = np.empty(nk), np.empty(nk)
        j = 0
        for i in range(n):
            if keep[i]:
                kx[j], ky[j] = px[i], py[i]
                j += 1
        fx, fy, fr = circle_fit(kx, ky)
        kr = np.empty(nk)
        j = 0
        for i in range(n):
            res[i] = np.hypot(px[i] - fx, py[i] - fy) - fr
            if keep[i]:
                kr[j] = res[i]
                j += 1
        med = _median(kr)
        mad = 1.4826 * _median(np.abs(kr - med)) + 0.05
        for i in range(n):
            keep[i] = keep[i] and abs(res[i]) < 3 * mad
    return True, fx, fy, fr, res, keep


@_jit
def inside(img: np.ndarray, cx: float, cy: float, far: float) -> bool:
    """Return whether every point within ``far`` px of (cx, cy) has its bilinear neighbours in the frame."""
    h, w = img.shape
    finite = np.isfinite(cx) and np.isfinite(cy)
    return finite and cx - far >= 0 and cy - far >= 0 and cx + far < w - 1 and cy + far < h - 1


@_jit
def gradient_pass(
    img: np.ndarray,
    cx: float,
    cy: float,
    r: float,
    rad: np.ndarray,
    cos: np.ndarray,
    sin: np.ndarray,
    sigma: float,
    min_kept: int,
) -> tuple:
    """Return a pass of :func:`.edge.fit_ball` on the rough edges: (fitted, x, y, r, residuals, keep, step)."""
    prof = profiles(img, cx, cy, r, rad, cos, sin)
    ends, step = ends_step(prof)
    keep = step > np.float32(6 * sigma)
    edge = edges_gradient(prof, rad, ends)
    px, py = cx + cos * (r + edge), cy + sin * (r + edge)
    fitted, fx, fy, fr, res, keep = circle_robust(px, py, keep, min_kept)
    return fitted, fx, fy, fr, res, keep, step


@_jit
def model_pass(
    img: np.ndarray,
    cx: float,
    cy: float,
    r: float,
    rad: np.ndarray,
    cos: np.ndarray,
    sin: np.ndarray,
    bases: np.ndarray,
    past: np.ndarray,
    starts: np.ndarray,
    cand: np.ndarray,
    sigma: float,
    kept: np.ndarray,
    models: np.ndarray,
    min_kept: int,
) -> tuple:
    """Return a pass of :func:`.edge.fit_ball` by the ray model: (fitted, x, y, r, residuals, keep, step).

    ``bases`` (groups x samples x 6 * tried edges) are the lit model's bases and coefficient of each
    group of rays (by their blur; rays ``starts[g]`` to ``starts[g + 1]``), their columns term by
    term, ``past`` the terminators' (:func:`edges_model`); the products with ``bases`` are BLAS's
    (numpy's ``dot``). ``models``: each ray's model, -1 until chosen (updated in place).
    """
    prof = profiles(img, cx, cy, r, rad, cos, sin)
    y, yy = centred(prof)
    step = ends_step(prof)[1]
    p = np.empty((y.shape[0], bases.shape[2]))
    for g in range(bases.shape[0]):
        p[starts[g] : starts[g + 1]] = np.dot(y[starts[g] : starts[g + 1]], bases[g])
    edge, chi2 = edges_model(p, y, yy, past, starts, cand, step, sigma, rad.size, models)
    keep = (step > np.float32(6 * sigma)) & (chi2 < 2.0) & kept
    px, py = cx + cos * (r + edge), cy + sin * (r + edge)
    fitted, fx, fy, fr, res, keep = circle_robust(px, py, keep, min_kept)
    return fitted, fx, fy, fr, res, keep, step


# -- the searches (:mod:`ballbat.video.search`) -----------------------------------------------


@_jit
def _reflect(i, n):
    """Return the index that ``mode="reflect"`` (d c b a | a b c d | d c b a) reads at ``i`` of a line of ``n``."""
    i %= 2 * n
    return i if i < n else 2 * n - 1 - i


@_jit
def uniform_filter(a: np.ndarray, size: int) -> np.ndarray:
    """Return ``scipy.ndimage.uniform_filter(a, size)`` of a float32 image, as scipy computes it.

    Along axis 0 then axis 1 (``mode="reflect"``), each line a running sum in float64 divided by
    ``size`` (the first window's sum, then plus the sample entering less the one leaving),
    stored in float32 between the axes.
    """
    h, w = a.shape
    before = size // 2
    rows = np.empty(h + size - 1, np.int64)  # the rows (then columns) each position of the extended line reads
    for i in range(h + size - 1):
        rows[i] = _reflect(i - before, h)
    mid = np.empty((h, w), np.float32)
    tmp = np.zeros(w)
    for i in range(size):  # axis 0: every column at once, row by row
        src = a[rows[i]]
        for j in range(w):
            tmp[j] += src[j]
    for j in range(w):
        mid[0, j] = tmp[j] / size
    for i in range(1, h):
        enter, leave = a[rows[i + size - 1]], a[rows[i - 1]]
        for j in range(w):
            tmp[j] += np.float64(enter[j]) - np.float64(leave[j])
            mid[i, j] = tmp[j] / size
    cols = np.empty(w + size - 1, np.int64)
    for i in range(w + size - 1):
        cols[i] = _reflect(i - before, w)
    out = np.empty((h, w), np.float32)
    ext = np.empty(w + size - 1)
    for k in range(h):  # axis 1: each row
        for i in range(w + size - 1):
            ext[i] = mid[k, cols[i]]
        t = 0.0
        for i in range(size):
            t += ext[i]
        out[k, 0] = t / size
        for i in range(1, w):
            t += ext[i + size - 1] - ext[i - 1]
            out[k, i] = t / size
    return out


@_jit
def _root(parent, a):
    """Return the root of ``a`` in the union-find forest ``parent``, halving the path."""
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@_jit
def label(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """Return ``scipy.ndimage.label(mask)`` (4-connected): the labels (int32) and their number.

    Numbered as scipy numbers them: in the order of each region's first pixel, row by row.
    """
    h, w = mask.shape
    lab = np.zeros((h, w), np.int32)
    parent = np.empty(h * w // 2 + 2, np.int64)
    nxt = 1
    for i in range(h):
        for j in range(w):
            if not mask[i, j]:
                continue
            up = lab[i - 1, j] if i > 0 else 0
            left = lab[i, j - 1] if j > 0 else 0
            if up == 0 and left == 0:
                if nxt >= parent.size:
                    grown = np.empty(2 * parent.size, np.int64)
                    grown[: parent.size] = parent
                    parent = grown
                parent[nxt] = nxt
                lab[i, j] = nxt
                nxt += 1
            elif up == 0 or left == 0 or up == left:
                lab[i, j] = max(up, left)
            else:
                a, b = _root(parent, up), _root(parent, left)
                lo = min(a, b)
                parent[a] = parent[b] = lo
                lab[i, j] = lo
    final = np.zeros(nxt, np.int32)
    n = 0
    for k in range(1, nxt):  # roots in the order they were made: each region's first pixel, row by row
        rk = _root(parent, k)
        if rk == k:
            n += 1
            final[k] = n
    for i in range(h):
        for j in range(w):
            if lab[i, j]:
                lab[i, j] = final[_root(parent, lab[i, j])]
    return lab, n


@_jit
def _beyond(dx, dy, rad):
    """Return the sign of np.hypot(dx, dy) - rad, exactly: from the squares, by hypot only where they are near."""
    if rad <= 0:
        return 1
    dd, bb = dx * dx + dy * dy, rad * rad
    if dd < bb * (1 - 1e-9):
        return -1
    if dd > bb * (1 + 1e-9):
        return 1
    d = np.hypot(dx, dy)
    return -1 if d < rad else (1 if d > rad else 0)


@_jit
def _median32(v):
    """Return ``np.median`` of float32 values, in float32 as numpy takes it (the mean of the middle two in float32)."""
    n = v.size
    s = np.partition(v, n // 2)  # the middle one in place, the smaller ones before it
    if n % 2:
        return s[n // 2]
    return (s[: n // 2].max() + s[n // 2]) / np.float32(2.0)


@_jit
def _marker_at(sub, mx, my, mr):
    """Return (the end cap's level, found, centroid x, y) of a spot at (mx, my) (:func:`.search._marker_at`)."""
    h, w = sub.shape
    ws = int(np.ceil(2.5 * mr)) + 1
    ya, xa = max(int(my) - ws, 0), max(int(mx) - ws, 0)
    yb, xb = min(int(my) + ws + 1, h), min(int(mx) + ws + 1, w)
    ring = np.empty((yb - ya) * (xb - xa), np.float32)
    nr = 0
    for i in range(ya, yb):
        for j in range(xa, xb):
            if _beyond(j - mx, i - my, 1.5 * mr) > 0 and _beyond(j - mx, i - my, 2.5 * mr) < 0:
                ring[nr] = sub[i, j]
                nr += 1
    if nr == 0:
        return np.nan, False, 0.0, 0.0
    level = _median32(ring[:nr])
    tot = sx = sy = 0.0
    for i in range(ya, yb):
        for j in range(xa, xb):
            if _beyond(j - mx, i - my, 1.3 * mr) < 0:
                v = max(sub[i, j] - level, np.float32(0.0))
                tot += v
                sx += v * j
                sy += v * i
    if not tot > 0:
        return float(level), False, 0.0, 0.0
    return float(level), True, sx / tot, sy / tot


@_jit
def marker_search(sub: np.ndarray, cx: float, cy: float, mr: float, sigma: float, top: float) -> tuple:
    """Return the tip marker nearest (cx, cy) in the region ``sub`` (float32, its pixels): :func:`.search.find_marker`.

    (found, x, y, contrast); ``top`` NaN: the region's brightest value. The spots are tried
    nearest first, until no further one can give a nearer marker (its centre is within 1.3
    marker radii of its spot's).
    """
    lab, n = label(sub - uniform_filter(sub, int(4 * mr + 1)) > np.float32(8 * sigma))
    if n == 0:
        return False, 0.0, 0.0, 0.0
    area, sums = _label_sums(lab, n, sub)
    top = float(sub.max()) if np.isnan(top) else top
    ok = np.flatnonzero((area > 0.3 * np.pi * mr**2) & (area < 2.0 * np.pi * mr**2))
    mx, my = sums[ok, 1] / sums[ok, 0], sums[ok, 2] / sums[ok, 0]  # the spots' brightness-weighted centroids
    near = np.hypot(mx - cx, my - cy)
    found, bx, by, bc, bd = False, 0.0, 0.0, 0.0, 0.0
    for i in np.argsort(near, kind="mergesort"):
        if found and near[i] - 1.3 * mr > bd + 1e-9:  # no further spot can give a nearer marker
            break
        if not (np.isfinite(mx[i]) and np.isfinite(my[i])):
            continue
        level, centred_ok, x, y = _marker_at(sub, mx[i], my[i], mr)
        if not centred_ok:
            continue
        contrast = float(np.float32(sums[ok[i], 0] / area[ok[i]]) - np.float32(level))  # as numpy's float32 mean
        d = np.hypot(x - cx, y - cy)
        if contrast > 0.3 * (top - level) and (not found or d < bd):
            found, bx, by, bc, bd = True, x, y, contrast, d
    return found, bx, by, bc


@_jit
def _label_sums(lab, n, weights):
    """Return each label's area, and its sums of the weights and of the weights times x and times y (rows by label)."""
    h, w = lab.shape
    area = np.zeros(n + 1, np.int64)
    sums = np.zeros((n + 1, 3))
    for i in range(h):
        for j in range(w):
            k = lab[i, j]
            if k:
                v = weights[i, j]
                area[k] += 1
                sums[k, 0] += v
                sums[k, 1] += v * j
                sums[k, 2] += v * i
    return area, sums


@_jit
def _extreme_rows(src, size, is_max):
    """Return the running maximum (or minimum) over ``size`` (odd) along each row, transposed.

    The window is cut at the ends, as "reflect" reads it (only values inside the window cut
    there).

    van Herk's: the row padded by -inf (+inf) and cut into blocks of ``size``; each window spans
    at most two blocks, so its extreme is that of the first block's suffix and the second's prefix.
    """
    h, n = src.shape
    half = size // 2
    m = ((n + 2 * half + size - 1) // size) * size
    sign = np.float32(1.0) if is_max else np.float32(-1.0)  # a minimum is the maximum of the negated values
    line = np.full(m, -np.inf, np.float32)
    pre = np.empty(m, np.float32)
    suf = np.empty(m, np.float32)
    out = np.empty((n, h), np.float32)
    for k in range(h):
        for i in range(n):
            line[half + i] = sign * src[k, i]
        for a in range(0, m, size):
            z = a + size
            v = line[a]
            pre[a] = v
            for i in range(a + 1, z):
                v = v if v > line[i] else line[i]
                pre[i] = v
            v = line[z - 1]
            suf[z - 1] = v
            for i in range(z - 2, a - 1, -1):
                v = v if v > line[i] else line[i]
                suf[i] = v
        for i in range(n):  # the window [i, i + size) of the padded row
            p, q = suf[i], pre[i + size - 1]
            out[i, k] = sign * (p if p > q else q)
    return out


@_jit
def grey_closing(a: np.ndarray, size: int) -> np.ndarray:
    """Return ``scipy.ndimage.grey_closing(a, size=(size, size))`` of a float32 image, for an odd ``size``.

    The maximum over the square, then the minimum (each separable; the order of the axes does
    not change an extreme).
    """
    t = _extreme_rows(a, size, True)  # each pass returns its result transposed: the next runs along the other axis
    t = _extreme_rows(t, size, True)
    t = _extreme_rows(t, size, False)
    return _extreme_rows(t, size, False)


@_jit
def dots_search(
    sub: np.ndarray, x0: int, y0: int, cx: float, cy: float, r: float, dot_r: float, sigma: float
) -> tuple[np.ndarray, int]:
    """Return the dark spots inside the ball (:func:`.search.find_dots`) in its region ``sub`` (float32) at (x0, y0).

    The spots (x, y, contrast, distance / radius; rows in the order of their labels) and 0, or
    none and -1 where nothing inside the ball is dark enough.
    """
    h, w = sub.shape
    dark = grey_closing(sub, int(2 * np.ceil(2 * dot_r) + 1)) - sub
    inside = np.empty((h, w), np.bool_)
    ball_px = np.empty(h * w, np.float32)
    nb = 0
    for i in range(h):
        for j in range(w):
            inside[i, j] = _beyond(j + x0 - cx, i + y0 - cy, r - 2) < 0
            if inside[i, j]:
                ball_px[nb] = sub[i, j]
                nb += 1
    # a dot is dark: more than 5 noise sigma and a third of the ball's own level below the shading
    thr = np.float32(max(5 * sigma, float(_median32(ball_px[:nb])) / 3) if nb else 5 * sigma)
    lab, n = label((dark > thr) & inside)
    out = np.empty((n, 4))
    if n == 0:
        return out, -1
    area, boxes = _boxes(lab, n)
    m = 0
    for k in range(1, n + 1):
        if area[k] >= max(0.25 * np.pi * dot_r**2, 3):
            x, y, deepest = _spot(lab, k, boxes[k], dark, inside)
            x, y = x + x0, y + y0
            out[m, 0], out[m, 1], out[m, 2], out[m, 3] = x, y, deepest, np.hypot(x - cx, y - cy) / r
            m += 1
    return out[:m], 0


@_jit
def _boxes(lab, n):
    """Return each label's area and box (first row, row past the last, first column, column past the last)."""
    h, w = lab.shape
    area = np.zeros(n + 1, np.int64)
    boxes = np.empty((n + 1, 4), np.int64)
    boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3] = h, 0, w, 0
    for i in range(h):
        for j in range(w):
            k = lab[i, j]
            if k:
                area[k] += 1
                boxes[k, 0], boxes[k, 1] = min(boxes[k, 0], i), max(boxes[k, 1], i + 1)
                boxes[k, 2], boxes[k, 3] = min(boxes[k, 2], j), max(boxes[k, 3], j + 1)
    return area, boxes


@_jit
def _spot(lab, k, box, dark, inside):
    """Return spot ``k``'s darkness-weighted centroid (x, y) over it grown by 2 px inside the ball, and its darkest.

    Grown as by two binary dilations by the cross: the pixels within 2 px, city block, of the
    spot, in its box grown by 2 px.
    """
    h, w = lab.shape
    ya, yb, xa, xb = max(box[0] - 2, 0), min(box[1] + 2, h), max(box[2] - 2, 0), min(box[3] + 2, w)
    tot = sx = sy = 0.0
    deepest = -np.inf
    for i in range(ya, yb):
        for j in range(xa, xb):
            if lab[i, j] == k:
                deepest = max(deepest, dark[i, j])
            if not inside[i, j]:
                continue
            near = False
            for di in range(-2, 3):
                for dj in range(abs(di) - 2, 3 - abs(di)):
                    ii, jj = i + di, j + dj
                    if ya <= ii < yb and xa <= jj < xb and lab[ii, jj] == k:
                        near = True
            if near:
                v = max(dark[i, j], np.float32(0.0))
                tot += v
                sx += v * j
                sy += v * i
    return sx / tot, sy / tot, deepest


@_jit
def _shading(sub, x0, y0, x, y, cx, cy, r, dot_r, core_k, ring_k):
    """Return the quadratic shading fitted on the ring round a dot at (x, y), and whether there was one.

    As :func:`.search._shading_fit`: least squares on the ring, then again without the pixels
    darker than it by 4 robust sd. The shading on the window, (h, w), float64.
    """
    h, w = sub.shape
    rows = np.empty((h * w, 6))
    vals = np.empty(h * w)
    at = np.empty(h * w, np.int64)
    n = 0
    for i in range(h):
        for j in range(w):
            gx, gy = j + x0, i + y0
            d = np.hypot(gx - x, gy - y)
            if np.hypot(gx - cx, gy - cy) < r - 2.0 and core_k * dot_r + 1.0 < d < ring_k * dot_r + 1.0:
                u, v = (gx - x) / dot_r, (gy - y) / dot_r
                rows[n, 0], rows[n, 1], rows[n, 2], rows[n, 3], rows[n, 4], rows[n, 5] = 1.0, u, v, u * u, u * v, v * v
                vals[n] = sub[i, j]
                at[n] = i * w + j
                n += 1
    coef = np.zeros(6)
    if n < 12:
        return coef, False
    keep = np.ones(n, np.bool_)
    for _ in range(2):
        A = rows[:n][keep[:n]]
        coef = np.linalg.solve(A.T @ A, A.T @ vals[:n][keep[:n]])
        res = vals[:n] - rows[:n] @ coef
        s = 1.4826 * np.median(np.abs(res[keep[:n]]))
        keep[:n] = res > -4 * max(s, 1e-9)
    return coef, True


@_jit
def dot_refine(sub, x0, y0, x, y, cx, cy, r, dot_r, core_k, ring_k, passes):
    """Return a dot's centroid weighted by the light it takes from the shading (:func:`.search.refine_dot`).

    ``sub`` (float64) is the frame's region at (x0, y0) holding the dot's window for every pass.
    """
    h, w = sub.shape
    for _ in range(passes):
        coef, ok = _shading(sub, x0, y0, x, y, cx, cy, r, dot_r, core_k, ring_k)
        if not ok:
            return x, y
        tot = sx = sy = 0.0
        for i in range(h):
            for j in range(w):
                gx, gy = j + x0, i + y0
                if np.hypot(gx - x, gy - y) < core_k * dot_r and np.hypot(gx - cx, gy - cy) < r - 2.0:
                    u, v = (gx - x) / dot_r, (gy - y) / dot_r
                    shade = coef[0] + coef[1] * u + coef[2] * v + coef[3] * u * u + coef[4] * u * v + coef[5] * v * v
                    wt = max(1.0 - sub[i, j] / max(shade, 1e-9), 0.0)
                    tot += wt
                    sx += wt * gx
                    sy += wt * gy
        if not tot > 0:
            return x, y
        x, y = sx / tot, sy / tot
    return x, y


def load(dtype: type = np.uint8) -> None:
    """Load every kernel the tracker calls on frames of ``dtype`` (compiling any not in the cache).

    What a process pays once, before its first frame (about 0.2 s of CPU from the cache, 17 s to
    compile; docs/video.md, "Speed"). ``bench/bench_video.py`` calls it before it times the
    tracker. The arguments are of the types the tracker passes (their values do not matter).
    """
    img = np.zeros((80, 80), dtype)
    ray = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    cos, sin = np.cos(ray), np.sin(ray)
    wide, samples, cand = np.arange(-10.0, 10.01, 0.5), np.arange(-5.0, 5.01, 0.5), np.arange(-3.0, 3.0001, 0.1)
    inside(img, 40.0, 40.0, 15.0)
    gradient_pass(img, 40.0, 40.0, 5.0, wide, cos, sin, 1.0, 24)
    bases, past = np.zeros((1, samples.size, 6 * cand.size)), np.zeros((1, samples.size, 4 * cand.size))
    starts, kept = np.array([0, 48]), np.ones(48, np.bool_)
    models = np.full(48, -1)
    model_pass(img, 40.0, 40.0, 5.0, samples, cos, sin, bases, past, starts, cand, 1.0, kept, models, 24)
    marker_search(np.zeros((40, 40), np.float32), 20.0, 20.0, 4.0, 1.0, np.nan)
    dots_search(np.zeros((40, 40), np.float32), 0, 0, 20.0, 20.0, 15.0, 2.0, 1.0)
    dot_refine(np.ones((40, 40)), 0, 0, 20.0, 20.0, 20.0, 20.0, 15.0, 2.0, 1.4, 2.6, 2)
