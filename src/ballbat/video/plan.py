"""One job per batch of clips: which clips a dataset has, and how they are cut into the jobs that track them.

A dataset whose tracks come from clips (a ``format: video`` folder, or a filmed synthetic
experiment) is tracked by the workflow's rule ``track_clips``, one job per batch of
``video.clips_per_job`` clips, then gathered by ``import_clips`` (docs/video.md, "In the
workflow"). The clip list is known when Snakemake reads the workflow (no checkpoint): a lab's
folder is listed as the import lists it (:func:`folder_clips`), a filmed experiment's clips are
named from its config (:func:`rendered_clips`: impacts numbered from 0, as ``simulate.nc``
numbers them). :func:`plan_batches` cuts the clips, in the import's order, into runs.

Each batch job declares its resources (:func:`batch_mem_mb`, :func:`batch_runtime_min`): one
thread (a clip is tracked on one core; ``snakemake -c2`` runs two batches side by side, a
cluster profile submits each as its own job), memory from the frame size (the tracker streams
its frames: memory does not grow with a clip's length), time from the frames.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from ..tracks.data import CAMERAS

if TYPE_CHECKING:
    from collections.abc import Iterable

#: The file each ``render.video.format`` writes (docs/video.md, "Files").
EXTENSIONS = {"tif": ".tif", "mkv": ".mkv", "mp4": ".mp4"}
#: Memory of a batch job before its frames, MB: the interpreter with numpy, scipy, xarray, PyAV and
#: tifffile loaded (measured peak RSS of a batch of 8 FFV1 clips, 1024 x 512 8-bit: see docs/video.md),
#: with room to spare.
TRACK_BASE_MB = 500
#: Frames' worth of memory a batch job may hold at once (the decoded frame, the reader's buffers,
#: the tracker's float copies of regions of it), a generous bound.
FRAME_COPIES = 16
#: The largest frame assumed of a lab's clip, bytes, when its size is not known before the job
#: runs (a 4K frame at 32 bits a pixel; high-speed cameras' frames are 1-4 MB).
LARGEST_FRAME_BYTES = 3840 * 2160 * 4
#: Frames a batch job tracks per second at the least (the tracker: about 200 a second a core; FFV1
#: decoding about 76: docs/video.md, "Measured"), for its time limit.
SLOWEST_FRAMES_PER_S = 20
#: The fewest bytes a frame of a lab's clip takes in its file (a compressed frame), to bound its frames.
SMALLEST_FRAME_BYTES = 10_000

#: One clip: (impact id, camera, path as the import names it).
Clip = tuple[str, str, str]


def rendered_clips(clips_dir: str, n_impacts: int, fmt: str) -> list[Clip]:
    """Return the clips rule ``render_clips`` writes of a filmed experiment of ``n_impacts`` impacts.

    Named ``{impact}_{camera}{ext}`` (:data:`EXTENSIONS`), impacts numbered from 0; in the import's order.
    """
    if fmt not in EXTENSIONS:
        raise ValueError(f"render.video.format {fmt!r} is not one of {', '.join(EXTENSIONS)}")
    clips = [(str(i), c, str(Path(clips_dir) / clip_name(str(i), c, fmt))) for i in range(n_impacts) for c in CAMERAS]
    return sorted(clips, key=lambda c: (c[0], c[1]))


def clip_name(impact_id: str, camera: str, fmt: str) -> str:
    """Return the file name of one rendered clip (``{impact_id}_{camera}{ext}``)."""
    return f"{impact_id}_{camera}{EXTENSIONS[fmt]}"


def folder_clips(block: dict) -> list[Clip]:
    """Return the clips of a ``format: video`` folder as the import finds them (its pattern, its order).

    Files the import would refuse (a name off the pattern, a second clip of one impact and camera)
    are not planned: the import names them.
    """
    from ..tracks.formats.layout import find_files

    files, _ = find_files([block["dir"]], block["pattern"], "video")
    return [(i, c, str(p)) for i, c, p in files]


def plan_batches(clips: Iterable[Clip], per_job: int) -> list[list[Clip]]:
    """Cut ``clips`` into batches of ``per_job``, in the import's order (by impact id, then camera).

    Each clip is in exactly one batch; the batches depend only on the clips' names, so a clip whose
    content changes reruns only its own batch (a clip added or removed moves the batches after it).
    """
    if isinstance(per_job, bool) or not isinstance(per_job, int) or per_job < 1:
        raise ValueError(f"video.clips_per_job: {per_job!r} is not a whole number of clips, 1 or more")
    ordered = sorted(clips, key=lambda c: (c[0], c[1]))
    seen: dict[tuple[str, str], str] = {}
    for iid, cam, path in ordered:
        if (iid, cam) in seen:
            raise ValueError(f"{path}: impact {iid!r}, camera {cam} is already the clip {seen[(iid, cam)]}")
        seen[(iid, cam)] = path
    return [ordered[k : k + per_job] for k in range(0, len(ordered), per_job)]


def batch_mem_mb(frame_bytes: int) -> int:
    """Return the memory of a batch job whose largest frame holds ``frame_bytes``, MB."""
    return TRACK_BASE_MB + math.ceil(FRAME_COPIES * frame_bytes / 1e6)


def batch_runtime_min(frames: int) -> int:
    """Return the time limit of a batch job of ``frames`` frames in all, minutes (5 to start, and the frames)."""
    return 5 + math.ceil(frames / SLOWEST_FRAMES_PER_S / 60)


def file_frames(paths: Iterable[str]) -> int:
    """Return a bound on the frames of a lab's clips, from their files' sizes (:data:`SMALLEST_FRAME_BYTES`)."""
    total = sum(Path(p).stat().st_size for p in paths if Path(p).is_file())
    return math.ceil(total / SMALLEST_FRAME_BYTES)
