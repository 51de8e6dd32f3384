"""``ballbat bat``: a lab's measurements of a bat (ASTM F2398 / F2219) as a bat-table row.

Prints the bat in the paper's convention (the columns of ``config/bats.csv``) and in the lab
convention (``convention`` = ``lab``), its centre of percussion for the pivot, its recoil
factors with a ball, and what each measured value's uncertainty does to e_x. The conversion
and the checks are :mod:`ballbat.batlab`'s (the workflow's own); exit 1 when the bat fails them.

What a bat property does to e_x: psi (Eq. angmom) does not depend on the bat, so the fitted
slope of Eq. omega, (1 + e_x), scales as (1 + r_x) (Eq. rx) at fixed data:
delta e_x = (1 + e_x) delta r_x / (1 + r_x). Each measured value is moved by +-1 standard
uncertainty and half the difference of e_x reported; "all" adds them in quadrature.
"""

from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

from .. import batlab
from ..properties import recoil_factors
from ..units import INCH, OUNCE, OZ_IN2

if TYPE_CHECKING:
    import argparse
    from collections.abc import Callable
    from pathlib import Path

    from ..properties import Ball

#: Measured values: option -> (lab column, help, unit, default standard uncertainty, relative?).
MEASURED = {
    "length": ("length_in", "bat length", "in", 0.05, False),
    "weight": ("weight_oz", "bat weight", "oz", 0.1, False),
    "balance-point": ("balance_in", "balance point from the knob end", "in", 0.1, False),
    "moi": ("moi_oz_in2", "MOI about the pivot (--pivot)", "oz in^2", 0.01, True),
    "period": ("period_s", "pendulum period about the pivot (--pivot)", "s", 0.001, True),
    "impact-from-tip": ("impact_from_tip_in", "impact point from the barrel tip", "in", 0.25, False),
    "impact-from-knob": ("impact_from_knob_in", "impact point from the knob end", "in", 0.25, False),
    "diameter": ("diameter_in", "barrel diameter at the impact point", "in", 0.01, False),
    "iz": ("Iz_oz_in2", "MOI about the long axis", "oz in^2", 0.05, True),
}


#: Why a value is needed although some lab sheets lack it.
_WHY_REQUIRED = {
    "iz": (
        ": the MOI about the long axis enters r_x (Eq. rx) through R^2/Iz, the largest of its three terms "
        "(5 % of Iz moves e_x by about 0.01); ASTM F2398 does not measure it, measure it about the bat's axis"
    )
}


def register(sub: argparse._SubParsersAction, number: Callable[[str], float], balls: Path, epilog: str) -> None:
    """Add the ``bat`` command to ``sub`` (``number`` parses a finite number; ``balls``: default ball table)."""
    import argparse

    p = sub.add_parser(
        "bat",
        help="a lab's bat measurements (ASTM F2398) as a bat-table row",
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    for opt, (_, text, unit, err, rel) in MEASURED.items():
        p.add_argument(f"--{opt}", type=number, metavar=unit.split()[0].upper(), help=f"{text}, {unit}")
        what = f"relative, default {100 * err:g} %%" if rel else f"{unit}, default {err:g}"
        p.add_argument(
            f"--{opt}-err", type=number, default=err, metavar="SD", help=f"its standard uncertainty ({what})"
        )
    p.add_argument("--moi-6in", type=number, metavar="OZ", help="MOI about the pivot 6 in from the knob (ASTM F2398)")
    p.add_argument("--pivot", type=number, default=batlab.PIVOT_ASTM_IN, help="pivot from the knob end, in (default 6)")
    p.add_argument("--name", default="mybat", help="the bat's key in the table (default mybat)")
    p.add_argument("--ball", default="baseball", help="ball for r_x and e_x (default baseball)")
    p.add_argument("--balls", default=str(balls), help="ball table (default: the workflow's config/balls.csv)")
    p.add_argument("--e-x", type=number, default=0.45, help="e_x at which to judge the uncertainties (default 0.45)")
    p.set_defaults(func=cmd_bat)


def lab_row(args: argparse.Namespace) -> dict[str, float]:
    """Return the measured values of ``args`` as a lab-convention row; raise ValueError naming what is missing."""
    if args.moi_6in is not None:
        if args.moi is not None or args.pivot != batlab.PIVOT_ASTM_IN:
            raise ValueError(
                "argument --moi-6in: not with --moi or another --pivot (it is the MOI about the 6-in pivot)"
            )
        args.moi = args.moi_6in
    need = [
        ("length", "weight", "balance-point", "diameter", "iz"),
        ("moi", "period"),
        ("impact-from-tip", "impact-from-knob"),
    ]
    row = {"pivot_in": args.pivot}
    for group in need:
        given = [o for o in group if getattr(args, o.replace("-", "_")) is not None]
        missing = [o for o in group if o not in given] if len(group) > 2 else []
        if missing:
            why = _WHY_REQUIRED.get(missing[0], "")
            raise ValueError(f"argument --{missing[0]}: required{why}")
        if len(group) == 2 and len(given) != 1:
            raise ValueError(f"give one of --{group[0]}{'/--moi-6in' if group[0] == 'moi' else ''} or --{group[1]}")
        row.update({MEASURED[o][0]: getattr(args, o.replace("-", "_")) for o in given})
    return row


def e_x_shift(row: dict, ball: Ball, e_x: float) -> Callable[[dict], float]:
    """Return a function of a changed row giving the change of e_x it causes (at fixed data)."""
    r_x0 = recoil_factors(ball, _bat(row))[0]
    return lambda changed: (1.0 + e_x) * (recoil_factors(ball, _bat(changed))[0] - r_x0) / (1.0 + r_x0)


def _bat(row: dict):
    """Return a lab row as an SI :class:`~ballbat.properties.Bat`."""
    from ..properties import Bat

    p = batlab.paper_row(row)
    return Bat(
        "bat",
        "bat",
        p["M_oz"] * OUNCE,
        p["I0_oz_in2"] * OZ_IN2,
        p["Iz_oz_in2"] * OZ_IN2,
        p["b_in"] * INCH,
        p["R_in"] * INCH,
    )


def uncertainty_lines(row: dict, args: argparse.Namespace, ball: Ball) -> list[str]:
    """One line per measured value: its uncertainty and the e_x it moves (+-1 sigma, half the difference)."""
    shift = e_x_shift(row, ball, args.e_x)
    lines, total = [], 0.0
    for opt, (col, _text, unit, _err, rel) in MEASURED.items():
        if col not in row:
            continue
        sd = getattr(args, f"{opt.replace('-', '_')}_err") * (row[col] if rel else 1.0)
        d = abs(shift({**row, col: row[col] + sd}) - shift({**row, col: row[col] - sd})) / 2.0
        total += d * d
        lines.append(f"  {col:<20} {row[col]:>10g} {unit:<8} +- {sd:<9.3g} e_x +- {d:.4f}")
    lines.append(f"  {'all, in quadrature':<52} e_x +- {math.sqrt(total):.4f}")
    return lines


def cmd_bat(args: argparse.Namespace) -> int:
    """Print the bat's rows, centre of percussion, recoil factors and e_x uncertainties; 1 when it fails the checks."""
    from ..properties import load_balls
    from ..usage import UsageError

    try:
        row = lab_row(args)
        balls = load_balls(args.balls)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if args.ball not in balls:
        raise UsageError(f"argument --ball: {args.ball!r} is not in {args.balls} (known: {', '.join(sorted(balls))})")
    problems = batlab.row_problems("bat", row, "lab")
    if problems:
        print("\n".join(problems))
        print(f"{args.name}: not a bat row: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    paper = batlab.paper_row(row)
    lab_cols = [c for c in batlab.LAB if c in row]
    r_x, r_y = recoil_factors(balls[args.ball], _bat(row))
    cop = batlab.centre_of_percussion(row)
    out = [
        "paper convention (Table II; the columns of config/bats.csv):",
        "bat,name," + ",".join(batlab.PAPER),
        f"{args.name},{args.name}," + ",".join(f"{paper[c]:.6g}" for c in batlab.PAPER),
        "lab convention (ASTM F2398/F2219; a table with convention = lab):",
        "bat,name,convention," + ",".join(lab_cols),
        f"{args.name},{args.name},lab," + ",".join(f"{row[c]:g}" for c in lab_cols),
        f"centre of percussion for the {row['pivot_in']:g}-in pivot: {cop:.2f} in from the knob "
        f"(impact point {batlab.impact_from_knob(row):.2f} in)",
        f"recoil factors with a {args.ball}: r_x = {r_x:.4f} (Eq. rx), r_y = {r_y:.4f} (Eq. ry)",
        f"what each measured value's standard uncertainty does to e_x (at e_x = {args.e_x:g}, {args.ball}):",
        *uncertainty_lines(row, args, balls[args.ball]),
    ]
    print("\n".join(out))
    return 0
