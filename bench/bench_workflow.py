"""Benchmarks of the workflow backbone (issue 2).

1. Cold ``snakemake -c2`` of the default workflow in a fresh copy of the repository.
2. A no-op rerun, against Snakemake's own no-op on a one-rule workflow (issue 39's target: within
   1.2x; 1.22-1.31x on 2026-11-28, docs/studies.md "Where issue 39 stands"), and on a one-rule
   workflow with a param (Snakemake imports pandas to store params, which our workflow spares it:
   ballbat.pipeline.params_record). The three no-ops take turns (medians of 7).
3. The fit stage alone (``ballbat.stages.fit_ex.run``) at 10^3 .. 10^5 impacts
   (targets: linear in the number of impacts, 10^5 impacts in under 5 s).

Run: ``.venv/bin/python bench/bench_workflow.py`` (or ``make bench``). Prints a table.
"""

from __future__ import annotations

import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]


def timed(cmd, cwd) -> float:
    """Return the wall-clock time of a command."""
    t0 = time.perf_counter()
    subprocess.run(cmd, cwd=cwd, check=True, capture_output=True)
    return time.perf_counter() - t0


def fresh_copy(tmp: Path) -> Path:
    """Copy the workflow (Snakefile, workflow/, config/) into ``tmp``/wf; return that folder."""
    wd = tmp / "wf"
    wd.mkdir()
    shutil.copy(ROOT / "Snakefile", wd)
    shutil.copytree(ROOT / "workflow", wd / "workflow", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(ROOT / "config", wd / "config")
    return wd


def snakemake_times(repeats: int = 7) -> dict:
    """Return the times of a cold run and of no-op reruns of the default workflow and of the references.

    Each workflow is run once before it is timed (the references' first runs, the default
    workflow's first no-op), then the three no-ops take turns ``repeats`` times, so that a load
    that comes and goes on a shared machine weighs on each alike; each time is their median.
    """
    sm = [sys.executable, "-m", "snakemake", "-c2"]
    with tempfile.TemporaryDirectory() as tmp:
        wd = fresh_copy(Path(tmp))
        cold = timed(sm, wd)
        dirs = {"noop": wd}
        for name, params in (("noop_one_rule", ""), ("noop_one_rule_params", "    params:\n        x=1,\n")):
            one = Path(tmp) / name
            one.mkdir()
            rule = f'rule a:\n    output:\n        "a.txt"\n{params}    shell:\n        "touch {{output}}"\n'
            (one / "Snakefile").write_text(rule)
            dirs[name] = one
        for d in dirs.values():
            timed(sm, d)
        times = {name: [] for name in dirs}
        for _ in range(repeats):
            for name, d in dirs.items():
                times[name].append(timed(sm, d))
        # a regression guard: Snakemake imports pandas for the params' records unless the workflow
        # spares it (ballbat.pipeline.params_record)
        imports = subprocess.run([sys.executable, "-X", "importtime", *sm[1:]], cwd=wd, capture_output=True, text=True)
        pandas = any(line.rstrip().endswith("| pandas") for line in imports.stderr.splitlines())
    return {"cold": cold, **{name: statistics.median(t) for name, t in times.items()}, "pandas": pandas}


def fit_times(sizes=(1_000, 10_000, 100_000)) -> list[tuple[int, float]]:
    """Return the fit-stage time for each number of impacts."""
    from ballbat.properties import load_balls, load_bats
    from ballbat.stages import fit_ex, normalize, reconstruct, simulate
    from ballbat.synthetic import SyntheticSettings

    norm, rec = normalize.NormalizeSettings(v_ref_mph=77.0), reconstruct.ReconstructSettings()
    fit = fit_ex.FitExSettings(mu_k_example=0.5, systematic=True, check_physical=True, mu_k_bound=True)

    balls = load_balls(ROOT / "config" / "balls.csv")
    bats = load_bats(ROOT / "config" / "bats.csv")
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["datasets"]["synthetic"]["synthetic"]
    total = sum(sum(v.values()) for v in base["impacts"].values())
    fit_ex.run(
        fit,
        reconstruct.run(rec, normalize.run(norm, simulate.run(SyntheticSettings(**base), balls, bats)), balls, bats),
    )
    out = []
    for n in sizes:
        scale = n / total
        impacts = {b: {t: max(3, round(k * scale)) for t, k in v.items()} for b, v in base["impacts"].items()}
        sim = simulate.run(SyntheticSettings(**{**base, "impacts": impacts}), balls, bats)
        ds = reconstruct.run(rec, normalize.run(norm, sim), balls, bats)
        t0 = time.perf_counter()
        fit_ex.run(fit, ds)
        out.append((ds.sizes["impact"], time.perf_counter() - t0))
    return out


def main() -> None:
    """Print the timings."""
    sm = snakemake_times()
    print("workflow (default config, snakemake -c2)")
    print(f"  cold run                       {sm['cold']:7.2f} s")
    print(f"  no-op rerun (median of 7)      {sm['noop']:7.2f} s")
    print(f"  one-rule workflow no-op        {sm['noop_one_rule']:7.2f} s")
    print(f"  ratio (target <= 1.2)          {sm['noop'] / sm['noop_one_rule']:7.2f}")
    # Snakemake imports pandas (about 0.15 s, and more at exit) to store the params of a rule that has them
    print(f"  one rule with a param, no-op   {sm['noop_one_rule_params']:7.2f} s")
    print(f"  ratio to it                    {sm['noop'] / sm['noop_one_rule_params']:7.2f}")
    print(f"  pandas imported by the no-op   {'yes' if sm['pandas'] else 'no':>7s}")
    print("fit stage alone (stages.fit_ex.run, all fits of Sec. IV)")
    fits = fit_times()
    for n, t in fits:
        print(f"  {n:>7d} impacts                {t:7.3f} s   {1e6 * t / n:8.2f} us/impact")
    print(f"  10^5 impacts under 5 s: {'yes' if fits[-1][1] < 5 else 'NO'}")


if __name__ == "__main__":
    main()
