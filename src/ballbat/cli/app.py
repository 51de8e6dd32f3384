"""The ``ballbat`` command: everyday questions without editing a config.

``ballbat check FILE`` validates a measured impacts file exactly as the workflow's ``ingest``
rule does (the same function, :func:`ballbat.stages.ingest.run`); ``ballbat fly`` flies batted
balls with Nathan's trajectory model (:func:`ballbat.flight.fly`), one from options or many
from a CSV file; ``ballbat summary results/{dataset}`` prints a dataset's headline numbers; ``ballbat import-tracks``
reads Tracker or Kinovea files into the long tracks CSV (:mod:`ballbat.tracks.formats`); ``ballbat
bat`` turns a lab's bat measurements into a bat-table row (:mod:`ballbat.cli.bat`); ``ballbat compare
FOLDER...`` prints the bats league table of results folders (:mod:`ballbat.cli.compare`); ``ballbat hit``
turns a pitch and a swing into a batted ball with bands from a dataset's e_x (:mod:`ballbat.cli.hit`);
``ballbat design`` gives the impacts per bat a lab needs from a pilot dataset (:mod:`ballbat.cli.design`).
Defaults (air, spin decay, integrator, property tables) are the config schema's, the one
place the workflow's defaults live. Errors are one line naming the bad argument (exit 2);
``check`` exits 1 when the file is not usable.

``ballbat check --kind tracks --config YAML`` checks raw camera tracks as the ``reduce`` rule
does (the same steps: read and check the files, reduce, cross-check;
:func:`ballbat.chain.reduce_tracks_block`).
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from .. import __version__
from ..usage import UsageError
from ..writer import OutputFailed, OutputRefused
from . import compare, design, hit, track_video
from .check import cmd_check
from .common import EXAMPLES, _finite, _Parser, _schema_defaults
from .fly import FLY_NUMBERS, _wind, cmd_fly
from .import_tracks import _import_tracks_parser
from .summary import cmd_summary

if TYPE_CHECKING:
    from collections.abc import Sequence


def parser() -> argparse.ArgumentParser:
    """Return the ``ballbat`` argument parser (defaults from the config schema)."""
    d = _schema_defaults()
    air, flight = d["air"], d["flight"]
    top = _Parser(prog="ballbat", description=__doc__.split("\n\n")[0])
    top.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = top.add_subparsers(dest="command", required=True, parser_class=_Parser)
    fmt = argparse.RawDescriptionHelpFormatter

    p = sub.add_parser("check", help="validate a measured impacts file", epilog=EXAMPLES["check"], formatter_class=fmt)
    p.add_argument("file", nargs="?", help="impacts file (CSV or NetCDF, the paper's units), or tracks file")
    p.add_argument("--bats", help="bat table (default: the workflow's config/bats.csv)")
    p.add_argument("--balls", help="ball table (default: the workflow's config/balls.csv)")
    p.add_argument("--kind", choices=("impacts", "tracks"), default="impacts", help="what the file holds")
    p.add_argument("--impacts", metavar="FILE", help="with --kind tracks: the impact table (impact_id,bat,ball)")
    p.add_argument(
        "--config",
        metavar="YAML",
        help="with --kind tracks: a workflow config whose dataset's tracks block gives the files, camera settings "
        "and rig; runs the reduce rule's reduction and cross-checks",
    )
    p.add_argument("--dataset", help="with --config: the dataset (default: the one with a tracks block)")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser(
        "fly", help="carry, hang time and apex of batted balls", epilog=EXAMPLES["fly"], formatter_class=fmt
    )
    for name, (unit, text, _) in FLY_NUMBERS.items():
        p.add_argument(f"--{name}", type=_finite, metavar=unit.upper(), help=f"{text}, {unit}")
    p.add_argument("--csv", metavar="FILE", help="many balls: a CSV with columns named like the options above")
    p.add_argument(
        "--temperature", type=_finite, default=air["temperature_F"], help="air temperature, deg F (default %(default)s)"
    )
    p.add_argument("--elevation", type=_finite, default=air["elevation_ft"], help="elevation, ft (default %(default)s)")
    p.add_argument(
        "--humidity", type=_finite, default=air["humidity_pct"], help="relative humidity, %% (default %(default)s)"
    )
    p.add_argument(
        "--pressure", type=_finite, default=air["pressure_inHg"], help="pressure, inHg (default %(default)s)"
    )
    p.add_argument("--wind", type=_wind, default=tuple(flight["wind_mph"]), help="wind 'x,y', mph (default 0,0)")
    p.add_argument(
        "--spin-decay",
        type=_finite,
        default=flight["tau_s"],
        metavar="SECONDS",
        help="spin-decay time (default %(default)s s)",
    )
    p.add_argument(
        "--method",
        choices=("accurate", "calculator"),
        default=flight["method"],
        help="integrator (default %(default)s)",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_fly)

    _import_tracks_parser(sub, fmt)

    track_video.add_parser(sub, fmt)
    p = sub.add_parser("summary", help="a dataset's headline numbers", epilog=EXAMPLES["summary"], formatter_class=fmt)
    p.add_argument("folder", help="a results folder, e.g. results/synthetic")
    p.set_defaults(func=cmd_summary)
    _add_bat(sub, Path(d["tables"]["balls"]))
    _add_lab_commands(sub, d["tables"])
    return top


def _add_bat(sub: argparse._SubParsersAction, balls: Path) -> None:
    """Add ``ballbat bat`` (:mod:`ballbat.cli.bat`, imported only here: it needs numpy)."""
    from .bat import register

    register(sub, _finite, balls, EXAMPLES["bat"])


def _add_lab_commands(sub: argparse._SubParsersAction, tables: dict) -> None:
    """Add a lab's season commands (issue 37): ``compare``, ``hit`` and ``design``."""
    compare.register(sub, _finite)
    hit.register(sub, _finite, tables)
    design.register(sub, _finite)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``ballbat`` command; return its exit status."""
    args = parser().parse_args(argv)
    try:
        status = args.func(args)
        sys.stdout.flush()
    except (UsageError, OutputRefused) as exc:
        print(f"ballbat {args.command}: error: {exc}", file=sys.stderr)
        return 1 if isinstance(exc, OutputFailed) else 2
    except BrokenPipeError:  # the reader left (`ballbat summary ... | head`): stop quietly, as cat does
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # nothing left to flush at exit
        return 141  # 128 + SIGPIPE, the status of a Unix tool the pipe ended
    return status
