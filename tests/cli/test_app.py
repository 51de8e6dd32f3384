"""`ballbat` itself (ballbat.cli.app): its start without the heavy libraries, the entry point, each command's
help and its examples run, bad arguments in one line (issue 13).
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT
from helpers import BALLBAT
from helpers import ballbat_in_process as ballbat

from ballbat import __version__
from ballbat.cli.common import EXAMPLES

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"


def ballbat_process(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """Run the installed `ballbat` command in a process of its own."""
    env = {**os.environ, "COLUMNS": "200"}  # argparse wraps the help at the terminal's width
    return subprocess.run([str(BALLBAT), *args], capture_output=True, text=True, timeout=120, cwd=cwd, env=env)


COMMANDS = {
    "check": "validate a measured impacts file",
    "fly": "carry, hang time and apex of batted balls",
    "import-tracks": "read Tracker or Kinovea files into ballbat's long tracks CSV",
    "track-video": "track high-speed clips into ballbat's long tracks CSV",
    "summary": "a dataset's headline numbers",
    "bat": "a lab's bat measurements (ASTM F2398) as a bat-table row",
    "compare": "the bats league table of results folders: e_x per bat, pairwise tests, equivalence",
    "hit": "a pitch and a swing into a batted ball and its carry, with bands from e_x",
    "design": "impacts per bat to tell two bats apart, from a pilot dataset's measured scatter",
}


def test_the_command_line_starts_without_the_heavy_libraries():
    """Parsing the arguments imports no xarray, scipy, lmfit or matplotlib: a mistyped argument costs
    0.3 s, not the 2.4 s it took when the compare command's defaults imported the league (scipy.stats).
    """
    code = (
        "import sys\nfrom ballbat import cli\n"
        "try:\n    cli.main(['fly', '--speed', '100', '--angle', 'nan'])\n"
        "except SystemExit as e:\n    assert e.code == 2\n"
        "print(sorted(m for m in ('xarray', 'scipy', 'lmfit', 'matplotlib', 'pandas') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout


def test_entry_point_is_installed():
    """`make install` installs the console script: it runs cli.main, with its exit status and streams."""
    assert BALLBAT.is_file(), "make install installs the console script"
    out = ballbat_process("--version")
    assert out.returncode == 0 and out.stdout == f"ballbat {__version__}\n"
    out = ballbat_process("--help")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert (
        lines[0]
        == "usage: ballbat [-h] [--version] {check,fly,import-tracks,track-video,summary,bat,compare,hit,design} ..."
    )
    listed = dict(line.split(None, 1) for line in lines if line.startswith("    ") and not line.startswith("     "))
    assert listed == COMMANDS  # every command, each with its one-line help
    out = ballbat_process("fly", "--speed", "fast", "--angle", "20")
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr == "ballbat fly: error: argument --speed: 'fast' is not a number\n"


@pytest.mark.parametrize("command", list(COMMANDS))
def test_help_ends_with_its_examples(command):
    out = ballbat(command, "--help")
    assert out.returncode == 0 and out.stderr == ""
    assert out.stdout.startswith(f"usage: ballbat {command} ")
    assert out.stdout.endswith("\n\n" + EXAMPLES[command] + "\n")


def _examples() -> list[str]:
    """The one-line examples of every command's help (a continued line or one with '...' is a sketch)."""
    lines = [line.strip() for text in EXAMPLES.values() for line in text.splitlines()]
    return [line.split("  (")[0].strip() for line in lines if line.startswith("ballbat ") and "\\" not in line]


#: What an example on the repository's own files prints (a line of its output).
EXAMPLE_OUTPUT = {
    "ballbat check config/examples/maple_impacts.csv --bats config/examples/maple_bats.csv": (
        "config/examples/maple_impacts.csv: usable: 31 impacts, 1 excluded"
    ),
    "ballbat check config/examples/tracked_tracks.csv --kind tracks --impacts config/examples/tracked_impacts.csv": (
        "read and validated: 12 impacts tracked by the cameras spin, swing"
    ),
    "ballbat check --kind tracks --config config/examples/tracked.yaml": "cross-check: ",
    "ballbat fly --speed 103 --angle 27.5 --backspin 2500": "carry 422.6 ft, hang time 5.52 s, apex 92.1 ft",
    "ballbat fly --speed 103 --angle 27.5 --backspin 2500 --method calculator --json": '"carry_ft": 421.48',
    "ballbat check config/examples/hickory_impacts.csv --bats config/examples/hickory_bats.csv": (
        "config/examples/hickory_impacts.csv: usable: 30 impacts, 0 excluded, 0 warning(s)"
    ),
    "ballbat fly --speed 95 --angle 30 --backspin 2200 --sidespin -500 --spray 15 --wind 0,10": (
        "landing bearing +16.9 deg (+: towards first base)"
    ),
    "ballbat bat --length 34 --weight 32 --balance-point 23.0 --moi-6in 11200 --impact-from-tip 6 --diameter 2.6 "
    "--iz 11": "centre of percussion for the 6-in pivot: 26.59 in from the knob (impact point 28.00 in)",
    # a results folder exists only after a run: what is printed depends on that run
    "ballbat summary results/synthetic": "synthetic: 108 impacts,",
    "ballbat summary results/maple": "maple: ",
    "ballbat hit --pitch-speed 85 --bat-speed 73 --bat wood --e-x 0.4 --D 0.5": "carry         381.9 ft",
    "ballbat design results/synthetic --delta 0.02": "baseball, pooled over 3 bat(s): ",
    "ballbat compare results/": "League table (e_x per bat; reference bats: ",
    "ballbat compare results/ --reference-bat wood --margin 0.02 --alpha 0.05": "TOST margin +-0.02, alpha 0.05",
}


@pytest.mark.parametrize("example", _examples())
def test_help_examples_run(example):
    """Each example of the help runs as printed, from the repository: on its own files it succeeds
    (with the output the docs quote); a placeholder file (data/mylab/...) is named as missing.
    """
    argv = shlex.split(example)[1:]
    out = ballbat(*argv, cwd=ROOT)
    paths = [a for i, a in enumerate(argv) if ("/" in a or "." in a) and argv[i - 1] not in ("-o", "--points")]
    paths = [a for a in paths if not a.replace(".", "").replace(",", "").lstrip("-").isdigit()]
    missing = [a for a in paths if not (ROOT / a).exists()]
    if missing:
        assert out.returncode != 0 and missing[0].rstrip("/") in out.stderr, (example, out.stderr)
        assert "Traceback" not in out.stderr
    else:
        assert out.returncode == 0, (example, out.stdout, out.stderr)
        assert example in EXAMPLE_OUTPUT, f"{example}: runs here, so give the output the docs quote"
        assert EXAMPLE_OUTPUT[example] in out.stdout, (example, out.stdout)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["fly", "--speed", "fast", "--angle", "20"], "argument --speed: 'fast' is not a number"),
        (["fly", "--angle", "20"], "argument --speed: required"),
        (["fly", "--speed", "-3", "--angle", "20"], "argument --speed: -3 mph is outside (0, 200] mph"),
        (
            ["fly", "--speed", "90", "--angle", "20", "--humidity", "120"],
            "argument --humidity: 120 % is outside [0, 100] %",
        ),
        (["fly", "--speed", "90", "--angle", "20", "--wind", "north"], "argument --wind: invalid wind 'north'"),
        (["fly", "--speed", "90", "--angle", "20", "--method", "euler"], "argument --method: invalid choice: 'euler'"),
        (["fly", "--csv", "nothere.csv"], "argument --csv: nothere.csv: no such file"),
        (["check", "nothere.csv"], "argument file: nothere.csv: no such file"),
        (["check", "config"], "argument file: config is a directory"),
        (["check", "config/examples/tracked_tracks.csv", "--kind", "tracks"], "argument --impacts: required"),
        (["check", str(MAPLE), "--impacts", "x.csv"], "argument --impacts: only with --kind tracks"),
        (["summary", "results/none"], "argument folder: results/none: not a directory"),
        (["bake"], "argument command: invalid choice: 'bake'"),
    ],
)
def test_bad_arguments_are_one_line(args, message):
    out = ballbat(*args, cwd=ROOT)
    assert out.returncode == 2, (out.stdout, out.stderr)
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], out.stderr
    assert "Traceback" not in out.stderr
