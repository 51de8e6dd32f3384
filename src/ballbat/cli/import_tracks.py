"""``ballbat import-tracks``: Tracker or Kinovea files into the long tracks CSV (:mod:`ballbat.tracks.formats`)."""

from __future__ import annotations

import argparse
import sys

from ..usage import UsageError
from ..writer import OutputRefused
from .common import EXAMPLES


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

    from ..pipeline.checked import sealed_csv
    from ..tracks.formats import FormatError
    from ..tracks.formats.layout import DEFAULT_PATTERN, import_files
    from ..tracks.io import long_csv_text
    from ..writer import STDOUT, output_problem, write_output

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
