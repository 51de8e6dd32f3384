"""e_x per bat from filmed replicates (issue 38): the filmed example drawn again and again, tracked, e_x judged.

    .venv/bin/python bench/video_replicates.py [N] [FORMAT[:CRF]] [--first K] [--keep DIR]  (50 replicates, mkv)
    .venv/bin/python bench/video_replicates.py --pool DIR...   (the table of kept runs together)

``config/examples/video.yaml``'s dataset (two bats, 10 impacts each, both cameras filmed at
1024 x 512, 50 us exposure, noise, uneven light and clutter) is repeated ``N`` times as datasets
``video_r0`` ... of one configuration, each with its own ``synthetic.seed`` and ``render.seed``
(a new experiment and new clips: sensor noise, sub-frame phases, look) and nothing else changed,
and one ``snakemake -c2`` in a fresh copy of the workflow draws every replicate's clips, tracks
them (the tracker's jobs side by side), reduces, and fits, to ``results/video_rK/fit_ex.nc``:
the workflow's own path from pixels, no second one.

The truth of e_x per bat is the configured value: the model gives every impact of a bat that
e_x (no intrinsic scatter in the example), so e_x of one bat is the same however many impacts a
design has. Prints, per bat: the mean of (e_x - truth) and its standard error, the mean
standard error (SE), bias / SE, the pulls' spread (SD of (e_x - truth) / SE), the coverage of
the 95 % interval fit_ex.nc gives (``e_x_ci_low``, ``e_x_ci_high``) and of the 68 % one (the
same Student t, at 68 %), with their binomial errors, each measured value's pulls against its
truth (reduce.nc against simulate.nc: where a bias comes from), and the impacts left out.
About 45 s of CPU a replicate (drawing 40 clips 18 s, tracking them 17 s). ``--keep DIR`` runs
in ``DIR`` (a new folder) and keeps it, results and clips, to look into; else a temporary one.
``--first K`` starts at replicate K (seeds of their own, apart from those of replicates 0 to
K - 1: a second, independent run). ``--pool DIR...`` prints the table of runs kept with
``--keep`` together (their replicates must differ).

Last, what the fits alone do: each replicate's reduce.nc with every measured value replaced by
its truth plus a normal error of its stated size (``IDEAL_DRAWS`` draws), through the same
fits (:func:`ballbat.chain.run`). Their bias is the fits' own (weights, errors-in-variables);
what the filmed replicates have beyond it comes from the tracked values.
"""

from __future__ import annotations

import collections
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml
from scipy.special import stdtrit

from ballbat import chain
from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "config" / "examples" / "video.yaml"
QUANTITIES = ("v_bat", "v_ball", "theta", "omega")  # the measured values reduce.nc holds with their errors
IDEAL_DRAWS = 4  # draws of truth + stated errors per replicate (the fits' own bias)
SEED_STEP = 7919  # replicate k's seeds: the example's + k * SEED_STEP (apart from every other replicate's)


def replicate_config(ks: range, fmt: str, crf: int | None) -> dict:
    """The example's config with its dataset repeated as replicates ``ks``, each with seeds of its own."""
    example = yaml.safe_load(EXAMPLE.read_text())
    base = example["datasets"].pop("video")
    for k in ks:
        ds = yaml.safe_load(yaml.safe_dump(base))
        ds["synthetic"]["seed"] = int(base["synthetic"]["seed"]) + k * SEED_STEP
        ds["render"]["seed"] = int(base["render"]["seed"]) + k * SEED_STEP
        ds["render"]["video"].update({"format": fmt} | ({"crf": crf} if crf is not None else {}))
        example["datasets"][f"video_r{k}"] = ds
    return example


def run(ks: range, fmt: str, crf: int | None, tmp: Path) -> tuple[Path, float]:
    """Run the replicates ``ks`` in a fresh copy under ``tmp``; return its results folder and the wall time."""
    wd = tmp / "wf"
    wd.mkdir()
    for name in ("Snakefile", "workflow", "config", "src"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, wd / name)
    (wd / "replicates.yaml").write_text(yaml.safe_dump(replicate_config(ks, fmt, crf), sort_keys=False))
    targets = [f"results/video_r{k}/fit_ex.nc" for k in ks]
    cmd = [sys.executable, "-m", "snakemake", "-c2", "--configfile", "replicates.yaml", "-q", "--", *targets]
    env = {**os.environ, "PYTHONPATH": str(wd / "src")}
    t0 = time.perf_counter()
    done = subprocess.run(cmd, cwd=wd, capture_output=True, text=True, env=env)
    if done.returncode:
        sys.exit(f"snakemake failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return wd / "results", time.perf_counter() - t0


def report(folders: list[Path], seconds: float | None) -> list[str]:
    """The table of the replicates in the results ``folders`` (``video_rK``): e_x per bat against the truth."""
    truth = yaml.safe_load(EXAMPLE.read_text())["datasets"]["video"]["synthetic"]["e_x"]["baseball"]
    rows = collections.defaultdict(list)
    left = collections.Counter()
    usable = []
    pulls_of = collections.defaultdict(list)  # measured quantity -> each usable impact's (measured - truth) / error
    reps = sorted((d for f in folders for d in f.glob("video_r*")), key=lambda d: int(d.name[7:]))
    if len({d.name for d in reps}) < len(reps):
        sys.exit("the runs pooled share replicates (the same seeds): pool runs with different --first")
    n = len(reps)
    for rep in reps:
        fit, red, sim, rec = (xr.open_dataset(rep / f"{s}.nc") for s in ("fit_ex", "reduce", "simulate", "reconstruct"))
        reasons = [str(r) for r in red["ingest_flag_reason"].values]
        ok = rec["flag"].values == 0  # the impacts the fits use (reconstruct also leaves out those psi cannot take)
        usable.append(int(ok.sum()))
        left.update(
            f"reconstruct: {r}"[:72]
            for r, f, g in zip(
                rec["flag_reason"].values.astype(str), rec["flag"].values, red["ingest_flag"].values, strict=True
            )
            if f and not g
        )
        for q in QUANTITIES:
            d = red[q].values - sim[f"truth_{q}"].sel(impact=red["impact"]).values
            pulls_of[q].extend((d / red[f"{q}_err"].values)[ok])
        left.update((r.partition(":")[2] or r).strip()[:60] for r in reasons if r != "ok")
        for bat in fit["bat"].values.astype(str):
            f = fit.sel(ball="baseball", bat=bat)
            rows[bat].append(
                (float(f["e_x"]), float(f["e_x_err"]), float(f["e_x_ci_low"]), float(f["e_x_ci_high"]), int(f["e_x_n"]))
            )
    when = f", {seconds / 60:.1f} min on 2 cores" if seconds is not None else ""
    lines = [
        f"{n} filmed replicates of config/examples/video.yaml ({reps[0].name}-{reps[-1].name}){when}; usable "
        f"impacts per replicate {min(usable)}-{max(usable)} of 20"
    ]
    for bat, r in rows.items():
        e, se, lo, hi, nn = (np.array(c) for c in zip(*r, strict=True))
        t = truth[bat]
        d = e - t
        pulls = d / se
        cover95 = np.mean((lo <= t) & (t <= hi))
        half68 = (hi - e) / stdtrit(nn - 1, 0.975) * stdtrit(nn - 1, 0.84)
        cover68 = np.mean(np.abs(d) <= half68)
        m = len(e)
        bias_err = d.std(ddof=1) / math.sqrt(m) / se.mean()
        lines.append(
            f"  {bat:12s} truth {t:.3f}  mean e_x - truth {d.mean():+.6f} +- {d.std(ddof=1) / math.sqrt(m):.6f}  "
            f"mean SE {se.mean():.6f}  bias/SE {d.mean() / se.mean():+.3f} +- {bias_err:.3f}  "
            f"pulls' SD {pulls.std(ddof=1):.3f}  "
            f"95 %: {100 * cover95:.1f} +- {100 * math.sqrt(0.95 * 0.05 / m):.1f}  "
            f"68 %: {100 * cover68:.1f} +- {100 * math.sqrt(0.68 * 0.32 / m):.1f}  (n {m} replicates)"
        )
    lines.append("  each usable impact's measured value against its truth (simulate.nc), in its stated errors:")
    for q, p in pulls_of.items():
        p = np.asarray(p)
        med = float(np.median(p))
        lines.append(
            f"    {q:7s} median pull {med:+.3f}  robust SD {1.4826 * np.median(np.abs(p - med)):.3f}  "
            f"mean {p.mean():+.3f} +- {p.std(ddof=1) / math.sqrt(p.size):.3f}  SD {p.std(ddof=1):.3f}  "
            f"beyond 5: {int(np.sum(np.abs(p) > 5))}  (n {p.size})"
        )
    lines += [f"  left out {c} impacts: {k}" for k, c in left.most_common()]
    return lines + ideal_lines(reps, truth)


def ideal_lines(reps: list[Path], truth: dict[str, float]) -> list[str]:
    """e_x per bat from each replicate's truth plus normal errors of the stated sizes, through the same fits."""
    settings = chain.DatasetSettings.from_config(load_config(EXAMPLE), "video")
    balls, bats = load_balls(ROOT / "config" / "balls.csv"), load_bats(ROOT / "config" / "bats.csv")
    rng = np.random.default_rng(20261128)
    out = collections.defaultdict(list)
    for rep in reps:
        red = xr.load_dataset(rep / "reduce.nc")
        sim = xr.load_dataset(rep / "simulate.nc").sel(impact=red["impact"])
        for _ in range(IDEAL_DRAWS):
            ds = red.copy()
            for q in QUANTITIES:
                noise = rng.standard_normal(red.sizes["impact"]) * red[f"{q}_err"].values
                ds[q] = ds[q].copy(data=sim[f"truth_{q}"].values + noise)
            fit = chain.run(settings, ds, balls, bats).fit_ex.sel(ball="baseball")
            for bat in truth:
                f = fit.sel(bat=bat)
                out[bat].append((float(f["e_x"]) - truth[bat], float(f["e_x_err"])))
    lines = [f"  the same fits from each replicate's truth + its stated errors ({IDEAL_DRAWS} draws a replicate):"]
    for bat, v in out.items():
        d, se = (np.array(c) for c in zip(*v, strict=True))
        lines.append(
            f"    {bat:12s} bias/SE {d.mean() / se.mean():+.3f} +- {d.std(ddof=1) / math.sqrt(d.size) / se.mean():.3f}"
            f"  pulls' SD {np.std(d / se, ddof=1):.3f}  (n {d.size})"
        )
    return lines


def main() -> None:
    """Run the replicates named on the command line and print the table."""
    args = sys.argv[1:]
    keep = None
    if "--keep" in args:
        i = args.index("--keep")
        keep = Path(args[i + 1])
        del args[i : i + 2]
        keep.mkdir(parents=True)  # a new folder: never one with a lab's files in it
    if args and args[0] == "--pool":
        print("\n".join(report([Path(a) / "wf" / "results" for a in args[1:]], None)), flush=True)
        return
    first = 0
    if "--first" in args:
        i = args.index("--first")
        first = int(args[i + 1])
        del args[i : i + 2]
    n = int(args[0]) if args else 50
    fmt, _, crf = (args[1] if len(args) > 1 else "mkv").partition(":")
    with tempfile.TemporaryDirectory() as tmp:
        results, seconds = run(range(first, first + n), fmt, int(crf) if crf else None, keep or Path(tmp))
        print("\n".join(report([results], seconds)), flush=True)


if __name__ == "__main__":
    main()
