"""``ballbat hit``: a pitch and a swing into a batted ball and its carry, for a lab's own bat (docs/flight.md).

The same code as a D-sweep scenario of the workflow (:func:`ballbat.scenario_bands.scenario_with_bands`,
one offset D): with ``--results results/{dataset}`` the bat's properties are those the dataset was
analysed with (``bat_properties`` of its fit_ex.nc) and its e_x the dataset's fit of that bat (or
the ball's pooled e_x), and the batted ball comes with 68 % and 95 % bands from e_x's statistical
and systematic uncertainty. Without it, ``--e-x`` and the bat table (``--bats``) give them, no bands.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

from ..usage import UsageError

if TYPE_CHECKING:
    from collections.abc import Callable

    import xarray as xr

EXAMPLE = """examples:
  ballbat hit --pitch-speed 90 --bat-speed 70 --bat hickory --results results/h01 --D 0.5
  ballbat hit --pitch-speed 85 --bat-speed 73 --bat wood --e-x 0.4 --D 0.5
Pitch descent, pitch backspin and attack angle default to Sec. V.B's (6 deg, 2000 rpm, 6 deg)."""

#: option -> (scenario sweep key, unit, help, default or None for required)
SWING = {
    "pitch-speed": ("pitch_mph", "mph", "pitch speed", None),
    "bat-speed": ("bat_mph", "mph", "bat speed at the impact point", None),
    "pitch-descent": ("pitch_descent_deg", "deg", "descent angle of the pitch", 6.0),
    "pitch-backspin": ("pitch_backspin_rpm", "rpm", "backspin of the pitch", 2000.0),
    "attack": ("attack_deg", "deg", "attack angle of the swing, upward positive", 6.0),
}


def register(sub: argparse._SubParsersAction, number: Callable[[str], float], tables: dict) -> None:
    """Add the ``hit`` command to ``sub`` (``number``: a finite number; ``tables``: the default property tables)."""
    p = sub.add_parser(
        "hit",
        help="a pitch and a swing into a batted ball and its carry, with bands from e_x",
        epilog=EXAMPLE,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    for opt, (_, unit, what, default) in SWING.items():
        extra = {"required": True} if default is None else {"default": default}
        p.add_argument(f"--{opt}", type=number, metavar=unit.upper(), help=f"{what}, {unit}", **extra)
    p.add_argument("--D", type=number, required=True, metavar="IN", help="offset D of the impact, in")
    p.add_argument("--bat", required=True, help="the bat (a bat of the dataset, or of the bat table)")
    p.add_argument("--ball", default="baseball", help="ball (default %(default)s)")
    p.add_argument("--results", metavar="FOLDER", help="a dataset's results folder: its bat and its e_x, with bands")
    p.add_argument("--e-x", type=number, help="e_x without --results (default: the config schema's scenario e_x)")
    p.add_argument("--bats", default=tables["bats"], help="bat table without --results (default: the workflow's)")
    p.add_argument("--balls", default=tables["balls"], help="ball table (default: the workflow's config/balls.csv)")
    p.set_defaults(func=cmd_hit)


def _dataset(folder: str, bat: str, ball: str):
    """Return the bat of a results folder (its fit_ex.nc's ``bat_properties``) and the e_x of it there."""
    from ..league import LeagueInputError, read_folder
    from ..properties import Bat
    from ..scenario_bands import dataset_e_x
    from ..units import INCH, OUNCE, OZ_IN2

    try:
        sessions = read_folder(folder)
    except LeagueInputError as exc:
        raise UsageError(str(exc)) from None
    if len(sessions) != 1:
        names = ", ".join(s.dataset for s in sessions)
        raise UsageError(f"--results {folder}: holds {len(sessions)} datasets ({names}); name one dataset's folder")
    session = sessions[0]
    record = json.loads(session.fit.attrs.get("bat_properties", "{}"))
    if bat not in record:
        raise UsageError(f"--bat {bat}: not a bat of {folder} (its bats: {', '.join(sorted(record)) or 'none'})")
    u = record[bat]["used"]
    the_bat = Bat(
        bat=bat,
        name=bat,
        M=u["M_oz"] * OUNCE,
        I0=u["I0_oz_in2"] * OZ_IN2,
        Iz=u["Iz_oz_in2"] * OZ_IN2,
        b=u["b_in"] * INCH,
        R=u["R_in"] * INCH,
    )
    try:
        ex = dataset_e_x(session.fit, ball, bat, Path(folder).name)
    except ValueError as exc:
        raise UsageError(f"{folder}: {exc}") from None
    return the_bat, ex


def scenario(args: argparse.Namespace, e_x: float | None) -> tuple[dict, dict]:
    """Return the one-offset D sweep of ``args`` as a checked scenario block, and the air (the schema's defaults)."""
    from ..pipeline.config import ConfigError, checked_block

    sweep = {key: getattr(args, opt.replace("-", "_")) for opt, (key, *_) in SWING.items()}
    sweep["D_in"] = {"start": args.D, "stop": args.D, "num": 1}
    block = {"ball": args.ball, "bat": args.bat, "sweep": sweep, **({} if e_x is None else {"e_x": e_x})}
    try:
        imp = checked_block({"scenarios": {"hit": block}}, "implications", where="ballbat hit")
    except ConfigError as exc:
        raise UsageError(" ".join(str(exc).split())) from None
    return imp["scenarios"]["hit"], imp["air"]


def cmd_hit(args: argparse.Namespace) -> int:
    """Print the batted ball of a pitch and a swing, and its bands when e_x comes from a dataset."""
    from ..properties import InputError, load_balls, load_bats
    from ..scenario_bands import scenario_with_bands
    from ..stages.implications import ImplicationsSettings

    if args.results is not None and args.e_x is not None:
        raise UsageError("--e-x: not with --results (the dataset gives e_x)")
    try:
        balls = load_balls(args.balls)
        bats, ex = ({}, None) if args.results else (load_bats(args.bats), None)
    except (InputError, OSError) as exc:
        raise UsageError(str(exc)) from None
    if args.results:
        bat, ex = _dataset(args.results, args.bat, args.ball)
        bats = {args.bat: bat}
    sc, air = scenario(args, args.e_x if ex is None else ex.value)
    try:
        ds = scenario_with_bands(ImplicationsSettings(scenario=sc, air=air), balls, bats, ex)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    print("\n".join(hit_lines(ds, sc)))
    return 0


def hit_lines(ds: xr.Dataset, sc: dict) -> list[str]:
    """Return the batted ball in words: exit speed, launch angle, backspin and carry, with their bands."""
    import numpy as np

    from ..units import from_si

    sw = sc["sweep"]
    out = [
        f"{sc['ball']} on the {sc['bat']}: {sw['pitch_mph']:g} mph pitch, {sw['bat_mph']:g} mph swing, "
        f"D = {sw['D_in']['start']:g} in; e_x = {ds.attrs['e_x']:.4f}"
        + (
            f" ± {ds.attrs['e_x_stat']:.4f} (stat.) ± {ds.attrs['e_x_syst']:.4f} (syst.), {ds.attrs['e_x_source']}"
            if "e_x_stat" in ds.attrs
            else " (given; no bands)"
        )
    ]
    for q, unit, fmt, word in (
        ("exit_speed", "mph", ".1f", "exit speed"),
        ("launch_angle", "deg", ".1f", "launch angle"),
        ("backspin", "rpm", ".0f", "backspin"),
        ("carry", "ft", ".1f", "carry"),
    ):
        conv = np.degrees if unit == "deg" else (lambda v, u=unit: from_si(v, u))
        line = f"  {word:13} {conv(float(ds[q].values[0])):{fmt}} {unit}"
        if f"{q}_low68" in ds:
            b = {t: conv(float(ds[f"{q}_{t}"].values[0])) for t in ("low68", "high68", "low95", "high95")}
            line += (
                f"   68 %: {b['low68']:{fmt}} to {b['high68']:{fmt}}   95 %: {b['low95']:{fmt}} to {b['high95']:{fmt}}"
            )
        out.append(line)
    return out
