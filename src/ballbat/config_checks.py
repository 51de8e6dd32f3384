"""The config's rules of the domain: studies, sweeps, memory and scenarios; the check the workflow runs at its start.

:mod:`ballbat.pipeline.config` checks a config against its JSON schema and fills its defaults
(plumbing, which knows nothing of what the settings mean); this module adds what the schema
cannot say: a study's dataset and sweep (:mod:`ballbat.studies.sweeps`), the memory a dataset,
a study or a scenario may need on this machine, the per-ball and per-bat keys of a synthetic
dataset, and each scenario's tables and dataset. :func:`validate_config` runs both, in that
order; ``workflow/rules/common.smk`` calls it when the workflow starts, and :func:`load_config`
for callers outside Snakemake.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .datasets import films, renders
from .pipeline.config import (
    ConfigError,
    _message,
    block_schema,
    fill_defaults,
    packaged_schema,
    schema_problems,
)

if TYPE_CHECKING:
    import os


#: Bytes of memory one impact and one batted-ball case need. Measured peaks (ru_maxrss, default
#: stack, 2026-11): simulate + normalize + reconstruct + fit_ex + fit_stronge of 10^5 impacts
#: ~1.0 kB per impact (4 kB here leaves room for the NetCDF copies); a D sweep of 10^4 and
#: 4 x 10^4 cases with 101 trajectory samples 59 and 52 kB per case.
BYTES_PER_IMPACT = 4_000


BYTES_PER_CASE = 60_000


#: An impact rendered as camera tracks and reduced (dense tracks of both cameras, the fits'
#: arrays): 34-35 kB measured (2026-11, 7000 and 28000 impacts through render, reduce and the
#: Sec. IV fits); 50 kB leaves room.
BYTES_PER_TRACKED_IMPACT = 50_000


def impact_bytes(dataset: dict) -> int:
    """Return the memory one impact of a validated dataset's chain may need (bytes): more when it renders tracks."""
    return BYTES_PER_TRACKED_IMPACT if renders(dataset) or "tracks" in dataset else BYTES_PER_IMPACT


#: Share of the machine's available memory one job may plan to use.
MEMORY_SHARE = 0.5


#: A study's aggregate memory per replicate: 4 numbers of 8 bytes per quantity (21 quantities in
#: the paper's design: 0.7 kB), copied about 3 times while the batches are combined; 4 kB leaves
#: room for more bats. Measured: 190 MB in all for the calibration study's 1000 replicates.
STUDY_BYTES_PER_REPLICATE = 4_000


#: Most batch jobs one study may have: Snakemake builds its job graph before running anything,
#: and at 10^5 jobs that takes minutes and gigabytes (10^7 replicates had not finished after 300 s
#: at 4.2 GB); a larger study needs a larger ``batch_size``.
MAX_STUDY_BATCHES = 10_000


def study_impacts(dataset: dict, parameter: str | tuple | None, values: list, truth_impacts: int) -> tuple[int, int]:
    """Impacts of a study's largest replicate, and of its largest truth job, over its sweep points.

    A grid gives ``parameter`` as a tuple of names and ``values`` as tuples (one per point);
    no sweep gives no values. The truth job's size is :func:`ballbat.studies.sweeps.truth_counts`, the
    rule the truth job runs.
    """
    from .studies.sweeps import point_dataset, truth_counts

    # the counts are the synthetic block's impacts alone (truth_counts reads nothing else): each point's
    # impacts_per_bat is set on a copy of them, not of the whole block (a grid's 27 points, 10 ms a start)
    light = {"synthetic": {"impacts": dataset["synthetic"]["impacts"]}}
    names = (parameter,) if isinstance(parameter, str) else tuple(parameter or ())
    sizes = set()
    for value in values if parameter else [None]:
        point = dict(zip(names, (value,) if isinstance(parameter, str) else value, strict=True)) if parameter else {}
        sizes.add(point.get("impacts_per_bat"))
    one = truth = 0
    for size in sorted(sizes, key=lambda s: (s is None, s)):
        ds = light if size is None else point_dataset(light, "impacts_per_bat", size)
        counts = [int(n) for v in ds["synthetic"]["impacts"].values() for n in (v or {}).values()]
        if sum(counts) == 0:
            continue
        one = max(one, sum(counts))
        truth = max(truth, sum(n for v in truth_counts(ds, truth_impacts)[1].values() for n in v.values()))
    return one, truth


def _render_without_synthetic(config: dict) -> list[str]:
    """Name each measured dataset with a ``render`` block (it renders a synthetic truth; a measured one has none)."""
    datasets = config.get("datasets")
    return [
        f"datasets.{name}.render: only a synthetic dataset renders camera tracks (this one is measured: "
        f"{next(k for k in ('impacts', 'tracks') if k in ds)}); remove its render block"
        for name, ds in (datasets.items() if isinstance(datasets, dict) else ())
        if isinstance(ds, dict) and "render" in ds and "synthetic" not in ds and ("impacts" in ds or "tracks" in ds)
    ]


def _studies(config: dict, schema: dict | None = None, sweep_schema: bool = True) -> list[str]:
    """Check that each study names a synthetic dataset and that its sweep suits that dataset.

    ``sweep_schema=False``: the sweep points' blocks are not checked against the schema again
    (a config remembered as passed: :mod:`ballbat.pipeline.validated`).
    """
    from .studies.sweeps import check_study_sweep

    problems = []
    datasets = config.get("datasets") or {}
    checked: dict[tuple[str, str], list[str]] = {}  # the studies' sweep points share their blocks' checks
    for name, study in (config.get("studies") or {}).items():
        where = f"studies.{name}"
        ds = datasets.get(study["dataset"])
        if ds is None:
            problems.append(
                f"{where}.dataset: no dataset {study['dataset']!r} (datasets: {', '.join(datasets)}); "
                f"name one, or drop the study with {where}: null"
            )
        elif "synthetic" not in ds:
            problems.append(
                f"{where}.dataset: {study['dataset']!r} is not synthetic (a study replicates a synthetic experiment)"
            )
        elif films(ds):
            problems.append(
                f"{where}.dataset: {study['dataset']!r} films its impacts (render.video): a study replicates "
                "rendered tracks, not clips (minutes a replicate); name a dataset without render.video"
            )
        else:
            found = check_study_sweep(ds, study, where)
            problems += found or (_sweep_point_problems(ds, study, where, schema, checked) if sweep_schema else [])
            problems += _draw_properties_problems(config, ds, study, where)
    return problems


def _draw_properties_problems(config: dict, dataset: dict, study: dict, where: str) -> list[str]:
    """Return the problem of a study that draws properties from tables that state no uncertainty (no ``*_err``)."""
    from .properties import InputError, load_balls, load_bats

    if not study.get("draw_properties"):
        return []
    tables = config.get("tables") or {}
    paths = {k: dataset.get(k, tables.get(k)) for k in ("bats", "balls")}
    try:
        rows = [*load_bats(paths["bats"]).values(), *load_balls(paths["balls"]).values()]
    except (InputError, OSError, ValueError, TypeError, UnicodeDecodeError):
        return []  # a table that cannot be read: the jobs that read it say why
    if any(r.err for r in rows):
        return []
    return [
        f"{where}.draw_properties: the tables {paths['bats']} and {paths['balls']} state no uncertainty "
        "(no *_err column): there is nothing to draw; add <column>_err beside the measured values, or set it false"
    ]


def _sweep_point_problems(
    dataset: dict, study: dict, where: str, schema: dict | None = None, checked: dict | None = None
) -> list[str]:
    """Return the schema's problems of the dataset at each swept value (the schema owns every setting's range).

    Each value of each swept setting is checked once (a grid's settings are independent keys).
    A block a point leaves as it is (the render block of an ``impacts_per_bat`` point), or that
    another point or study made the same, is checked once: ``checked`` holds the messages of each
    block checked, by its kind and ``repr`` (which tells 1 from 1.0 and True, and keeps the keys'
    order: the same text, the same errors in the same order).
    """
    import jsonschema

    from .studies.sweeps import point_dataset, sweep_points

    names, points = sweep_points(study.get("sweep"))
    problems = []
    schema = packaged_schema() if schema is None else schema
    checked = {} if checked is None else checked
    kinds = [k for k in ("synthetic", "render") if k in dataset]
    validators = {}
    for i, name in enumerate(names):
        for value in sorted({p[i] for p in points}):
            point = point_dataset(dataset, name, value)
            for kind in kinds:
                key = (kind, repr(point[kind]))
                if key not in checked:
                    if kind not in validators:
                        validators[kind] = jsonschema.Draft202012Validator(block_schema(kind, schema))
                    checked[key] = [_message(err) for err in validators[kind].iter_errors(point[kind])]
                problems += [f"{where}.sweep ({name} = {value:g}): {kind}.{message}" for message in checked[key]]
    return problems


def _synthetic_keys(config: dict) -> list[str]:
    """Check that the per-ball and per-bat mappings of each synthetic dataset name the balls and bats it draws.

    ``impacts`` names the balls and, under each, the bats; ``e_x`` must give every one of these
    pairs and no other, ``e_y`` every ball, and ``psi_deg`` only these balls: a misspelt name
    (``psi_deg: {basebal: ...}``) would otherwise be ignored and the default used silently.
    """
    problems = []
    for name, ds in (config.get("datasets") or {}).items():
        syn = ds.get("synthetic") if isinstance(ds, dict) else None
        if not isinstance(syn, dict):
            continue
        where = f"datasets.{name}.synthetic"
        impacts = {b: set(v or {}) for b, v in (syn.get("impacts") or {}).items()}
        balls = ", ".join(map(str, impacts)) or "none"
        for key in ("e_x", "e_y", "psi_deg"):
            for ball in syn.get(key) or {}:
                if ball not in impacts:
                    problems.append(
                        f"{where}.{key}.{ball}: unknown ball (the balls of {where}.impacts: {balls}); a misspelt name?"
                    )
        for ball, bats in impacts.items():
            e_x = (syn.get("e_x") or {}).get(ball)
            if e_x is None:
                problems.append(f"{where}.e_x: no entry for ball {ball} (it has impacts); give its true e_x per bat")
            else:
                for bat in sorted(set(e_x) - bats, key=str):
                    problems.append(
                        f"{where}.e_x.{ball}.{bat}: unknown bat (the bats of {where}.impacts.{ball}: "
                        f"{', '.join(map(str, bats))}); a misspelt name?"
                    )
                for bat in sorted(bats - set(e_x), key=str):
                    problems.append(f"{where}.e_x.{ball}: no entry for bat {bat} (it has impacts); give its true e_x")
            if ball not in (syn.get("e_y") or {}):
                problems.append(f"{where}.e_y: no entry for ball {ball} (it has impacts); give its true e_y")
    return problems


def _offsets(config: dict) -> list[str]:
    """Refuse a D sweep of one offset that names a stop it would drop."""
    problems = []
    for name, sc in ((config.get("implications") or {}).get("scenarios") or {}).items():
        d = (sc.get("sweep") or {}).get("D_in") if isinstance(sc, dict) else None
        if isinstance(d, dict) and d.get("num") == 1 and d.get("start") != d.get("stop"):
            problems.append(
                f"implications.scenarios.{name}.sweep.D_in: num 1 gives the one offset start = {d['start']} in, "
                f"so stop = {d['stop']} would be dropped; give num >= 2, or stop equal to start"
            )
    return problems


def _available_memory() -> int:
    """Return the memory available to a job, bytes (psutil; /proc/meminfo as a fallback)."""
    try:
        import psutil

        return int(psutil.virtual_memory().available)
    except ImportError:  # pragma: no cover - psutil ships with snakemake
        with open("/proc/meminfo") as fh:
            info = dict(line.split(":", 1) for line in fh)
        return int(info["MemAvailable"].split()[0]) * 1024


def _sizes(config: dict, available: int) -> list[str]:
    """Refuse counts the machine cannot hold, with the estimate; refuse empty datasets."""
    problems = []
    budget = MEMORY_SHARE * available

    def check(where: str, count: int, per: int, what: str) -> None:
        need = count * per
        if need > budget:
            problems.append(
                f"{where}: {count:,} {what} need about {need / 2**30:.1f} GiB of memory (estimate: "
                f"{per:,} bytes each), more than half the {available / 2**30:.1f} GiB this machine has "
                "available; use fewer"
            )

    for name, ds in (config.get("datasets") or {}).items():
        syn = ds.get("synthetic") if isinstance(ds, dict) else None
        if not isinstance(syn, dict):
            continue
        total = sum(int(n) for bats in (syn.get("impacts") or {}).values() for n in (bats or {}).values())
        if total == 0:
            problems.append(f"datasets.{name}.synthetic.impacts: no impacts (every count is 0): nothing to fit")
        check(f"datasets.{name}.synthetic.impacts", total, impact_bytes(ds), "impacts")
    datasets = config.get("datasets") or {}
    for name, st in (config.get("studies") or {}).items():
        ds = datasets.get(st.get("dataset")) if isinstance(st, dict) else None
        if isinstance(ds, dict) and isinstance(ds.get("synthetic"), dict):
            from .studies.sweeps import sweep_points

            sweep = st.get("sweep") or {}
            names, values = sweep_points(sweep)
            one, truth = study_impacts(ds, names, values, st["truth_impacts"])
            where = f"studies.{name}"
            if "impacts_per_bat" in names:
                key = "sweep.grid.impacts_per_bat" if "grid" in sweep else "sweep.values"
                check(f"{where}.{key}", one, impact_bytes(ds), "impacts in one replicate")
            check(f"{where}.truth_impacts", truth, impact_bytes(ds), "impacts")
            total = int(st["replicates"]) * max(len(values), 1)
            check(f"{where}.replicates", total, STUDY_BYTES_PER_REPLICATE, "replicates (all sweep points)")
            batches = -(-total // int(st["batch_size"]))
            if batches > MAX_STUDY_BATCHES:
                problems.append(
                    f"{where}.replicates: {total:,} replicates in batches of {int(st['batch_size'])} make "
                    f"{batches:,} batch jobs, more than the {MAX_STUDY_BATCHES:,} a job graph can hold in reasonable "
                    "time and memory; use fewer replicates or a larger batch_size"
                )
    for name, sc in ((config.get("implications") or {}).get("scenarios") or {}).items():
        if "sweep" in sc:
            check(
                f"implications.scenarios.{name}.sweep.D_in.num",
                int(sc["sweep"]["D_in"]["num"]),
                BYTES_PER_CASE,
                "cases",
            )
        elif "launch" in sc:
            sizes = [len(v) if isinstance(v, list) else 1 for k, v in sc["launch"].items() if k != "combine"]
            grid = sc["launch"]["combine"] == "grid"
            count = math.prod(sizes) if grid else max(sizes)
            check(f"implications.scenarios.{name}.launch", count, BYTES_PER_CASE, "cases")
    return problems


def validate_config(
    config: dict,
    schema: dict,
    source: str = "config",
    available: int | None = None,
    record: os.PathLike[str] | str | None = None,
) -> dict:
    """Check ``config`` against ``schema``; fill defaults; raise :class:`ConfigError` listing all problems.

    Beyond the schema (:func:`ballbat.pipeline.config.schema_problems`: names of datasets and
    scenarios, the whole name, reserved names): the rules of the domain below, and counts the
    machine cannot hold (``available`` bytes of memory; default: what it has now).

    ``record``: a folder of the configs that passed (:mod:`ballbat.pipeline.validated`; the
    workflow's ``.snakemake/ballbat/validated``). A config remembered there, with this schema and
    this code, skips the schema's checks (its own and its sweep points'); the rest run.
    """
    from pathlib import Path

    from .pipeline import validated

    key = validated.config_key(config, schema) if record is not None else None
    passed = key is not None and validated.seen(key, Path(record))
    lines = ([] if passed else schema_problems(config, schema, source)) + _render_without_synthetic(config)
    if not lines:
        lines = _synthetic_keys(config) + _offsets(config)
    if not lines:
        fill_defaults(config, schema)
        memory = _available_memory() if available is None else available
        lines = _studies(config, schema, sweep_schema=not passed) + _sizes(config, memory)
    if lines:
        raise ConfigError(f"{source} is not valid:\n  " + "\n  ".join(lines))
    if key is not None and not passed:
        validated.remember(key, Path(record))
    return config


def load_config(path: str | os.PathLike[str] | None = None, schema_path: str | os.PathLike[str] | None = None) -> dict:
    """Return the workflow's config file (default ``config/config.yaml``), validated, with the schema's defaults.

    For callers outside Snakemake (tests, benchmarks, examples) that need the same values
    the workflow uses. Paths default to the repository checkout this package lives in.
    """
    from pathlib import Path

    import yaml

    root = Path(__file__).resolve().parents[2]
    path = Path(path) if path else root / "config" / "config.yaml"
    schema_path = Path(schema_path) if schema_path else root / "workflow" / "schemas" / "config.schema.yaml"
    with open(schema_path) as fh:
        schema = yaml.safe_load(fh)
    with open(path) as fh:
        config = yaml.safe_load(fh)
    return validate_config(config, schema, source=str(path))


def _dataset_balls(dataset: dict) -> set[str] | None:
    """Return the balls a validated dataset has impacts of (None when its file cannot tell: its own job will)."""
    from .properties import InputError

    if "synthetic" in dataset:
        return {str(b) for b, bats in dataset["synthetic"]["impacts"].items() if any((bats or {}).values())}
    path = dataset["impacts"] if "impacts" in dataset else dataset.get("tracks", {}).get("impacts")
    if path is None:
        return None  # rendered tracks come from a synthetic block (above)
    try:
        if "impacts" in dataset:
            from .ingest import read_impacts_table

            _, rows = read_impacts_table(path)
        else:
            from .properties import read_table

            _, rows = read_table(path, ("impact_id", "bat", "ball"), "impact")
    except (InputError, OSError, ValueError):
        return None
    balls = {row.get("ball", "").strip() for _, row in rows}
    return (balls - {""}) or None


def _table_names(path: str, loader) -> set[str] | None:
    """Names of a property table's entries (None when it cannot be read: the jobs that read it say why)."""
    from .properties import InputError

    try:
        return set(loader(path))
    except (InputError, OSError, ValueError, UnicodeDecodeError):
        return None


def scenario_problems(config: dict) -> list[str]:
    """Check each scenario of a validated config against the files it needs, before any job runs.

    Its ball and (sweep) bat must be in the property tables of config ``tables`` (of its ``e_x_from_dataset``
    dataset when that has its own), and the dataset of
    ``e_x_from_dataset`` must exist and have impacts of its ball. Each problem names the scenario's key.
    """
    from .properties import load_balls, load_bats

    scenarios = (config.get("implications") or {}).get("scenarios") or {}
    if not scenarios:
        return []
    problems = []
    for name, sc in scenarios.items():
        where = f"implications.scenarios.{name}"
        tables = scenario_tables(config, sc)
        for key, table in (("ball", "balls"), ("bat", "bats")):
            names = _table_names(tables[table], load_bats if key == "bat" else load_balls)
            if key in sc and names is not None and sc[key] not in names:
                problems.append(
                    f"{where}.{key}: {sc[key]!r} is not in the {key} table {tables[table]} "
                    f"({', '.join(sorted(names))}); a misspelt name? A lab's own {key}: add it to "
                    f"tables.{table}, or name its dataset in e_x_from_dataset (its {table} table is used)"
                )
        problems += _e_x_source_problems(config, where, sc)
    return problems


def scenario_tables(config: dict, scenario: dict) -> dict[str, str]:
    """Return a scenario's property tables (``balls``, ``bats``): its dataset's where they hold its ball (bat).

    For each, the ``e_x_from_dataset`` dataset's own table when that holds the scenario's ball
    (bat), else the config's ``tables``. A lab's own bat needs no extra config: a bat only its
    dataset's table knows is found there.
    """
    from .properties import load_balls, load_bats

    block = (config.get("datasets") or {}).get(scenario.get("e_x_from_dataset")) or {}
    out = {}
    for key, table, loader in (("ball", "balls", load_balls), ("bat", "bats", load_bats)):
        own = block.get(table)
        names = _table_names(own, loader) if own else None
        out[table] = own if names is not None and scenario.get(key) in names else config["tables"][table]
    return out


def _e_x_source_problems(config: dict, where: str, scenario: dict) -> list[str]:
    """Check the dataset of a scenario's ``e_x_from_dataset``: it must exist and have impacts of the scenario's ball."""
    name = scenario.get("e_x_from_dataset")
    if name is None:
        return []
    datasets = config.get("datasets") or {}
    if name not in datasets:
        return [f"{where}.e_x_from_dataset: {name!r} is not a dataset ({', '.join(sorted(datasets)) or 'none'})"]
    balls = _dataset_balls(datasets[name])
    if balls is not None and scenario["ball"] not in balls:
        return [
            f"{where}.e_x_from_dataset: dataset {name!r} has no impacts of the scenario's ball "
            f"{scenario['ball']!r} (its balls: {', '.join(sorted(balls))}), so it has no pooled e_x for it; "
            "name a dataset with that ball, or give e_x"
        ]
    return []
