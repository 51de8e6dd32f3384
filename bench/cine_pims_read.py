"""What pims reads of cine files: run by bench/cine_pims_check.py in a venv that holds pims (never ballbat's).

    /tmp/pimsvenv/bin/python bench/cine_pims_read.py FILE.cine...

Prints one JSON object per file: pims 0.7's ``Cine`` reader's size, count, first image number,
setup frame rate, mean frame rate from the timestamps, exposure (the setup's and block 1003's),
RealBPP, each image's SHA-256 (uint16 little-endian, top row first) and time from the trigger.
"""

from __future__ import annotations

import hashlib
import json
import sys

import numpy as np
import pims


def _read(path: str) -> dict:
    cine = pims.Cine(path)
    setup = cine.setup_fields_dict
    images = [np.asarray(cine.get_frame(i)) for i in range(len(cine))]
    return {
        "file": path.rsplit("/", 1)[-1],
        "shape": list(cine.shape),
        "dtype": str(images[0].dtype),
        "first_image_no": cine.header_dict["first_image_no"],
        "frame_rate": cine.frame_rate,
        "frame_rate_avg": float(cine.get_frame_rate_avg()) if len(cine) > 1 else None,
        "shutter_ns": setup.get("shutter_ns"),
        "shutter_us": setup.get("shutter"),
        "exposure_1003_s": [float(e) for e in cine.all_exposures],
        "real_bpp": setup.get("real_bpp"),
        "sha256": [hashlib.sha256(np.ascontiguousarray(a).astype("<u2").tobytes()).hexdigest() for a in images],
        "time_to_trigger_s": [float(cine.get_time_to_trigger(i)) for i in range(len(cine))],
    }


if __name__ == "__main__":
    for name in sys.argv[1:]:
        print(json.dumps(_read(name)))
