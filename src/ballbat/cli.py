"""The ``ballbat`` command: everyday questions without editing a config.

``ballbat check FILE`` validates a measured impacts file exactly as the workflow's ``ingest``
rule does (the same function, :func:`ballbat.ingest.ingest`); ``ballbat fly`` flies batted
balls with Nathan's trajectory model (:func:`ballbat.flight.fly`), one from options or many
from a CSV file; ``ballbat summary results/{dataset}`` prints a dataset's headline numbers.
Defaults (air, spin decay, integrator, property tables) are the config schema's, the one
place the workflow's defaults live. Errors are one line naming the bad argument (exit 2);
``check`` exits 1 when the file is not usable.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from . import __version__

if TYPE_CHECKING:
    from collections.abc import Sequence

#: The repository checkout this package runs from (config/ and workflow/ live there).
ROOT = Path(__file__).resolve().parents[2]

EXAMPLES = {
    "check": """examples:
  ballbat check data/mylab/impacts.csv
  ballbat check data/mylab/impacts.csv --bats data/mylab/bats.csv
  ballbat check config/examples/maple_impacts.csv --bats config/examples/maple_bats.csv
  ballbat check config/examples/tracked_tracks.csv --kind tracks --impacts config/examples/tracked_impacts.csv""",
    "fly": """examples:
  ballbat fly --speed 103 --angle 27.5 --backspin 2500
  ballbat fly --speed 103 --angle 27.5 --backspin 2500 --method calculator --json
  ballbat fly --speed 95 --angle 30 --backspin 2200 --sidespin -500 --spray 15 --wind 0,10
  ballbat fly --csv balls.csv        (columns named like the options: speed, angle, backspin, ...)""",
    "summary": """examples:
  ballbat summary results/synthetic
  ballbat summary results/maple""",
}


class UsageError(Exception):
    """A bad argument: reported as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) and exit with status 2."""

    def error(self, message: str) -> NoReturn:
        """Report ``message`` as one line on stderr and exit 2."""
        self.exit(2, f"{self.prog}: error: {message}\n")


def _schema_defaults() -> dict:
    """Return the defaults the config schema gives the air and the flight (the workflow's own)."""
    import yaml

    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    air = schema["properties"]["implications"]["properties"]["air"]["properties"]
    flight = schema["$defs"]["flight"]["properties"]
    tables = schema["properties"]["tables"]["properties"]
    return {
        "air": {k: v["default"] for k, v in air.items()},
        "flight": {k: v["default"] for k, v in flight.items()},
        "tables": {k: str(ROOT / v["default"]) for k, v in tables.items()},
    }


# --------------------------------------------------------------------------------------
# check


def cmd_check(args: argparse.Namespace) -> int:
    """Validate a measured impacts file as the ingest rule does; print every problem and warning."""
    from .ingest import excluded_listing, ingest
    from .properties import InputError

    path = Path(args.file)
    if path.is_dir():
        raise UsageError(f"argument file: {path} is a directory, not an impacts file")
    if not path.exists():
        raise UsageError(f"argument file: {path}: no such file")
    defaults = _schema_defaults()["tables"]
    if args.kind == "tracks":
        return _check_tracks(path, args, defaults)
    if args.impacts:
        raise UsageError("argument --impacts: only with --kind tracks (the impact table of a tracks file)")
    try:
        ds, warnings = ingest(path, balls_path=args.balls or defaults["balls"], bats_path=args.bats or defaults["bats"])
    except InputError as exc:
        for problem in exc.problems:
            print(problem)
        print(f"{path}: not usable: {len(exc.problems)} problem(s)", file=sys.stderr)
        return 1
    for text in warnings:
        print(f"warning: {text}")
    for line in excluded_listing(ds):
        print(f"excluded: {line}")
    print(
        f"{path}: usable: {ds.sizes['impact']} impacts, {int(ds.attrs['n_excluded'])} excluded, "
        f"{len(warnings)} warning(s)"
    )
    return 0


def _check_tracks(path: Path, args: argparse.Namespace, defaults: dict) -> int:
    """Validate a raw-tracks file and its impact table as the workflow's reduce rule reads them."""
    from .properties import InputError, load_balls, load_bats
    from .tracks.io import load_tracks

    if path.suffix.lower() != ".nc" and not args.impacts:
        raise UsageError("argument --impacts: required with --kind tracks for a CSV tracks file (impact_id,bat,ball)")
    try:
        balls = load_balls(args.balls or defaults["balls"])
        bats = load_bats(args.bats or defaults["bats"])
        tracks = load_tracks(path, args.impacts, balls, bats)
    except InputError as exc:
        for problem in exc.problems:
            print(problem)
        print(f"{path}: not usable: {len(exc.problems)} problem(s)", file=sys.stderr)
        return 1
    cams = ", ".join(sorted(tracks.cameras))
    print(f"{path}: usable: {tracks.n} impacts tracked by the cameras {cams}")
    return 0


# --------------------------------------------------------------------------------------
# fly

#: ``fly`` options that take one number per ball: name -> (unit, help).
FLY_NUMBERS = {
    "speed": ("mph", "exit speed (required)"),
    "angle": ("deg", "launch angle above the horizontal (required)"),
    "backspin": ("rpm", "backspin; negative is topspin (default 0)"),
    "sidespin": ("rpm", "sidespin; positive curves towards third base (default 0)"),
    "spray": ("deg", "spray angle from centre field towards first base (default 0)"),
}


def _wind(text: str) -> tuple[float, float]:
    try:
        wx, wy = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid wind {text!r}: give 'x,y' in mph") from None
    return wx, wy


def _read_balls_csv(path: Path) -> dict[str, list[float]]:
    """Return the columns of a ``fly --csv`` file (names as the options), one value per ball."""
    if not path.is_file():
        raise UsageError(f"argument --csv: {path}: no such file")
    with open(path, newline="", encoding="utf-8-sig") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise UsageError(f"argument --csv: {path}: no rows")
    unknown = sorted(set(rows[0]) - set(FLY_NUMBERS))
    if unknown:
        raise UsageError(
            f"argument --csv: {path}: unknown column(s) {', '.join(unknown)} (allowed: {', '.join(FLY_NUMBERS)})"
        )
    missing = [c for c in ("speed", "angle") if c not in rows[0]]
    if missing:
        raise UsageError(f"argument --csv: {path}: missing column(s) {', '.join(missing)}")
    cols: dict[str, list[float]] = {k: [] for k in FLY_NUMBERS}
    for line, row in enumerate(rows, start=2):
        for k in FLY_NUMBERS:
            raw = (row.get(k) or "").strip()
            if not raw and k not in ("speed", "angle"):
                raw = "0"
            try:
                cols[k].append(float(raw))
            except ValueError:
                raise UsageError(f"argument --csv: {path}, line {line}, column {k}: {raw!r} is not a number") from None
    return cols


def fly_table(args: argparse.Namespace) -> list[dict]:
    """Fly the balls the arguments describe; return one result row per ball (calculator units)."""
    import numpy as np

    from .flight import air_density, fly
    from .units import DEGREE, FOOT, INHG_IN_MMHG, MPH, RPM, fahrenheit_to_celsius

    if args.csv:
        cols = _read_balls_csv(Path(args.csv))
    else:
        missing = [f"--{k}" for k in ("speed", "angle") if getattr(args, k) is None]
        if missing:
            raise UsageError(f"argument {missing[0]}: required (or give --csv FILE)")
        cols = {k: [getattr(args, k) or 0.0] for k in FLY_NUMBERS}
    speed = np.asarray(cols["speed"], dtype=float)
    if np.any(speed <= 0) or not np.all(np.isfinite(speed)):
        raise UsageError("argument --speed: must be a positive number of mph")
    if not 0 <= args.humidity <= 100:
        raise UsageError("argument --humidity: must lie in 0-100 %")
    if args.pressure <= 0:
        raise UsageError("argument --pressure: must be positive (inHg)")
    if args.spin_decay <= 0:
        raise UsageError("argument --spin-decay: must be positive (s)")
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


# --------------------------------------------------------------------------------------
# summary


def summary_lines(folder: Path) -> list[str]:
    """Return the headline numbers of a dataset's results folder as lines of a terminal table."""
    from .pipeline.ncio import read_dataset

    need = {name: folder / f"{name}.nc" for name in ("reconstruct", "fit_ex", "stronge")}
    missing = [str(p) for p in need.values() if not p.is_file()]
    if missing:
        raise UsageError(f"argument folder: {folder} lacks {', '.join(missing)} (run the workflow first)")
    rec, fit, st = (read_dataset(p) for p in need.values())
    lines = [f"{folder.name}: {rec.sizes['impact']} impacts, {int((rec['flag'].values != 0).sum())} not used (flagged)"]
    from .compare import format_measurement, total_uncertainty

    scale = "e_x_err_scale" in fit
    head = f"{'ball':<10} {'bat':<20} {'e_x':>8} {'± stat':>8}"
    head += f" {'± syst':>8} {'± total':>8}" if scale else ""
    lines += ["", head + f" {'95 % interval (stat)':>22} {'n':>4}"]
    for ball in fit["ball"].values.astype(str):
        for bat in [*fit["bat"].values.astype(str), "pooled"]:
            f = fit.sel(ball=ball) if bat == "pooled" else fit.sel(ball=ball, bat=bat)
            pre = "e_x_pooled" if bat == "pooled" else "e_x"
            n = int(f[f"{pre}_n"])
            if n == 0:
                continue
            v, e = float(f[pre]), float(f[f"{pre}_err"])
            sys_ = float(f[f"{pre}_err_scale"]) if scale else None
            errs = (e, sys_, total_uncertainty(e, sys_)) if scale else (e,)
            # rounded as the field does: the errors to two significant digits, the value to match
            cells = format_measurement(v, *errs)
            lo, hi = (
                format_measurement(float(f[f"{pre}_ci_low"]), e, sys_)[0],
                format_measurement(float(f[f"{pre}_ci_high"]), e, sys_)[0],
            )
            lines.append(
                f"{ball:<10} {bat:<20} " + " ".join(f"{c:>8}" for c in cells) + f" {f'[{lo}, {hi}]':>22} {n:4d}"
            )
    if scale:
        lines += [
            "syst: the pixel-scale systematic of the swing camera, shared by every impact of a bat "
            "(not in stat); total: both in quadrature."
        ]
    lines += ["", f"{'ball':<10} {'eta^2':>7} {'± se':>7} {'95 % interval':>17} {'n':>4}"]
    for ball in st["ball"].values.astype(str):
        s = st.sel(ball=ball)
        lo, hi = float(s["eta2_ci_low"]), float(s["eta2_ci_high"])
        lines.append(
            f"{ball:<10} {float(s['eta2']):7.3f} {float(s['eta2_err']):7.3f} {f'[{lo:.3f}, {hi:.3f}]':>17} "
            f"{int(s['eta2_n']):4d}"
        )
    reasons = rec["flag_reason"].values[rec["flag"].values != 0].astype(str)
    if reasons.size:
        lines += ["", "not used:"] + [f"  {r}" for r in reasons]
    return lines


def cmd_summary(args: argparse.Namespace) -> int:
    """Print the headline numbers of a dataset's results."""
    folder = Path(args.folder)
    if not folder.is_dir():
        raise UsageError(f"argument folder: {folder}: not a directory")
    print("\n".join(summary_lines(folder)))
    return 0


# --------------------------------------------------------------------------------------


def parser() -> argparse.ArgumentParser:
    """Return the ``ballbat`` argument parser (defaults from the config schema)."""
    d = _schema_defaults()
    air, flight = d["air"], d["flight"]
    top = _Parser(prog="ballbat", description=__doc__.split("\n\n")[0])
    top.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = top.add_subparsers(dest="command", required=True, parser_class=_Parser)
    fmt = argparse.RawDescriptionHelpFormatter

    p = sub.add_parser("check", help="validate a measured impacts file", epilog=EXAMPLES["check"], formatter_class=fmt)
    p.add_argument("file", help="impacts file (CSV or NetCDF, the paper's units)")
    p.add_argument("--bats", help="bat table (default: the workflow's config/bats.csv)")
    p.add_argument("--balls", help="ball table (default: the workflow's config/balls.csv)")
    p.add_argument("--kind", choices=("impacts", "tracks"), default="impacts", help="what the file holds")
    p.add_argument("--impacts", metavar="FILE", help="with --kind tracks: the impact table (impact_id,bat,ball)")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser(
        "fly", help="carry, hang time and apex of batted balls", epilog=EXAMPLES["fly"], formatter_class=fmt
    )
    for name, (unit, text) in FLY_NUMBERS.items():
        p.add_argument(f"--{name}", type=float, metavar=unit.upper(), help=f"{text}, {unit}")
    p.add_argument("--csv", metavar="FILE", help="many balls: a CSV with columns named like the options above")
    p.add_argument(
        "--temperature", type=float, default=air["temperature_F"], help="air temperature, deg F (default %(default)s)"
    )
    p.add_argument("--elevation", type=float, default=air["elevation_ft"], help="elevation, ft (default %(default)s)")
    p.add_argument(
        "--humidity", type=float, default=air["humidity_pct"], help="relative humidity, %% (default %(default)s)"
    )
    p.add_argument("--pressure", type=float, default=air["pressure_inHg"], help="pressure, inHg (default %(default)s)")
    p.add_argument("--wind", type=_wind, default=tuple(flight["wind_mph"]), help="wind 'x,y', mph (default 0,0)")
    p.add_argument(
        "--spin-decay",
        type=float,
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

    p = sub.add_parser("summary", help="a dataset's headline numbers", epilog=EXAMPLES["summary"], formatter_class=fmt)
    p.add_argument("folder", help="a results folder, e.g. results/synthetic")
    p.set_defaults(func=cmd_summary)
    return top


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``ballbat`` command; return its exit status."""
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except UsageError as exc:
        print(f"ballbat {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
