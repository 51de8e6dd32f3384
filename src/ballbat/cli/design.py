"""``ballbat design FOLDER --delta 0.02``: impacts per bat a lab needs, from a pilot dataset's own scatter.

Reads the dataset's fit_ex.nc (a dataset folder, or a results folder holding one dataset) and
prints, per ball, the impacts per bat needed to tell two bats ``--delta`` apart in e_x, pooled over
the bats, then per bat, each with its 95 % interval (:func:`ballbat.pilot.pilot_design`).
"""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from ..usage import UsageError

if TYPE_CHECKING:
    from collections.abc import Callable

EXAMPLE = """examples:
  ballbat design results/synthetic --delta 0.02
  ballbat design results/h01 --delta 0.02 --confidence 0.95 --power 0.9"""


def register(sub: argparse._SubParsersAction, number: Callable[[str], float]) -> None:
    """Add the ``design`` command to ``sub`` (``number`` parses a finite number)."""
    p = sub.add_parser(
        "design",
        help="impacts per bat to tell two bats apart, from a pilot dataset's measured scatter",
        epilog=EXAMPLE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("folder", help="a dataset's results folder (holding fit_ex.nc)")
    p.add_argument("--delta", type=number, required=True, help="difference in e_x to tell apart")
    p.add_argument("--confidence", type=number, default=0.95, help="two-sided confidence (default %(default)s)")
    p.add_argument("--power", type=number, default=0.8, help="power (default %(default)s)")
    p.set_defaults(func=cmd_design)


def cmd_design(args: argparse.Namespace) -> int:
    """Print the impacts per bat of the pilot ``args.folder``."""
    from ..league import LeagueInputError, read_folder
    from ..pilot import pilot_design, requirement_lines

    for name, value, low, high in (("delta", args.delta, 0, 2), ("confidence", args.confidence, 0, 1)):
        if not low < value < high:
            raise UsageError(f"--{name} {value}: must lie between {low} and {high}")
    if not 0 < args.power < 1:
        raise UsageError(f"--power {args.power}: must lie between 0 and 1")
    try:
        sessions = read_folder(args.folder)
    except LeagueInputError as exc:
        raise UsageError(str(exc)) from None
    if len(sessions) != 1:
        names = ", ".join(s.dataset for s in sessions)
        raise UsageError(f"{args.folder}: holds {len(sessions)} datasets ({names}); name one dataset's folder")
    try:
        reqs = pilot_design(sessions[0].fit, args.delta, args.confidence, args.power)
    except ValueError as exc:
        raise UsageError(f"{args.folder}: {exc}") from None
    print(f"From {args.folder} ({sessions[0].dataset}):")
    print("\n".join(requirement_lines(reqs, args.delta, args.confidence, args.power)))
    return 0
