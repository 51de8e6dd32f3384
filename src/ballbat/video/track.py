"""Find the ball, its two dots and the bat's tip marker in each frame of a clip, and link them (docs/video.md).

Streamed: one frame at a time, each searched near where the previous frames predict (a
region of interest), the whole frame (at half or quarter resolution) only where no
prediction is at hand (not found yet, or lost for more than 3 frames). The searches are
:mod:`ballbat.video.search`, the ball's edge fit :mod:`ballbat.video.edge`. Per point:

* **ball** -- a bright disc of about the expected radius. Its edge is found on 48 rays from
  the rough centre, first at the peak of the intensity gradient, then by a model of each
  ray's profile (a shaded sphere on a background, blurred by the motion); a circle is fitted
  to the edge points by least squares, rays more than 3 robust standard deviations off
  rejected (the barrel in front, a dot on the limb), twice. Quality: the RMS
  residual of the edge (px) and the contrast of the edge. Left out: fewer than half of the
  rays kept (occluded), the disc touching the frame's border, no such disc, or two.
* **dot_a, dot_b** -- dark spots inside the disc: the ball's own shading (a grey closing,
  which removes spots smaller than it) minus the frame, thresholded at 5 noise sigma; each
  spot then located by its centroid weighted by the light it takes from the ball's shading,
  a quadratic fitted on a ring round it (:func:`~ballbat.video.search.refine_dot`). Left out:
  a spot beyond 0.9 of the radius (on the limb: foreshortened, partly hidden), and both dots
  when there are none or more than two spots. The names a and b are the tracker's own, kept
  from frame to frame (by the turn from a to b when both are seen, by the angle carried on at
  the last spin when one is).
* **bat_tip** -- a small bright disc (the marker) inside a dark surround (the end cap):
  its centroid weighted by brightness above the surround. A bright spot that stays put for
  :data:`STILL_FRAMES` frames is the background's, not the swinging bat's: its marks are
  taken back (with the trail's latest marks within two marker radii of it) and left out with
  the reason, and the search skips it from then on. A marker whose window reaches the
  frame's border (:data:`MARKER_MARGIN`) is cut by it: left out.

Nothing is guessed: a point that fails a test is left out, with the reason.
"""

from __future__ import annotations

import bisect
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from .clip import VideoError
from .edge import fit_ball
from .io import Clip
from .search import (
    ball_centroid,
    ball_silhouette,
    find_balls,
    find_dots,
    find_marker,
    find_marker_whole,
    refine_dot,
    refine_marker,
    roi,
)


@dataclass(frozen=True)
class TrackOptions:
    """What the tracker expects (pixels): the ball's radius (e.g. Table I's diameter / 2 / m_per_px), dots and marker.

    ``points``: which points to find (``ball`` always; ``("ball",)`` alone: the ball only).
    ``background``: ``"none"`` (the frames as they are), or ``"median"``: the clip's still
    background, the per-pixel median of up to :data:`BACKGROUND_FRAMES` frames spread evenly
    over it (a first pass through the clip), is subtracted from every frame before the
    searches, so that what stays put (a scale, a bright mark, clutter) is not taken for the
    moving ball (docs/video.md, "A real clip"). ``search_px``: the half-side of the square
    about the predicted position where the ball is looked for when its fit there fails (default
    4 ball radii); a ball that moves further than that between frames (a slow camera) needs more.
    ``ball_fit``: ``"edge"`` (the sub-pixel edge model, :func:`~ballbat.video.edge.fit_ball`),
    or ``"centroid"`` for a ball a few pixels across, too small for it
    (:func:`~ballbat.video.search.ball_centroid`; no edge residual: NaN), or ``"silhouette"``
    (needs the median background) for a ball that is no bright disc, darker than the ground or
    lit unevenly: the region that differs from the still background by more than
    :data:`SILHOUETTE_SIGMAS` times each pixel's own spread over the background frames
    (:func:`~ballbat.video.search.ball_silhouette`; no edge residual: NaN).
    """

    ball_radius_px: float
    points: tuple[str, ...] = ("ball",)
    dot_radius_px: float = 3.0
    marker_radius_px: float = 8.0
    radius_tolerance: float = 0.3
    background: str = "none"
    search_px: float | None = None
    ball_fit: str = "edge"

    def __post_init__(self) -> None:
        """Refuse a background, a search region or a ball fit the tracker does not know."""
        if self.background not in ("none", "median"):
            raise ValueError(f"TrackOptions: background {self.background!r} is not 'none' or 'median'")
        if self.ball_fit not in ("edge", "centroid", "silhouette"):
            raise ValueError(f"TrackOptions: ball_fit {self.ball_fit!r} is not 'edge', 'centroid' or 'silhouette'")
        if self.ball_fit == "silhouette" and self.background != "median":
            raise ValueError("TrackOptions: ball_fit 'silhouette' needs background 'median' (the still background)")
        if self.search_px is not None and not self.search_px > 0:
            raise ValueError(f"TrackOptions: search_px {self.search_px!r} must be positive")


#: Frames whose per-pixel median is a clip's still background (``TrackOptions.background = "median"``).
BACKGROUND_FRAMES = 25
#: A pixel is the ball's silhouette (``ball_fit="silhouette"``) where it differs from the still background by more
#: than this many times its own spread over the background frames (at least the frame's noise sigma).
SILHOUETTE_SIGMAS = 6.0


@dataclass
class Found:
    """Rows of the long tracks table with their quality, and the points left out with their reason."""

    rows: dict[str, list] = field(
        default_factory=lambda: {k: [] for k in ("point", "frame", "x_px", "y_px", "residual_px", "contrast")}
    )
    left_out: list[tuple[str, int, str]] = field(default_factory=list)
    ball_radii: list[float] = field(default_factory=list)  # the fitted radius (px) of each ball found

    def add(self, point: str, frame: int, x: float, y: float, residual: float, contrast: float) -> None:
        """Add a found point."""
        for k, v in zip(self.rows, (point, frame, x, y, residual, contrast), strict=True):
            self.rows[k].append(v)

    def take_back(self, point: str, frames: set, reason: str) -> None:
        """Remove the point's rows of these frames, each left out with the reason."""
        keep = [
            i
            for i, (p, k) in enumerate(zip(self.rows["point"], self.rows["frame"], strict=True))
            if p != point or k not in frames
        ]
        for name, v in self.rows.items():
            self.rows[name] = [v[i] for i in keep]
        for k in sorted(frames):
            self.leave_out(point, k, reason)

    def leave_out(self, point: str, frame: int, reason: str) -> None:
        """Note a point not given, and why."""
        self.left_out.append((point, frame, reason))


def _noise_sigma(img: np.ndarray) -> float:
    """Robust pixel noise from the differences of neighbouring pixels (MAD), at least the quantisation's (0.29).

    For integer frames both medians come from histograms of the differences (exact: the same
    float32 values as numpy's medians, in a third of the time).
    """
    if img.dtype.kind in "ui":
        d = np.diff(img[::4, :].astype(np.int32), axis=1).ravel()
        twice = _twice_median(d)  # the median of the differences, doubled: an integer
        mad = np.float32(_twice_median(np.abs(2 * d - twice))) / np.float32(4)
    else:
        d = np.diff(img[::4, :].astype(np.float32), axis=1)
        mad = np.median(np.abs(d - np.median(d)))
    return max(float(np.float32(1.4826) * mad / np.sqrt(2)), 1 / np.sqrt(12))


def _twice_median(v: np.ndarray) -> int:
    """Twice the median of integers (the sum of the middle two where there is an even number), by their histogram."""
    lo = int(v.min())
    cum = np.cumsum(np.bincount(v - lo))
    n = int(cum[-1])

    def at(k):  # the k-th smallest (from 0)
        return int(np.searchsorted(cum, k + 1)) + lo

    return 2 * at(n // 2) if n % 2 else at(n // 2 - 1) + at(n // 2)


#: A tip marker found within STILL_PX of where it was, frame after frame, for STILL_FRAMES frames is a
#: still spot of the background (clutter): the bat's marker crosses the swing camera's view at 10-20 px
#: a frame, and a bat filmed at rest gives no bat speed.
STILL_FRAMES = 2
STILL_PX = 0.5
#: How many of a trail's latest marks are kept to be taken back with a still spot: those within 2 marker radii of
#: it are the same spot, measured a pixel or two off before it stayed put (a clutter spot the bat passed).
RECENT = 5
#: A tip marker is left out where the frame's border is nearer than this many marker radii (its centroid's window of
#: 1.3 radii and the blur): a marker partly out of the view is placed 0.2-1.9 px inside it; 9 px (1.9 radii) off
#: the border the filmed replicates' marks were within 0.02 px of their truth.
MARKER_MARGIN = 1.5


@dataclass
class _Trail:
    """Latest positions of a point (frame, x, y), the last two for predicting the next, and the contrasts found."""

    recent: list = field(default_factory=list)  # the last RECENT positions (a still spot's earlier marks)
    contrasts: list = field(default_factory=list)  # sorted, for their median (:meth:`usual`)
    still: list = field(default_factory=list)  # the latest positions within STILL_PX of each other's frame
    spots: list = field(default_factory=list)  # still spots found: (x, y), skipped by the search

    def push(self, k: int, x: float, y: float) -> None:
        """Add a position."""
        if self.still and np.hypot(x - self.still[-1][1], y - self.still[-1][2]) < STILL_PX * (k - self.still[-1][0]):
            self.still.append((k, x, y))
        else:
            self.still = [(k, x, y)]
        self.recent = [*self.recent[-(RECENT - 1) :], (k, x, y)]

    @property
    def last(self) -> list:
        """The last two positions (fewer before two)."""
        return self.recent[-2:]

    def forget(self) -> None:
        """Start again (a still spot taken for the marker): no positions, no contrasts."""
        self.recent, self.contrasts, self.still = [], [], []

    def predict(self, k: int) -> tuple[float, float] | None:
        """Return the position expected at frame ``k`` (constant velocity), None when lost for over 3 frames."""
        if not self.last or k - self.last[-1][0] > 3:
            return None
        k1, x1, y1 = self.last[-1]
        if len(self.last) < 2:
            return x1, y1
        k0, x0, y0 = self.last[0]
        f = (k - k1) / (k1 - k0)
        return x1 + f * (x1 - x0), y1 + f * (y1 - y0)

    def found(self, contrast: float) -> None:
        """Add a contrast found."""
        bisect.insort(self.contrasts, contrast)

    def usual(self) -> float:
        """Return the median of the contrasts found (np.median's value: the mean of the middle two), 0 before any."""
        c, n = self.contrasts, len(self.contrasts)
        if not n:
            return 0.0
        return c[n // 2] if n % 2 else (c[n // 2 - 1] + c[n // 2]) / 2

    def velocity(self) -> tuple[float, float]:
        """Return the last velocity (px per frame; 0 before two positions)."""
        if len(self.last) < 2:
            return 0.0, 0.0
        (k0, x0, y0), (k1, x1, y1) = self.last
        return (x1 - x0) / (k1 - k0), (y1 - y0) / (k1 - k0)


def _ball_candidates(img, guess, opt: TrackOptions) -> list:
    r = opt.ball_radius_px
    if guess is None:
        return find_balls(img, r, opt.radius_tolerance)
    sub, x0, y0 = roi(img, guess[0], guess[1], opt.search_px or 4 * r)
    return [(x + x0, y + y0) for x, y in find_balls(sub, r, opt.radius_tolerance)]


def _ball(img, k, opt: TrackOptions, trail: _Trail, sigma: float, found: Found, exposure_frames: float):
    r = opt.ball_radius_px
    guess = trail.predict(k)
    v = trail.velocity()
    blur = (v[0] * exposure_frames, v[1] * exposure_frames)
    if opt.ball_fit == "silhouette":
        return _silhouette(img, k, opt, trail, found, guess)
    if opt.ball_fit == "centroid":
        fit_at = lambda x, y: _centroid_at(img, x, y, opt, sigma, trail)  # noqa: E731
    else:
        fit_at = lambda x, y: fit_ball(img, x, y, r, sigma, blur)  # noqa: E731
    fit, reason = fit_at(*guess) if guess is not None else ((), "")
    if not fit:  # no prediction yet, or the fit failed there: look for the disc in the region
        cands = _ball_candidates(img, guess, opt)
        if len(cands) != 1:
            found.leave_out("ball", k, "no ball found" if not cands else f"{len(cands)} balls found")
            return None
        fit, reason = fit_at(*cands[0])
    return _keep_ball(fit, reason, k, opt, trail, found)


def _keep_ball(fit, reason, k, opt: TrackOptions, trail: _Trail, found: Found):
    r = opt.ball_radius_px
    if reason is None and abs(fit[2] / r - 1) > opt.radius_tolerance:
        reason = f"fitted radius {fit[2]:.1f} px, expected {r:.1f} px"
    if reason:
        found.leave_out("ball", k, reason)
        return None
    trail.push(k, fit[0], fit[1])
    trail.found(fit[4])
    found.add("ball", k, fit[0], fit[1], fit[3], fit[4])
    found.ball_radii.append(fit[2])
    return fit


def _silhouette(img, k: int, opt: TrackOptions, trail: _Trail, found: Found, guess):
    """Find the ball's silhouette (``ball_fit`` "silhouette") about the prediction, or in the whole frame without one.

    ``img`` is the frame minus the still background with the threshold map attached
    (:class:`_Diff`).
    """
    if guess is None:
        diff, level, x0, y0 = img.diff, img.level, 0, 0
    else:
        diff, x0, y0 = roi(img.diff, guess[0], guess[1], opt.search_px or 4 * opt.ball_radius_px)
        level = img.level[y0 : y0 + diff.shape[0], x0 : x0 + diff.shape[1]]
    balls, why = ball_silhouette(diff, level, opt.ball_radius_px, opt.radius_tolerance, (x0, y0), img.diff.shape)
    if len(balls) != 1:
        found.leave_out("ball", k, why if not balls else f"{len(balls)} balls found")
        return None
    return _keep_ball(balls[0], None, k, opt, trail, found)


@dataclass
class _Diff:
    """A frame minus the still background (``diff``) and the silhouette's threshold for each pixel (``level``)."""

    diff: np.ndarray
    level: np.ndarray


def _centroid_at(img, x: float, y: float, opt: TrackOptions, sigma: float, trail: _Trail) -> tuple[tuple, str | None]:
    """Return a small ball's centroid near (x, y) (``ball_fit`` "centroid"), refused where it is not the ball.

    Refused: a radius off by more than the tolerance, or a peak under half the ball's usual one
    (the median of those found in the clip so far): a part of the ball's edge, or noise, when
    the prediction missed it. The ball is then looked for in the region about the prediction.
    """
    fit, reason = ball_centroid(img, x, y, opt.ball_radius_px, sigma)
    if reason:
        return fit, reason
    if abs(fit[2] / opt.ball_radius_px - 1) > opt.radius_tolerance:
        return (), f"fitted radius {fit[2]:.1f} px, expected {opt.ball_radius_px:.1f} px"
    usual = trail.usual()
    if fit[4] < 0.5 * usual:
        return (), f"a spot at {fit[0]:.1f}, {fit[1]:.1f} too faint for the ball ({fit[4]:.0f} vs {usual:.0f})"
    return fit, None


@dataclass
class _DotMemory:
    """What names the dots: the turn from a to b (its sign, fixed on a rigid ball), each dot's last angle, the spin."""

    chirality: float = 0.0
    last: dict = field(default_factory=dict)  # label -> (frame, angle about the ball's centre)
    spin: float = 0.0  # rad per frame

    def predict(self, p: str, k: int) -> float | None:
        """Return the angle of dot ``p`` expected at frame ``k`` (None if never seen)."""
        if p not in self.last:
            return None
        k0, a0 = self.last[p]
        return a0 + self.spin * (k - k0)

    def remember(self, p: str, k: int, angle: float) -> None:
        """Note dot ``p`` at ``angle``; a dot seen within 3 frames updates the spin."""
        if p in self.last and 0 < k - self.last[p][0] <= 3:
            k0, a0 = self.last[p]
            self.spin = float(np.angle(np.exp(1j * (angle - a0)))) / (k - k0)
        self.last[p] = (k, angle)


def _label_dots(rel: list, k: int, mem: _DotMemory) -> dict[str, int]:
    """Name the spots (positions relative to the ball's centre).

    Two spots: by the turn from a to b, whose sign the first pair seen fixes (a, b in order of
    angle then). One spot: the dot whose angle, carried on at the last spin, is nearest (a if
    none was seen yet).
    """
    ang = [float(np.arctan2(q[1], q[0])) for q in rel]
    if len(rel) == 2:
        cross = rel[0][0] * rel[1][1] - rel[0][1] * rel[1][0]
        if mem.chirality == 0.0:
            first = int(np.argmin(ang))
            mem.chirality = float(np.sign(cross)) * (1.0 if first == 0 else -1.0)
        return {"dot_a": 0, "dot_b": 1} if np.sign(cross) == mem.chirality else {"dot_a": 1, "dot_b": 0}
    guesses = {p: mem.predict(p, k) for p in ("dot_a", "dot_b")}
    known = {p: abs(float(np.angle(np.exp(1j * (ang[0] - g))))) for p, g in guesses.items() if g is not None}
    return {min(known, key=known.get) if known else "dot_a": 0}


def _dots(img, k, ball, opt: TrackOptions, sigma, mem: _DotMemory, found: Found) -> None:
    spots, reason = find_dots(img, ball, opt.dot_radius_px, sigma)
    for s in [s for s in spots if s[3] > 0.9]:
        found.leave_out("dot", k, f"spot at {s[0]:.1f}, {s[1]:.1f} on the limb ({s[3]:.2f} of the radius)")
    spots = [s for s in spots if s[3] <= 0.9]
    if reason or not spots or len(spots) > 2:
        why = reason or f"{len(spots)} dark spots inside the ball (one or two expected)"
        for p in ("dot_a", "dot_b"):
            found.leave_out(p, k, why)
        return
    rel = [(s[0] - ball[0], s[1] - ball[1]) for s in spots]
    labels = _label_dots(rel, k, mem)
    for p in ("dot_a", "dot_b"):
        if p not in labels:
            found.leave_out(p, k, "not seen inside the ball (hidden or on the limb)")
            continue
        s = spots[labels[p]]
        mem.remember(p, k, float(np.arctan2(rel[labels[p]][1], rel[labels[p]][0])))
        x, y = refine_dot(img, s[0], s[1], ball, opt.dot_radius_px)
        found.add(p, k, x, y, np.nan, s[2])


def _tip(img, k, opt: TrackOptions, trail: _Trail, sigma: float, found: Found) -> None:
    guess = trail.predict(k)
    mr = opt.marker_radius_px
    if guess is None:  # lost, or not found yet: the whole frame
        m = find_marker_whole(img, mr, sigma, avoid=trail.spots)
    else:
        m = find_marker(img, guess[0], guess[1], 4 * mr + 20, mr, sigma)
    if m is None:
        found.leave_out("bat_tip", k, "no tip marker found")
        return
    if any(np.hypot(m[0] - x, m[1] - y) < 2 * mr for x, y in trail.spots):  # the marker passing a still spot
        found.leave_out("bat_tip", k, f"a spot at {m[0]:.1f}, {m[1]:.1f}, beside a still spot of the background")
        return
    usual = trail.usual()
    if m[2] < 0.5 * usual:  # fainter than half the marker's usual contrast: some other bright spot
        found.leave_out(
            "bat_tip", k, f"a spot at {m[0]:.1f}, {m[1]:.1f} too faint for the marker ({m[2]:.0f} vs {usual:.0f})"
        )
        return
    x, y = refine_marker(img, m[0], m[1], mr)
    edge = min(x, y, img.shape[1] - 1 - x, img.shape[0] - 1 - y)
    if not edge >= MARKER_MARGIN * mr:  # not a number is cut off too
        found.leave_out("bat_tip", k, f"marker at {x:.1f}, {y:.1f}, {max(edge, 0):.1f} px from the frame's border: cut")
        return
    trail.push(k, x, y)
    trail.found(m[2])
    found.add("bat_tip", k, x, y, np.nan, m[2])
    if len(trail.still) >= STILL_FRAMES:  # a spot of the background: its marks taken back, the search skips it
        sx, sy = np.mean([q[1] for q in trail.still]), np.mean([q[2] for q in trail.still])
        frames = {q[0] for q in trail.still} | {q[0] for q in trail.recent if np.hypot(q[1] - sx, q[2] - sy) < 2 * mr}
        found.take_back("bat_tip", frames, f"a bright spot at {sx:.1f}, {sy:.1f} that does not move: the background's")
        trail.spots.append((float(sx), float(sy)))
        trail.forget()


def _check_time(clip: Clip, k: int, t: float | None, t0: list) -> None:
    """Refuse a timestamp off the frame rate's grid by more than a quarter frame: a dropped frame or a jump."""
    fps = clip.info.fps
    if t is None or fps is None:
        return
    if not t0:
        t0.append(t - k / fps)
    lag = (t - t0[0]) * fps - k
    if abs(lag) > 0.25:
        raise VideoError(
            f"{clip.info.path}: frame {k}: timestamp {t:.6g} s is {lag:+.2f} frames off {fps:g} fps "
            "(a frame dropped or the clock jumped)"
        )


def still_background(clip: Clip, n: int = BACKGROUND_FRAMES) -> np.ndarray:
    """Return the per-pixel median of up to ``n`` frames spread evenly over the clip (float32): what stays put.

    Streamed: only the frames taken are kept. A moving ball is in few of them, so the median is
    the ground behind it; something that stays where it is for most of the clip is background.
    """
    return _still(clip, n)[0]


def _still(clip: Clip, n: int = BACKGROUND_FRAMES, spread: bool = False) -> tuple[np.ndarray, np.ndarray | None]:
    """Return the still background (:func:`still_background`) and, with ``spread``, each pixel's spread about it.

    The spread over the same frames is 1.4826 times the median absolute deviation (the normal
    distribution's standard deviation per MAD; float32): a pixel's own noise, the compression's,
    a flicker, robust to the ball passing in a few of the frames. Only the silhouette reads it.
    """
    total = clip.info.n_frames if clip.info.n_frames is not None else sum(1 for _ in clip.frames())
    take = set(np.unique(np.linspace(0, max(total - 1, 0), min(n, max(total, 1))).round().astype(int)).tolist())
    kept = [img for k, _, img in clip.frames() if k in take]
    if not kept:
        raise VideoError(f"{clip.info.path}: no frames for the still background")
    stack = np.stack(kept).astype(np.float32)
    med = np.median(stack, axis=0)
    if not spread:
        return med, None
    return med, (1.4826 * np.median(np.abs(stack - med), axis=0)).astype(np.float32)


def track_clip(clip: Clip, opt: TrackOptions) -> Found:
    """Track one clip, streamed; frames numbered by the file's frame numbers where it has them, else from 0.

    With ``opt.background == "median"`` the clip is read twice: first for its still background
    (:func:`still_background`), then frame by frame with the background subtracted.
    """
    silhouette = opt.ball_fit == "silhouette"
    background, spread = _still(clip, spread=silhouette) if opt.background == "median" else (None, None)
    level = None
    found = Found()
    trails = {"ball": _Trail(), "bat_tip": _Trail()}
    mem = _DotMemory()
    numbers = clip.info.frame_numbers
    t0: list = []
    sigma = None
    info = clip.info
    exposure_frames = info.exposure_s * info.fps if info.exposure_s and info.fps else 0.0
    for k, t, img in clip.frames():
        _check_time(clip, k, t, t0)
        if background is not None:
            img = img.astype(np.float32) - background
        f = int(numbers[k]) if numbers is not None and k < numbers.size else k
        sigma = _noise_sigma(img) if sigma is None else sigma
        if silhouette:
            level = SILHOUETTE_SIGMAS * np.maximum(spread, sigma) if level is None else level
            ball = _ball(_Diff(img, level), f, opt, trails["ball"], sigma, found, exposure_frames)
        else:
            ball = _ball(img, f, opt, trails["ball"], sigma, found, exposure_frames)
        if ball is not None and "dot_a" in opt.points:
            _dots(img, f, ball, opt, sigma, mem, found)
        elif "dot_a" in opt.points:
            for p in ("dot_a", "dot_b"):
                found.leave_out(p, f, "no ball")
        if "bat_tip" in opt.points:
            _tip(img, f, opt, trails["bat_tip"], sigma, found)
    return found


def require_ball(found: Found, path: str) -> None:
    """Refuse a clip in which the ball is never found (none in view, two balls, never out of the bat's shadow).

    The message names the file, the first frame and why the ball was left out there.
    """
    if "ball" in found.rows["point"]:
        return
    out = [(k, why) for p, k, why in found.left_out if p == "ball"]
    if not out:
        raise VideoError(f"{path}: no frames")
    reasons = Counter(why for _, why in out)
    raise VideoError(
        f"{path}: frame {out[0][0]}: {out[0][1]}; the ball is found in none of its {len(out)} frames "
        f"({', '.join(f'{n} x {why}' for why, n in reasons.most_common(3))})"
    )


#: Columns of the quality table beside the tracks: each point found, and each left out with its reason.
QUALITY_COLUMNS = ("residual_px", "contrast", "left_out")


def found_columns(found: Found, impact_id: str, camera: str) -> tuple[dict, dict]:
    """Return the long tracks table's columns of one clip, and its quality table's (found and left-out points).

    The tracks hold only the points found. The quality table holds them too, with their
    edge-fit residual (px; the ball's, NaN for centroids) and contrast (grey levels), and
    every point left out, with empty coordinates and the reason in ``left_out``.
    """
    r = found.rows
    n, m = len(r["frame"]), len(found.left_out)
    tracks = {
        "impact_id": np.full(n, impact_id, dtype=object),
        "camera": np.full(n, camera, dtype=object),
        "point": np.array(r["point"], dtype=object),
        "frame": np.array(r["frame"], dtype=np.int64),
        "x_px": np.array(r["x_px"], dtype=float),
        "y_px": np.array(r["y_px"], dtype=float),
    }
    lo = found.left_out
    quality = {
        "impact_id": np.full(n + m, impact_id, dtype=object),
        "camera": np.full(n + m, camera, dtype=object),
        "point": np.array(r["point"] + [p for p, _, _ in lo], dtype=object),
        "frame": np.array(r["frame"] + [k for _, k, _ in lo], dtype=np.int64),
        "x_px": np.concatenate([tracks["x_px"], np.full(m, np.nan)]),
        "y_px": np.concatenate([tracks["y_px"], np.full(m, np.nan)]),
        "residual_px": np.array(r["residual_px"] + [np.nan] * m, dtype=float),
        "contrast": np.array(r["contrast"] + [np.nan] * m, dtype=float),
        "left_out": np.array([""] * n + [why for _, _, why in lo], dtype=object),
    }
    return tracks, quality


def joined_quality(tables: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """Return clips' quality tables (:func:`found_columns`) one after another; an empty table where there are none."""
    tables = tables or [found_columns(Found(), "", "")[1]]
    return {k: np.concatenate([t[k] for t in tables]) for k in tables[0]}
