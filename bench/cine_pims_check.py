"""pims reads the cine files the tests write (tests/cine_files.py; tests/video/test_cine.py holds the values).

    python3 -m venv /tmp/pimsvenv && /tmp/pimsvenv/bin/pip install pims==0.7 numpy
    PYTHONPATH=src .venv/bin/python bench/cine_pims_check.py /tmp/pimsvenv/bin/python > cine_pims_check.out

Writes each file of ``cine_files.SPECS`` into a temporary folder with ballbat's test writer,
has pims 0.7 (an independent reader, in its own venv: it is no dependency of ballbat) read them
with bench/cine_pims_read.py, and prints what pims read beside what ballbat reads. pims reads
bottom-up grey files with both tagged blocks 1002 and 1003 only; it ignores the setup's
``Length`` (it reads the whole structure, dropping the fields newer than the file's
``SoftwareVersion``).
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))
from cine_files import SPECS, write_cine

from ballbat.video.io import open_clip


def _ballbat(path: Path) -> dict:
    clip = open_clip(path)
    info = clip.info
    times = [t for _, t, _ in clip.frames()]
    return {
        "fps": info.fps,
        "fps_source": info.source["fps"],
        "exposure_s": info.exposure_s,
        "bit_depth": info.bit_depth,
        "first_frame_number": int(info.frame_numbers[0]),
        "times_s": times,
    }


def main(pims_python: str) -> None:
    """Write the files, have pims read them, print both readings."""
    with tempfile.TemporaryDirectory() as tmp:
        paths = [write_cine(Path(tmp) / f"{name}.cine", spec) for name, spec in SPECS.items()]
        read = Path(__file__).with_name("cine_pims_read.py")
        out = subprocess.run([pims_python, str(read), *map(str, paths)], stdout=subprocess.PIPE, text=True, check=True)
        for path, line in zip(paths, out.stdout.splitlines(), strict=True):
            pims_read, ours = json.loads(line), _ballbat(path)
            lag = np.max(np.abs(np.subtract(pims_read["time_to_trigger_s"], ours["times_s"])))
            print(json.dumps({"pims": pims_read, "ballbat": ours, "max_time_difference_s": float(lag)}, indent=1))


if __name__ == "__main__":
    main(sys.argv[1])
