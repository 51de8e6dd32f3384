"""Reduce raw camera tracks to the impacts the chain analyses (Sec. II).

Per impact, all impacts of a block at once (dense arrays, masked sums; no Python loop over
impacts; a dataset held in blocks, :class:`~ballbat.tracks.data.TrackBlocks`, block by block,
with every step that pools impacts run on all of them together: :func:`reduce_tracks`); each
step's fit is a module of its own (:mod:`~ballbat.tracks.fit_flight` steps 1-2,
:mod:`~ballbat.tracks.fit_contact` and :mod:`~ballbat.tracks.fit_swing` step 3,
:mod:`~ballbat.tracks.fit_spin` step 4), and this module runs them and marks the exclusions:

1. **Impact** (each camera): the ball's rest position is the median of its first
   :data:`N_REST` tracked frames; the first frame from which the ball stays further than a
   threshold (``max(THRESHOLD_FLOOR_PX, THRESHOLD_SIGMA x`` the rest scatter)) is the
   impact frame; the last frame before it at rest is ``rest_frame``.
2. **Free flight** (each camera): from ``ceil(CONTACT_MAX fps)`` frames after impact,
   x = a + v_x u and y + g u^2/2 = b + v_y u, a linear least-squares fit with the
   residual scatter as noise. Earlier frames that agree with the flight (within
   :data:`SEPARATION_SIGMA` sigma) are added; the first one is the separation frame; u is
   the time from separation (half a frame before it). Swing camera: v_ball and the launch
   angle (to the horizontal, in the swing direction).
3. **Contact** (swing camera): the contact's middle from the free flight extrapolated back to
   the rest position, its duration a nuisance parameter fitted to the ball's departure from
   rest (:func:`fit_contact`); its start, with its uncertainty.
   **Bat** (swing camera, frames before the contact's start only: the bat slows in the
   collision): the tip dot's positions give the swing direction (principal axis: the
   swing-plane angle beta) and, along it, u(t) = a + L sin(Omega (t - tau)) (a circle about
   the pivot seen edge-on, L = pivot_to_tip), fitted by Gauss-Newton with a prior
   tau ~ contact start +- (its error and TAU_PRIOR_FRAMES in quadrature);
   v_bat = Omega pivot_to_impact. theta = launch - beta.
4. **Spin** (spin camera, frames after separation): each dot's angle about the fitted
   ball centre, unwrapped frame to frame, fitted by one straight line per dot with a
   common slope omega (counter-clockwise on the image for a +x swing is backspin, > 0).

Uncertainties are the fits' own: residual scatter times the square root of the
(co)variance of the fitted parameters. A relative pixel-scale uncertainty
(``Camera.m_per_px_err``) is a systematic shared by all impacts of the camera: it scales
v_bat and v_ball together and is reported apart (``*_err_scale``).

Exclusions (flag > 0, values kept where they could be computed): no impact found; too
few frames for a fit; a dot whose distance from the ball's centre is not constant (the
dots do not rotate about the centre: a tilted spin axis); a spin too fast for the frame
rate to unwrap. Exclude, never drop.

:func:`reduce_tracks` returns a :class:`Reduction` (arrays and fits); the stage
:mod:`ballbat.stages.reduce` declares ``reduce.nc`` and assembles it.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, fields, is_dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..units import G
from .checks import IMPACT_Z, START_MARKS, camera_agreement, glitch_mask, misplaced_starts, pooled_noise
from .data import POINTS, Camera, CameraTracks, Rig, TrackBlocks, Tracks, gather
from .fit_contact import Contact, ContactLikelihood, contact_likelihood, contact_population, contact_posterior
from .fit_flight import CONTACT_MAX, Flight, find_onset, fit_flight
from .fit_spin import (
    OFFSET_FALSE_ALARM,
    OFFSET_TOLERANCE,
    RADIUS_TOLERANCE,
    UNWRAP_LIMIT,
    Spin,
    fit_spin,
    radius_scatter_limit,
)
from .fit_swing import Swing, fit_swing

if TYPE_CHECKING:
    pass


class ReduceFlag(enum.IntEnum):
    """Why an impact is excluded by the reduction (0: usable)."""

    OK = 0
    NO_IMPACT = 1
    TOO_FEW_FRAMES = 2
    DOT_NOT_ROTATING_ABOUT_CENTRE = 3
    SPIN_TOO_FAST = 4
    CAMERAS_DISAGREE = 5
    IMPLAUSIBLE = 6
    MISPLACED_MARK = 7


#: Name of the flag the rest of the chain reads (the source stage's exclusions).
FLAG_VAR = "ingest_flag"
#: Stage named in every exclusion reason this module gives.
STAGE = "reduce"


@dataclass(frozen=True)
class ReduceOptions:
    """Fewest frames per fit (the fits need at least two more than their parameters).

    No field has a default: the defaults are the config schema's ``min_frames`` alone
    (:func:`ballbat.stages.reduce.reduce_options`; :meth:`schema_defaults`).
    """

    min_tip_frames: int
    min_flight_frames: int
    min_spin_frames: int

    @classmethod
    def schema_defaults(cls) -> ReduceOptions:
        """Return the options the config schema gives a block without ``min_frames``."""
        from ..pipeline.config import checked_block

        mf = checked_block({}, "min_frames")
        return cls(int(mf["tip"]), int(mf["flight"]), int(mf["spin"]))


# ---------------------------------------------------------------------------------------
# masked helpers (arrays are (impact, column); w is a 0/1 float mask)


@dataclass
class Reduction:
    """Everything the reduction found, per impact (for the results file and the QA figure)."""

    tracks: Tracks
    cameras: dict
    rig: Rig
    onset: dict
    flight: dict
    swing: Swing
    spin: Spin
    times: dict
    phys: dict
    values: dict
    flag: np.ndarray
    reason: np.ndarray
    n_outliers: dict
    agreement: object = None
    contact: Contact | None = None
    shifts: object = None  # calibration systematics (ballbat.systematics.reduce_shifts), when asked for
    #: A dataset held in blocks (``tracks`` a :class:`TrackBlocks`): each block's own reduction, in
    #: the order of ``tracks.blocks``, holding the arrays along frame columns (``times``, ``phys``,
    #: the fits' masks), which are empty or None here; the per-impact arrays here are the dataset's.
    blocks: list[Reduction] | None = None
    #: The contact population's estimation error (:func:`contact_shifts`): per name of
    #: :data:`CONTACT_SHIFTED`, the change of every impact's value when the reduction is solved
    #: again with its ball type's population mean at +1 and at -1 standard error (a tuple of the two).
    contact_shift: dict | None = None
    #: Each impact's ball type's population mean contact time and its standard error (s).
    contact_mean: tuple | None = None

    def parts(self) -> list[tuple[Reduction, np.ndarray]]:
        """Each block's reduction and its impacts' positions in the dataset (one block: this one, all)."""
        if self.blocks is None:
            return [(self, np.arange(self.tracks.n))]
        return list(zip(self.blocks, self.tracks.index, strict=True))


def remove_glitches(
    tracks: Tracks, cameras: dict[str, Camera], noise: dict | None = None, onsets: dict | None = None
) -> tuple[Tracks, dict[str, np.ndarray]]:
    """Return the tracks without their single-frame glitches (:func:`.checks.glitch_mask`), and the count per impact.

    The ball's and the dots' frames from the last at rest to the end of the longest contact
    (:data:`CONTACT_MAX`) after the impact frame (:func:`find_onset` on the raw track) are
    not tested. The input is not changed. Counts are per camera (all its points), shape (impact,).
    ``noise``: each (camera, point)'s noise over all impacts when ``tracks`` is a block of them
    (:func:`pooled_noises`); default: of the impacts given. ``onsets`` (a dict, filled): each
    camera's onset of the raw ball track where none of its frames was a glitch (the cleaned
    track's onset is then that very one: :func:`_fit_ball` need not find it again).
    """
    noise = noise or {}
    cams, counts = {}, {}
    for name, ct in tracks.cameras.items():
        xs, ys = {}, {}
        count = np.zeros(tracks.n, dtype=np.int64)
        on = find_onset(ct.x["ball"], ct.y["ball"])
        n_c = int(np.ceil(CONTACT_MAX * cameras[name].fps - 1e-9))
        cols = np.arange(ct.n_columns)[None, :]
        kink = on.found[:, None] & (cols >= on.rest[:, None] - 1) & (cols <= on.onset[:, None] + n_c + 1)
        for p in POINTS[name]:
            bad = glitch_mask(ct.x[p], ct.y[p], None if p == "bat_tip" else kink, noise.get((name, p)))
            xs[p], ys[p] = np.where(bad, np.nan, ct.x[p]), np.where(bad, np.nan, ct.y[p])
            count += bad.sum(axis=1)
            if p == "ball" and onsets is not None and not bad.any():
                onsets[name] = on
        cams[name] = CameraTracks(ct.frame0, xs, ys)
        counts[name] = count
    return replace(tracks, cameras=cams), counts


def physical(ct: CameraTracks, cam: Camera, point: str) -> tuple[np.ndarray, np.ndarray]:
    """Pixel track -> physical frame (m): X along the swing direction's horizontal, Y up."""
    return cam.sign * ct.x[point] * cam.m_per_px, -ct.y[point] * cam.m_per_px


def pooled_noises(blocks: list[Tracks]) -> dict[tuple[str, str], float]:
    """Each (camera, point)'s midpoint noise over the impacts of every block (:func:`.checks.pooled_noise`).

    Empty for one block: the checks then pool the impacts they are given, all of them.
    """
    if len(blocks) == 1:
        return {}
    return {
        (c, p): pooled_noise([(b.cameras[c].x[p], b.cameras[c].y[p]) for b in blocks])
        for c in POINTS
        for p in POINTS[c]
    }


def reduce_tracks(
    tracks: Tracks | TrackBlocks,
    cameras: dict[str, Camera],
    rig: Rig,
    options: ReduceOptions | None = None,
    population_shifts: bool = True,
    like: Reduction | None = None,
) -> Reduction:
    """Reduce every impact's tracks to v_bat, v_ball, theta, omega with fitted uncertainties.

    Block by block for tracks held in blocks; the steps that pool the impacts (the glitch and
    misplaced-mark tests' noise of all impacts, :func:`pooled_noises`; the contact times' prior
    per ball type, :func:`~ballbat.tracks.fit_contact.contact_prior`) run on all impacts
    together, so that every impact's numbers do not depend on the blocks.

    Parameters
    ----------
    tracks : Tracks or TrackBlocks
        Dense tracks of both cameras (:func:`ballbat.tracks.io.load_tracks`).
    cameras : dict
        ``swing`` and ``spin`` :class:`Camera` settings.
    rig : Rig
        Pivot-to-tip and pivot-to-impact distances.
    options : ReduceOptions, optional
        Fewest frames per fit (default: the config schema's, :meth:`ReduceOptions.schema_defaults`).
    population_shifts : bool
        Solve the contact again at +-1 standard error of each ball type's population mean
        (:func:`contact_shifts`, where :data:`CONTACT_POPULATION_SHIFTS`); the calibration
        reruns (:func:`ballbat.systematics.reduce_shifts`) need only the values.
    like : Reduction, optional
        The nominal reduction of the same ``tracks`` (and ``options``), of which these settings
        move one calibration: the calibration reruns (:func:`ballbat.systematics.reduce_shifts`),
        which read the values alone. Every step whose inputs did not move is taken from it, not
        made again: the glitches found (where both frame rates are the same), a camera's onset,
        free flight and spin fit (where its settings are the same: :func:`_fit_ball`,
        :func:`_fit_bat_and_spin`). The exclusions are not tested again: the flags, reasons and
        agreement are ``like``'s. The values are those of the reduction from scratch, to the bit
        (tests/tracks/test_reduce.py).

    Returns
    -------
    Reduction
        The fits, the values (SI) and the flag and reason of every impact, in the dataset's
        order (tracks in blocks: the blocks' own reductions in ``blocks``).
    """
    opt = options or ReduceOptions.schema_defaults()
    blocks = tracks.blocks
    onsets: list[dict] = [{} for _ in blocks]  # the raw ball tracks' onsets that glitches left alone
    nominal = [None] * len(blocks) if like is None else [part for part, _ in like.parts()]
    if like is not None and all(like.cameras[c].fps == cameras[c].fps for c in cameras):
        cleaned = [(part.tracks, part.n_outliers) for part in nominal]  # the glitches depend on the frame rates alone
    else:
        glitch_noise = pooled_noises(blocks)
        cleaned = [remove_glitches(b, cameras, glitch_noise, o) for b, o in zip(blocks, onsets, strict=True)]
    start_noise = pooled_noises([tr for tr, _ in cleaned]) if like is None else {}
    balls = [_fit_ball(tr, cameras, part, o) for (tr, _), part, o in zip(cleaned, nominal, onsets, strict=True)]
    lik = [m[-1] for m in balls]
    pop = contact_population(
        gather([c.lik for c in lik], tracks.index, tracks.n),
        gather([c.found for c in lik], tracks.index, tracks.n),
        tracks.ball,
    )
    parts = [
        _finish(tr, counts, ball, pop.prior[idx], cameras, rig, opt, start_noise, part)
        for (tr, counts), ball, idx, part in zip(cleaned, balls, tracks.index, nominal, strict=True)
    ]
    if population_shifts and CONTACT_POPULATION_SHIFTS:
        for part, ball, idx in zip(parts, balls, tracks.index, strict=True):
            part.contact_shift = contact_shifts(part, ball[-1], tuple(p[idx] for p in pop.shifted))
    if len(parts) == 1:
        parts[0].contact_mean = (pop.mean, pop.mean_err)
        return parts[0]
    merged = _gathered(parts, tracks)
    merged = replace(merged, tracks=tracks, cameras=cameras, rig=rig, times={}, phys={}, blocks=parts)
    merged.contact_mean = (pop.mean, pop.mean_err)
    return merged


#: Solve the reduction again at +-1 standard error of each ball type's contact population mean
#: (:func:`contact_shifts`). False: not (the studies' comparison, bench/intervals_study.py).
CONTACT_POPULATION_SHIFTS = True
#: The measured values (and uncertainties) the contact population moves (omega and v_ball_err do not depend on it).
CONTACT_SHIFTED = ("v_bat", "v_ball", "theta", "v_bat_err", "theta_err")


def value_change(name: str, new: np.ndarray, old: np.ndarray) -> np.ndarray:
    """Return ``new - old`` of a measured value (contact or calibration shift); theta's wrapped to (-pi, pi]."""
    d = new - old
    return np.angle(np.exp(1j * d)) if name == "theta" else d


def contact_shifts(part: Reduction, lik: ContactLikelihood, shifted: tuple) -> dict[str, tuple]:
    """Change of each impact's measured values with its ball type's contact population at +1 and -1 standard error.

    Every impact's contact is solved again under the shifted distribution
    (:func:`~ballbat.tracks.fit_contact.contact_posterior`), then its tip fit (whose alignment
    prior is the contact's start) and its values; the flight and spin fits do not depend on the
    contact and are kept. An impact whose distribution did not move (its ball type's likelihoods
    flat, the uniform distribution kept) gets 0, as does one excluded for no impact found.

    Parameters
    ----------
    part : Reduction
        One block's nominal reduction (its ``phys`` holds the tip's track).
    lik : ContactLikelihood
        The block's contact likelihoods.
    shifted : tuple
        The block's rows of the distributions at +1 and at -1 standard error
        (:attr:`~ballbat.tracks.fit_contact.ContactPopulation.shifted`).

    Returns
    -------
    dict
        Name of :data:`CONTACT_SHIFTED` -> (change at +1, change at -1), each (impact,), in the values' units.
    """
    out = {k: [] for k in CONTACT_SHIFTED}
    for prior in shifted:
        contact = contact_posterior(lik, prior)
        moved = contact.duration != part.contact.duration
        Xt, Yt = part.phys[("swing", "bat_tip")]
        swing = fit_swing(
            Xt,
            Yt,
            part.times["swing"],
            part.onset["swing"],
            part.cameras["swing"].fps,
            part.rig.pivot_to_tip,
            contact.t_start,
            contact.t_start_err,
            part.cameras["swing"].exposure_s,
        )
        values = _measured_values(part.flight["swing"], swing, part.spin, contact, part.cameras, part.rig)
        with np.errstate(invalid="ignore"):
            for k in CONTACT_SHIFTED:
                d = value_change(k, values[k], part.values[k])
                out[k].append(np.where(moved & np.isfinite(d), d, 0.0))
    return {k: tuple(v) for k, v in out.items()}


def _gathered(objs: list, tracks: TrackBlocks):
    """Return the blocks' results ``objs`` (arrays, dicts, dataclasses of them) in the dataset's order.

    Arrays of one dimension (impact) are gathered; arrays along frame columns, whose widths
    differ between blocks, are None (each block's are in its own result).
    """
    first = objs[0]
    if isinstance(first, np.ndarray):
        return tracks.gather(objs) if first.ndim == 1 else None
    if isinstance(first, dict):
        return {k: _gathered([o[k] for o in objs], tracks) for k in first}
    if isinstance(first, tuple):
        return tuple(_gathered(list(v), tracks) for v in zip(*objs, strict=True))
    if is_dataclass(first) and not isinstance(first, (Tracks, Camera, Rig)):
        return replace(first, **{f.name: _gathered([getattr(o, f.name) for o in objs], tracks) for f in fields(first)})
    return first


def _finish(
    tracks: Tracks,
    n_outliers: dict,
    ball: tuple,
    prior: np.ndarray,
    cameras,
    rig: Rig,
    opt,
    start_noise: dict,
    like: Reduction | None = None,
) -> Reduction:
    """Reduce one block from its ball fits (:func:`_fit_ball`) and its rows of the contact times' prior.

    ``like``: the block's nominal reduction (:func:`reduce_tracks`'s ``like``): its exclusions kept.
    """
    onset, flight, times, phys, lik = ball
    contact = contact_posterior(lik, prior)
    swing, spin = _fit_bat_and_spin(tracks, cameras, rig, onset, flight, times, phys, contact, like)
    values = _measured_values(flight["swing"], swing, spin, contact, cameras, rig)
    if like is None:
        flag, reason, agree = _exclusions(tracks, onset, flight, swing, spin, cameras, opt, start_noise)
    else:
        flag, reason, agree = like.flag, like.reason, like.agreement
    return Reduction(
        tracks,
        cameras,
        rig,
        onset,
        flight,
        swing,
        spin,
        times,
        phys,
        values,
        flag,
        reason.astype(str),
        n_outliers,
        agree,
        contact,
    )


def _same_camera(like: Reduction | None, cameras: dict[str, Camera], name: str) -> bool:
    """Whether ``like`` (a nominal reduction, or None) reduced camera ``name`` with these very settings."""
    return like is not None and like.cameras[name] == cameras[name]


def _fit_ball(tracks: Tracks, cameras: dict[str, Camera], like: Reduction | None = None, known=None) -> tuple:
    """Fit the ball of every impact: its onset and free flight in each camera, its contact's likelihood.

    Returns ``onset, flight, times, phys`` (:class:`Reduction`'s fields) and the
    :class:`~ballbat.tracks.fit_contact.ContactLikelihood`. ``like``: a reduction of the same
    cleaned tracks, whose camera of unchanged settings is taken as it is, and whose onsets (found
    on the pixels alone) are taken for every camera where these are its very tracks. ``known``:
    onsets found on these very pixels already, by camera (:func:`remove_glitches`'s).
    """
    n = tracks.n
    onset, flight, times, phys = {}, {}, {}, {}
    for name in ("swing", "spin"):
        if _same_camera(like, cameras, name):
            onset[name], flight[name], times[name] = like.onset[name], like.flight[name], like.times[name]
            phys[(name, "ball")] = like.phys[(name, "ball")]
            continue
        ct, cam = tracks.cameras[name], cameras[name]
        t = np.broadcast_to(np.arange(ct.n_columns)[None, :] / cam.fps, (n, ct.n_columns))
        times[name] = t
        same_pixels = like is not None and like.tracks is tracks
        if same_pixels:
            onset[name] = like.onset[name]
        else:
            found = (known or {}).get(name)
            onset[name] = find_onset(ct.x["ball"], ct.y["ball"]) if found is None else found
        X, Y = physical(ct, cam, "ball")
        phys[(name, "ball")] = (X, Y)
        flight[name] = fit_flight(X, Y, t, onset[name], cam.fps)
    lik: ContactLikelihood = contact_likelihood(
        *phys[("swing", "ball")], times["swing"], onset["swing"], flight["swing"]
    )
    return onset, flight, times, phys, lik


def _fit_bat_and_spin(
    tracks: Tracks,
    cameras: dict[str, Camera],
    rig: Rig,
    onset: dict,
    flight: dict,
    times: dict,
    phys: dict,
    contact,
    like: Reduction | None = None,
) -> tuple[Swing, Spin]:
    """Fit every impact's swing (before the contact's start) and spin; ``phys`` gets the tip's and dots' tracks.

    ``like``: as :func:`_fit_ball`'s (the spin fit taken from it where the spin camera's settings are the same).
    """
    Xt, Yt = physical(tracks.cameras["swing"], cameras["swing"], "bat_tip")
    phys[("swing", "bat_tip")] = (Xt, Yt)
    swing = fit_swing(
        Xt,
        Yt,
        times["swing"],
        onset["swing"],
        cameras["swing"].fps,
        rig.pivot_to_tip,
        contact.t_start,
        contact.t_start_err,
        cameras["swing"].exposure_s,
    )
    if _same_camera(like, cameras, "spin"):
        for p in ("dot_a", "dot_b"):
            phys[("spin", p)] = like.phys[("spin", p)]
        return swing, like.spin
    dots = {p: physical(tracks.cameras["spin"], cameras["spin"], p) for p in ("dot_a", "dot_b")}
    for p, v in dots.items():
        phys[("spin", p)] = v
    spin = fit_spin(
        {p: v[0] for p, v in dots.items()},
        {p: v[1] for p, v in dots.items()},
        times["spin"],
        flight["spin"],
        cameras["spin"],
        phys[("spin", "ball")],
    )
    return swing, spin


def _measured_values(
    fs: Flight, swing: Swing, spin: Spin, contact: Contact, cameras: dict[str, Camera], rig: Rig
) -> dict[str, np.ndarray]:
    """v_bat, v_ball, theta, omega and the other measured values of every impact (SI), from the fits.

    The ball's velocity is the flight fit's at the contact's end, where the ball leaves the bat
    (the fit's own velocity is at its reference time, the separation frame's, which is on
    average 0.17 ms before the contact's end at 1 px and 0.63 ms after it at 5 px, while gravity
    turns the flight down by g / v ~ 0.3 rad/s: +5e-5 to -2e-4 rad on every launch angle;
    without a fitted contact, the fit's own).
    """
    with np.errstate(all="ignore"):
        t_end = contact.t_mid + 0.5 * contact.duration - fs.t_ref
        known = np.isfinite(t_end)
        vy = np.where(known, fs.vy - G * t_end, fs.vy)
        v_ball = np.hypot(fs.vx, vy)
        v_ball_err = np.sqrt(fs.var_along)  # the scatter along the motion
        launch = np.arctan2(vy, fs.vx)
        # the contact end's error turns the velocity by g cos(launch) / v per second
        end_err = np.where(known, contact.t_start_err, 0.0)  # t_mid + t_c / 2: the start's error
        launch_err = np.hypot(np.sqrt(fs.var_across) / v_ball, G * np.cos(launch) * end_err / v_ball)
        theta = launch - swing.beta
        theta = np.angle(np.exp(1j * theta))
        theta_err = np.hypot(launch_err, swing.beta_err)
        v_bat = swing.omega * rig.pivot_to_impact
        v_bat_err = swing.omega_err * rig.pivot_to_impact
    rel = cameras["swing"].m_per_px_err
    values = {
        "v_bat": v_bat,
        "v_bat_err": v_bat_err,
        "v_ball": v_ball,
        "v_ball_err": v_ball_err,
        "theta": theta,
        "theta_err": theta_err,
        "omega": spin.omega,
        "omega_err": spin.omega_err,
        "v_bat_err_scale": np.abs(v_bat) * rel,
        "v_ball_err_scale": np.abs(v_ball) * rel,
        "swing_plane_angle": swing.beta,
        "swing_plane_angle_err": swing.beta_err,
        "launch_angle": launch,
        "launch_angle_err": launch_err,
        "contact_time": contact.duration,
        "contact_time_err": contact.duration_err,
    }
    return values


class _Marks:
    """The flag and reason of every impact: each impact keeps the first reason that applies."""

    def __init__(self, n: int):
        self.flag = np.zeros(n, dtype=np.int8)
        self.reason = np.full(n, "ok", dtype=object)

    def __call__(self, cond: np.ndarray, code: ReduceFlag, texts) -> None:
        new = cond & (self.flag == 0)
        self.flag[new] = code
        for i in np.flatnonzero(new):
            self.reason[i] = f"{STAGE}: {texts(i)}"


def _exclusions(
    tracks: Tracks,
    onset: dict,
    flight: dict,
    swing: Swing,
    spin: Spin,
    cameras: dict[str, Camera],
    opt: ReduceOptions,
    noise: dict | None = None,
) -> tuple[np.ndarray, np.ndarray, object]:
    """Return the flag and reason of every impact (the first reason that applies), and the cameras' agreement.

    ``noise``: the misplaced-mark test's noise of all impacts (:func:`pooled_noises`) for a block.
    """
    mark = _Marks(tracks.n)
    _start_exclusions(mark, tracks, noise or {})
    agree = _motion_exclusions(mark, onset, flight, swing, cameras, opt)
    _spin_exclusions(mark, flight, spin, cameras["spin"].fps, opt)
    return mark.flag, mark.reason, agree


def _start_exclusions(mark: _Marks, tracks: Tracks, noise: dict) -> None:
    """Mark impacts with a track whose first marks lie far off its run (:func:`.checks.misplaced_starts`)."""
    for cam, ct in tracks.cameras.items():
        for p in POINTS[cam]:
            ms = misplaced_starts(ct.x[p], ct.y[p], noise.get((cam, p)))
            mark(
                ms.found,
                ReduceFlag.MISPLACED_MARK,
                lambda i, cam=cam, p=p, ms=ms, ct=ct: (
                    f"{p}'s mark at frame {int(ct.frame0[i] + ms.column[i])} in the {cam} camera (one of the track's "
                    f"first {START_MARKS}) lies {ms.distance[i]:.0f} px off the line of its next marks (noise "
                    f"{ms.noise[i]:.2f} px): a misplaced click? Fix or delete that mark in the tracking tool"
                ),
            )


def _motion_exclusions(
    mark: _Marks, onset: dict, flight: dict, swing: Swing, cameras: dict[str, Camera], opt: ReduceOptions
) -> object:
    """Mark impacts without an impact, with too few frames or whose cameras disagree; return the agreement."""
    for name in ("swing", "spin"):
        mark(
            ~onset[name].found,
            ReduceFlag.NO_IMPACT,
            lambda i, name=name: (
                f"no impact found in the {name} camera: its ball track never leaves a rest position "
                "(needs >= 2 frames at rest, then motion to the end of the track)"
            ),
        )
    for name in ("swing", "spin"):
        mark(
            flight[name].n < opt.min_flight_frames,
            ReduceFlag.TOO_FEW_FRAMES,
            lambda i, name=name: (
                f"{flight[name].n[i]} free-flight frame(s) of the ball in the {name} camera, "
                f"fewer than {opt.min_flight_frames}"
            ),
        )
    agree = camera_agreement(flight, cameras)
    mark(
        np.abs(agree.z_speed) > IMPACT_Z,
        ReduceFlag.CAMERAS_DISAGREE,
        lambda i: (
            f"the ball's speed differs between the cameras: {agree.v['swing'][i]:.2f} +- "
            f"{agree.v_err['swing'][i]:.2f} m/s in swing, {agree.v['spin'][i]:.2f} +- {agree.v_err['spin'][i]:.2f} in "
            f"spin (z = {agree.z_speed[i]:.1f}): rows filed under the wrong camera or impact?"
        ),
    )
    mark(
        agree.angles_disagree(),
        ReduceFlag.CAMERAS_DISAGREE,
        lambda i: (
            f"the ball's launch angle differs between the cameras: {np.degrees(agree.launch['swing'][i]):.1f} "
            f"+- {np.degrees(agree.launch_err['swing'][i]):.1f} deg in swing, "
            f"{np.degrees(agree.launch['spin'][i]):.1f} +- {np.degrees(agree.launch_err['spin'][i]):.1f} in spin "
            f"(z = {agree.z_angle[i]:.1f}): rows filed under the "
            "wrong camera or impact, or a mirror or y setting?"
        ),
    )
    mark(
        swing.n < opt.min_tip_frames,
        ReduceFlag.TOO_FEW_FRAMES,
        lambda i: f"{swing.n[i]} pre-impact frame(s) of bat_tip in the swing camera, fewer than {opt.min_tip_frames}",
    )
    return agree


def _spin_exclusions(mark: _Marks, flight: dict, spin: Spin, fps_spin: float, opt: ReduceOptions) -> None:
    """Mark impacts whose spin dots are too few, do not rotate about the ball's centre, or turn too fast."""
    for p in ("dot_a", "dot_b"):
        n_p = spin.mask[p].sum(axis=1)
        mark(
            n_p < opt.min_spin_frames,
            ReduceFlag.TOO_FEW_FRAMES,
            lambda i, p=p, n_p=n_p: (
                f"{n_p[i]} frame(s) of {p} after separation in the spin camera, fewer than {opt.min_spin_frames}"
            ),
        )
    noise = flight["spin"].sigma
    noise_dof = 2 * flight["spin"].n - 4  # two coordinates, four fitted parameters
    for p in ("dot_a", "dot_b"):
        allowed = np.maximum(
            RADIUS_TOLERANCE * spin.radius[p], radius_scatter_limit(noise, noise_dof, spin.mask[p].sum(axis=1))
        )
        mark(
            spin.radius_sd[p] > allowed,
            ReduceFlag.DOT_NOT_ROTATING_ABOUT_CENTRE,
            lambda i, p=p, allowed=allowed: (
                f"{p}'s distance from the ball's centre varies by "
                f"{1e3 * spin.radius_sd[p][i]:.1f} mm rms (mean {1e3 * spin.radius[p][i]:.1f} mm, allowed "
                f"{1e3 * allowed[i]:.1f} mm): the dots do not rotate about the centre (tilted spin axis?)"
            ),
        )
    if spin.offset_chi2 is not None:
        limit = -2.0 * np.log(OFFSET_FALSE_ALARM)  # chi^2 with 2 degrees of freedom
        mark(
            spin.offset_chi2 > limit,
            ReduceFlag.DOT_NOT_ROTATING_ABOUT_CENTRE,
            lambda i: (
                f"the dots turn about a point {1e3 * np.hypot(*spin.offset[i]):.1f} mm off the ball's centre, "
                f"more than the {1e3 * OFFSET_TOLERANCE:.1f} mm tolerated (chi^2 {spin.offset_chi2[i]:.1f}, "
                f"limit {limit:.1f}): a spin axis tilted from the line of sight"
            ),
        )
    mark(
        spin.max_step > UNWRAP_LIMIT,
        ReduceFlag.SPIN_TOO_FAST,
        lambda i: (
            f"a dot turns up to {spin.max_step[i]:.2f} rad between frames (limit {UNWRAP_LIMIT:.2f}): "
            f"spin too fast for {fps_spin:g} fps to unwrap"
        ),
    )
