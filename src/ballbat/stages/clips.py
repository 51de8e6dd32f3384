"""Stage render_clips: ``results/{dataset}/clips/``, both cameras' high-speed clips of a synthetic experiment.

A synthetic dataset whose ``render`` block holds ``video`` is filmed rather than tracked: each
impact's two clips are drawn (:func:`ballbat.video.scene.clip_truths`, the tracks renderer's
own positions without its tracking noise, drawn by :func:`ballbat.video.render.render_frames`)
and written as a lab's files (:func:`ballbat.video.io.write_clip`), with the impacts table
beside them. The import then tracks them as it tracks a lab's folder of clips
(:mod:`ballbat.video.importer`), and the reduction goes on: the whole chain from pixels.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

from ..video.plan import clip_name
from .render import render_inputs

if TYPE_CHECKING:
    import xarray as xr

    from ..properties import Ball
    from ..tracks.render import RenderSettings
    from ..video.render import Look

__all__ = ["clip_look", "render_clips"]

#: Clip k of a render seed s draws its background and noise from seed s * CLIP_SEED_STRIDE + k: a
#: prime larger than any dataset's clip count, so that no two (seed, clip) pairs share a stream.
CLIP_SEED_STRIDE = 100_003


def clip_look(video: dict, seed: int) -> Look:
    """Return how the cameras image the scene: the ``render.video`` block's exposure, bits and markers."""
    from ..video.render import Look

    return Look(
        exposure_s=video["exposure_us"] * 1e-6,
        bit_depth=video["bit_depth"],
        dot_radius_m=video["dot_radius_mm"] * 1e-3,
        marker_radius_m=video["marker_radius_mm"] * 1e-3,
        seed=seed,
    )


def render_clips(
    settings: RenderSettings, video: dict, simulated: xr.Dataset, balls: dict[str, Ball], out: str | os.PathLike[str]
) -> tuple[list[Path], int]:
    """Write every impact's two clips and ``impacts.csv`` into the folder ``out``, whole or not at all.

    Returns the clips written and their frames in all.

    ``video`` is the ``render.video`` block: the file format (and H.264's ``crf``), the exposure,
    the bit depth and the markers' sizes. The clips are written into a temporary folder beside
    ``out`` and renamed to it at the end.
    """
    from ..video.io import write_clip
    from ..video.render import render_frames
    from ..video.scene import clip_truths

    truth, r, ids, ball, bat = render_inputs(simulated, balls)
    clips = clip_truths(settings, truth, r, ids, ball, bat)
    out = Path(out)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    try:
        written, n_frames = [], 0
        for i, c in enumerate(clips):
            look = clip_look(video, settings.seed * CLIP_SEED_STRIDE + i)  # each clip its own background and noise
            m = getattr(settings, c.camera).camera.m_per_px
            name = clip_name(str(c.impact_id), c.camera, video["format"])  # as ballbat.video.plan plans them
            frames = render_frames(c, look, m)
            write_clip(tmp / name, frames, c.fps, exposure_s=look.exposure_s, frame_numbers=c.frames, crf=video["crf"])
            written.append(out / name)
            n_frames += c.frames.size
        rows = "".join(f"{a},{t},{b}\n" for a, t, b in zip(ids, bat.astype(str), ball.astype(str), strict=True))
        (tmp / "impacts.csv").write_text("impact_id,bat,ball\n" + rows)
        if out.exists():
            shutil.rmtree(out)
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return written, n_frames
