"""Synthetic raw camera tracks rendered from the truth of a synthetic experiment (Sec. II).

Geometry (docs/tracks.md). Both cameras look along the bat's axis at impact, so their
image plane is the scattering plane. In a physical frame with X along the swing and Y up
(the image is X mirrored when the camera is ``mirror``), for an impact at t = 0:

* the bat's velocity points at the swing-plane angle beta above the horizontal; the tip
  dot sits on the bat's axis, so on the image it is a distance ``bat_axis_to_ball`` from
  the ball's centre along -n (n at psi above the bat's path) and moves along the swing
  direction by ``pivot_to_tip * sin(Omega t)`` (a circle about the pivot seen edge-on),
  Omega = v_bat / pivot_to_impact before impact and Omega (1 - slowdown) after;
* the ball rests on the tee, is accelerated for the contact time t_c (drawn from
  ``contact_ms``) by a force that follows sin^2 (:func:`contact_distance`), and then flies
  freely under gravity with the true exit velocity at the launch angle beta + theta;
* two adjacent corner dots of a 1.5-inch square spin about the spin axis, which passes
  through the ball's centre within the square (offset from its centre); the axis points
  at the camera except for a few impacts where it is tilted (their dots trace ellipses
  not centred on the ball and must be excluded); a dot on the far side is hidden.

Frames are sampled with a random sub-frame phase of the impact, Gaussian pixel noise is
added, points outside the view (by their true position) are missing, and each camera's
track ends when the ball leaves its view. Vectorised over impacts and frames.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..units import DEGREE, INCH, G
from .data import POINTS, RENDERED_EXPOSURE_US, Camera, CameraTracks, Rig, Tracks

#: Side of the square of dots drawn around the spin axis (Sec. II): 1.5 in.
DOT_SQUARE = 1.5 * INCH


@dataclass(frozen=True)
class RenderCamera:
    """A camera of the synthetic rig: its settings plus view and noise.

    Parameters
    ----------
    camera : Camera
        Frame rate, pixel scale, mirror.
    width_px, height_px : int
        Size of the view.
    tee_px : tuple of float
        Pixel position of the ball on the tee.
    pixel_noise_px : float
        Standard deviation of the tracking noise of every point, per coordinate.
    pre_impact_frames : int
        Frames recorded before the impact.
    max_frames : int
        Longest track (frames) a camera records.
    """

    camera: Camera
    width_px: int
    height_px: int
    tee_px: tuple[float, float]
    pixel_noise_px: float
    pre_impact_frames: int
    max_frames: int


@dataclass(frozen=True)
class RenderSettings:
    """Settings of the rendering (SI inside), built by :func:`settings_from_config`.

    No field has a default: the defaults are the config schema's alone (the block given to
    :func:`settings_from_config` is validated, its defaults filled).
    """

    swing: RenderCamera
    spin: RenderCamera
    rig: Rig
    seed: int
    swing_plane: tuple[float, float]
    contact_time: tuple[float, float]
    bat_slowdown: tuple[float, float]
    bat_axis_to_ball: float
    axis_offset: float
    tilted_fraction: float
    tilt: tuple[float, float]


#: Calibrations a lab states with an uncertainty, which ``draw_calibration`` draws:
#: (block, setting, its uncertainty's key, relative). A camera's ``m_per_px_err`` is relative
#: (as the reduction reads it), ``fps_err`` too; the rig's ``*_err_in`` are absolute (inches, as
#: their names say). An uncertainty of 0 (the schema's default) is not drawn.
CALIBRATION_ERRORS = (
    ("cameras", "m_per_px", "m_per_px_err", True),
    ("cameras", "fps", "fps_err", True),
    ("rig", "pivot_to_tip_in", "pivot_to_tip_err_in", False),
    ("rig", "pivot_to_impact_in", "pivot_to_impact_err_in", False),
)

#: Spawn key of the calibration's draw under the render seed: a stream of its own, so that the
#: impacts' draws (``numpy.random.default_rng(seed)``) are the same whether it is drawn or not.
CALIBRATION_SPAWN_KEY = 0xCA1


def drawn_calibration(cfg: dict) -> dict:
    """Return the render block with its true calibration drawn from the stated uncertainties (a copy).

    Every setting of :data:`CALIBRATION_ERRORS` whose uncertainty the block states (non-zero)
    becomes ``value * (1 + err * z)`` (relative) or ``value + err * z`` (absolute), z standard
    normal from ``numpy.random.SeedSequence(cfg["seed"], spawn_key=(CALIBRATION_SPAWN_KEY,))``,
    in the order of the table, camera by camera (swing, spin): reproducible from the render seed.
    The renderer draws the tracks with these; the reduction reads the declared block
    (:func:`ballbat.tracks.data.camera_block` of the config), so the difference is the
    calibration error a lab's declared uncertainty is meant to cover. The draw of a setting is
    the same whether or not the others are stated (each takes its own normal).
    """
    out = {**cfg, "cameras": {n: dict(c) for n, c in cfg["cameras"].items()}, "rig": dict(cfg["rig"])}
    z = iter(calibration_draws(cfg))
    for b, key, err_key, relative in _calibration_entries(out):
        zk = next(z)
        err = float(b[err_key])
        if err > 0:
            b[key] = float(b[key]) * (1.0 + err * zk) if relative else float(b[key]) + err * zk
    return out


def _calibration_entries(cfg: dict) -> list[tuple[dict, str, str, bool]]:
    """Return the drawn settings in the order of their draws: (block, setting, its uncertainty's key, relative)."""
    blocks = {"cameras": [cfg["cameras"][n] for n in ("swing", "spin")], "rig": [cfg["rig"]]}
    return [(b, key, err_key, rel) for block, key, err_key, rel in CALIBRATION_ERRORS for b in blocks[block]]


def calibration_draws(cfg: dict) -> np.ndarray:
    """Return the standard normals :func:`drawn_calibration` draws, one per calibration source.

    In the order of :data:`ballbat.systematics.SOURCES` (swing and spin pixel scale, swing and
    spin frame rate, pivot-to-tip, pivot-to-impact): the drawn true calibration of source k is
    the declared one moved by ``z[k]`` of its stated uncertainty, so a quantity's change under
    the draw is, to first order, the sum of ``z[k]`` times its change per +1 sigma of source k
    (what a replicate study uses to take the draw's spread out of a bias,
    :func:`ballbat.studies.replicates.run_replicate`). Drawn whether or not a source's uncertainty is stated.
    """
    rng = np.random.default_rng(np.random.SeedSequence(int(cfg["seed"]), spawn_key=(CALIBRATION_SPAWN_KEY,)))
    return rng.standard_normal(len(_calibration_entries(cfg)))


def settings_from_config(cfg: dict) -> RenderSettings:
    """Render settings from a dataset's validated ``render`` config block (paper units: in, deg, ms, mm).

    Parameters
    ----------
    cfg : dict
        The block of the validated config, every default filled (the workflow's config;
        :func:`ballbat.pipeline.config.checked_block` for a block of one's own). A key
        missing is a ``KeyError``: no default is restated here. With ``draw_calibration``
        true the tracks are drawn with a true calibration drawn from the stated
        uncertainties (:func:`drawn_calibration`).

    Returns
    -------
    RenderSettings
    """
    if cfg["draw_calibration"]:
        cfg = drawn_calibration(cfg)
    cams = {}
    for name, c in cfg["cameras"].items():
        cams[name] = RenderCamera(
            camera=Camera(
                fps=float(c["fps"]),
                m_per_px=float(c["m_per_px"]),
                mirror=bool(c["mirror"]),
                m_per_px_err=float(c["m_per_px_err"]),
                fps_err=float(c["fps_err"]),
                exposure_s=RENDERED_EXPOSURE_US * 1e-6,  # the tracks sample the motion at instants
            ),
            width_px=int(c["width_px"]),
            height_px=int(c["height_px"]),
            tee_px=tuple(float(v) for v in c["tee_px"]),
            pixel_noise_px=float(c["pixel_noise_px"]),
            pre_impact_frames=int(c["pre_impact_frames"]),
            max_frames=int(c["max_frames"]),
        )
    rig = Rig.from_inches(**{k: float(v) for k, v in cfg["rig"].items()})
    deg = lambda k: tuple(v * DEGREE for v in cfg[k])  # noqa: E731
    return RenderSettings(
        swing=cams["swing"],
        spin=cams["spin"],
        rig=rig,
        seed=int(cfg["seed"]),
        swing_plane=deg("swing_plane_deg"),
        contact_time=tuple(v * 1e-3 for v in cfg["contact_ms"]),
        bat_slowdown=tuple(cfg["bat_slowdown"]),
        bat_axis_to_ball=float(cfg["bat_axis_to_ball_mm"]) * 1e-3,
        axis_offset=float(cfg["axis_offset_mm"]) * 1e-3,
        tilted_fraction=float(cfg["tilted_fraction"]),
        tilt=deg("tilt_deg"),
    )


def contact_distance(x: np.ndarray, t_c: np.ndarray | float) -> np.ndarray:
    """Distance / exit speed travelled a time ``x`` into a contact of duration ``t_c`` (0 <= x <= t_c).

    The force follows sin^2(pi x / t_c) (zero at both ends, peak at the middle: the shape of a
    ball-bat force pulse, Russell, "Forces between bat and ball"); the ball's speed is then
    v (x / t_c - sin(2 pi x / t_c) / (2 pi)) and at the end it is v t_c / 2 from its start.
    """
    return x**2 / (2 * t_c) + t_c * (np.cos(2 * np.pi * x / t_c) - 1) / (4 * np.pi**2)


def _ball_motion(t, v, launch, t_c):
    """Ball centre (X, Y) and rotation fraction clock: a sin^2 force pulse, then free flight."""
    vx, vy = v * np.cos(launch), v * np.sin(launch)
    tc = t_c[:, None]
    during = (t > 0) & (t < tc)
    after = t >= tc
    x = np.clip(t, 0.0, tc)
    s = np.where(during, contact_distance(x, tc), np.where(after, t - tc / 2, 0.0))  # distance / speed
    tf = np.where(after, t - tc, 0.0)
    X = vx[:, None] * s
    Y = vy[:, None] * s - 0.5 * G * tf**2
    return X, Y, s


def _sample_times(n, cam: RenderCamera, t_end, rng):
    """Frame times (impact at t = 0, random sub-frame phase), integer frame origins, and each impact's phase."""
    fps = cam.camera.fps
    phase = rng.uniform(0.0, 1.0, n)
    ncol = int(min(cam.max_frames, cam.pre_impact_frames + np.ceil(np.max(t_end) * fps) + 2))
    k = np.arange(ncol)[None, :] - cam.pre_impact_frames
    t = (k + phase[:, None]) / fps
    frame0 = rng.integers(0, 5000, n)
    return t, frame0, phase


def _to_pixels(X, Y, cam: RenderCamera, noise):
    m = cam.camera.m_per_px
    x = cam.tee_px[0] + cam.camera.sign * X / m + noise[0]
    y = cam.tee_px[1] - Y / m + noise[1]
    return x, y


def _exit_time(v, launch, t_c, cam: RenderCamera):
    """Time the ball leaves the view, ignoring gravity (an upper bound on the columns needed, + margin)."""
    m = cam.camera.m_per_px
    vx_px = np.abs(v * np.cos(launch)) / m
    vy_px = np.abs(v * np.sin(launch)) / m
    right = np.where(cam.camera.sign * np.cos(launch) >= 0, cam.width_px - cam.tee_px[0], cam.tee_px[0])
    up = np.where(np.sin(launch) >= 0, cam.tee_px[1], cam.height_px - cam.tee_px[1])
    with np.errstate(divide="ignore"):
        t = np.minimum(right / vx_px, up / vy_px)
    return 1.2 * t + t_c + 3.0 / cam.camera.fps


def _dot_track(X, Y, r, rho, phi, frame) -> tuple[np.ndarray, np.ndarray]:
    """Return a spin dot's position: at ``rho`` from the spin axis, turned to ``phi``; NaN behind the ball.

    ``frame`` is the spin axis and two unit vectors across it (each 3 x impact); the camera
    looks along -z, so a dot with z < 0 is hidden.
    """
    axis, e1, e2 = frame
    gamma = np.arcsin(np.clip(rho / r, -1, 1))
    c, sn = np.cos(phi), np.sin(phi)
    comp = [
        r[:, None]
        * (
            np.cos(gamma)[:, None] * axis[i][:, None]
            + np.sin(gamma)[:, None] * (c * e1[i][:, None] + sn * e2[i][:, None])
        )
        for i in range(3)
    ]
    hidden = comp[2] < 0
    return np.where(hidden, np.nan, X + comp[0]), np.where(hidden, np.nan, Y + comp[1])


def _observed(pts: dict, points: tuple, cam, t: np.ndarray, rng) -> tuple[dict, dict]:
    """Return the pixel tracks of ``points`` as the camera records them.

    With its tracking noise, NaN outside the view, and ended when the ball leaves the view.
    Whether a point is in view is a matter of where it is, not of the tracking's error: a
    point is kept or lost by its true position. (Deciding on the noisy position kept, near
    the edge of the view, the frames whose error pointed inwards, and so slowed the ball's
    fitted speed by about 0.1 of its standard error at 5 px: docs/tracks.md.)
    """
    xs, ys = {}, {}
    for p in points:
        Xp, Yp = pts[p]
        noise = rng.standard_normal((2, *Xp.shape)) * cam.pixel_noise_px
        x_true, y_true = _to_pixels(Xp, Yp, cam, (0.0, 0.0))
        out = ~((x_true >= 0) & (x_true < cam.width_px) & (y_true >= 0) & (y_true < cam.height_px))
        x, y = x_true + noise[0], y_true + noise[1]
        x[out] = np.nan
        y[out] = np.nan
        xs[p], ys[p] = x, y
    # the track ends when the ball leaves the view (after impact)
    gone = (t > 0) & np.isnan(xs["ball"])
    ended = np.cumsum(gone, axis=1) > 0
    for p in points:
        xs[p][ended] = np.nan
        ys[p][ended] = np.nan
    return xs, ys


def _dot_geometry(rng: np.random.Generator, n: int, axis_offset: float) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each dot's distance from the spin axis and its angle at time 0, drawn for ``n`` impacts.

    The dots are two adjacent corners of a square; the spin axis is offset from its centre by up
    to ``axis_offset`` (uniform over the disc), and the square is turned by a uniform angle.
    """
    off_r = axis_offset * np.sqrt(rng.uniform(size=n))
    off_a = rng.uniform(0, 2 * np.pi, n)
    rot0 = rng.uniform(0, 2 * np.pi, n)
    h = DOT_SQUARE / 2
    corners = np.array([[h, h], [-h, h]])  # dot_a, dot_b in the square's frame
    dots = {}
    for j, p in enumerate(("dot_a", "dot_b")):
        cx = corners[j, 0] - off_r * np.cos(off_a)
        cy = corners[j, 1] - off_r * np.sin(off_a)
        dots[p] = (np.hypot(cx, cy), np.arctan2(cy, cx) + rot0)
    return dots


@dataclass(frozen=True)
class Motion:
    """Every impact's true motion as the renderer draws it: the points' positions at any time.

    The draws of :func:`render_tracks` (swing-plane angle, contact time, the bat's slowdown,
    the spin axis and dots) with the truth they move by; :meth:`points` gives each point's
    position (m, physical frame, impact at t = 0) at any times, which the tracks sample at their
    frames and :mod:`ballbat.video.render` within each frame's exposure (the motion blur).
    """

    settings: RenderSettings
    v_bat: np.ndarray
    v_ball: np.ndarray
    omega: np.ndarray
    psi: np.ndarray
    r: np.ndarray
    beta: np.ndarray
    launch: np.ndarray
    t_c: np.ndarray
    slow: np.ndarray
    chi: np.ndarray
    dots: dict
    frame: tuple

    def take(self, i: int) -> Motion:
        """Return the motion of impact ``i`` alone (every array of length one)."""
        one = slice(i, i + 1)
        per_impact = {f.name: getattr(self, f.name) for f in fields(self)}
        per_impact = {k: v[one] for k, v in per_impact.items() if isinstance(v, np.ndarray)}
        dots = {p: (rho[one], phi[one]) for p, (rho, phi) in self.dots.items()}
        return replace(self, **per_impact, dots=dots, frame=tuple(v[:, one] for v in self.frame))

    def points(self, camera: str, t: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Each point ``camera`` records at times ``t`` (s, (impact, time)): (X, Y) in m, NaN for a hidden dot."""
        X, Y, s = _ball_motion(t, self.v_ball, self.launch, self.t_c)
        pts = {"ball": (X, Y)}
        if camera == "swing":
            omega_bat = self.v_bat / self.settings.rig.pivot_to_impact
            ang = np.where(t < 0, omega_bat[:, None] * t, omega_bat[:, None] * (1 - self.slow[:, None]) * t)
            u = self.settings.rig.pivot_to_tip * np.sin(ang)
            n_dir = self.beta + self.psi
            tx0 = -self.settings.bat_axis_to_ball * np.cos(n_dir)
            ty0 = -self.settings.bat_axis_to_ball * np.sin(n_dir)
            pts["bat_tip"] = (
                tx0[:, None] + u * np.cos(self.beta)[:, None],
                ty0[:, None] + u * np.sin(self.beta)[:, None],
            )
        else:
            turn = self.omega[:, None] * s  # rotation angle (s is distance / speed: same clock)
            for p, (rho, phi0) in self.dots.items():
                pts[p] = _dot_track(X, Y, self.r, rho, phi0[:, None] + turn, self.frame)
        return pts


def _draw_motion(truth: dict, ball_radius: np.ndarray, settings: RenderSettings, rng: np.random.Generator) -> Motion:
    """Draw every impact's motion (:class:`Motion`) from ``rng``, in the order the tracks always drew it."""
    n = len(np.asarray(truth["v_bat"]))
    theta, psi = (np.asarray(truth[k], float) for k in ("theta", "psi"))
    beta = rng.uniform(*settings.swing_plane, n)
    t_c = rng.uniform(*settings.contact_time, n)
    slow = rng.uniform(*settings.bat_slowdown, n)
    tilted = rng.uniform(size=n) < settings.tilted_fraction
    chi = np.where(tilted, rng.uniform(*settings.tilt, n), 0.0)
    zeta = rng.uniform(0, 2 * np.pi, n)
    dots = _dot_geometry(rng, n, settings.axis_offset)
    axis = np.stack([np.sin(chi) * np.cos(zeta), np.sin(chi) * np.sin(zeta), np.cos(chi)])
    e1 = np.stack([np.cos(zeta) * np.cos(chi), np.sin(zeta) * np.cos(chi), -np.sin(chi)])
    e2 = np.stack([-np.sin(zeta), np.cos(zeta), np.zeros(n)])
    return Motion(
        settings,
        v_bat=np.asarray(truth["v_bat"], float),
        v_ball=np.asarray(truth["v_ball"], float),
        omega=np.asarray(truth["omega"], float),
        psi=psi,
        r=np.asarray(ball_radius, float),
        beta=beta,
        launch=beta + theta,
        t_c=t_c,
        slow=slow,
        chi=chi,
        dots=dots,
        frame=(axis, e1, e2),
    )


@dataclass(frozen=True)
class Clock:
    """When a camera's columns are: column k of impact i at (k - ``pre_impact_frames`` + ``phase[i]``) / ``fps``."""

    fps: float
    pre_impact_frames: int
    phase: np.ndarray

    def take(self, i: int) -> Clock:
        """Return the clock of impact ``i`` alone."""
        return Clock(self.fps, self.pre_impact_frames, self.phase[i : i + 1])

    def times(self, i: int, columns: np.ndarray) -> np.ndarray:
        """Return the times (s, impact at 0) of impact ``i``'s (fractional) ``columns``."""
        return (np.asarray(columns, float) - self.pre_impact_frames + self.phase[i]) / self.fps


def render_tracks(
    truth: dict[str, np.ndarray],
    ball_radius: np.ndarray,
    settings: RenderSettings,
    impact_id: np.ndarray,
    ball: np.ndarray,
    bat: np.ndarray,
) -> Tracks:
    """Render both cameras' tracks of every impact.

    Parameters
    ----------
    truth : dict
        Per-impact true values (SI): ``v_bat``, ``v_ball``, ``theta``, ``omega``, ``psi``
        and any further ``truth_*`` to keep (copied to :attr:`Tracks.truth`).
    ball_radius : ndarray
        Radius of each impact's ball (m).
    settings : RenderSettings
    impact_id, ball, bat : ndarray
        Identity of each impact.

    Returns
    -------
    Tracks
        Dense noisy tracks, and the truth (``truth_*``) including the rendering's own
        draws (swing-plane angle, launch angle, spin-axis tilt, dot radii, contact time).
    """
    return render_motion(truth, ball_radius, settings, impact_id, ball, bat)[0]


def render_motion(
    truth: dict[str, np.ndarray],
    ball_radius: np.ndarray,
    settings: RenderSettings,
    impact_id: np.ndarray,
    ball: np.ndarray,
    bat: np.ndarray,
) -> tuple[Tracks, Motion, dict[str, Clock]]:
    """:func:`render_tracks`, with the motion drawn and each camera's clock (the truth between frames)."""
    rng = np.random.default_rng(settings.seed)
    motion = _draw_motion(truth, ball_radius, settings, rng)
    cams, clocks = {}, {}
    for name, cam in (("swing", settings.swing), ("spin", settings.spin)):
        t_end = _exit_time(motion.v_ball, motion.launch, motion.t_c, cam)
        t, frame0, phase = _sample_times(len(impact_id), cam, t_end, rng)
        clocks[name] = Clock(cam.camera.fps, cam.pre_impact_frames, phase)
        xs, ys = _observed(motion.points(name, t), POINTS[name], cam, t, rng)
        cams[name] = CameraTracks(frame0.astype(np.int64), xs, ys)

    keep = {f"truth_{k}": np.asarray(v) for k, v in truth.items()}
    keep.update(
        truth_swing_plane=motion.beta,
        truth_launch_angle=motion.launch,
        truth_contact_time=motion.t_c,
        truth_bat_slowdown=motion.slow,
        truth_spin_axis_tilt=motion.chi,
        truth_dot_a_radius=motion.dots["dot_a"][0],
        truth_dot_b_radius=motion.dots["dot_b"][0],
    )
    tracks = Tracks(
        impact_id=np.asarray(impact_id).astype(str),
        ball=np.asarray(ball).astype(str),
        bat=np.asarray(bat).astype(str),
        cameras=cams,
        truth=keep,
    )
    return tracks, motion, clocks
