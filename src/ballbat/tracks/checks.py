"""Physical cross-checks of raw camera tracks: the mistakes labs make with settings and files.

The reduction (:mod:`.reduce`) trusts the camera settings and the rows it is given. What the
tracks themselves can tell, checked here (docs/tracks.md, "Cross-checks"):

* **Frame runs** (:func:`check_frame_runs`, when the file is read): a frame number far outside
  its impact's run (a typo such as +1e9) is named by its row; nothing is allocated for the gap.
* **Single-frame glitches** (:func:`glitch_mask`, before any fit): a point that sticks out of
  its track on both sides is removed and counted (``n_outliers_*`` in reduce.nc).
* **g with g free** (:func:`free_fall`): the ball's acceleration across its velocity is
  gravity (drag acts along the velocity; Magnus lift, bounded by Nathan's lift coefficient,
  is allowed for). It scales as m_per_px x fps^2 and changes sign when y points up.
* **The two cameras** (:func:`camera_agreement`): they film the same ball, so its speed
  (scaling as m_per_px x fps) and launch direction must agree within their errors.
* **The tip's arc** (:func:`tip_arc`): the tip dot moves on a circle whose radius, seen in the
  image, is pivot_to_tip; it scales with the swing camera's m_per_px only (not with fps).
* **Spin dots** (dataset level): a dot on the ball is no further than the ball's radius
  (Table I) from its centre; its distance scales with the spin camera's m_per_px.

These are the per-impact detectors and the tests they share; the reduction calls the
detectors (glitches, a misplaced first mark, the two cameras' agreement) and
:mod:`.verdict` judges the dataset with the rest: a check that fails for the dataset as a whole
stops it (:class:`~ballbat.properties.InputError`, naming the setting); where several checks
point to one mistake, :func:`diagnose` names the setting that explains them best. A check that
fails for single impacts excludes them.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..batched import gram, nanmedian_rows, tdot
from .masked import fitted_columns

if TYPE_CHECKING:
    import os
    from collections.abc import Sequence

    from numpy.typing import ArrayLike

    from .data import CameraTracks, TrackBlocks, Tracks

#: False-alarm probability of the glitch test per tracked point (2-D Gaussian noise:
#: P(|r| > Z s) = exp(-Z^2 / 2)); 10^4 impacts of 200 points make 2e6 points.
GLITCH_FALSE_ALARM = 1e-9
#: z beyond which one impact's two cameras disagree (two-sided normal, 1e-6 per test).
IMPACT_Z = 4.89
#: Launch angles of one impact's two cameras closer than this (rad) are not a disagreement, however
#: significant: the check is for gross mistakes (rows of another camera or impact, a mirror or a
#: flipped y, which differ by degrees); at 0.05 px a filmed ball's direction is known to 0.01 deg,
#: and two cameras set up by hand differ by more than that (levelling, lens distortion).
ANGLE_TOLERANCE = 0.5 * np.pi / 180
#: z beyond which a dataset's pooled check fails (two-sided normal, 6e-7).
DATASET_Z = 5.0
#: z of the one-sided test of g's sign: a camera whose y points up sees g negative. A y-down
#: camera shows at least g less the largest Magnus lift, so a g that is negative and more than
#: FLIP_Z standard errors below that is a y axis pointing up (false alarm 1.3e-3 per camera for
#: Gaussian errors); the two-sided test at DATASET_Z must also allow for the lift, and misses
#: a flip whenever the lift allowance is large against g.
FLIP_Z = 3.0
#: A setting is wrong for the whole dataset when more than this fraction of impacts fails.
DATASET_FRACTION = 0.5
#: Air density (kg m-3) bounding the aerodynamic allowance (sea level, cold: 1.3).
RHO_AIR_MAX = 1.3
#: Allowance on Nathan's lift coefficient (its spread over measured baseballs is about +-30 %).
LIFT_MARGIN = 1.5
#: Relative tolerance of the tip's arc radius beyond its fitted error: the dot's offset from
#: the bat's axis, a measured pivot distance and the machine's angular acceleration.
ARC_TOLERANCE = 0.10
#: A relative pixel-scale uncertainty at or above this is a percentage typed as a fraction.
SCALE_ERR_MAX = 0.1


# ---------------------------------------------------------------------------------------
# frame runs


def check_frame_runs(
    path: str | os.PathLike[str],
    impact_id: np.ndarray,
    camera: np.ndarray,
    frame: np.ndarray,
    labels: Sequence[str],
    column: str = ", column frame",
) -> list[str]:
    """Rows whose frame lies far outside the run of its impact and camera.

    The frames of one impact in one camera are one clip. Sorted, they are split where a gap
    holds more untracked frames than the impact has tracked frames in that camera (the dense
    array would be mostly empty); the part with the most frames is the impact's run, and
    every row of another part is a problem (a typo in the frame number, most likely).

    Parameters
    ----------
    path : str
        The tracks file, for messages.
    impact_id, camera : array of str
    frame : array of int
    labels : array of str
        Each row's label (``row 5``; a tool file's ``track 'ball'``).
    column : str
        What follows the label in a message (a tool file has no column ``frame``).

    Returns
    -------
    list of str
    """
    impact_id = np.asarray(impact_id).astype(str)
    camera = np.asarray(camera).astype(str)
    frame = np.asarray(frame, dtype=np.int64)
    labels = np.asarray(labels).astype(str)
    problems: list[str] = []
    if frame.size == 0:
        return problems
    key = np.char.add(np.char.add(impact_id, "\x00"), camera)
    order = np.lexsort((frame, key))
    k, f = key[order], frame[order]
    starts = np.flatnonzero(np.r_[True, k[1:] != k[:-1]])
    ends = np.r_[starts[1:], k.size]
    for s, e in zip(starts, ends, strict=True):
        ff = f[s:e]
        uniq = np.unique(ff)
        gaps = np.diff(uniq) - 1
        cut = np.flatnonzero(gaps > uniq.size)
        if cut.size == 0:
            continue
        bounds = np.r_[0, cut + 1, uniq.size]
        sizes = np.diff(bounds)
        main = int(np.argmax(sizes))
        lo, hi = uniq[bounds[main]], uniq[bounds[main + 1] - 1]
        out = (ff < lo) | (ff > hi)
        rows = order[s:e][out]
        iid, cam = str(impact_id[rows[0]]), str(camera[rows[0]])  # text, not numpy's repr np.str_('L005')
        for r in rows[:5]:
            d = frame[r] - hi if frame[r] > hi else lo - frame[r]
            side = "after" if frame[r] > hi else "before"
            problems.append(
                f"{path}: {labels[r]}{column}: frame {frame[r]} of impact {iid!r} in the {cam} camera is "
                f"{d} frames {side} the rest of its run (frames {lo}-{hi}, {uniq.size} tracked): a typo?"
            )
        if rows.size > 5:
            problems.append(f"{path}: and {rows.size - 5} more rows of impact {iid!r} in the {cam} camera far outside")
    return problems


# ---------------------------------------------------------------------------------------
# glitches


def _mad_sd(values: np.ndarray) -> float:
    v = values[np.isfinite(values)]
    return float(1.4826 * np.median(np.abs(v))) if v.size else math.nan


def glitch_mask(
    x: np.ndarray, y: np.ndarray, skip: np.ndarray | None = None, pooled: float | None = None
) -> np.ndarray:
    """Single-frame glitches of one point's tracks, (impact, column) pixels, NaN untracked.

    A point at frame k is a glitch when it lies far from the midpoint of its neighbours
    (``r = p_k - (p_{k-1} + p_{k+1}) / 2`` beyond Z robust standard deviations, Z from
    :data:`GLITCH_FALSE_ALARM`) and also from the straight-line extrapolation of the two
    frames on each side, in the same direction (the projection of ``p_k - 2 p_{k-1} +
    p_{k-2}`` and of its mirror on r above |r| / 2, where those frames are tracked). A
    smooth track bent the other way (a kink at impact, a contact, a spinning dot) fails the
    second test: there the extrapolations miss on the other side. The noise is the larger of
    the track's own (1.4826 MAD of r's components) and the same point's over all impacts. Of
    neighbouring candidates only the one furthest out counts (a glitch's neighbours are off
    by half as much).
    Only points with two tracked frames on each side are tested (not a track's first or last
    two frames, nor those next to an untracked frame), and not the frames ``skip`` marks
    (the ball's and its dots' around the impact, where the motion itself has a kink that a
    noisy point can turn into a spike). ``pooled``: the noise of all impacts
    (:func:`pooled_noise`) when ``x``, ``y`` hold a block of them; default: of the impacts given.
    """
    n, m = x.shape
    if m < 3:
        return np.zeros((n, m), dtype=bool)
    if GLITCH_COMPILED:
        return _glitch_mask_compiled(x, y, skip, pooled)
    ok = np.isfinite(x) & np.isfinite(y)
    out = np.zeros((n, m), dtype=bool)
    sh = _shifter(m)
    rx, ry, sd = _midpoint_noise(x, y, pooled)
    with np.errstate(invalid="ignore"):
        lx, ly = x - 2 * sh(x, -1) + sh(x, -2), y - 2 * sh(y, -1) + sh(y, -2)
        qx, qy = x - 2 * sh(x, 1) + sh(x, 2), y - 2 * sh(y, 1) + sh(y, 2)
    if sd is None:
        return out
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows
        z = math.sqrt(2 * math.log(1 / GLITCH_FALSE_ALARM))
        rn = np.hypot(rx, ry)
        big = rn > z * sd[:, None]
        left = np.isfinite(lx) & np.isfinite(ly)
        right = np.isfinite(qx) & np.isfinite(qy)
        pl = (lx * rx + ly * ry) / rn
        pr = (qx * rx + qy * ry) / rn
        same = left & right & (pl > 0.5 * rn) & (pr > 0.5 * rn)
        # a glitch's neighbours stick out by half as much: keep the local maximum only
        peak = (rn >= np.nan_to_num(sh(rn, -1))) & (rn >= np.nan_to_num(sh(rn, 1)))
    out = big & same & peak & ok
    return out if skip is None else out & ~skip


#: The glitch test in compiled loops (:mod:`ballbat.tracks.glitch_kernel`); False: the numpy reference.
GLITCH_COMPILED = True


def _glitch_mask_compiled(x, y, skip, pooled) -> np.ndarray:
    """:func:`glitch_mask` in compiled loops: the same flags."""
    from . import glitch_kernel as kern

    x, y = np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(y, dtype=float)
    rx, ry, sd = _midpoint_noise_compiled(x, y, pooled)
    if sd is None:
        return np.zeros(x.shape, dtype=bool)
    z = math.sqrt(2 * math.log(1 / GLITCH_FALSE_ALARM))
    has_skip = skip is not None
    mask = np.ascontiguousarray(skip, dtype=np.bool_) if has_skip else np.zeros((1, 1), dtype=np.bool_)
    return kern.glitches(x, y, rx, ry, sd, z, mask, has_skip)


def _midpoint_noise_compiled(x, y, pooled):
    """:func:`_midpoint_noise` in compiled loops (``x``, ``y`` contiguous floats): the same numbers."""
    from . import glitch_kernel as kern

    rx, ry = kern.midpoint_offsets(x, y)
    pooled = kern.pooled_mad(rx, ry) if pooled is None else float(pooled)
    if not np.isfinite(pooled):
        return rx, ry, None
    return rx, ry, kern.track_noise(rx, ry, pooled)


def _shifter(m: int):
    """Return sh(a, k): ``a`` (impact, column) shifted so that column j holds a[:, j + k] (NaN outside)."""

    def sh(a, k):
        b = np.full_like(a, np.nan)
        if k > 0:
            b[:, :-k] = a[:, k:]
        else:
            b[:, -k:] = a[:, : m + k]
        return b

    return sh


def _midpoint_offsets(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return each point's offset from the midpoint of its neighbours (rx, ry), NaN without two."""
    sh = _shifter(x.shape[1])
    with np.errstate(invalid="ignore"):
        return x - 0.5 * (sh(x, -1) + sh(x, 1)), y - 0.5 * (sh(y, -1) + sh(y, 1))


def pooled_noise(blocks: Sequence[tuple[np.ndarray, np.ndarray]]) -> float:
    """Return the robust sd (1.4826 MAD) of the midpoint offsets' components of one point over all impacts.

    ``blocks``: the point's (x, y) of each block of impacts; the median of the same values
    however they are blocked (:func:`glitch_mask`'s and :func:`misplaced_starts`' pooled noise).
    """
    parts = [np.concatenate(_midpoint_offsets(x, y), axis=1).ravel() for x, y in blocks]
    return _mad_sd(np.concatenate(parts))


def _midpoint_noise(
    x: np.ndarray, y: np.ndarray, pooled: float | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Return each point's offset from the midpoint of its neighbours (rx, ry) and the robust sd per impact.

    The sd of the offsets' components is the track's own (1.4826 MAD, from 10 values) or, if larger,
    that of all impacts (``pooled``, default: of the impacts given; None when no point has two neighbours).
    """
    rx, ry = _midpoint_offsets(x, y)
    comps = np.concatenate([rx, ry], axis=1)
    if pooled is None:
        pooled = _mad_sd(comps.ravel())
    if not np.isfinite(pooled):
        return rx, ry, None
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows
        enough = np.isfinite(comps).sum(axis=1) >= 10
        med = np.where(enough, nanmedian_rows(np.abs(comps)), 0.0)  # numpy.nanmedian's numbers, faster
    return rx, ry, np.maximum(1.4826 * med, pooled)


#: Marks at the start of a track that :func:`misplaced_starts` tests (the glitch test needs two tracked
#: frames on each side, so it never tests a track's first two).
START_MARKS = 2
#: Marks after a track's first START_MARKS to which :func:`misplaced_starts` fits a parabola (where the track has them).
BEND_MARKS = 5
#: Untracked frames :func:`misplaced_starts` allows among a track's first START_MARKS + 2 marks (a first mark
#: followed by frames not clicked, or not found, is tested too; over longer gaps a straight line is no prediction).
START_GAPS = 2


@dataclass
class MisplacedStart:
    """Per impact: whether one of a track's first marks is far off its run, which column, how far (px), the noise."""

    found: np.ndarray
    column: np.ndarray
    distance: np.ndarray
    noise: np.ndarray


def misplaced_starts(x: np.ndarray, y: np.ndarray, pooled: float | None = None) -> MisplacedStart:
    """Test the first :data:`START_MARKS` marks of each track against the run of the next ones.

    A mark at column k of a track whose first mark is at f is predicted from the marks at f + 2 and
    f + 3 (p = p2 + (2 - k)(p2 - p3)); with point noise s per coordinate its offset has sd
    s sqrt(14) (k = 0) or s sqrt(6) (k = 1). It is misplaced when it is that far off and also
    further than z s sqrt(2) from each of the other first three marks (a ball at rest whose
    third and fourth marks already straddle the impact agrees with its neighbour). s comes from
    the offsets of each mark from its neighbours' midpoint (sd 1.5^0.5 s: :func:`glitch_mask`'s
    robust noise); the threshold is the glitch test's z. A misplaced first click (hundreds of
    pixels off) is found; a track with fewer than four marks is not tested. Up to
    :data:`START_GAPS` untracked frames among the four are allowed: the marks are then
    predicted at their frames (p = p2 + lam (p3 - p2), lam = (f_k - f2) / (f3 - f2); offset sd
    s sqrt(1 + (1 - lam)^2 + lam^2)). Before, a first mark followed by an untracked frame was
    not tested, and neither is it by the glitch test.

    Where the track has :data:`BEND_MARKS` more marks after them (within the gaps allowed), the
    prediction is the parabola fitted by least squares to the marks from f + 2 on instead
    (weights w; offset sd s sqrt(1 + sum w^2): 4.1 s for k = 0, 2.4 s for k = 1 without gaps,
    about the line's): a track that bends is followed. A tip filmed on its arc and tracked to
    0.01 px bends by more than its noise over its first marks (it slows towards the alignment),
    and the line put those 0.1-0.2 px "off": most such tracks were flagged.
    ``pooled``: as for :func:`glitch_mask`.
    """
    n, m = x.shape
    found = np.zeros(n, dtype=bool)
    column = np.zeros(n, dtype=np.int64)
    distance = np.zeros(n)
    if GLITCH_COMPILED:
        _, _, sd = _midpoint_noise_compiled(
            np.ascontiguousarray(x, dtype=float), np.ascontiguousarray(y, dtype=float), pooled
        )
    else:
        _, _, sd = _midpoint_noise(x, y, pooled)
    if sd is None or m < START_MARKS + 2:
        return MisplacedStart(found, column, distance, np.full(n, np.nan))
    ok = np.isfinite(x) & np.isfinite(y)
    rank = np.cumsum(ok, axis=1)  # the marks up to each column
    cols = np.stack([np.argmax(ok & (rank == j + 1), axis=1) for j in range(START_MARKS + BEND_MARKS)], axis=1)
    px, py = np.take_along_axis(x, cols, axis=1), np.take_along_axis(y, cols, axis=1)
    first = cols[:, 0]
    tested = (rank[:, -1] >= START_MARKS + 2) & (cols[:, 3] - first <= START_MARKS + 1 + START_GAPS)
    z = math.sqrt(2 * math.log(1 / GLITCH_FALSE_ALARM))
    point_sd = sd / math.sqrt(1.5)
    t = cols.astype(float)
    bends = (
        tested
        & (rank[:, -1] >= START_MARKS + BEND_MARKS)
        & (cols[:, -1] - first <= START_MARKS + BEND_MARKS - 1 + START_GAPS)
    )
    for k in range(START_MARKS - 1, -1, -1):  # the earliest far mark is named
        ex, ey, factor = _start_offset(px, py, t, k, tested, bends)
        d = np.hypot(ex, ey)
        # a mark that sits on one of its neighbours is not misplaced (a ball at rest whose next marks
        # already straddle the impact is not on one line with them)
        others = [j for j in range(3) if j != k]
        near = np.min([np.hypot(px[:, k] - px[:, j], py[:, k] - py[:, j]) for j in others], axis=0)
        alone = near > z * point_sd * math.sqrt(2)
        far = tested & alone & (d > z * point_sd * factor)
        found |= far
        column = np.where(far, cols[:, k], column)
        distance = np.where(far, d, distance)
    return MisplacedStart(found, column, distance, point_sd)


def _start_offset(px, py, t, k: int, tested, bends) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return mark ``k``'s offset (x, y) from its prediction and the offset's sd in units of the point noise.

    The line through marks 2 and 3, or where ``bends`` the parabola fitted to marks 2 on
    (:func:`misplaced_starts`).
    """
    lam = (t[:, k] - t[:, 2]) / np.where(tested, t[:, 3] - t[:, 2], 1.0)  # -2 and -1 without gaps
    ex = px[:, k] - (px[:, 2] + lam * (px[:, 3] - px[:, 2]))
    ey = py[:, k] - (py[:, 2] + lam * (py[:, 3] - py[:, 2]))
    factor = np.sqrt(1 + (1 - lam) ** 2 + lam**2)
    if not bends.any():
        return ex, ey, factor
    u = t[bends, 2:] - t[bends, k : k + 1]  # time from mark k: the prediction is the fit's constant
    design = np.stack([np.ones_like(u), u, u * u], axis=2)
    w = np.linalg.solve(np.swapaxes(design, 1, 2) @ design, np.swapaxes(design, 1, 2))[:, 0, :]
    ex[bends] = px[bends, k] - np.sum(w * px[bends, 2:], axis=1)
    ey[bends] = py[bends, k] - np.sum(w * py[bends, 2:], axis=1)
    factor[bends] = np.sqrt(1 + np.sum(w * w, axis=1))
    return ex, ey, factor


# ---------------------------------------------------------------------------------------
# free fall with g free


@dataclass
class FreeFall:
    """Per impact: gravity from the flight fitted with a free acceleration (m s-2), its error."""

    g: np.ndarray
    g_err: np.ndarray
    lift_max: np.ndarray


def lift_bound(v: ArrayLike, r: ArrayLike, m: ArrayLike, omega: ArrayLike) -> np.ndarray:
    """Largest Magnus acceleration (m s-2) of a ball of radius r and mass m at speed v and spin omega.

    ``RHO_AIR_MAX pi r^2 C_L v^2 / (2 m)`` with Nathan's lift coefficient ``C_L = 1.120 S /
    (0.583 + 2.333 S)``, ``S = r |omega| / v``, times :data:`LIFT_MARGIN`, v at most the
    fastest batted ball (:data:`ballbat.ingest.SPEED_MAX_MPH`), so that a wrong setting
    does not widen the allowance without bound.
    """
    from ..ingest import SPEED_MAX_MPH
    from ..units import MPH

    v, r, m, omega = (np.asarray(a, dtype=float) for a in (v, r, m, omega))
    with np.errstate(all="ignore"):
        v = np.minimum(v, SPEED_MAX_MPH["v_ball"] * MPH)
        S = r * np.abs(omega) / v
        cl = 1.120 * S / (0.583 + 2.333 * S)
        return LIFT_MARGIN * RHO_AIR_MAX * np.pi * r**2 * np.nan_to_num(cl) * v**2 / (2 * m)


def free_fall(
    X: np.ndarray,
    Y: np.ndarray,
    t: np.ndarray,
    flight: np.ndarray,
    r: np.ndarray,
    m: np.ndarray,
    omega: np.ndarray,
) -> FreeFall:
    """Fit ``X = a + b u + c u^2`` and the same in Y over the flight frames; g across the velocity.

    Drag acts along the velocity, so the acceleration's component across it, divided by
    the cosine of the launch angle, is g (plus Magnus lift, bounded by :func:`lift_bound`).

    Parameters
    ----------
    X, Y, t : ndarray
        Ball centre (m, X along the swing, Y up) and time (s), (impact, column).
    flight : reduce.Flight
        The flight fit (its frames and reference time).
    r, m, omega : ndarray
        Ball radius and mass per impact (SI), and its measured spin (rad s-1).
    """
    w = flight.mask.astype(float)
    u = np.where(flight.mask, t - flight.t_ref[:, None], 0.0)
    n = w.sum(axis=1)
    P = np.stack([np.ones_like(u), u, u**2], axis=-1) * w[..., None]
    A = gram(P)
    bad = n < 4
    A[bad] = np.eye(3)
    Ainv = np.linalg.inv(A)
    Xz, Yz = np.where(flight.mask, X, 0.0), np.where(flight.mask, Y, 0.0)
    cx = (Ainv @ tdot(P, Xz)[..., None])[..., 0]
    cy = (Ainv @ tdot(P, Yz)[..., None])[..., 0]
    with np.errstate(all="ignore"):
        rx = np.where(flight.mask, X - (P @ cx[..., None])[..., 0], 0.0)
        ry = np.where(flight.mask, Y - (P @ cy[..., None])[..., 0], 0.0)
        s2 = (np.sum(rx**2, axis=1) + np.sum(ry**2, axis=1)) / (2 * n - 6)
        ax, ay = 2 * cx[:, 2], 2 * cy[:, 2]
        var_a = 4 * s2 * Ainv[:, 2, 2]
        tan = flight.vy / flight.vx
        g = ax * tan - ay
        g_err = np.sqrt(var_a * (1 + tan**2))
        v = np.hypot(flight.vx, flight.vy)
    ok = ~bad & np.isfinite(g_err) & (n >= 6)
    return FreeFall(np.where(ok, g, np.nan), np.where(ok, g_err, np.nan), lift_bound(v, r, m, omega))


# ---------------------------------------------------------------------------------------
# the tip's arc radius


def _masked_columns(mask: np.ndarray, cols: tuple) -> np.ndarray:
    """Return the columns stacked on a last axis, 0 off ``mask`` (filled in place: no stack, no 3-d where)."""
    J = np.empty((*mask.shape, len(cols)))
    for c, v in enumerate(cols):
        J[..., c] = np.where(mask, v, 0.0)
    return J


def tip_arc(
    swing: CameraTracks,
    X: np.ndarray,
    Y: np.ndarray,
    t: np.ndarray,
    t_contact: np.ndarray,
    L_cfg: float,
    fps: float,
    tau_prior_frames: float | np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Per impact: ``kappa = (L_cfg / L_arc)^2`` and its error, from the tip's pre-impact frames.

    Along the swing direction the tip moves as ``a + V s - V^3 w s^3 / 6 + ...`` (the series
    of ``L sin(V s / L)``, s the time from alignment, w = 1 / L^2): a circle's radius L seen
    from the curvature of the motion, in the swing camera's metres (independent of fps).
    Fitted by Gauss-Newton from a straight line (w = 0), with the reduction's prior on the
    alignment time (the contact's start ``t_contact``, +- ``tau_prior_frames``), so that
    nothing of L_cfg enters the fit; kappa = w L_cfg^2 is 1 when the rig and pixel scale agree.
    """
    # the frames before the contact only (their columns: every sum keeps its bits, :func:`fitted_columns`)
    X, Y, t, mask = fitted_columns(swing.mask, X, Y, t)
    along = np.where(mask, (X - swing.cx[:, None]) * swing.ux[:, None] + (Y - swing.cy[:, None]) * swing.uy[:, None], 0)
    n = mask.sum(axis=1)
    tau0 = np.asarray(t_contact, dtype=float).copy()
    with np.errstate(all="ignore"):
        s0 = np.where(mask, t - tau0[:, None], 0.0)
        sm = s0.sum(axis=1) / n
        um = along.sum(axis=1) / n
        V = np.sum(np.where(mask, (s0 - sm[:, None]) * along, 0), axis=1) / np.sum(
            np.where(mask, (s0 - sm[:, None]) ** 2, 0), axis=1
        )
        a = um - V * sm
    tau = tau0.copy()
    sigma_tau = tau_prior_frames / fps
    ok = (n >= 6) & np.isfinite(V) & np.isfinite(tau) & np.isfinite(a)
    with np.errstate(all="ignore"):
        a, V, tau = np.where(ok, a, 0.0), np.where(ok, V, 1.0), np.where(ok, tau, 0.0)
        tau0 = np.where(ok, tau0, 0.0)
    steps = _tip_arc_compiled if ARC_COMPILED else _tip_arc_numpy
    return steps(along, t, mask, n, (a, V, tau, tau0, ok), sigma_tau, L_cfg)


#: The tip-arc fit in compiled loops (:mod:`ballbat.tracks.arc_kernel`); False: numpy's (the reference).
ARC_COMPILED = True


def _tip_arc_compiled(along, t, mask, n, start, sigma_tau, L_cfg) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tip_arc`'s Gauss-Newton steps and covariance in compiled loops: kappa and its error (NaN: not made)."""
    from .arc_kernel import fit

    a, V, tau, tau0, ok = start
    shape = a.shape
    w, var_w, ok = fit(
        np.ascontiguousarray(along, dtype=float),
        np.ascontiguousarray(np.broadcast_to(t, mask.shape), dtype=float),
        np.ascontiguousarray(mask),
        np.asarray(n, dtype=float),
        *(np.ascontiguousarray(np.broadcast_to(v, shape), dtype=float) for v in (a, V, tau, tau0)),
        np.ascontiguousarray(ok),
        np.ascontiguousarray(np.broadcast_to(sigma_tau, shape), dtype=float),
        10,
    )
    with np.errstate(all="ignore"):
        kappa, kappa_err = w * L_cfg**2, np.sqrt(var_w) * L_cfg**2
    good = ok & np.isfinite(kappa) & np.isfinite(kappa_err) & (kappa_err > 0)
    return np.where(good, kappa, np.nan), np.where(good, kappa_err, np.nan)


def _tip_arc_numpy(along, t, mask, n, start, sigma_tau, L_cfg) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_tip_arc_compiled` with numpy's batched products and solves (the reference)."""
    a, V, tau, tau0, ok = start
    w = np.zeros(a.shape)
    fact = [math.factorial(2 * k + 1) for k in range(5)]

    def model(a, V, tau, w):
        # the series in x = V s: f = sum_k c_k x^(2k+1), c_k = (-w)^k / (2k+1)!; its derivatives
        # by V and s share sum_k c_k (2k+1) x^(2k), by w sum_k k (-1)^k w^(k-1) x^(2k+1) / (2k+1)!
        # (in place where it can be: the same operations on the same numbers as out of place)
        s = np.where(mask, t - tau[:, None], 0.0)
        x = V[:, None] * s
        x2 = x * x
        x2k = np.ones_like(s)  # x^(2k)
        f, dx, dw, tmp = np.zeros_like(s), np.zeros_like(s), np.zeros_like(s), np.empty_like(s)
        for k in range(5):
            term = (-w[:, None]) ** k / fact[k] * x2k
            f += np.multiply(term, x, out=tmp)
            dx += np.multiply(2 * k + 1, term, out=tmp)
            if k:
                dw += np.multiply(k * (-1) ** k * w[:, None] ** (k - 1) / fact[k] * x2k, x, out=tmp)
            x2k *= x2
        return a[:, None] + f, _masked_columns(mask, (np.ones_like(s), s * dx, -V[:, None] * dx, dw))

    with np.errstate(all="ignore"):
        for _ in range(10):
            f, J = model(a, V, tau, w)
            r = np.where(mask, along - f, 0.0)
            s2 = np.sum(r**2, axis=1) / np.maximum(n - 4, 1)
            A = gram(J)
            b = tdot(J, r)
            prior = s2 / sigma_tau**2
            A[:, 2, 2] += prior
            b[:, 2] += prior * (tau0 - tau)
            A[~ok] = np.eye(4)
            b[~ok] = 0.0
            step = _solve_each(A, b)
            ok &= np.isfinite(step).all(axis=1)  # a singular system: that impact's check is not made
            a, V, tau, w = (q + np.where(ok, step[:, j], 0.0) for j, q in enumerate((a, V, tau, w)))
        f, J = model(a, V, tau, w)
        r = np.where(mask, along - f, 0.0)
        s2 = np.sum(r**2, axis=1) / np.maximum(n - 4, 1)
        A = gram(J)
        A[:, 2, 2] += s2 / sigma_tau**2
        A[~ok] = np.eye(4)
        cov = _solve_each(A, np.broadcast_to(np.eye(4), A.shape).copy()) * s2[:, None, None]
        kappa = w * L_cfg**2
        kappa_err = np.sqrt(cov[:, 3, 3]) * L_cfg**2
    good = ok & np.isfinite(kappa) & np.isfinite(kappa_err) & (kappa_err > 0)
    return np.where(good, kappa, np.nan), np.where(good, kappa_err, np.nan)


def _solve_each(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve each system ``A[i] x = b[i]`` (b a vector or a matrix per system); NaN where ``A[i]`` is singular.

    One batched solve; only if it fails, system by system, so one impact's degenerate fit does not
    stop the others' checks.
    """
    vec = b.ndim == A.ndim - 1
    rhs = b[..., None] if vec else b
    try:
        x = np.linalg.solve(A, rhs)
    except np.linalg.LinAlgError:
        x = np.full(rhs.shape, np.nan)
        for i in range(A.shape[0]):
            try:
                x[i] = np.linalg.solve(A[i], rhs[i])
            except np.linalg.LinAlgError:
                pass
    return x[..., 0] if vec else x


# ---------------------------------------------------------------------------------------
# the two cameras


@dataclass
class Agreement:
    """Per impact: the ball's speed and launch angle in each camera and the z of their difference."""

    v: dict
    v_err: dict
    launch: dict
    launch_err: dict
    z_speed: np.ndarray
    z_angle: np.ndarray
    ratio: np.ndarray
    ratio_err: np.ndarray

    def angles_disagree(self) -> np.ndarray:
        """Return the impacts whose launch angles differ beyond IMPACT_Z of their errors and beyond ANGLE_TOLERANCE."""
        diff = np.angle(np.exp(1j * (self.launch["swing"] - self.launch["spin"])))
        with np.errstate(invalid="ignore"):
            return (np.abs(self.z_angle) > IMPACT_Z) & (np.abs(diff) > ANGLE_TOLERANCE)


def camera_agreement(flight: dict, cameras: dict) -> Agreement:
    """Return the ball's speed and launch direction seen by the two cameras, and the z of their differences.

    Each camera's speed carries its fit error and its pixel scale's stated relative error
    (``m_per_px_err``); the launch angles their fit errors.
    """
    v, ve, la, le = {}, {}, {}, {}
    with np.errstate(all="ignore"):
        for c in ("swing", "spin"):
            f = flight[c]
            v[c] = np.hypot(f.vx, f.vy)
            ve[c] = np.hypot(np.sqrt(f.var_along), v[c] * cameras[c].m_per_px_err)
            la[c] = np.arctan2(f.vy, f.vx)
            le[c] = np.sqrt(f.var_across) / v[c]
        z_speed = (v["swing"] - v["spin"]) / np.hypot(ve["swing"], ve["spin"])
        z_angle = np.angle(np.exp(1j * (la["swing"] - la["spin"]))) / np.hypot(le["swing"], le["spin"])
        ratio = v["swing"] / v["spin"]
        ratio_err = ratio * np.hypot(ve["swing"] / v["swing"], ve["spin"] / v["spin"])
    return Agreement(v, ve, la, le, z_speed, z_angle, ratio, ratio_err)


def weighted_mean(x: ArrayLike, err: ArrayLike) -> tuple[float, float, int]:
    """Inverse-variance weighted mean of the finite values, its error (scaled up by the scatter if larger), count."""
    x, err = np.asarray(x, dtype=float), np.asarray(err, dtype=float)
    ok = np.isfinite(x) & np.isfinite(err) & (err > 0)
    k = int(ok.sum())
    if k == 0:
        return math.nan, math.nan, 0
    w = 1 / err[ok] ** 2
    mean = float(np.sum(w * x[ok]) / np.sum(w))
    se = float(1 / np.sqrt(np.sum(w)))
    if k > 1:
        chi2 = float(np.sum(w * (x[ok] - mean) ** 2) / (k - 1))
        se *= math.sqrt(max(chi2, 1.0))
    return mean, se, k


# ---------------------------------------------------------------------------------------
# diagnosis: which one setting explains what the checks see


def hypotheses(cameras: dict, steps: dict | None = None) -> list[tuple[str, dict]]:
    """Single mistakes and what they scale (config value over true value), most specific first.

    Keys: ``swing_m_per_px``, ``swing_fps``, ``spin_m_per_px``, ``spin_fps``, ``rig``, ``y_swing``, ``y_spin``,
    ``x_swing``, ``x_spin`` (signs). ``steps``: the step every impact's frames share in a camera
    (:func:`frame_steps`); a step d > 1 adds the mistake "frame numbers d x the video's", which
    scales time as fps d x too low does and comes first (the frames show it).
    """
    out = _frame_step_hypotheses(steps or {})
    for c in ("swing", "spin"):
        out += [
            (f"cameras.{c}.fps is 2x too high", {f"{c}_fps": 2.0}),
            (f"cameras.{c}.fps is 2x too low", {f"{c}_fps": 0.5}),
            (f"cameras.{c}.m_per_px is in mm per pixel, not m", {f"{c}_m_per_px": 1000.0}),
            (f"cameras.{c}.m_per_px is in cm per pixel, not m", {f"{c}_m_per_px": 100.0}),
            (
                f"y points up in the {c} camera's rows (Tracker and Kinovea export y up; ballbat's pixels have y down)",
                {f"y_{c}": -1.0},
            ),
        ]
    out += _both_camera_hypotheses()
    out += [
        ("y points up in both cameras' rows (Tracker and Kinovea export y up)", {"y_swing": -1.0, "y_spin": -1.0}),
        ("the rig lengths are in metres, not inches", {"rig": 1 / 39.37}),
        ("the rig lengths are in cm, not inches", {"rig": 2.54}),
    ]
    mm = {f"{c}_m_per_px": cameras[c].m_per_px / 1e-3 for c in ("swing", "spin")}
    out += [
        ("x_px and y_px are millimetres, not pixels (a world-unit export)", mm),
        (
            "x_px and y_px are millimetres with y up, not pixels (a world-unit export)",
            {**mm, "y_swing": -1, "y_spin": -1},
        ),
    ]
    sw, sp = cameras["swing"], cameras["spin"]
    out.append(
        (
            "the swing and spin camera settings are swapped",
            {
                "swing_m_per_px": sw.m_per_px / sp.m_per_px,
                "swing_fps": sw.fps / sp.fps,
                "spin_m_per_px": sp.m_per_px / sw.m_per_px,
            },
        )
    )
    out[-1][1]["spin_fps"] = sp.fps / sw.fps
    return out


def _frame_step_hypotheses(steps: dict) -> list[tuple[str, dict]]:
    """Return the mistake "frame numbers d x the video's" for the cameras whose frames all step by d > 1."""
    cams = sorted((c for c, d in steps.items() if d > 1), reverse=True)
    if not cams:
        return []
    d = max(steps[c] for c in cams)
    which = " and ".join(cams) + (" cameras" if len(cams) > 1 else " camera")
    name = (
        f"the frame numbers of the {which} are {d}x the video's: every impact's tracked frames step by {d} "
        f"(number the video's frames 0, 1, 2, ..., or divide them by {d})"
    )
    return [(name, {f"{c}_fps": 1.0 / steps[c] for c in cams})]


def _both_camera_hypotheses() -> list[tuple[str, dict]]:
    """Mistakes made alike in both cameras: a scale or frame rate off by 2, the axes turned 180 deg, a mirror."""
    out: list[tuple[str, dict]] = []
    for k, how in ((2.0, "2x too high"), (0.5, "2x too low (half the true value)")):
        out.append(
            (
                f"cameras.swing.m_per_px and cameras.spin.m_per_px are both {how}",
                {"swing_m_per_px": k, "spin_m_per_px": k},
            )
        )
        out.append((f"cameras.swing.fps and cameras.spin.fps are both {how}", {"swing_fps": k, "spin_fps": k}))
    out += _length_unit_hypotheses()
    turned = "x points left and y up: Tracker's coordinate axes turned 180 deg, or the video upside down"
    for c in ("swing", "spin"):
        out.append((f"the {c} camera's axes are turned 180 deg ({turned})", {f"x_{c}": -1.0, f"y_{c}": -1.0}))
        out.append((f"cameras.{c}.mirror is the wrong way round (the ball flies against x)", {f"x_{c}": -1.0}))
    both = {"x_swing": -1.0, "y_swing": -1.0, "x_spin": -1.0, "y_spin": -1.0}
    out.append((f"both cameras' axes are turned 180 deg ({turned})", both))
    return out


#: Length units whose mix-up in an exported table (``units.length``) the diagnosis weighs, metres each.
TABLE_LENGTHS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254, "ft": 0.3048}


def _length_unit_hypotheses() -> list[tuple[str, dict]]:
    """Lengths of both cameras scaled by the ratio of two length units: a table's ``units.length`` wrong."""
    out = []
    for said, s_m in TABLE_LENGTHS.items():
        for true, t_m in TABLE_LENGTHS.items():
            if said != true:
                k = s_m / t_m
                out.append(
                    (
                        f"units.length says {said!r} but the exported tables are in {true} (both cameras' lengths "
                        f"{k:.4g}x the true ones; or both cameras' m_per_px off by that factor)",
                        {"swing_m_per_px": k, "spin_m_per_px": k},
                    )
                )
    return out


def frame_steps(tracks: Tracks | TrackBlocks, largest: int = 10) -> dict[str, int]:
    """Return, per camera, the step d (2 to ``largest``) that every impact's tracked frames share; 1 if none.

    An impact counts when it has at least three tracked frames; a camera steps by d when each such
    impact's tracked frames (any point) are all its first frame plus a multiple of d (in every block).
    """
    out = {}
    for cam in tracks.blocks[0].cameras:
        steps = [_steps_of(blk.cameras[cam], largest) for blk in tracks.blocks]
        shared = set.intersection(*[s for s in steps if s is not None]) if any(s is not None for s in steps) else set()
        out[cam] = max(shared, default=1)
    return out


def _steps_of(ct: CameraTracks, largest: int) -> set[int] | None:
    """Return the steps 2 to ``largest`` every impact of ``ct`` with three tracked frames keeps (None: none)."""
    tracked = np.any([np.isfinite(v) for v in ct.x.values()], axis=0)
    rows = tracked.sum(axis=1) >= 3
    if not rows.any():
        return None
    tracked = tracked[rows]
    first = np.argmax(tracked, axis=1)[:, None]
    cols = np.arange(tracked.shape[1])[None, :]
    return {d for d in range(2, largest + 1) if not np.any(tracked & ((cols - first) % d != 0))}


def predict(h: dict) -> dict:
    """Observables a mistake predicts: g over its value per camera, L_arc / L_cfg, v_swing / v_spin."""
    keys = ("swing_m_per_px", "swing_fps", "spin_m_per_px", "spin_fps", "rig", "y_swing", "y_spin", "x_swing", "x_spin")
    f = {k: h.get(k, 1.0) for k in keys}
    return {
        "dir_swing": f["x_swing"],
        "dir_spin": f["x_spin"],
        "g_swing": f["y_swing"] * f["swing_m_per_px"] * f["swing_fps"] ** 2,
        "g_spin": f["y_spin"] * f["spin_m_per_px"] * f["spin_fps"] ** 2,
        "arc": f["swing_m_per_px"] / f["rig"],
        "speed": f["swing_m_per_px"] * f["swing_fps"] / (f["spin_m_per_px"] * f["spin_fps"]),
    }


def diagnose(observed: dict, cameras: dict, steps: dict | None = None) -> tuple[str, float, float] | None:
    """Return the single mistake that explains the observables best: (name, its chi^2, no mistake's chi^2).

    ``observed`` maps ``g_swing``, ``g_spin``, ``arc``, ``speed`` to (ratio, relative error), and
    ``dir_swing``, ``dir_spin`` to the sign of the ball's horizontal flight (+1: along the swing);
    missing or non-finite ones are skipped. chi^2 compares log ratios (a wrong sign counts as 100); of
    mistakes that explain them equally, the first of :func:`hypotheses` (``steps``: :func:`frame_steps`).
    """

    def chi2(pred):
        total = 0.0
        for k, (val, rel) in observed.items():
            if not (np.isfinite(val) and np.isfinite(rel)):
                continue
            p = pred[k]
            if np.sign(val) != np.sign(p) or val == 0:
                total += 100.0
                continue
            total += (math.log(abs(val) / abs(p)) / max(rel, 1e-3)) ** 2
        return total

    none = chi2(predict({}))
    scored = [(chi2(predict(h)), i, name) for i, (name, h) in enumerate(hypotheses(cameras, steps))]
    best = min(scored, default=None)
    if best is None:
        return None
    return best[2], best[0], none
