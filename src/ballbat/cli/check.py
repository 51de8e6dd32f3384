"""``ballbat check``: a measured impacts file or raw camera tracks, checked as the workflow's rules check them."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..usage import UsageError
from .common import _schema_defaults


def cmd_check(args: argparse.Namespace) -> int:
    """Validate a measured impacts file as the ingest rule does; print every problem and warning."""
    from .. import chain
    from ..chain import fit_problems, schema_settings
    from ..properties import InputError, load_balls, load_bats
    from ..stages import ingest

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
        ds = chain.ingest(path, args.balls or defaults["balls"], args.bats or defaults["bats"])
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
    from ..pipeline.config import alias_problem

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
    from ..pipeline.config import ConfigError, checked_block

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

    from ..chain import reduce_tracks_block
    from ..linefit import MIN_FIT_IMPACTS
    from ..properties import InputError, load_balls, load_bats
    from ..tracks.io import load_tracks

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
    cams = ", ".join(sorted(tracks.blocks[0].cameras))
    print(
        f"{path}: read and validated: {tracks.n} impacts tracked by the cameras {cams}; not reduced: give --config "
        "(the dataset's camera settings and rig) for the reduction and its cross-checks"
    )
    return 0
