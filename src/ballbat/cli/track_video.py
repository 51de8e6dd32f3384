"""``ballbat track-video CLIP... -o tracks.csv``: track clips into the long tracks table (docs/video.md).

Each clip is named ``{impact_id}_{camera}.{ext}`` (camera ``swing`` or ``spin``), as the
tracking tools' files are. Every clip is tracked before anything is written: a clip that
cannot be read stops the command with its file and frame named, and nothing is written.
Writes the tracks (``-o``) and, beside them, ``<name>.quality.csv`` (every point found with its
residual and contrast, every point left out with its reason); prints the settings each file
holds, and the points found and left out, as YAML.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import Counter
from pathlib import Path

_NAME = re.compile(r"^(?P<impact_id>.+)_(?P<camera>swing|spin)$")

#: The ball's measured radius (median over the frames it is found in) may differ from the one given by
#: this much before the command warns. On rendered clips the measured radius is within 0.3 % of the
#: truth in lossless files at 29-49 px, 0.9 % at 15 px, and 1 % in H.264 at CRF 18 (docs/video.md): a
#: larger difference says the ``m_per_px`` the radius came from, or the ball, is not what was typed.
RADIUS_WARN = 0.02

EXAMPLE = """examples:
  ballbat track-video W01_swing.mkv W01_spin.mkv --ball-radius-px 49.5,29.3 -o tracks.csv
  ballbat track-video clips/*.cihx --ball-radius-px 49.5,29.3 --dot-radius-px 3.2 -o tracks.csv
  ballbat track-video clips/*.cine --ball-radius-px 49.5,29.3 -o tracks.csv
  ballbat track-video T1_spin.mp4 --ball-radius-px 5,5 --background median --ball-fit centroid -o tracks.csv"""


def add_parser(sub: argparse._SubParsersAction, formatter_class: type[argparse.HelpFormatter]) -> None:
    """Register ``track-video`` on the ``ballbat`` command's subparsers."""
    p = sub.add_parser(
        "track-video",
        help="track high-speed clips into ballbat's long tracks CSV",
        epilog=EXAMPLE,
        formatter_class=formatter_class,
    )
    p.add_argument("clips", nargs="+", metavar="CLIP", help="clips named {impact_id}_{camera}.{ext}")
    p.add_argument("-o", "--output", required=True, help="long tracks CSV to write (and <name>.quality.csv)")
    p.add_argument("--parents", action="store_true", help="create the output's missing folders")
    p.add_argument(
        "--ball-radius-px",
        required=True,
        metavar="SWING,SPIN",
        help="the ball's radius in each camera's pixels (Table I's diameter / 2 / m_per_px)",
    )
    for key, what in (("dot_radius_px", "the spin dots' radius"), ("marker_radius_px", "the tip marker's radius")):
        p.add_argument(f"--{key.replace('_', '-')}", type=float, help=f"{what}, px (default: TrackOptions')")
    p.add_argument(
        "--background",
        choices=("none", "median"),
        help="median: subtract the clip's still background (the per-pixel median of 25 frames) first (default none)",
    )
    p.add_argument(
        "--search-px", type=float, help="half-side of the region searched about the ball's prediction (default 4 radii)"
    )
    p.add_argument(
        "--ball-fit",
        choices=("edge", "centroid", "silhouette"),
        help="centroid: for a ball a few pixels across; silhouette: a ball that is no bright disc (default edge)",
    )
    p.set_defaults(func=cmd_track_video)


def _radii(text: str) -> dict[str, float]:
    try:
        swing, spin = (float(v) for v in text.split(","))
    except ValueError:
        raise SystemExit(
            f"ballbat track-video: error: --ball-radius-px {text!r} is not SWING,SPIN (two numbers)"
        ) from None
    return {"swing": swing, "spin": spin}


def _track_one(path: Path, radii: dict, args) -> tuple[dict, dict, dict]:
    from ..video.io import open_clip
    from ..video.track import TrackOptions, found_columns, require_ball, track_clip

    m = _NAME.match(path.stem)
    if not m:
        raise ValueError(f"{path}: not named {{impact_id}}_{{camera}}.{{ext}} (camera swing or spin)")
    cam = m["camera"]
    points = ("ball", "bat_tip") if cam == "swing" else ("ball", "dot_a", "dot_b")
    clip = open_clip(path)
    keys = ("dot_radius_px", "marker_radius_px", "background", "search_px", "ball_fit")
    sizes = {k: getattr(args, k) for k in keys if getattr(args, k, None) is not None}
    found = track_clip(clip, TrackOptions(radii[cam], points, **sizes))
    require_ball(found, str(path))
    tracks, quality = found_columns(found, m["impact_id"], cam)
    info = clip.info
    report = {
        "file": str(path),
        "impact_id": m["impact_id"],
        "camera": cam,
        "size_px": [info.width, info.height],
        "bit_depth": info.bit_depth,
        "fps": info.fps,
        "exposure_s": info.exposure_s,
        "trigger_frame": info.trigger_frame,
        "source": dict(info.source),
        "ball_radius_px": _radius_check(path, radii[cam], found.ball_radii),
        "points_found": dict(Counter(found.rows["point"])),
        "left_out": dict(Counter(f"{p}: {why}" for p, _, why in found.left_out)),
    }
    return tracks, quality, report


def _radius_check(path: Path, given: float, radii: list[float]) -> dict:
    """Return the ball's radius given and measured (median of its frames); warn when they differ by over RADIUS_WARN."""
    import numpy as np

    measured = float(np.median(radii))
    off = measured / given - 1.0
    if abs(off) > RADIUS_WARN:
        print(
            f"ballbat track-video: warning: {path}: the ball measures {measured:.2f} px in radius (median of "
            f"{len(radii)} frames), {100 * off:+.1f} % from the {given:g} px given: is the m_per_px it came from "
            "(Table I's diameter / 2 / m_per_px), or the ball, right?",
            file=sys.stderr,
        )
    return {"given": given, "measured": round(measured, 3), "frames": len(radii), "off": f"{100 * off:+.2f} %"}


def cmd_track_video(args: argparse.Namespace) -> int:
    """Track every clip, then write the tracks and quality tables; print what was found as YAML."""
    import numpy as np
    import yaml

    from ..pipeline.checked import sealed_csv
    from ..tracks.io import long_csv_text
    from ..video.clip import VideoError
    from ..video.track import QUALITY_COLUMNS
    from ..writer import OutputRefused, output_problem, write_output

    if args.output == "-":
        raise OutputRefused("-o -: track-video writes two tables (the tracks and their quality); name a file")
    out = Path(args.output)
    qpath = out.with_name(f"{out.stem}.quality.csv")
    for target in (out, qpath):  # refused before any clip is tracked (write_output checks again)
        problem = output_problem(target, args.clips, args.parents)
        if problem:
            raise OutputRefused(problem)
    radii = _radii(args.ball_radius_px)
    parts, reports = [], []
    try:
        for path in map(Path, args.clips):
            tracks, quality, report = _track_one(path, radii, args)
            parts.append((tracks, quality))
            reports.append(report)
    except (VideoError, ValueError) as exc:
        print(exc, file=sys.stderr)
        print("ballbat track-video: nothing written", file=sys.stderr)
        return 1
    join = lambda i: {k: np.concatenate([p[i][k] for p in parts]) for k in parts[0][i]}  # noqa: E731
    # the check line marks each file as ballbat's: only such a file is ever replaced (ballbat.writer)
    written = [
        write_output(str(path), sealed_csv(text), args.clips, parents=args.parents)
        for path, text in ((out, long_csv_text(join(0))), (qpath, long_csv_text(join(1), QUALITY_COLUMNS)))
    ]
    print(yaml.safe_dump({"clips": reports, "written": written}, sort_keys=False), end="")
    return 0
