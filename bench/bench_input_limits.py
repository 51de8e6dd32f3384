"""Hostile inputs of issue 34: the time and peak memory of ballbat's refusal of each.

Each case is a folder of Tracker projects (the example's tracks, tests/track_files.py) with one
file made hostile, or a lab CSV, or a config; ``ballbat import-tracks`` or ``ballbat check`` runs
on it in a child process under a 4 GiB address-space limit. Printed per case: exit status, wall
time, the child's peak resident memory, and the start of the line that names the problem.
Before issue 34 these took 89 GiB (a frame 999999999), 3.5 GB and 148 s (a 1e6-point .kva),
9.7 GB (1e6 rest frames in a lab CSV), or hung (a YAML alias bomb).

Run: ``.venv/bin/python bench/bench_input_limits.py`` (about a minute; writes only to a
temporary folder).
"""

from __future__ import annotations

import resource
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from track_files import TOOL_NAMES, kva_text, read_long_csv, trk_text, write_lab_folder  # noqa: E402

EXAMPLE = ROOT / "config" / "examples"
CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}
POINTS = "--points=ball=ball,bat_tip=tip,dot_a=A,dot_b=B"
LIMIT = 4 * 2**30


#: The command line, reporting its own peak resident memory (KiB) as its last line on stderr.
CHILD = (
    "import atexit, resource, sys\n"
    "atexit.register(lambda: sys.stderr.write('\\nPEAK %d\\n' % resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))\n"
    "from ballbat.cli import main\n"
    "sys.exit(main(sys.argv[1:]))\n"
)


def run(*args: object) -> tuple[int, float, float, str]:
    """Run the command line in a child (4 GiB limit): status, seconds, peak MiB, its first problem line."""

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))

    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, "-c", CHILD, *map(str, args)], capture_output=True, text=True, preexec_fn=limit
    )
    dt = time.perf_counter() - t0
    peaks = [int(ln.split()[1]) for ln in out.stderr.splitlines() if ln.startswith("PEAK ")]
    lines = [ln for ln in (out.stdout + out.stderr).splitlines() if "error" in ln or "MiB" in ln or "frame" in ln]
    return out.returncode, dt, (peaks[-1] / 1024 if peaks else float("nan")), (lines[0] if lines else "")


def show(case: str, command: str, result: tuple) -> None:
    """Print one row of the table."""
    status, dt, peak, line = result
    print(f"{case:<36} {command:<14} {status:>6} {dt:>8.1f} {peak:>9.0f}  {line[-110:]}")


def tool_cases(lab: Path) -> dict:
    """Case -> a function that makes the folder hostile."""
    rows = read_long_csv(EXAMPLE / "tracked_tracks.csv")[("W05", "swing")]

    def far_mark():
        tracks = {n: rows[n] for n in ("ball", "tip")}
        fr, x, y = tracks["ball"]
        tracks["ball"] = (np.r_[fr, 999999999], np.r_[x, x[-1]], np.r_[y, y[-1]])
        (lab / "W05_swing.trk").write_text(trk_text(tracks, 3000.0, 0.00074))

    def big_kva():
        (lab / "W05_swing.trk").unlink()
        fr = np.arange(1_000_000)
        tracks = {"ball": (fr, 500 + 1e-4 * fr, 400 + 0 * fr), "tip": (fr[:50], fr[:50] + 0.0, fr[:50] + 0.0)}
        (lab / "W05_swing.kva").write_text(kva_text(tracks, 3000.0, 0.00074))

    def zip_bomb():  # 1 GiB of zeros in some 1 MB: refused from the member's header
        (lab / "W05_swing.trk").unlink()
        with zipfile.ZipFile(lab / "W05_swing.trz", "w", zipfile.ZIP_DEFLATED) as z:
            with z.open("W05_swing.trk", "w", force_zip64=True) as fh:
                block = b"\0" * 2**24
                for _ in range(64):
                    fh.write(block)

    return {"a .trk mark at frame 999999999": far_mark, "a 1e6-point .kva track": big_kva, "a .trz bomb": zip_bomb}


def main() -> None:
    """Run every case and print the table."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        template = write_lab_folder(tmp / "template", EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
        print(f"{'case':<36} {'command':<14} {'status':>6} {'seconds':>8} {'peak MiB':>9}  first problem line")
        for case, make in tool_cases(tmp / "lab").items():
            shutil.rmtree(tmp / "lab", ignore_errors=True)
            lab = Path(shutil.copytree(template, tmp / "lab"))
            make()
            block = {"dir": str(lab), "points": dict(TOOL_NAMES), "impacts": str(EXAMPLE / "tracked_impacts.csv")}
            cams = {"swing": {"mirror": False}, "spin": {"mirror": True}}
            rig = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
            cfg = tmp / "lab.yaml"
            cfg.write_text(yaml.safe_dump({"datasets": {"lab": {"tracks": {**block, "cameras": cams, "rig": rig}}}}))
            for name, args in (
                ("import-tracks", ("import-tracks", lab, POINTS, "-o", tmp / "t.csv")),
                ("check", ("check", "--kind", "tracks", "--config", cfg)),
            ):
                show(case, name, run(*args))
        lines = (EXAMPLE / "tracked_tracks.csv").read_text().splitlines()
        ball = [ln.split(",") for ln in lines[1:] if ln.startswith("W03,swing,ball,")]
        last = max(int(r[3]) for r in ball)
        rest = [f"W03,swing,ball,{last + k},{ball[-1][4]},{ball[-1][5]}" for k in range(1, 1_000_001)]
        csv = tmp / "tracks.csv"
        csv.write_text("\n".join([*lines, *rest]) + "\n")
        impacts = EXAMPLE / "tracked_impacts.csv"
        show("a lab CSV with 1e6 rest frames", "check", run("check", csv, "--kind", "tracks", "--impacts", impacts))
        bomb = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
        bomb += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 12)]
        bomb += ["datasets: {lab: {tracks: *a11}}"]
        path = tmp / "bomb.yaml"
        path.write_text("\n".join(bomb) + "\n")
        show("a YAML alias bomb (3e11 values)", "check", run("check", "--kind", "tracks", "--config", path))


if __name__ == "__main__":
    main()
