"""The truth of a rendered clip: every point's sub-pixel position per frame, from the tracks renderer.

:func:`clip_truths` runs :func:`ballbat.tracks.render.render_tracks` with no tracking noise,
so the positions are the renderer's true ones (the physics is that module's alone), and cuts
them into one :class:`ClipTruth` per impact and camera. The barrel's geometry on the image
(the projected point of the pivot, about which the tip moves) comes from the same
settings: the tip sits ``bat_axis_to_ball`` from the ball's centre along -n at impact.
Each clip also keeps its impact's motion between frames (:class:`ClipMotion`), so that a
frame's exposure is drawn from where the points truly are during it: across the contact's
start the motion is not linear between frames (the tip slows at once, the ball starts from
rest), and a blur interpolated between frames there moved the frame before the contact by up
to 0.06 px along the swing, which read as a bat speed 2e-4 low.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..tracks.data import POINTS
from ..tracks.render import RenderSettings, _to_pixels, render_motion

if TYPE_CHECKING:
    from ..tracks.render import Clock, Motion, RenderCamera


@dataclass(frozen=True)
class ClipMotion:
    """Where one clip's points truly are at any (fractional) frame of the clip: the renderer's motion.

    ``motion`` and ``clock`` are the clip's impact's alone (:meth:`Motion.take`, :meth:`Clock.take`).

    Calling it with frame positions ``k`` (frames from the clip's first, may be fractional)
    returns each point's pixel position, (len(k), 2), noise-free; NaN where a dot is on the
    ball's far side.
    """

    motion: Motion
    clock: Clock
    camera: str
    view: RenderCamera

    def __call__(self, k: np.ndarray) -> dict[str, np.ndarray]:
        """Each point's pixel position at frames ``k`` of the clip."""
        t = self.clock.times(0, k)[None, :]
        pts = self.motion.points(self.camera, t)
        out = {}
        for p in POINTS[self.camera]:
            x, y = _to_pixels(*pts[p], self.view, (0.0, 0.0))
            out[p] = np.stack([x[0], y[0]], axis=1)
        return out


@dataclass
class ClipTruth:
    """True positions (pixels, x right, y down) of the points one camera records in one clip.

    ``x[point]``, ``y[point]`` hold one value per frame of ``frames``, NaN where the point is
    not in view (outside the image, a dot on the ball's far side). ``bat_base_px`` is where
    the bat's axis crosses the image at impact (the tip's position then), None for a camera
    that does not see the bat; ``impact_depth`` is pivot_to_impact / pivot_to_tip (the part of
    the barrel between it and the tip is in front of the ball). ``motion``: where the points are
    between frames (None: linear between them).
    """

    impact_id: str
    camera: str
    fps: float
    width: int
    height: int
    frames: np.ndarray
    x: dict[str, np.ndarray]
    y: dict[str, np.ndarray]
    ball_radius_px: float
    bat_base_px: tuple[float, float] | None
    impact_depth: float
    motion: ClipMotion | None = None

    @property
    def n_frames(self) -> int:
        """Number of frames of the clip."""
        return int(self.frames.size)


def _noise_free(settings: RenderSettings) -> RenderSettings:
    cams = {c: dataclasses.replace(getattr(settings, c), pixel_noise_px=0.0) for c in ("swing", "spin")}
    return dataclasses.replace(settings, **cams)


def clip_truths(
    settings: RenderSettings,
    truth: dict[str, np.ndarray],
    ball_radius: np.ndarray,
    impact_id: np.ndarray,
    ball: np.ndarray,
    bat: np.ndarray,
) -> list[ClipTruth]:
    """Return the true clips (impact by impact, swing then spin) of a rendered experiment.

    Arguments as :func:`ballbat.tracks.render.render_tracks` (its tracking noise is set to 0).
    A clip runs from the first frame the renderer records to the last in which any point is
    in view, plus two (the ball's leaving edge). Each keeps its impact's motion between frames
    (:class:`ClipMotion`).
    """
    settings = _noise_free(settings)
    tracks, motion, clocks = render_motion(truth, ball_radius, settings, impact_id, ball, bat)
    beta = tracks.truth["truth_swing_plane"]
    psi = np.asarray(truth["psi"], float)
    out = []
    for i, iid in enumerate(tracks.impact_id):
        for cam in ("swing", "spin"):
            rc = getattr(settings, cam)
            ct = tracks.cameras[cam]
            seen = np.zeros(ct.n_columns, bool)
            for p in POINTS[cam]:
                seen |= np.isfinite(ct.x[p][i])
            end = min(int(np.flatnonzero(seen).max()) + 3, ct.n_columns) if seen.any() else 0
            base = None
            if "bat_tip" in POINTS[cam]:
                n_dir = beta[i] + psi[i]
                bx, by = -settings.bat_axis_to_ball * np.cos(n_dir), -settings.bat_axis_to_ball * np.sin(n_dir)
                m = rc.camera.m_per_px
                base = (rc.tee_px[0] + rc.camera.sign * bx / m, rc.tee_px[1] - by / m)
            out.append(
                ClipTruth(
                    impact_id=str(iid),
                    camera=cam,
                    fps=rc.camera.fps,
                    width=rc.width_px,
                    height=rc.height_px,
                    frames=ct.frames()[i, :end],
                    x={p: ct.x[p][i, :end].copy() for p in POINTS[cam]},
                    y={p: ct.y[p][i, :end].copy() for p in POINTS[cam]},
                    ball_radius_px=float(ball_radius[i]) / rc.camera.m_per_px,
                    bat_base_px=base,
                    impact_depth=settings.rig.pivot_to_impact / settings.rig.pivot_to_tip,
                    motion=ClipMotion(motion.take(i), clocks[cam].take(i), cam, rc),
                )
            )
    return out
