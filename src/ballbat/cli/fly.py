"""``ballbat fly``: batted balls flown with Nathan's trajectory model (:func:`ballbat.flight.fly`)."""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

from ..usage import UsageError
from .common import _range_problem, _schema_defaults

FLY_NUMBERS = {
    "speed": ("mph", "exit speed (required)", "exit_speed_mph"),
    "angle": ("deg", "launch angle above the horizontal (required)", "launch_deg"),
    "backspin": ("rpm", "backspin; negative is topspin (default 0)", "spin_rpm"),
    "sidespin": ("rpm", "sidespin; positive curves towards third base (default 0)", "spin_rpm"),
    "spray": ("deg", "spray angle from centre field towards first base (default 0)", "spray_deg"),
}
#: ``fly`` options of the conditions: option -> (attribute, unit, the schema's range of it).
FLY_CONDITIONS = {
    "--temperature": ("temperature", "deg F", "temperature_F"),
    "--elevation": ("elevation", "ft", "elevation_ft"),
    "--humidity": ("humidity", "%", "humidity_pct"),
    "--pressure": ("pressure", "inHg", "pressure_inHg"),
    "--spin-decay": ("spin_decay", "s", "tau_s"),
}


def _wind(text: str) -> tuple[float, float]:
    try:
        wx, wy = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid wind {text!r}: give 'x,y' in mph") from None
    if not (math.isfinite(wx) and math.isfinite(wy)):
        raise argparse.ArgumentTypeError(f"invalid wind {text!r}: both components must be finite numbers of mph")
    return wx, wy


def _read_balls_csv(path: Path, limits: dict) -> dict[str, list[float]]:
    """Return the columns of a ``fly --csv`` file (names as the options), one value per ball.

    Read as the workflow reads a lab's CSV (:func:`ballbat.properties.read_csv_rows`: comma or
    semicolon, a byte-order mark, UTF-8 only). Every cell of a column the header names must hold
    a finite number: a blank cell is an error naming its row and column, never 0.
    """
    from ..properties import InputError, read_csv_rows

    if path.is_dir():
        raise UsageError(f"argument --csv: {path}: is a directory, not a CSV file")
    if not path.exists():
        raise UsageError(f"argument --csv: {path}: no such file")
    try:
        header, lines = read_csv_rows(path)
    except InputError as exc:
        raise UsageError(f"argument --csv: {exc.problems[0]}") from None
    if not header:
        raise UsageError(f"argument --csv: {path}: empty file (expected a header line speed,angle,...)")
    if not lines:
        raise UsageError(f"argument --csv: {path}: no rows")
    unknown = sorted(set(header) - set(FLY_NUMBERS))
    if unknown:
        raise UsageError(
            f"argument --csv: {path}: unknown column(s) {', '.join(unknown)} (allowed: {', '.join(FLY_NUMBERS)})"
        )
    missing = [c for c in ("speed", "angle") if c not in header]
    if missing:
        raise UsageError(f"argument --csv: {path}: missing column(s) {', '.join(missing)}")
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated:
        raise UsageError(f"argument --csv: {path}: column(s) {', '.join(repeated)} appear more than once")
    cols: dict[str, list[float]] = {k: [] for k in FLY_NUMBERS}
    for line, cells in lines:
        at = f"argument --csv: {path}, row {line}"
        if len(cells) > len(header):
            raise UsageError(f"{at}: {len(cells) - len(header)} more cell(s) than the header has columns")
        row = dict(zip(header, cells, strict=False))
        for k in FLY_NUMBERS:
            if k not in header:  # a column the file does not have: the option's default
                cols[k].append(0.0)
                continue
            raw = row.get(k, "")
            if not raw:
                raise UsageError(f"{at}, column {k}: empty (give a value; 0 {FLY_NUMBERS[k][0]} is a value too)")
            try:
                val = float(raw)
            except ValueError:
                raise UsageError(f"{at}, column {k}: {raw!r} is not a number") from None
            if not math.isfinite(val):
                raise UsageError(f"{at}, column {k}: {raw!r} is not a finite number")
            why = _range_problem(val, limits[FLY_NUMBERS[k][2]], FLY_NUMBERS[k][0])
            if why:
                raise UsageError(f"{at}, column {k}: {why}")
            cols[k].append(val)
    return cols


def _check_ranges(args: argparse.Namespace, cols: dict[str, list[float]], limits: dict) -> None:
    """Refuse any ball or condition outside the config schema's physical ranges, naming the argument."""
    if not args.csv:  # a CSV file's cells are checked as they are read, naming row and column
        for k, (unit, _, ref) in FLY_NUMBERS.items():
            why = _range_problem(cols[k][0], limits[ref], unit)
            if why:
                raise UsageError(f"argument --{k}: {why}")
    for opt, (attr, unit, ref) in FLY_CONDITIONS.items():
        why = _range_problem(getattr(args, attr), limits[ref], unit)
        if why:
            raise UsageError(f"argument {opt}: {why}")
    for val in args.wind:
        why = _range_problem(val, limits["wind_component_mph"], "mph")
        if why:
            raise UsageError(f"argument --wind: {why}")


def fly_table(args: argparse.Namespace) -> list[dict]:
    """Fly the balls the arguments describe; return one result row per ball (calculator units)."""
    import numpy as np

    from ..flight import air_density, fly
    from ..units import DEGREE, FOOT, INHG_IN_MMHG, MPH, RPM, fahrenheit_to_celsius

    limits = _schema_defaults()["limits"]
    if args.csv:
        cols = _read_balls_csv(Path(args.csv), limits)
    else:
        missing = [f"--{k}" for k in ("speed", "angle") if getattr(args, k) is None]
        if missing:
            raise UsageError(f"argument {missing[0]}: required (or give --csv FILE)")
        cols = {k: [getattr(args, k) or 0.0] for k in FLY_NUMBERS}
    _check_ranges(args, cols, limits)
    speed = np.asarray(cols["speed"], dtype=float)
    rho = air_density(
        fahrenheit_to_celsius(args.temperature),
        args.pressure * INHG_IN_MMHG,
        args.elevation * FOOT,
        args.humidity,
    )
    res = fly(
        speed * MPH,
        np.asarray(cols["angle"]) * DEGREE,
        np.asarray(cols["spray"]) * DEGREE,
        np.asarray(cols["backspin"]) * RPM,
        np.asarray(cols["sidespin"]) * RPM,
        rho=rho,
        wind=np.asarray(args.wind, dtype=float) * MPH,
        tau=args.spin_decay,
        method=args.method,
    )
    x, y = res.landing[..., 0], res.landing[..., 1]
    rows = []
    for i in range(speed.size):
        rows.append(
            {
                **{k: cols[k][i] for k in FLY_NUMBERS},
                "carry_ft": float(np.atleast_1d(res.carry)[i] / FOOT),
                "hang_time_s": float(np.atleast_1d(res.hang_time)[i]),
                "apex_ft": float(np.atleast_1d(res.apex)[i] / FOOT),
                "bearing_deg": float(np.degrees(np.arctan2(np.atleast_1d(x)[i], np.atleast_1d(y)[i]))),
            }
        )
    return rows


def cmd_fly(args: argparse.Namespace) -> int:
    """Print carry, hang time, apex and landing bearing of each ball (text, CSV or JSON)."""
    rows = fly_table(args)
    if args.json:
        print(json.dumps(rows if args.csv else rows[0], indent=2))
    elif args.csv:
        w = csv.DictWriter(sys.stdout, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        w.writerows({k: f"{v:.6g}" for k, v in r.items()} for r in rows)
    else:
        r = rows[0]
        print(f"carry {r['carry_ft']:.1f} ft, hang time {r['hang_time_s']:.2f} s, apex {r['apex_ft']:.1f} ft, ", end="")
        print(f"landing bearing {r['bearing_deg']:+.1f} deg (+: towards first base)")
    return 0
