"""What a clip is, whatever its file: its settings (:class:`ClipInfo`) and the error of an unreadable one."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


class VideoError(Exception):
    """A clip that cannot be read or written (the message names the file and the frame)."""


@dataclass
class ClipInfo:
    """Settings of a clip from its file; None where the file does not hold them."""

    path: str
    format: str
    width: int
    height: int
    n_frames: int | None
    bit_depth: int
    fps: float | None = None
    exposure_s: float | None = None
    trigger_frame: int | None = None
    frame_numbers: np.ndarray | None = None
    source: dict[str, str] = field(default_factory=dict)
