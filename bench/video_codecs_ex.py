"""What compression costs e_x: the filmed example (config/examples/video.yaml) drawn as lossless FFV1 and as H.264.

    .venv/bin/python bench/video_codecs_ex.py [FORMAT:CRF ...]   (default: mkv mp4:18 mp4:23)

Each format runs the example in a fresh copy of the workflow (``snakemake -c2 --configfile
config/examples/video.yaml`` with ``render.video.format``/``crf`` replaced), to
``results/video/fit_ex.nc``. The seeds are the example's, so every format films the same 20
impacts with the same sensor noise: the formats differ only by the codec. Prints, per format and
bat, e_x with its standard error and the impacts used, its difference from the truth in standard
errors, and the impacts left out with their reasons. About 75 s a format on two cores.
"""

from __future__ import annotations

import collections
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parents[1]


def run_format(fmt: str, crf: int | None, tmp: Path) -> Path:
    """Run the example with the clips written as ``fmt`` (and ``crf``) in a copy under ``tmp``; return its results."""
    wd = tmp / f"{fmt}{crf or ''}"
    wd.mkdir()
    for name in ("Snakefile", "workflow", "config", "src"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, wd / name)
    example = yaml.safe_load((ROOT / "config" / "examples" / "video.yaml").read_text())
    video = example["datasets"]["video"]["render"]["video"]
    video.update({"format": fmt} | ({"crf": crf} if crf is not None else {}))
    (wd / "codec.yaml").write_text(yaml.safe_dump(example, sort_keys=False))  # the bats in their order: it is the draws
    cmd = [sys.executable, "-m", "snakemake", "-c2", "--configfile", "codec.yaml", "-q"]
    env = {**os.environ, "PYTHONPATH": str(wd / "src")}
    subprocess.run([*cmd, "--", "results/video/fit_ex.nc"], cwd=wd, check=True, capture_output=True, env=env)
    return wd / "results" / "video"


def report(label: str, res: Path, seconds: float) -> list[str]:
    """Lines of one format's table."""
    fit, red = xr.open_dataset(res / "fit_ex.nc"), xr.open_dataset(res / "reduce.nc")
    truth = yaml.safe_load((ROOT / "config" / "examples" / "video.yaml").read_text())["datasets"]["video"]
    true_e_x = truth["synthetic"]["e_x"]["baseball"]
    reasons = [str(r) for r in red["ingest_flag_reason"].values]
    lines = [f"{label}: {reasons.count('ok')} of {len(reasons)} impacts usable ({seconds:.0f} s)"]
    for bat in fit["bat"].values.astype(str):
        f = fit.sel(ball="baseball", bat=bat)
        e, err, n = float(f["e_x"]), float(f["e_x_err"]), int(f["e_x_n"])
        t = true_e_x[bat]
        pull = (e - t) / err
        lines.append(f"  {bat:12s} e_x {e:.5f} +- {err:.5f} (n {n})  truth {t:.3f}  (e_x - truth) / SE {pull:+.2f}")
    left = collections.Counter(r.split(":")[1].strip()[:48] for r in reasons if r != "ok")
    lines += [f"  left out {k}: {c}" for k, c in left.most_common()]
    return lines


def main() -> None:
    """Run each format named on the command line and print its table."""
    specs = sys.argv[1:] or ["mkv", "mp4:18", "mp4:23"]
    with tempfile.TemporaryDirectory() as tmp:
        for spec in specs:
            fmt, _, crf = spec.partition(":")
            t0 = time.perf_counter()
            res = run_format(fmt, int(crf) if crf else None, Path(tmp))
            label = fmt.upper() if not crf else f"{fmt.upper()} CRF {crf}"
            print("\n".join(report(label, res, time.perf_counter() - t0)), flush=True)


if __name__ == "__main__":
    main()
