"""Where the ball, its dots and the tip marker are in a frame or a region of it (docs/video.md, "The tracker").

The searches of :mod:`ballbat.video.track`, each written for speed (issue 38): label statistics
by ``np.bincount`` (one pass for every label), each spot's own work in a window about it (not
the whole region), and the whole frame searched at quarter resolution (:func:`block_sum`),
only where no prediction is at hand. The marker's and the dots' searches in their regions run
compiled (:mod:`ballbat.video.kernels`); the numpy here is their reference (``compiled=False``).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage


def roi(img: np.ndarray, cx: float, cy: float, half: float) -> tuple[np.ndarray, int, int]:
    """Return the square of half-side ``half`` about (cx, cy), clipped to the frame, and its origin."""
    x0, y0 = max(int(cx - half), 0), max(int(cy - half), 0)
    return img[y0 : int(cy + half) + 1, x0 : int(cx + half) + 1], x0, y0


def block_sum(img: np.ndarray, s: int) -> np.ndarray:
    """Return the sums of the frame's s x s blocks (the last rows and columns short of a block dropped)."""
    h, w = (img.shape[0] // s) * s, (img.shape[1] // s) * s
    acc = np.uint16 if img.dtype == np.uint8 and s <= 16 else np.float64
    rows = img[0:h:s, :w].astype(acc)
    for i in range(1, s):
        rows += img[i:h:s, :w]
    out = rows[:, 0::s].copy()
    for i in range(1, s):
        out += rows[:, i::s]
    return out


def _median_top(v: np.ndarray, q: float) -> tuple[float, float]:
    """Return the median and the ``q`` percentile (linear, as numpy's) of ``v``; exact, by a histogram for integers."""
    if v.dtype != np.uint16:
        return float(np.median(v)), float(np.percentile(v, q))
    cum = np.cumsum(np.bincount(v.ravel()))
    n = cum[-1]

    def at(k):  # the k-th smallest value (from 0)
        return float(np.searchsorted(cum, k + 1))

    mid = at(n // 2) if n % 2 else 0.5 * (at(n // 2 - 1) + at(n // 2))
    pos = q / 100 * (n - 1)
    lo = int(np.floor(pos))
    top = at(lo) + (pos - lo) * (at(min(lo + 1, n - 1)) - at(lo))
    return mid, top


def median_of(v: np.ndarray) -> float:
    """Return ``np.median`` of a 1-d float array without NaNs: the same partition and mean, minus its overhead."""
    n = v.size
    k = n // 2
    if n % 2:
        return float(np.partition(v, k)[k])
    s = np.partition(v, (k - 1, k))
    return float((s[k - 1] + s[k]) / 2)


#: The offsets within 2 px in city-block distance: two binary dilations by the cross, as one.
_DIAMOND2 = [(dy, dx) for dy in range(-2, 3) for dx in range(-2, 3) if abs(dy) + abs(dx) <= 2]


def _grown2(mask: np.ndarray) -> np.ndarray:
    """Return ``ndimage.binary_dilation(mask, iterations=2)`` (the cross twice; outside the array is False)."""
    h, w = mask.shape
    pad = np.zeros((h + 4, w + 4), bool)
    pad[2:-2, 2:-2] = mask
    out = np.zeros_like(mask)
    for dy, dx in _DIAMOND2:
        out |= pad[2 + dy : 2 + dy + h, 2 + dx : 2 + dx + w]
    return out


def _centroids(lab: np.ndarray, labels: np.ndarray, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray, list]:
    """Return the ``weights``-weighted centroids (x, y) of ``labels`` in the labelled array, and their boxes.

    Each label's work is in its own box (``ndimage.find_objects``), not the whole array.
    """
    objs = ndimage.find_objects(lab)
    mx, my, boxes = np.empty(labels.size), np.empty(labels.size), []
    for i, j in enumerate(labels):
        sl = objs[j - 1]
        wv = np.where(lab[sl] == j, weights[sl], 0)
        tot = wv.sum()
        mx[i] = (wv.sum(axis=0) @ np.arange(sl[1].start, sl[1].stop)) / tot
        my[i] = (wv.sum(axis=1) @ np.arange(sl[0].start, sl[0].stop)) / tot
        boxes.append(sl)
    return mx, my, boxes


def find_balls(img: np.ndarray, radius: float, tol: float) -> list[tuple[float, float]]:
    """Return the rough centres of every bright disc of about ``radius`` in the frame (quarter resolution)."""
    s = 4 if radius >= 12 else 2
    sums = block_sum(img, s)
    if sums.size == 0:  # a region (about a prediction) that is off the frame
        return []
    med, top = _median_top(sums, 99.9)
    lab, n = ndimage.label(sums > med + 0.6 * (top - med))
    if n == 0:
        return []
    area = np.bincount(lab.ravel(), minlength=n + 1)[1:] * s * s
    expect = np.pi * radius**2
    ok = np.flatnonzero((area > (1 - tol) ** 2 * expect * 0.5) & (area < (1 + tol) ** 2 * expect)) + 1
    out = []
    for x, y, sl in zip(*_centroids(lab, ok, sums), strict=True):  # round: about as wide as high, at most 2r
        bh, bw = (sl[0].stop - sl[0].start) * s, (sl[1].stop - sl[1].start) * s
        if max(bh, bw) <= 2 * radius * (1 + tol) + 2 * s and min(bh, bw) >= 0.5 * max(bh, bw):
            out.append(((x + 0.5) * s - 0.5, (y + 0.5) * s - 0.5))
    return out


def find_dots(
    img: np.ndarray, ball: tuple, dot_r: float, sigma: float, compiled: bool = True
) -> tuple[list, str | None]:
    """Return the dark spots inside the ball: [(x, y, contrast, distance / radius)], or the reason they are left out.

    Compiled (:func:`ballbat.video.kernels.dots_search`); ``compiled=False`` runs the numpy
    reference it is checked against.
    """
    cx, cy, r = ball[:3]
    sub, x0, y0 = roi(img, cx, cy, r + 2)
    sub = sub.astype(np.float32)  # the region only, not the whole frame
    if compiled:
        from . import kernels  # numba only where the dots are searched

        spots, status = kernels.dots_search(sub, x0, y0, cx, cy, r, dot_r, sigma)
        if status < 0:
            return [], "no dot seen on the ball"
        return [(float(x), float(y), float(c), float(d)) for x, y, c, d in spots.tolist()], None
    size = int(2 * np.ceil(2 * dot_r) + 1)
    dark = ndimage.grey_closing(sub, size=(size, size)) - sub
    yy, xx = np.arange(sub.shape[0])[:, None], np.arange(sub.shape[1])[None, :]
    inside = np.hypot(xx + x0 - cx, yy + y0 - cy) < r - 2
    # a dot is dark: more than 5 noise sigma and a third of the ball's own level below the shading
    ball_px = sub[inside]
    level = max(5 * sigma, median_of(ball_px) / 3) if ball_px.size else 5 * sigma
    lab, n = ndimage.label((dark > level) & inside)
    if n == 0:
        return [], "no dot seen on the ball"
    area = np.bincount(lab.ravel(), minlength=n + 1)[1:]
    out = []
    objs = ndimage.find_objects(lab)
    for j in np.flatnonzero(area >= max(0.25 * np.pi * dot_r**2, 3)) + 1:
        win = tuple(slice(max(q.start - 2, 0), q.stop + 2) for q in objs[j - 1])  # the spot grown by 2 px
        spot = lab[win] == j
        m = _grown2(spot) & inside[win]
        wgt = np.where(m, np.maximum(dark[win], 0), 0)
        tot = wgt.sum()
        x = (wgt * xx[:, win[1]]).sum() / tot + x0
        y = (wgt * yy[win[0], :]).sum() / tot + y0
        out.append((float(x), float(y), float(dark[win][spot].max()), float(np.hypot(x - cx, y - cy) / r)))
    return out, None


#: The dot's refinement (:func:`refine_dot`): the disc it is weighed in and the ring the ball's shading is
#: fitted on, in dot radii (the ring from 1 px beyond the disc), and its passes.
DOT_CORE, DOT_RING, DOT_PASSES = 1.4, 2.6, 2


def _shading_fit(sub: np.ndarray, A: np.ndarray, ring: np.ndarray) -> np.ndarray:
    """Return the ball's shading on the window: a quadratic fitted to ``ring``, then again without its dark outliers."""
    good = ring
    for _ in range(2):
        coef = np.linalg.lstsq(A[good], sub[good], rcond=None)[0]
        res = sub - A @ coef
        s = 1.4826 * float(np.median(np.abs(res[good])))
        good = ring & (res > -4 * max(s, 1e-9))  # another spot, a scratch: darker than the shading
    return A @ coef


def refine_dot(
    img: np.ndarray, x: float, y: float, ball: tuple, dot_r: float, compiled: bool = True
) -> tuple[float, float]:
    """Return a dot's centroid weighted by the light it takes away from the ball's shading there.

    A dot on the ball multiplies the shading by its darkness (1 - 0.85 of its coverage, for
    the renderer's); the shading about it is a quadratic in x and y fitted on a ring round the
    dot (from 1 px beyond :data:`DOT_CORE` dot radii to :data:`DOT_RING`, on the ball), and the
    centroid is weighted by 1 - image / shading over the disc of :data:`DOT_CORE` radii, twice
    (the disc re-centred). The search's centroid (:func:`find_dots`, weighted by the darkness
    under a grey closing) leans with the shading's gradient and curvature: 0.07-0.09 px RMS on
    noise-free 29-px balls, 0.03-0.04 px after this (docs/video.md, "The tracker"). Compiled
    (:func:`ballbat.video.kernels.dot_refine`); ``compiled=False`` runs this numpy reference.
    """
    cx, cy, r = ball[:3]
    if compiled:
        from . import kernels

        half = DOT_RING * dot_r + 2 + DOT_PASSES * dot_r  # every pass's window: the dot moves by under a radius
        sub, x0, y0 = roi(img, x, y, half)
        return kernels.dot_refine(
            sub.astype(np.float64), x0, y0, x, y, cx, cy, r, dot_r, DOT_CORE, DOT_RING, DOT_PASSES
        )
    for _ in range(DOT_PASSES):
        half = DOT_RING * dot_r + 2
        sub, x0, y0 = roi(img, x, y, half)
        sub = sub.astype(np.float64)
        gy, gx = np.mgrid[y0 : y0 + sub.shape[0], x0 : x0 + sub.shape[1]]
        d = np.hypot(gx - x, gy - y)
        on_ball = np.hypot(gx - cx, gy - cy) < r - 2.0
        ring = (d > DOT_CORE * dot_r + 1.0) & (d < DOT_RING * dot_r + 1.0) & on_ball
        core = (d < DOT_CORE * dot_r) & on_ball
        if ring.sum() < 12 or not core.any():
            return x, y
        u, v = (gx - x) / dot_r, (gy - y) / dot_r
        A = np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], axis=-1)
        shade = _shading_fit(sub, A, ring)
        w = np.where(core, np.maximum(1 - sub / np.maximum(shade, 1e-9), 0), 0)
        tot = w.sum()
        if not tot > 0:
            return x, y
        x, y = float((w * gx).sum() / tot), float((w * gy).sum() / tot)
    return x, y


#: The marker's refinement (:func:`refine_marker`): the light's gradient fitted within MARKER_CORE marker radii,
#: the centroid taken within 1.3 of them, MARKER_PASSES times.
MARKER_CORE = 0.8
MARKER_PASSES = 2


def refine_marker(img: np.ndarray, x: float, y: float, mr: float) -> tuple[float, float]:
    """Return the tip marker's centroid with the light's gradient across it taken out.

    The marker is lit as the rest of the frame is, so under uneven lighting one side of it is
    brighter and a brightness-weighted centroid leans that way, by the gradient times mr^2 / 4:
    about 0.005 px under the renderer's default lighting, varying along the swing, which made
    bat speeds 2e-5 low (docs/video.md, "The tracker"). A plane fitted to the marker's
    plateau (within :data:`MARKER_CORE` radii, inside the blur) gives the relative gradient;
    the centroid of the frame divided by it, above the end cap's level, within 1.3 radii, twice.
    """
    sub, x0, y0 = roi(img, x, y, int(np.ceil(2.5 * mr)) + 3)  # every pass's window: a pass moves it under a pixel
    sub = sub.astype(np.float64)
    gx = np.arange(x0, x0 + sub.shape[1], dtype=np.float64)[None, :]
    gy = np.arange(y0, y0 + sub.shape[0], dtype=np.float64)[:, None]
    for _ in range(MARKER_PASSES):
        u, v = gx - x, gy - y
        d2 = u * u + v * v
        ring = (d2 > (1.5 * mr) ** 2) & (d2 < (2.5 * mr) ** 2)
        core = d2 < (MARKER_CORE * mr) ** 2
        if ring.sum() < 12 or core.sum() < 6:
            return x, y
        level = float(np.median(sub[ring]))
        uc, vc = np.broadcast_to(u, sub.shape)[core], np.broadcast_to(v, sub.shape)[core]
        A = np.stack([np.ones_like(uc), uc, vc], axis=1)
        a, bx, by = np.linalg.solve(A.T @ A, A.T @ sub[core])  # the plane's least squares
        if not a > level:
            return x, y
        w = np.where(d2 < (1.3 * mr) ** 2, np.maximum(sub / (1.0 + (bx * u + by * v) / a) - level, 0.0), 0.0)
        tot = w.sum()
        if not tot > 0:
            return x, y
        x, y = float((w * gx).sum() / tot), float((w * gy).sum() / tot)
    return x, y


def _marker_at(sub, mx, my, mr):
    """Return the end cap's level round a spot centred at (mx, my), and the brightness-weighted centroid above it."""
    ws = int(np.ceil(2.5 * mr)) + 1
    ya, xa = max(int(my) - ws, 0), max(int(mx) - ws, 0)
    win = sub[ya : int(my) + ws + 1, xa : int(mx) + ws + 1]
    gy, gx = np.arange(ya, ya + win.shape[0])[:, None], np.arange(xa, xa + win.shape[1])[None, :]
    d = np.hypot(gx - mx, gy - my)
    level = median_of(win[(d > 1.5 * mr) & (d < 2.5 * mr)])  # the end cap round the marker
    core = d < 1.3 * mr
    wgt = np.maximum(win - level, 0) * core
    tot = wgt.sum()
    if tot <= 0:
        return level, None
    return level, ((wgt * gx).sum() / tot, (wgt * gy).sum() / tot)


def find_marker(
    img: np.ndarray,
    cx: float,
    cy: float,
    half: float,
    mr: float,
    sigma: float,
    top: float | None = None,
    compiled: bool = True,
) -> tuple | None:
    """Return the tip marker (a bright disc of radius ``mr`` in a dark surround) nearest (cx, cy): (x, y, contrast).

    A spot's contrast must be over 0.3 of the brightest value's above its surround (``top``:
    the region's brightest, unless given). Compiled (:func:`ballbat.video.kernels.marker_search`);
    ``compiled=False`` runs the numpy reference it is checked against.
    """
    sub, x0, y0 = roi(img, cx, cy, half)
    sub = sub.astype(np.float32)  # the region only, not the whole frame
    if min(sub.shape) < 2 * mr:
        return None
    if compiled:
        from . import kernels  # numba only where the marker is searched

        found, x, y, contrast = kernels.marker_search(sub, cx - x0, cy - y0, mr, sigma, np.nan if top is None else top)
        return (x + x0, y + y0, contrast) if found else None
    local = ndimage.uniform_filter(sub, size=int(4 * mr + 1))
    lab, n = ndimage.label(sub - local > 8 * sigma)
    if n == 0:
        return None
    area = np.bincount(lab.ravel(), minlength=n + 1)[1:]
    ok = np.flatnonzero((area > 0.3 * np.pi * mr**2) & (area < 2.0 * np.pi * mr**2)) + 1
    top = float(sub.max()) if top is None else top
    best = None
    mx, my, boxes = _centroids(lab, ok, sub)
    # the spots nearest first: a marker's centre is within 1.3 mr of its spot's, so a spot further than the best
    # marker so far by more than that cannot give a nearer one (the same marker as trying every spot)
    near = np.hypot(mx + x0 - cx, my + y0 - cy)
    for i in np.argsort(near, kind="stable"):
        if best is not None and near[i] - 1.3 * mr > best[3] + 1e-9:
            break
        level, c = _marker_at(sub, mx[i], my[i], mr)
        if c is None:
            continue
        x, y = c[0] + x0, c[1] + y0
        sl = boxes[i]
        contrast = float(sub[sl][lab[sl] == ok[i]].mean() - level)
        if contrast > 0.3 * (top - level) and (best is None or np.hypot(x - cx, y - cy) < best[3]):
            best = (float(x), float(y), contrast, float(np.hypot(x - cx, y - cy)))
    return best[:3] if best else None


def find_marker_whole(img: np.ndarray, mr: float, sigma: float, avoid: list | tuple = ()) -> tuple | None:
    """Return the tip marker nearest the frame's centre, searched in the whole frame: (x, y, contrast).

    ``avoid``: positions (x, y) of still spots of the background; a marker within 2 ``mr`` of one is not taken.

    Bright spots of about the marker's size are looked for at quarter resolution (block means:
    2 sigma above their surround, 0.1 to 4 times the marker's area), and each is then searched
    for at full resolution in a region about it, as a predicted marker is (:func:`find_marker`,
    against the frame's brightest value).
    """
    s = 4 if mr >= 6 else 2
    small = block_sum(img, s).astype(np.float32) / (s * s)
    local = ndimage.uniform_filter(small, size=int((4 * mr + 1) / s) | 1)
    lab, n = ndimage.label(small - local > 2 * sigma)
    if n == 0:
        return None
    area = np.bincount(lab.ravel(), minlength=n + 1)[1:] * s * s
    ok = np.flatnonzero((area > 0.1 * np.pi * mr**2) & (area < 4.0 * np.pi * mr**2)) + 1
    mx, my, _ = _centroids(lab, ok, small)
    h, w = img.shape
    top = float(img.max())
    best = None
    xs, ys = (mx + 0.5) * s - 0.5, (my + 0.5) * s - 0.5
    # the spots nearest the centre first: a marker taken is within 2 mr of its spot, so a spot further than the
    # best marker so far by more than that cannot give a nearer one (the same marker as trying every spot)
    near = np.hypot(xs - w / 2, ys - h / 2)
    for i in np.argsort(near, kind="stable"):
        if best is not None and near[i] - 2 * mr > best[3] + 1e-9:
            break
        x, y = xs[i], ys[i]
        m = find_marker(img, x, y, 4 * mr + 20, mr, sigma, top)
        if m is None or np.hypot(m[0] - x, m[1] - y) > 2 * mr:  # another spot's, near the region's border
            continue
        if any(np.hypot(m[0] - ax, m[1] - ay) < 2 * mr for ax, ay in avoid):
            continue
        if best is None or np.hypot(m[0] - w / 2, m[1] - h / 2) < best[3]:
            best = (*m, float(np.hypot(m[0] - w / 2, m[1] - h / 2)))
    return best[:3] if best else None


def ball_centroid(img: np.ndarray, cx: float, cy: float, r: float, sigma: float) -> tuple[tuple, str | None]:
    """Return a small ball's centre near (x, y) by its brightness-weighted centroid: ((x, y, r, nan, contrast), None).

    Or ((), the reason it is left out). For a ball too small for the edge model (a few pixels in
    radius: its edge too short for 48 rays, its rays crossing its centre). The ground is the
    median of a ring 1.5-2 radii out; the weights are the brightness above it inside 1.5
    radii of the current centre, capped at half the peak, so that the disc weighs about evenly
    however it is lit (a plain brightness weighting leans towards the lit side: 0.3 px on a
    drawn 4.5-px ball lit from above, 0.09 px capped, tests/video/test_search.py), recentred
    until the centre moves by under 0.01 px (at most 10 times). The radius is that of
    the disc as large as the pixels brighter than half the peak. Left out: the disc within 2
    radii of the frame's border, a peak under 6 noise sigma above the ground, a centre that
    does not settle.
    """
    h, w = img.shape
    half = 2 * r + 2
    moved = np.inf
    for _ in range(10):
        if min(cx, cy, w - 1 - cx, h - 1 - cy) < half:
            return (), "ball touches the frame's border"
        sub, x0, y0 = roi(img, cx, cy, half)
        sub = sub.astype(np.float64)
        yy, xx = np.ogrid[y0 : y0 + sub.shape[0], x0 : x0 + sub.shape[1]]
        d = np.hypot(xx - cx, yy - cy)
        level = float(np.median(sub[(d > 1.5 * r) & (d < 2 * r)]))
        above = np.clip(sub - level, 0, None) * (d < 1.5 * r)
        peak = float(above.max())
        if peak < 6 * sigma:
            return (), f"no ball: the brightest point {peak:.0f} above the ground, under 6 noise sigma"
        wgt = np.minimum(above, 0.5 * peak)  # the disc evenly, however it is shaded; its edge by its coverage
        tot = wgt.sum()
        nx, ny = float((wgt.sum(axis=0) @ xx[0]) / tot), float((wgt.sum(axis=1) @ yy[:, 0]) / tot)
        moved, cx, cy = float(np.hypot(nx - cx, ny - cy)), nx, ny
        if moved < 0.01:
            break
    if moved >= 0.01:
        return (), f"ball centroid did not settle (last step {moved:.2f} px)"
    radius = float(np.sqrt(np.count_nonzero(above > 0.5 * peak) / np.pi))
    return (cx, cy, radius, float("nan"), peak), None


def _robust_circle(edge: np.ndarray) -> tuple[float, float, float]:
    """Return the circle (x, y, r) fitted to the True pixels of ``edge`` (algebraic least squares), outliers dropped."""
    ys, xs = np.nonzero(edge)
    xs, ys = xs.astype(np.float64), ys.astype(np.float64)
    keep = np.ones(xs.size, bool)
    cx, cy, rad = float(xs.mean()), float(ys.mean()), 0.0
    for _ in range(5):
        if np.count_nonzero(keep) < 3:
            break
        a = np.column_stack([xs[keep], ys[keep], np.ones(np.count_nonzero(keep))])
        c = np.linalg.lstsq(a, xs[keep] ** 2 + ys[keep] ** 2, rcond=None)[0]
        cx, cy = c[0] / 2, c[1] / 2
        rad = float(np.sqrt(max(c[2] + cx * cx + cy * cy, 0.0)))
        off = np.hypot(xs - cx, ys - cy) - rad
        spread = 1.4826 * float(np.median(np.abs(off[keep])))
        keep = np.abs(off) < max(3 * spread, 1.0)
    return float(cx), float(cy), rad


def ball_silhouette(
    diff: np.ndarray, level: np.ndarray, r: float, tol: float, origin: tuple[int, int], frame_shape: tuple[int, int]
) -> tuple[list, str | None]:
    """Return the balls' silhouettes in a region of a background-subtracted frame: ([(x, y, r, nan, contrast)], None).

    Or ([], the reason none is given). ``diff`` is the region of the frame minus the still
    background, ``level`` the same region's threshold (grey levels, per pixel), ``origin`` the
    region's (x0, y0) in the frame of ``frame_shape``. A pixel is the ball's where it differs
    from the background by more than its level, either way (a ball darker than the ground, or
    lit unevenly: a dark steel ball with a bright highlight is no bright disc); the mask is
    opened by a 3 x 3 square (lone pixels: noise, compression), its holes filled (the ball's
    face where it matches the ground), and each region of ``(1 +- tol)^2`` times the disc's area
    ``pi r^2`` (blur lengthens it: its box at least half as wide as high) is a ball. Its centre
    and radius are a circle's fitted by least squares to the region's boundary pixels, those
    more than 3 robust standard deviations (at least 1 px) off dropped, five times: a part of
    the limb that matches the ground (a mirror-like ball reflects it) is then not the edge.
    Its contrast is the median absolute difference inside. A region that touches the frame's
    border is refused (a part of the ball), as is one that touches the region's border (the
    region cut it).
    """
    mask = ndimage.binary_fill_holes(ndimage.binary_opening(np.abs(diff) > level, np.ones((3, 3), bool)))
    lab, n = ndimage.label(mask)
    if n == 0:
        return [], "no ball found"
    area = np.bincount(lab.ravel(), minlength=n + 1)
    expect = np.pi * r * r
    ok = [j for j in range(1, n + 1) if (1 - tol) ** 2 * expect < area[j] < (1 + tol) ** 2 * expect]
    out, why = [], "no ball found"
    h, w = diff.shape
    fh, fw = frame_shape
    x0, y0 = origin
    objs = ndimage.find_objects(lab)
    for j in ok:
        sl = objs[j - 1]
        bh, bw = sl[0].stop - sl[0].start, sl[1].stop - sl[1].start
        if min(bh, bw) < 0.5 * max(bh, bw):
            why = f"a region of the ball's area {bw} x {bh} px: not round"
            continue
        at_frame = sl[0].start + y0 == 0 or sl[1].start + x0 == 0 or sl[0].stop + y0 == fh or sl[1].stop + x0 == fw
        if at_frame:
            why = "ball touches the frame's border"
            continue
        if sl[0].start == 0 or sl[1].start == 0 or sl[0].stop == h or sl[1].stop == w:
            why = "the ball's silhouette cut by the search region's border"
            continue
        region = lab[sl] == j
        contrast = float(np.median(np.abs(diff[sl][region])))
        cx, cy, rad = _robust_circle(region & ~ndimage.binary_erosion(region))
        out.append((cx + sl[1].start + x0, cy + sl[0].start + y0, rad, float("nan"), contrast))
    return out, None if out else why
