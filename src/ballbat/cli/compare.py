"""``ballbat compare FOLDER...``: the bats league table of results folders (docs/league.md).

Each folder is a results folder holding ``{dataset}/fit_ex.nc`` (``results/``, or a test
session's own folder) or a dataset folder holding ``fit_ex.nc``; each dataset is a test session.
Prints the league table (e_x per bat with stat. and syst., the consistency test of a bat in
several sessions, the equivalence test against the reference bat) and the pairwise differences
with Holm-adjusted p-values (:func:`ballbat.league.league`, the workflow's league rule's code).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from ..usage import UsageError

if TYPE_CHECKING:
    from collections.abc import Callable

EXAMPLE = """examples:
  ballbat compare results/
  ballbat compare results/2026-11-h01 results/2026-11-h02 results/2026-12-maple
  ballbat compare results/ --reference-bat wood --margin 0.02 --alpha 0.05
Folders hold {dataset}/fit_ex.nc (or fit_ex.nc itself); each dataset is a test session."""


def register(sub: argparse._SubParsersAction, number: Callable[[str], float]) -> None:
    """Add the ``compare`` command to ``sub`` (``number`` parses a finite number)."""
    from ..pipeline.config import checked_block  # the schema's defaults, without the league's scipy and xarray

    d = checked_block({}, "league")
    p = sub.add_parser(
        "compare",
        help="the bats league table of results folders: e_x per bat, pairwise tests, equivalence",
        epilog=EXAMPLE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("folders", nargs="+", metavar="FOLDER", help="results folders (or dataset folders)")
    p.add_argument("--reference-bat", help="bat of the equivalence test (default: per ball, the most impacts)")
    p.add_argument("--margin", type=number, default=d["margin"], help="equivalence margin in e_x (default %(default)s)")
    p.add_argument("--alpha", type=number, default=d["alpha"], help="level of every test (default %(default)s)")
    p.set_defaults(func=cmd_compare)


def cmd_compare(args: argparse.Namespace) -> int:
    """Print the league table of ``args.folders``; a folder the league cannot read is a usage error."""
    from ..league import LeagueInputError, LeagueSettings, league, pair_lines, read_folder, table_lines

    if not 0 < args.alpha < 0.5:
        raise UsageError(f"--alpha {args.alpha}: must lie between 0 and 0.5")
    if args.margin <= 0:
        raise UsageError(f"--margin {args.margin}: must be positive")
    sessions = []
    block = {"reference_bat": args.reference_bat, "margin": args.margin, "alpha": args.alpha}
    try:
        for folder in args.folders:
            sessions += read_folder(folder)
        ds = league(sessions, LeagueSettings.from_config({"league": block}))
    except (LeagueInputError, ValueError) as exc:
        raise UsageError(str(exc)) from None
    names = ", ".join(dict.fromkeys(s.name for s in sessions))
    print(f"{len(sessions)} test session(s): {names}\n")
    print("\n".join([*table_lines(ds), "", *pair_lines(ds)]))
    return 0
