"""Small clips made in the tests (tests/video/): a truth by hand, drawn by ballbat.video.render; a quality table."""

from __future__ import annotations

import numpy as np

from ballbat.video.render import Look
from ballbat.video.scene import ClipTruth
from ballbat.video.track import Found, found_columns

#: A small camera: 0.0025 m per px puts a baseball's radius (36.6 mm) at 14.6 px.
M_PER_PX = 0.0025
RADIUS_PX = 0.0366 / M_PER_PX
#: A plain look (no clutter, even light, low noise) and the default one.
PLAIN = Look(clutter=0, lighting=0.0, read_noise=0.004, shot_noise=0.0, exposure_s=0.0, seed=3)
BUSY = Look(seed=4, dot_radius_m=0.008)
#: A render block of the tracks renderer (the default rig) for clips drawn from a drawn motion.
SCENE_RENDER = {
    "cameras": {
        "swing": {"fps": 3000, "m_per_px": 0.00074, "tee_px": [540, 480], "pixel_noise_px": 2.0},
        "spin": {"fps": 1000, "m_per_px": 0.00125, "tee_px": [600, 480], "pre_impact_frames": 5},
    },
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    "seed": 5,
}


def spin_truth(
    n: int = 8, width: int = 240, height: int = 160, v_px: float = 6.0, hide_b_from: int | None = None, hide_b_to=None
):
    """A ball flying to the right at ``v_px`` per frame with two dots turning about its centre (spin camera).

    ``dot_b`` is hidden (behind the ball) from frame ``hide_b_from`` up to ``hide_b_to`` (exclusive; None: the end).
    """
    k = np.arange(n)
    bx, by = 70.0 + v_px * k + 0.37, 80.0 - 0.8 * k + 0.21
    ang = 0.3 + 0.25 * k
    x = {"ball": bx, "dot_a": bx + 7.0 * np.cos(ang), "dot_b": bx + 6.0 * np.cos(ang + 1.6)}
    y = {"ball": by, "dot_a": by + 7.0 * np.sin(ang), "dot_b": by + 6.0 * np.sin(ang + 1.6)}
    if hide_b_from is not None:
        x["dot_b"][hide_b_from:hide_b_to] = np.nan
        y["dot_b"][hide_b_from:hide_b_to] = np.nan
    return ClipTruth("T1", "spin", 1000.0, width, height, 100 + k, x, y, RADIUS_PX, None, 28 / 34)


def swing_truth(n: int = 8, width: int = 240, height: int = 160, tip_start: float = 20.0):
    """A ball at rest and the bat's tip marker moving towards it (swing camera)."""
    k = np.arange(n)
    x = {"ball": np.full(n, 150.3), "bat_tip": tip_start + 9.0 * k + 0.4}
    y = {"ball": np.full(n, 70.6), "bat_tip": np.full(n, 104.2) - 0.5 * k}
    base = (x["bat_tip"][-1] + 30.0, y["bat_tip"][-1])
    return ClipTruth("T1", "swing", 3000.0, width, height, k, x, y, RADIUS_PX, base, 28 / 34)


def still_balls(radius_px: float, n: int, seed: int = 0) -> list[tuple[np.ndarray, float, float]]:
    """``n`` noise-free frames of a still ball (16 bit, no clutter, even light, no blur) at random sub-pixel places.

    The ball is the renderer's, Lambert-shaded by its one light; each as (frame, true x, true y).
    """
    from ballbat.video.render import render_frames

    look = Look(read_noise=0.0, shot_noise=0.0, clutter=0, lighting=0.0, exposure_s=0.0, bit_depth=16, seed=1)
    size = int(2 * radius_px + 40)
    out = []
    for x, y in np.random.default_rng(seed).uniform(0, 1, (n, 2)) + size / 2:
        truth = ClipTruth("S", "spin", 1000.0, size, size, np.array([0]), {"ball": np.array([x])},
                          {"ball": np.array([y])}, radius_px, None, 28 / 34)  # fmt: skip
        out.append((next(render_frames(truth, look, M_PER_PX)), float(x), float(y)))
    return out


#: A lab's two cameras as the clips of a ``format: video`` folder are rendered (1024 x 512 px) and the rig.
LAB_CAMERAS = {
    "swing": {"fps": 3000, "m_per_px": 0.00074, "tee_px": [600, 300], "width_px": 1024, "height_px": 512},
    "spin": {"fps": 1000, "m_per_px": 0.00125, "tee_px": [350, 330], "width_px": 1024, "height_px": 512},
}
LAB_RIG = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
#: The true impacts of the clip folder: baseballs on the wood bat.
LAB_TRUTH = {
    "v_bat": np.array([70.0, 75.0, 72.0]),  # mph
    "v_ball": np.array([80.0, 90.0, 70.0]),  # mph
    "theta": np.array([8.0, 20.0, 30.0]),  # deg
    "omega": np.array([1500.0, 3000.0, 2500.0]),  # rpm
    "psi": np.array([10.0, 25.0, 35.0]),  # deg
}


def render_clip_folder(folder, seed: int = 3, n: int | None = None) -> list[ClipTruth]:
    """Render :data:`LAB_TRUTH`'s first ``n`` impacts (default all) W1.. in both cameras as TIFF stacks in ``folder``.

    With impacts.csv beside them. The markers are 4 mm (dots) and 6 mm (tip) in radius; returns
    each clip's truth.
    """
    from ballbat.pipeline.config import checked_block
    from ballbat.tracks.render import settings_from_config
    from ballbat.units import DEGREE, MPH, RPM
    from ballbat.video.io import write_clip
    from ballbat.video.render import render_frames
    from ballbat.video.scene import clip_truths

    s = settings_from_config(checked_block({"cameras": LAB_CAMERAS, "rig": LAB_RIG, "seed": seed}, "render"))
    unit = {"v_bat": MPH, "v_ball": MPH, "theta": DEGREE, "omega": RPM, "psi": DEGREE}
    n = LAB_TRUTH["psi"].size if n is None else n
    truth = {k: v[:n] * unit[k] for k, v in LAB_TRUTH.items()}
    ids = np.array([f"W{i + 1}" for i in range(n)])
    true = clip_truths(s, truth, np.full(n, 0.0366), ids, np.full(n, "baseball"), np.full(n, "wood"))
    look = Look(dot_radius_m=0.004, marker_radius_m=0.006)
    for c in true:
        frames = render_frames(c, look, LAB_CAMERAS[c.camera]["m_per_px"])
        write_clip(
            folder / f"{c.impact_id}_{c.camera}.tif", frames, c.fps, exposure_s=look.exposure_s, frame_numbers=c.frames
        )
    rows = "".join(f"{i},wood,baseball\n" for i in ids)
    (folder / "impacts.csv").write_text("impact_id,bat,ball\n" + rows)
    return true


def quality_clip(impact_id: str, camera: str, n: int, seed: int) -> dict:
    """A tracker's quality table of one clip of ``n`` frames, as the tracker lays it out (found_columns of a Found)."""
    rng = np.random.default_rng(seed)
    found = Found()
    points = ("ball", "bat_tip") if camera == "swing" else ("ball", "dot_a", "dot_b")
    for k in range(100, 100 + n):
        if k % 5 == 0:
            found.leave_out("ball", k, f"ball edge not round (residual {0.5 + rng.random():.2f} px; occluded)")
            for p in points[1:]:
                found.leave_out(p, k, "no ball" if p != "bat_tip" else "no tip marker found")
            continue
        found.add("ball", k, 300 + k, 200.0, 0.05 + 0.1 * rng.random(), 150 + 10 * rng.random())
        for p in points[1:]:
            if p == "dot_b" and k % 3 == 0:
                found.leave_out(p, k, "not seen inside the ball (hidden or on the limb)")
                found.leave_out("dot", k, f"spot at {300 + k:.1f}, 190.0 on the limb (0.9{k % 10} of the radius)")
            else:
                found.add(p, k, 300 + k, 190.0, np.nan, 60 + 20 * rng.random())
    return found_columns(found, impact_id, camera)[1]


def quality_table() -> dict:
    """A quality table of three impacts' clips in both cameras (12, 16, 20 frames), every kind of row."""
    tables = [
        quality_clip(f"W{i}", cam, 12 + 4 * i, seed=10 * i + (cam == "spin"))
        for i in range(3)
        for cam in ("swing", "spin")
    ]
    return {k: np.concatenate([t[k] for t in tables]) for k in tables[0]}


def two_impact_truths(seed: int = 5) -> list[ClipTruth]:
    """Two impacts' clip truths (swing, spin, swing, spin) drawn by the renderer with :data:`SCENE_RENDER`."""
    from ballbat.pipeline.config import checked_block
    from ballbat.tracks.render import settings_from_config
    from ballbat.units import DEGREE, MPH, RPM
    from ballbat.video.scene import clip_truths

    s = settings_from_config(checked_block(SCENE_RENDER | {"seed": seed}, "render"))
    truth = {
        "v_bat": np.array([75.0, 68.0]) * MPH,
        "v_ball": np.array([85.0, 90.0]) * MPH,
        "theta": np.array([10.0, -5.0]) * DEGREE,
        "omega": np.array([2000.0, 3500.0]) * RPM,
        "psi": np.array([15.0, -20.0]) * DEGREE,
    }
    ids = np.array(["W1", "W2"])
    return clip_truths(s, truth, np.full(2, 0.0366), ids, np.full(2, "baseball"), np.full(2, "wood"))
