"""The ``ballbat`` command: everyday questions without editing a config.

``ballbat check FILE`` validates a measured impacts file exactly as the workflow's ``ingest``
rule does (the same function, :func:`ballbat.stages.ingest.run`); ``ballbat fly`` flies batted
balls with Nathan's trajectory model (:func:`ballbat.flight.fly`), one from options or many
from a CSV file; ``ballbat summary results/{dataset}`` prints a dataset's headline numbers; ``ballbat import-tracks``
reads Tracker or Kinovea files into the long tracks CSV (:mod:`ballbat.tracks.formats`); ``ballbat
bat`` turns a lab's bat measurements into a bat-table row (:mod:`ballbat.batcli`); ``ballbat compare
FOLDER...`` prints the bats league table of results folders (:mod:`ballbat.league_cli`); ``ballbat hit``
turns a pitch and a swing into a batted ball with bands from a dataset's e_x (:mod:`ballbat.hit_cli`);
``ballbat design`` gives the impacts per bat a lab needs from a pilot dataset (:mod:`ballbat.design_cli`).
Defaults (air, spin decay, integrator, property tables) are the config schema's, the one
place the workflow's defaults live. Errors are one line naming the bad argument (exit 2);
``check`` exits 1 when the file is not usable.

``ballbat check --kind tracks --config YAML`` checks raw camera tracks as the ``reduce`` rule
does (the same steps: read and check the files, reduce, cross-check;
:func:`ballbat.chain.reduce_tracks_block`).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import re
import sys
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from . import __version__, design_cli, hit_cli, league_cli
from .usage import UsageError
from .video import cli as video_cli
from .writer import OutputFailed, OutputRefused

if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

#: The config schema and the default property tables, shipped with the package (``data/`` links
#: to ``workflow/schemas/`` and ``config/`` of the checkout, so there is one copy of each).
DATA = Path(__file__).resolve().parent / "data"

EXAMPLES = {
    "check": """examples:
  ballbat check data/mylab/impacts.csv
  ballbat check data/mylab/impacts.csv --bats data/mylab/bats.csv
  ballbat check config/examples/maple_impacts.csv --bats config/examples/maple_bats.csv
  ballbat check config/examples/hickory_impacts.csv --bats config/examples/hickory_bats.csv
  ballbat check config/examples/tracked_tracks.csv --kind tracks --impacts config/examples/tracked_impacts.csv
  ballbat check --kind tracks --config config/examples/tracked.yaml   (as the reduce rule: reduce, cross-check)""",
    "fly": """examples:
  ballbat fly --speed 103 --angle 27.5 --backspin 2500
  ballbat fly --speed 103 --angle 27.5 --backspin 2500 --method calculator --json
  ballbat fly --speed 95 --angle 30 --backspin 2200 --sidespin -500 --spray 15 --wind 0,10
  ballbat fly --csv balls.csv        (columns named like the options: speed, angle, backspin, ...)""",
    "import-tracks": """examples:
  ballbat import-tracks data/mylab/trk/ --points ball=ball,bat_tip=tip,dot_a=A,dot_b=B -o tracks.csv
  ballbat import-tracks W01_swing.trk W01_spin.kva --points ball=ball,bat_tip=tip,dot_a=A,dot_b=B -o W01.csv
  ballbat import-tracks data/mylab/tables/ --format tracker_table --units time=s,length=m,y=up \\
      --camera swing:fps=3000,m_per_px=0.00074 --camera spin:fps=1000,m_per_px=0.00125 --points ... -o tracks.csv
Files are named {impact_id}_{camera}.{ext} (camera: swing or spin; --pattern to change it).
Prints the camera settings found in the files as YAML; exits 1 when a file cannot be read.""",
    "bat": """examples:
  ballbat bat --length 34 --weight 32 --balance-point 23.0 --moi-6in 11200 --impact-from-tip 6 --diameter 2.6 --iz 11
  ballbat bat --length 34 --weight 32 --balance-point 23.0 --period 1.72 --pivot 6 --impact-from-knob 28 \\
      --diameter 2.6 --iz 11 --name hickory
Prints the bat in the paper's convention and the lab's, its centre of percussion and what each
measured value's uncertainty does to e_x; exits 1 when the values fail a bat row's checks.""",
    "summary": """examples:
  ballbat summary results/synthetic
  ballbat summary results/maple""",
}
EXAMPLES["track-video"] = video_cli.EXAMPLE
EXAMPLES["compare"] = league_cli.EXAMPLE
EXAMPLES["hit"] = hit_cli.EXAMPLE
EXAMPLES["design"] = design_cli.EXAMPLE


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (no usage block) and exit with status 2.

    A value that starts with ``-`` and a digit (``--elevation -1e6``, ``--wind -5,3``) or reads
    ``-inf``/``-nan`` is a value, not an option (argparse's own test misses exponents).
    """

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)

    def error(self, message: str) -> NoReturn:
        """Report ``message`` as one line on stderr and exit 2."""
        self.exit(2, f"{self.prog}: error: {message}\n")


def _schema_defaults() -> dict:
    """Return the defaults the config schema gives the air and the flight (the workflow's own)."""
    import yaml

    schema = yaml.safe_load((DATA / "config.schema.yaml").read_text())
    air = schema["properties"]["implications"]["properties"]["air"]["properties"]
    flight = schema["$defs"]["flight"]["properties"]
    tables = schema["properties"]["tables"]["properties"]
    return {
        "air": {k: v["default"] for k, v in air.items()},
        "flight": {k: v["default"] for k, v in flight.items()},
        "tables": {k: str(DATA / Path(v["default"]).name) for k, v in tables.items()},
        "limits": schema["$defs"],
    }


def _finite(text: str) -> float:
    """Parse a number that must be finite (``nan``, ``inf`` and ``1e400`` are not)."""
    try:
        val = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(val):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return val


def _range_problem(val: float, limits: dict, unit: str) -> str | None:
    """Return why ``val`` lies outside the schema's range ``limits`` (None when inside)."""
    if not math.isfinite(val):
        return f"{val!r} is not a finite number"
    lo, hi = limits.get("minimum"), limits.get("maximum")
    xlo, xhi = limits.get("exclusiveMinimum"), limits.get("exclusiveMaximum")
    below = (lo is not None and val < lo) or (xlo is not None and val <= xlo)
    above = (hi is not None and val > hi) or (xhi is not None and val >= xhi)
    if not (below or above):
        return None
    left = f"[{lo:g}" if lo is not None else f"({xlo:g}" if xlo is not None else "(-inf"
    right = f"{hi:g}]" if hi is not None else f"{xhi:g})" if xhi is not None else "inf)"
    about = limits.get("description", "")
    return f"{val:g} {unit} is outside {left}, {right} {unit}" + (f" ({about})" if about else "")


# --------------------------------------------------------------------------------------
# check


def cmd_check(args: argparse.Namespace) -> int:
    """Validate a measured impacts file as the ingest rule does; print every problem and warning."""
    from .chain import fit_problems, schema_settings
    from .properties import InputError, load_balls, load_bats
    from .stages import ingest

    defaults = _schema_defaults()["tables"]
    if args.kind == "tracks" and args.file is None:
        return _check_tracks(None, args, defaults)
    if args.file is None:
        raise UsageError("argument file: required")
    path = Path(args.file)
    if path.is_dir():
        raise UsageError(f"argument file: {path} is a directory, not an impacts file")
    if not path.exists():
        raise UsageError(f"argument file: {path}: no such file")
    if args.kind == "tracks":
        return _check_tracks(path, args, defaults)
    if args.config or args.dataset:
        raise UsageError("argument --config: only with --kind tracks (the dataset's camera settings and rig)")
    if args.impacts:
        raise UsageError("argument --impacts: only with --kind tracks (the impact table of a tracks file)")
    try:
        ds = ingest.run(
            ingest.IngestSettings(calibration={}),
            path,
            balls=args.balls or defaults["balls"],
            bats=args.bats or defaults["bats"],
        )
        warnings = ingest.warnings(ds)
    except InputError as exc:
        for problem in exc.problems:
            print(problem)
        print(f"{path}: not usable: {len(exc.problems)} problem(s)", file=sys.stderr)
        return 1
    balls, bats = load_balls(args.balls or defaults["balls"]), load_bats(args.bats or defaults["bats"])
    problems = fit_problems(schema_settings({"impacts": str(path)}, "check"), ds, balls, bats)
    if problems:  # what the workflow's fit_ex would stop on: the same chain and test (issue 19)
        for text in problems:
            print(f"{path}: {text}")
        for text in warnings:
            print(f"warning: {text}")
        print(f"{path}: not usable: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    for text in warnings:
        print(f"warning: {text}")
    for line in ingest.excluded_listing(ds):
        print(f"excluded: {line}")
    print(
        f"{path}: usable: {ds.sizes['impact']} impacts, {int(ds.attrs['n_excluded'])} excluded, "
        f"{len(warnings)} warning(s)"
    )
    return 0


def _tracks_dataset(args: argparse.Namespace, defaults: dict) -> tuple[str, dict, dict]:
    """Return the dataset of ``--config`` that has a ``tracks`` block: (name, block, its balls/bats tables)."""
    import yaml

    cfg_path = Path(args.config)
    if not cfg_path.is_file():
        raise UsageError(f"argument --config: {cfg_path}: no such file")
    from .pipeline.config import alias_problem

    try:
        cfg = yaml.safe_load(cfg_path.read_text(encoding="utf-8")) or {}
    except UnicodeDecodeError as exc:
        raise UsageError(
            f"argument --config: {cfg_path}: not UTF-8 text (byte {exc.start}): a binary file, not a YAML config?"
        ) from None
    except yaml.YAMLError as exc:
        raise UsageError(f"argument --config: {cfg_path}: not YAML ({' '.join(str(exc).split())})") from None
    bomb = alias_problem(cfg, str(cfg_path))
    if bomb:
        raise UsageError(f"argument --config: {bomb}")
    if not isinstance(cfg, dict):
        raise UsageError(f"argument --config: {cfg_path}: not a config (a YAML mapping of datasets, ...)")
    datasets = {k: v for k, v in (cfg.get("datasets") or {}).items() if isinstance(v, dict) and "tracks" in v}
    if args.dataset is None:
        if len(datasets) != 1:
            names = ", ".join(sorted(datasets)) or "none"
            raise UsageError(
                f"argument --dataset: {cfg_path} has {len(datasets)} datasets with tracks ({names}): name one"
            )
        args.dataset = next(iter(datasets))
    if args.dataset not in datasets:
        raise UsageError(f"argument --dataset: {cfg_path} has no dataset {args.dataset!r} with a tracks block")
    ds = datasets[args.dataset]
    tables = {**defaults, **(cfg.get("tables") or {})}
    from .pipeline.config import ConfigError, checked_block

    try:  # the block with the schema's defaults, as the workflow's validated config has it
        block = checked_block(ds["tracks"], "tracks", f"datasets.{args.dataset}.tracks")
    except ConfigError as exc:
        raise UsageError(f"argument --config: {cfg_path}: {exc}") from None
    return args.dataset, block, {k: ds.get(k, tables[k]) for k in ("balls", "bats")}


def _check_tracks(path: Path | None, args: argparse.Namespace, defaults: dict) -> int:
    """Check raw tracks as the workflow's reduce rule does: read, validate, reduce, cross-check.

    With ``--config``: the reduce rule's steps (:func:`ballbat.chain.reduce_tracks_block`),
    then what the workflow would do with every impact; exit 1 when the dataset would stop or
    a ball would have fewer than three usable impacts. Without: the files are only read.
    """
    import numpy as np

    from .chain import reduce_tracks_block
    from .linefit import MIN_FIT_IMPACTS
    from .properties import InputError, load_balls, load_bats
    from .tracks.io import load_tracks

    if args.config:
        name, block, tables = _tracks_dataset(args, defaults)
        where = f"datasets.{name}.tracks"
        shown = path or Path(block["dir"] if "dir" in block else block["file"])
        try:
            balls, bats = load_balls(args.balls or tables["balls"]), load_bats(args.bats or tables["bats"])
            red, verdict = reduce_tracks_block(block, where, balls, bats, path, args.impacts)
        except InputError as exc:
            for problem in exc.problems:
                print(problem)
            print(f"{shown}: the workflow would stop at reduce: {len(exc.problems)} problem(s)", file=sys.stderr)
            return 1
        for line in verdict.lines:
            print(f"cross-check: {line}")
        for text in verdict.warnings:
            print(f"warning: {text}")
        for iid, flag, why in zip(red.tracks.impact_id, red.flag, red.reason, strict=True):
            print(f"impact {iid}: " + ("used" if flag == 0 else f"excluded: {why}"))
        usable = red.flag == 0
        per_ball = {b: int((usable & (red.tracks.ball == b)).sum()) for b in sorted(set(red.tracks.ball))}
        listing = ", ".join(f"{b} {k}" for b, k in per_ball.items())
        short = [b for b, k in per_ball.items() if k < MIN_FIT_IMPACTS]
        n_out = int(sum(np.sum(v) for v in red.n_outliers.values()))
        summary = (
            f"{shown}: {int(usable.sum())} of {red.tracks.n} impacts usable (per ball: {listing}), "
            f"{red.tracks.n - int(usable.sum())} excluded, {n_out} tracking glitch(es) removed, "
            f"{len(verdict.warnings)} warning(s)"
        )
        if short:
            print(f"{summary}; fewer than {MIN_FIT_IMPACTS} usable impacts of {', '.join(short)}", file=sys.stderr)
            return 1
        print(summary)
        return 0
    if path is None:
        raise UsageError("argument file: required (or give --config with a dataset's tracks block)")
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
    print(
        f"{path}: read and validated: {tracks.n} impacts tracked by the cameras {cams}; not reduced: give --config "
        "(the dataset's camera settings and rig) for the reduction and its cross-checks"
    )
    return 0


# --------------------------------------------------------------------------------------
# import-tracks


def _pairs(text: str, what: str) -> dict[str, str]:
    """``a=1,b=2`` -> {a: "1", b: "2"}; a UsageError naming ``what`` when malformed."""
    out = {}
    for part in filter(None, (p.strip() for p in text.split(","))):
        key, sep, val = part.partition("=")
        if not sep or not key.strip() or not val.strip():
            raise UsageError(f"argument {what}: {part!r} is not NAME=VALUE")
        out[key.strip()] = val.strip()
    return out


def _number_arg(text: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"argument {what}: {text!r} is not a number") from None


def cmd_import_tracks(args: argparse.Namespace) -> int:
    """Read tracking-tool files into ballbat's long tracks CSV; print the camera settings found as YAML."""
    import yaml

    from .pipeline.checked import sealed_csv
    from .tracks.formats import FormatError
    from .tracks.formats.layout import DEFAULT_PATTERN, import_files
    from .tracks.io import long_csv_text
    from .writer import STDOUT, output_problem, write_output

    if args.output != STDOUT:  # refused before any file is read (write_output checks again)
        problem = output_problem(args.output, args.paths, args.parents)
        if problem:
            raise OutputRefused(problem)
    points = _pairs(args.points, "--points")
    units = _pairs(args.units, "--units") if args.units else None
    cameras: dict[str, dict] = {}
    for spec in args.camera or []:
        cam, sep, rest = spec.partition(":")
        if not sep:
            raise UsageError(f"argument --camera: {spec!r} is not CAMERA:fps=...,m_per_px=...")
        if cam not in ("swing", "spin"):
            raise UsageError(f"argument --camera: unknown camera {cam!r} (known: swing, spin)")
        cameras[cam] = {k: _number_arg(v, f"--camera {cam}:{k}") for k, v in _pairs(rest, "--camera").items()}
    try:
        imp = import_files(
            args.paths,
            points,
            pattern=args.pattern or DEFAULT_PATTERN,
            fmt=args.format,
            units=units,
            cameras=cameras,
            where="import-tracks",
        )
    except FormatError as exc:
        for problem in exc.problems:
            print(problem, file=sys.stderr)
        print(f"ballbat import-tracks: {len(exc.problems)} problem(s); nothing written", file=sys.stderr)
        return 1
    # the check line marks the file as ballbat's: only such a file is ever replaced (ballbat.writer)
    where = write_output(args.output, sealed_csv(long_csv_text(imp.columns)), args.paths, parents=args.parents)
    found = imp.settings_yaml()
    found["written"] = where
    print(yaml.safe_dump(found, sort_keys=False), end="", file=sys.stderr if args.output == STDOUT else sys.stdout)
    return 0


# --------------------------------------------------------------------------------------
# fly

#: ``fly`` options that take one number per ball: name -> (unit, help, the schema's range of it).
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
    from .properties import InputError, read_csv_rows

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

    from .flight import air_density, fly
    from .units import DEGREE, FOOT, INHG_IN_MMHG, MPH, RPM, fahrenheit_to_celsius

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


# --------------------------------------------------------------------------------------
# summary


def _verify_results(paths: Iterable[Path]) -> None:
    """Raise a UsageError naming the first of ``paths`` that is damaged (truncated, not NetCDF)."""
    from .pipeline.checked import verify_netcdf

    for path in paths:
        try:
            verify_netcdf(path)
        except Exception as exc:  # any damage gets the same answer
            why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise UsageError(
                f"argument folder: {path} cannot be read ({why}): damaged or cut short; "
                "rerun the workflow to rebuild it"
            ) from None


def summary_lines(folder: Path) -> list[str]:
    """Return the headline numbers of a dataset's results folder as lines of a terminal table."""
    from .analysis import impact_labels
    from .pipeline.ncio import read_dataset

    need = {name: folder / f"{name}.nc" for name in ("reconstruct", "fit_ex", "stronge")}
    missing = [str(p) for p in need.values() if not p.is_file()]
    if missing:
        raise UsageError(f"argument folder: {folder} lacks {', '.join(missing)} (run the workflow first)")
    from .pipeline.checked import DamagedFileError

    _verify_results(need.values())  # a damaged file is named first, before any file's identity
    try:
        read = [read_dataset(path) for path in need.values()]
    except DamagedFileError as exc:  # whole, but not the workflow's (no provenance record)
        raise UsageError(f"argument folder: {exc}") from None
    rec, fit, st = read
    lines = [f"{folder.name}: {rec.sizes['impact']} impacts, {int((rec['flag'].values != 0).sum())} not used (flagged)"]
    from .compare import format_measurement, systematic_var, total_uncertainty

    scale = systematic_var(fit, "e_x") is not None
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
            sys_ = float(f[systematic_var(f, pre)]) if scale else None
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
    lines += _e_x_source_lines(fit, scale)
    lines += ["", f"{'ball':<10} {'eta^2':>7} {'± se':>7} {'95 % interval':>17} {'n':>4}"]
    for ball in st["ball"].values.astype(str):
        s = st.sel(ball=ball)
        lo, hi = float(s["eta2_ci_low"]), float(s["eta2_ci_high"])
        lines.append(
            f"{ball:<10} {float(s['eta2']):7.3f} {float(s['eta2_err']):7.3f} {f'[{lo:.3f}, {hi:.3f}]':>17} "
            f"{int(s['eta2_n']):4d}"
        )
    lines += _systematic_lines(fit, st)
    bad = rec["flag"].values != 0
    reasons = rec["flag_reason"].values[bad].astype(str)
    if reasons.size:
        labels = impact_labels(rec)[bad]
        lines += ["", "not used:"] + [f"  {lab}: {r}" for lab, r in zip(labels, reasons, strict=True)]
    return lines


def _e_x_source_lines(fit, scale: bool) -> list[str]:
    """Return what e_x's systematic holds and its split by source (per bat and ball, pooled), or why there is none."""
    from .compare import NO_SYSTEMATIC_NOTE, source_parts, systematic_note

    if not scale:
        return [f"syst. —: {NO_SYSTEMATIC_NOTE}."]
    lines = [f"syst: {systematic_note(fit)}; total: both in quadrature."]
    if "e_x_syst_by_source" not in fit:
        return lines
    lines.append("e_x syst by source (largest first):")
    for ball in fit["ball"].values.astype(str):
        for bat in [*fit["bat"].values.astype(str), "pooled"]:
            f = fit.sel(ball=ball) if bat == "pooled" else fit.sel(ball=ball, bat=bat)
            parts = source_parts(f, "e_x_pooled" if bat == "pooled" else "e_x")
            if parts:
                lines.append(f"  {ball:<10} {bat:<20} " + ", ".join(f"{n} {v:.2g}" for n, v in parts))
    return lines


#: The per-ball quantities the summary lists with their systematics: (file, variable, unit shown).
SUMMARY_SYSTEMATICS = (
    ("fit", "tan_ratio_slope", "1"),
    ("fit", "e_y_implied", "1"),
    ("fit", "mu_k_lower_bound", "1"),
    ("fit", "spin_theta_slope", "rpm/deg"),
    ("fit", "speed_theta_slope", "mph/deg"),
    ("stronge", "eta2", "1"),
)


def _systematic_lines(fit, st) -> list[str]:
    """Lines of the per-ball quantities with stat, syst and total (datasets with calibration systematics only)."""
    from .compare import total_uncertainty, uncertainty_decimals
    from .units import from_si

    files = {"fit": fit, "stronge": st}
    if not any(f"{var}_syst" in files[k] for k, var, _ in SUMMARY_SYSTEMATICS):
        return []
    lines = ["", f"{'ball':<10} {'quantity':<18} {'value':>9} {'± stat':>8} {'± syst':>8} {'± total':>8}  unit"]
    for k, var, unit in SUMMARY_SYSTEMATICS:
        ds = files[k]
        if f"{var}_syst" not in ds:
            continue
        for ball in ds["ball"].values.astype(str):
            f = ds.sel(ball=ball)
            v, e, y = (from_si(float(f[n]), unit) for n in (var, f"{var}_err", f"{var}_syst"))
            total = total_uncertainty(e, y)
            # the decimals of the standard error and the total (a negligible systematic shows as 0)
            d = max(uncertainty_decimals(e, total) or 0, 0)
            cells = [f"{x:.{d}f}" if math.isfinite(x) else "" for x in (v, e, y, total)]
            lines.append(f"{ball:<10} {var:<18} " + " ".join(f"{c:>8}" for c in cells) + f"  {unit}")
    per_source = (
        [
            f"{src} ({float(r):g})" if math.isfinite(r) else f"{src} (absolute: fit_ex.nc's systematic coordinate)"
            for src, r in zip(fit["systematic"].values.astype(str), fit["systematic_rel_sigma"].values, strict=True)
            if r != 0
        ]
        if "systematic_rel_sigma" in fit
        else []
    )
    lines.append("systematic sources (relative sigma): " + (", ".join(per_source) or "none stated"))
    return lines


def cmd_summary(args: argparse.Namespace) -> int:
    """Print the headline numbers of a dataset's results."""
    folder = Path(args.folder)
    if not folder.is_dir():
        raise UsageError(f"argument folder: {folder}: not a directory")
    try:
        lines = summary_lines(folder)
    except KeyError as exc:  # a file of another version of the workflow
        raise UsageError(
            f"argument folder: {folder}: a results file lacks {exc} (made by another version?); rerun the workflow"
        ) from None
    from .pipeline.cratefiles import earlier_run_notes

    notes = earlier_run_notes(folder, ("reconstruct.nc", "fit_ex.nc", "stronge.nc"))
    for note in notes:  # numbers an earlier run or config made are never shown without saying so
        print(f"ballbat summary: note: {note}", file=sys.stderr)
    if notes:
        print(
            "ballbat summary: these numbers may be from an earlier run or config, not the last run's", file=sys.stderr
        )
    print("\n".join(lines))
    return 0


# --------------------------------------------------------------------------------------


def _import_tracks_parser(sub: argparse._SubParsersAction, fmt: type) -> None:
    """Add the ``import-tracks`` command to the subcommands ``sub``."""
    p = sub.add_parser(
        "import-tracks",
        help="read Tracker or Kinovea files into ballbat's long tracks CSV",
        epilog=EXAMPLES["import-tracks"],
        formatter_class=fmt,
    )
    p.add_argument("paths", nargs="+", metavar="FILE_OR_DIR", help="tool files, or folders of them")
    p.add_argument("--points", required=True, help="ballbat point=the tool's track name, e.g. ball=ball,bat_tip=tip")
    p.add_argument(
        "-o",
        "--output",
        required=True,
        help="long tracks CSV to write ('-': standard output); an existing file is replaced only if ballbat wrote it",
    )
    p.add_argument("--parents", action="store_true", help="create the output's folder if it does not exist")
    p.add_argument("--pattern", help="file names (default {impact_id}_{camera}.{ext})")
    p.add_argument(
        "--format",
        choices=("tracker", "kinovea", "tracker_table", "kinovea_table"),
        help="format of the files (default: from the extension, .trk/.trz/.kva; tables need it)",
    )
    p.add_argument("--units", help="tables only: time=s|ms|us|frames,length=m|cm|mm|in|ft|px,y=up|down")
    p.add_argument(
        "--camera",
        action="append",
        metavar="CAMERA:fps=..,m_per_px=..",
        help="a camera's settings the files lack (tables), or to check against theirs; repeat per camera",
    )
    p.set_defaults(func=cmd_import_tracks)


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

    video_cli.add_parser(sub, fmt)
    p = sub.add_parser("summary", help="a dataset's headline numbers", epilog=EXAMPLES["summary"], formatter_class=fmt)
    p.add_argument("folder", help="a results folder, e.g. results/synthetic")
    p.set_defaults(func=cmd_summary)
    _add_bat(sub, Path(d["tables"]["balls"]))
    _add_lab_commands(sub, d["tables"])
    return top


def _add_bat(sub: argparse._SubParsersAction, balls: Path) -> None:
    """Add ``ballbat bat`` (:mod:`ballbat.batcli`, imported only here: it needs numpy)."""
    from .batcli import register

    register(sub, _finite, balls, EXAMPLES["bat"])


def _add_lab_commands(sub: argparse._SubParsersAction, tables: dict) -> None:
    """Add a lab's season commands (issue 37): ``compare``, ``hit`` and ``design``."""
    league_cli.register(sub, _finite)
    hit_cli.register(sub, _finite, tables)
    design_cli.register(sub, _finite)


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


if __name__ == "__main__":
    sys.exit(main())
