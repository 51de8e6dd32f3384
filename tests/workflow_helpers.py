"""Helpers to run the real workflow in a temporary copy of the repository."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import forked

ROOT = Path(__file__).resolve().parents[1]


def make_workdir(tmp: Path, copy_package: bool = False) -> Path:
    """Copy Snakefile, workflow/ and config/ (and optionally src/) into ``tmp``.

    src/ comes with its bytecode (``make test`` compiles it): the copies keep the sources' times,
    so it stays valid, and the runs' jobs do not compile the package again (an edited module
    is compiled anew, as always).
    """
    shutil.copy(ROOT / "Snakefile", tmp / "Snakefile")
    shutil.copytree(ROOT / "workflow", tmp / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "config", tmp / "config")
    (tmp / "README.md").write_text("copy\n")
    if copy_package:
        shutil.copytree(ROOT / "src", tmp / "src", ignore=shutil.ignore_patterns("*.egg-info"))
    return tmp


#: A small synthetic experiment: 36 impacts on three ball x bat pairs (conftest.lab_run renders its tracks).
SMALL_SYNTHETIC = {
    "seed": 7,
    "impacts": {"baseball": {"wood": 12, "metal_rough": 12}, "softball": {"softball_composite": 12}},
    "e_x": {"baseball": {"wood": 0.464, "metal_rough": 0.356}, "softball": {"softball_composite": 0.128}},
    "e_y": {"baseball": 0.45, "softball": 0.32},
}


#: The targets of the fault tests' reruns (test_faults.py, test_faults_runs.py): the maple dataset's
#: data files (its figures and the report's front page are not what these tests are about).
MAPLE_DATA = [
    f"results/maple/{name}"
    for name in (
        "ingest.nc",
        "normalize.nc",
        "reconstruct.nc",
        "fit_ex.nc",
        "stronge.nc",
        "paper_comparison.csv",
        "results.xlsx",
    )
]


def maple_data_files(wd: Path) -> dict[str, str]:
    """Every NetCDF file of the maple dataset and the comparison table, with its sha256."""
    from ballbat.pipeline.provenance import sha256_file

    res = wd / "results" / "maple"
    files = [*sorted(res.glob("*.nc")), res / "paper_comparison.csv", res / "results.xlsx"]
    return {p.name: sha256_file(p) for p in files}


def write_config(workdir: Path, edit) -> None:
    """Edit the workdir's config/config.yaml in place: ``edit(cfg)`` changes the loaded mapping."""
    import yaml

    path = workdir / "config" / "config.yaml"
    cfg = yaml.safe_load(path.read_text())
    edit(cfg)
    path.write_text(yaml.safe_dump(cfg, sort_keys=False))


def copy_run(finished: Path, dest: Path) -> Path:
    """Copy a finished run's folder to ``dest`` for a test to change: the timestamps are kept
    (so Snakemake finds nothing to do) and the finished run's lock, if any, is left behind.
    """
    shutil.copytree(finished, dest, symlinks=True)
    shutil.rmtree(dest / ".snakemake" / "locks", ignore_errors=True)
    return dest


def snakemake(workdir: Path, *args: str, check: bool = True, timeout: int = 600) -> subprocess.CompletedProcess:
    """Run ``python -m snakemake ARGS`` in ``workdir`` (with workdir/src first on the path if present).

    The run is a child of a fork server that has Snakemake imported (:mod:`forked`); its exit
    status, standard output and standard error come back as those of a subprocess.
    """
    env = dict(os.environ)
    if (workdir / "src").is_dir():
        env["PYTHONPATH"] = os.pathsep.join([str(workdir / "src"), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    proc = forked.run("snakemake", workdir, list(args), env=env, timeout=timeout)
    if check and proc.returncode != 0:
        raise AssertionError(f"snakemake {' '.join(args)} failed:\n{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
    return proc


def assert_not_blank(png, min_colors: int = 6) -> None:
    """The PNG is a real picture: several distinct colours and some contrast."""
    import numpy as np
    from PIL import Image

    with Image.open(png) as im:
        img = np.asarray(im.convert("RGB"))
    assert img.shape[0] > 200 and img.shape[1] > 200, png
    rgb = (img[..., 0].astype(np.uint32) << 16) | (img[..., 1].astype(np.uint32) << 8) | img[..., 2]
    assert len(np.unique(rgb)) >= min_colors, png  # distinct colours (one number per pixel: 50x faster than rows)
    assert img.std() > 10, png


def planned_logs(workdir: Path, *args: str) -> dict[str, str]:
    """Log file -> rule of every job a run would do (empty when nothing is to be done).

    Reads Snakemake's machine-readable ``--summary`` table (tab-separated: output file, date,
    rule, log file(s), status, plan): a job is one (rule, log file) pair with an output whose
    plan is "update pending" (every rule of this workflow has a log of its own per job).
    """
    out = snakemake(workdir, "--summary", *args)
    lines = out.stdout.splitlines()
    header = lines[0].split("\t")
    col = {name: header.index(name) for name in ("rule", "log-file(s)", "plan")}
    jobs: dict[str, str] = {}
    for line in lines[1:]:
        cells = line.split("\t")
        if len(cells) == len(header) and cells[col["plan"]] == "update pending":
            jobs[cells[col["log-file(s)"]]] = cells[col["rule"]]
    return jobs


def planned_jobs(workdir: Path, *args: str) -> dict[str, int]:
    """Rule -> job count of what a run would do (empty when nothing is to be done): :func:`planned_logs`."""
    from collections import Counter

    return dict(Counter(planned_logs(workdir, *args).values()))


def run_cf_checker(files: list[str], report: Path, remembering: bool = True) -> dict:
    """The compliance-checker's CF 1.10 report on ``files`` (JSON, written to ``report``), by file.

    ``remembering``: through tests/cf_check.py (the checker with its dataset queries answered
    once per file: the same report, in a tenth of the time); otherwise the installed command.
    """
    import json

    here = Path(__file__).resolve().parent
    command = (
        [sys.executable, str(here / "cf_check.py")]
        if remembering
        else [str(Path(sys.executable).parent / "compliance-checker")]
    )
    subprocess.run(
        [*command, "--test", "cf:1.10", "-f", "json_new", "-o", str(report), *files], capture_output=True, timeout=600
    )
    return json.loads(report.read_text())


def assert_cf(files: list[str], report: Path) -> None:
    """Every file passes the IOOS compliance-checker's CF 1.10 suite (all points, no message).

    The checker raises inside its own monotonicity check on string-valued coordinates (ball,
    bat); that check is then not scored, so it cannot hide a failure of another.
    """
    results = run_cf_checker(files, report)
    assert sorted(results) == sorted(files)
    for name, res in results.items():
        cf = res["cf:1.10"]
        failed = [
            f"{c['name']}: {c['msgs']}"
            for level in ("high_priorities", "medium_priorities", "low_priorities")
            for c in cf[level]
            if c["msgs"]
        ]
        assert cf["scored_points"] == cf["possible_points"] and not failed, (name, failed)
