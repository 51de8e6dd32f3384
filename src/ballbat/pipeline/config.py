"""Validation of the workflow config against its JSON schema, with messages that name keys.

Used by ``workflow/rules/common.smk`` when the workflow starts. Every problem is reported
at once, each with the dotted path of the offending key (``datasets.synthetic.seed: 'x'
is not of type 'integer'``). Missing keys that the schema gives a ``default`` are filled in.
"""

from __future__ import annotations

import copy
import math
import re
from typing import TYPE_CHECKING

from ..sweeps import renders

if TYPE_CHECKING:
    import os


class ConfigError(ValueError):
    """The config does not match the schema."""


#: Names the workflow uses for folders and files of its own under ``results/`` (and ``all``,
#: the default rule): a dataset may not take them, nor, in ``results/implications/``, a scenario.
RESERVED_DATASET_NAMES = ("all", "benchmarks", "figures", "implications", "logs", "report", "studies", "tracks")
RESERVED_SCENARIO_NAMES = ("benchmarks", "figures", "logs", "paper_comparison", "results")

#: What a dataset or scenario may be called: letters, digits, _ and - (a folder and file name).
NAME = re.compile(r"[A-Za-z0-9_-]+")

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
    no sweep gives no values. The truth job's size is :func:`ballbat.sweeps.truth_counts`, the
    rule the truth job runs.
    """
    from ..sweeps import point_dataset, truth_counts

    one = truth = 0
    for value in values if parameter else [None]:
        ds = point_dataset(dataset, parameter or None, value)
        counts = [int(n) for v in ds["synthetic"]["impacts"].values() for n in (v or {}).values()]
        if sum(counts) == 0:
            continue
        one = max(one, sum(counts))
        truth = max(truth, sum(n for v in truth_counts(ds, truth_impacts)[1].values() for n in v.values()))
    return one, truth


#: What a null reads as where ``snakemake --config`` parses a value: its YAML reader keeps every
#: scalar as text, so ``--config "datasets={synthetic: null}"`` gives the text ``'null'``.
NULL_TEXTS = ("null", "Null", "NULL", "~")


def is_null(value: object) -> bool:
    """Whether a dataset, scenario or study entry is null: YAML's null, or its text from ``--config``."""
    return value is None or (isinstance(value, str) and value in NULL_TEXTS)


def drop_nulls(config: dict) -> dict:
    """Drop datasets, scenarios and studies set to null (``datasets: {synthetic: null}`` in an override).

    A study of a dataset dropped this way is dropped with it (it has nothing to replicate). The
    text ``null`` (:data:`NULL_TEXTS`: what ``--config`` passes) counts as null: an entry must be a
    mapping, so no entry can mean the text.
    """
    dropped = set()
    if isinstance(config.get("datasets"), dict):
        dropped = {k for k, v in config["datasets"].items() if is_null(v)}
        config["datasets"] = {k: v for k, v in config["datasets"].items() if not is_null(v)}
    if isinstance(config.get("studies"), dict):
        config["studies"] = {
            k: v
            for k, v in config["studies"].items()
            if not is_null(v) and not (isinstance(v, dict) and v.get("dataset") in dropped)
        }
    imp = config.get("implications")
    if isinstance(imp, dict) and isinstance(imp.get("scenarios"), dict):
        imp["scenarios"] = {k: v for k, v in imp["scenarios"].items() if not is_null(v)}
    return config


def _render_without_synthetic(config: dict) -> list[str]:
    """Name each measured dataset with a ``render`` block (it renders a synthetic truth; a measured one has none)."""
    datasets = config.get("datasets")
    return [
        f"datasets.{name}.render: only a synthetic dataset renders camera tracks (this one is measured: "
        f"{next(k for k in ('impacts', 'tracks') if k in ds)}); remove its render block"
        for name, ds in (datasets.items() if isinstance(datasets, dict) else ())
        if isinstance(ds, dict) and "render" in ds and "synthetic" not in ds and ("impacts" in ds or "tracks" in ds)
    ]


def _names(config: dict) -> list[str]:
    problems = []
    groups = (
        ("datasets", config.get("datasets") or {}, RESERVED_DATASET_NAMES, "results/{name}/"),
        (
            "implications.scenarios",
            (config.get("implications") or {}).get("scenarios") or {},
            RESERVED_SCENARIO_NAMES,
            "results/implications/{name}.*",
        ),
    )
    groups += (("studies", config.get("studies") or {}, (), "results/studies/{name}/"),)
    for where, table, reserved, folder in groups:
        if not isinstance(table, dict):
            continue
        for name in table:
            if not isinstance(name, str):
                kind = "a boolean (as yes, no, on, off)" if isinstance(name, bool) else "a number"
                example = "'yes'" if isinstance(name, bool) else f"'{name}'"
                problems.append(
                    f"{where}.{name}: YAML reads this name as {kind}, not text; a name must be text: "
                    f"quote it in the YAML file ({example}) or choose a name that starts with a letter"
                )
            elif not NAME.fullmatch(str(name)):
                problems.append(f"{where}.{name!r}: a name may hold only letters, digits, _ and - (it names {folder})")
            elif name in reserved:
                problems.append(
                    f"{where}.{name}: {name!r} is reserved for the workflow's own results "
                    f"(reserved: {', '.join(reserved)}); choose another name"
                )
    return problems


def _studies(config: dict, schema: dict | None = None) -> list[str]:
    """Check that each study names a synthetic dataset and that its sweep suits that dataset."""
    from ..sweeps import check_study_sweep

    problems = []
    datasets = config.get("datasets") or {}
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
        else:
            found = check_study_sweep(ds, study, where)
            problems += found or _sweep_point_problems(ds, study, where, schema)
            problems += _draw_properties_problems(config, ds, study, where)
    return problems


def _draw_properties_problems(config: dict, dataset: dict, study: dict, where: str) -> list[str]:
    """Return the problem of a study that draws properties from tables that state no uncertainty (no ``*_err``)."""
    from ..properties import InputError, load_balls, load_bats

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


def _sweep_point_problems(dataset: dict, study: dict, where: str, schema: dict | None = None) -> list[str]:
    """Return the schema's problems of the dataset at each swept value (the schema owns every setting's range).

    Each value of each swept setting is checked once (a grid's settings are independent keys).
    """
    import jsonschema

    from ..sweeps import point_dataset, sweep_points

    names, points = sweep_points(study.get("sweep"))
    problems = []
    schema = packaged_schema() if schema is None else schema
    kinds = [k for k in ("synthetic", "render") if k in dataset]
    validators = {k: jsonschema.Draft202012Validator(block_schema(k, schema)) for k in kinds}
    for i, name in enumerate(names):
        for value in sorted({p[i] for p in points}):
            point = point_dataset(dataset, name, value)
            for kind, validator in validators.items():
                for err in validator.iter_errors(point[kind]):
                    problems.append(f"{where}.sweep ({name} = {value:g}): {kind}.{_message(err)}")
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


#: The most values a config may hold once YAML's aliases (``&anchor`` ... ``*anchor``) are expanded, and
#: its deepest nesting: a few aliases of aliases (a "billion laughs" file) would otherwise hold
#: billions of values, and every check that walks the config would never end.
MAX_CONFIG_VALUES = 100_000
MAX_CONFIG_DEPTH = 40


def alias_problem(config: object, source: str = "config") -> str | None:
    """Return why ``config`` is too large or deep once its aliases are expanded (None when it is not).

    Counts each shared mapping or list once per use without walking it again, so the count of a
    bomb is found in the time of its few distinct nodes; a mapping that contains itself is named.
    """
    sizes: dict[int, int] = {}

    def size(node: object, depth: int, stack: set[int]) -> int:
        if not isinstance(node, (dict, list)):
            return 1
        if id(node) in stack:
            raise ValueError(f"{source}: a YAML alias makes the config contain itself")
        if depth > MAX_CONFIG_DEPTH:
            raise ValueError(f"{source}: nested deeper than {MAX_CONFIG_DEPTH} levels")
        if id(node) not in sizes:
            stack.add(id(node))
            items = node.values() if isinstance(node, dict) else node
            sizes[id(node)] = 1 + sum(size(v, depth + 1, stack) for v in items)
            stack.discard(id(node))
        return sizes[id(node)]

    try:
        total = size(config, 0, set())
    except ValueError as exc:
        return str(exc)
    if total > MAX_CONFIG_VALUES:
        return (
            f"{source}: holds {total} values once its YAML aliases (*name) are expanded, more than "
            f"{MAX_CONFIG_VALUES}: aliases of aliases (a file built to blow up when read?)"
        )
    return None


def _finite(node: object, where: str = "") -> list[str]:
    """Name every number that is not finite (``.nan``, ``.inf``): no range check can hold it."""
    if isinstance(node, dict):
        return [p for k, v in node.items() for p in _finite(v, f"{where}.{k}" if where else str(k))]
    if isinstance(node, list):
        return [p for i, v in enumerate(node) for p in _finite(v, f"{where}[{i}]")]
    if isinstance(node, float) and not math.isfinite(node):
        return [f"{where}: {node} is not a finite number"]
    return []


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
            from ..sweeps import sweep_points

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


def _path(error) -> str:
    return ".".join(str(p) for p in error.absolute_path) or "<top level>"


def _message(error) -> str:
    if error.validator == "additionalProperties":
        allowed = sorted(error.schema.get("properties", {}))
        extra = sorted(set(error.instance) - set(allowed))
        pattern = error.schema.get("patternProperties")
        if pattern:
            return f"{_path(error)}: key(s) {', '.join(map(repr, extra))} not allowed ({error.message})"
        where = _path(error)
        return "; ".join(
            f"{where + '.' if where != '<top level>' else ''}{k}: unknown key (allowed: {', '.join(allowed)})"
            for k in extra
        )
    if error.validator == "oneOf" and not error.context:  # more than one form matches
        forms = [" + ".join(f.get("required", [])) or "?" for f in error.validator_value]
        return f"{_path(error)}: give exactly one of {', '.join(forms)}, not several"
    if error.validator in ("oneOf", "anyOf") and error.context:
        relevant = [e for e in error.context if e.validator != "type"]
        if relevant and len(relevant) < len(error.context):  # a number or a list: the form it has
            return "; ".join(sorted({_message(e) for e in relevant}))
        inner = sorted({_message(e) for e in error.context})
        return f"{_path(error)}: matches none of the allowed forms: " + " | ".join(inner)
    if error.validator == "minProperties" and _path(error) == "datasets":
        return "datasets: no dataset is left (each one was set to null or removed); the workflow needs at least one"
    if error.validator in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        about = error.schema.get("description")
        return f"{_path(error)}: {error.message}" + (f" ({about})" if about else "")
    return f"{_path(error)}: {error.message}"


def _resolve(schema, root):
    """Follow a local ``$ref`` (``#/$defs/name``)."""
    while "$ref" in schema and schema["$ref"].startswith("#/"):
        target = root
        for part in schema["$ref"][2:].split("/"):
            target = target[part]
        schema = {**target, **{k: v for k, v in schema.items() if k != "$ref"}}
    return schema


def fill_defaults(instance: object, schema: dict, root: dict | None = None) -> object:
    """Fill missing keys that have a ``default`` in ``schema`` (recursively, in place).

    Each default is stated once, on the key it belongs to: a missing object whose
    properties have defaults is created empty and filled, so no object restates the
    defaults of its members.
    """
    root = schema if root is None else root
    schema = _resolve(schema, root)
    if not isinstance(instance, dict) or schema.get("type") != "object":
        return instance
    props = schema.get("properties", {})
    # keys that choose one form of the object (oneOf/anyOf: synthetic | impacts) are never created
    optional_forms = set(schema.get("required", ()))
    for form in (*schema.get("oneOf", ()), *schema.get("anyOf", ())):
        optional_forms.update(form.get("required", ()))
    for key, sub in props.items():
        sub = _resolve(sub, root)
        if key not in instance and "default" in sub:
            instance[key] = copy.deepcopy(sub["default"])
        elif (
            key not in instance
            and sub.get("type") == "object"
            and key not in optional_forms
            and not sub.get("required")  # an object with required keys is the user's to give
        ):
            if any("default" in _resolve(v, root) for v in sub.get("properties", {}).values()):
                instance[key] = {}
        if key in instance:
            fill_defaults(instance[key], sub, root)
    if isinstance(schema.get("additionalProperties"), dict):
        for key, val in instance.items():
            if key not in props:
                fill_defaults(val, schema["additionalProperties"], root)
    return instance


def validate_config(config: dict, schema: dict, source: str = "config", available: int | None = None) -> dict:
    """Check ``config`` against ``schema``; fill defaults; raise :class:`ConfigError` listing all problems.

    Beyond the schema: names of datasets and scenarios (the whole name, reserved names) and
    counts the machine cannot hold (``available`` bytes of memory; default: what it has now).
    """
    import jsonschema

    bomb = alias_problem(config, source)
    if bomb:
        raise ConfigError(f"{source} is not valid:\n  {bomb}")
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(config), key=lambda e: (list(map(str, e.absolute_path)), e.message))
    lines = [_message(e) for e in errors] + _names(config) + _finite(config) + _render_without_synthetic(config)
    if not lines:
        lines = _synthetic_keys(config) + _offsets(config)
    if not lines:
        fill_defaults(config, schema)
        lines = _studies(config, schema) + _sizes(config, _available_memory() if available is None else available)
    if lines:
        raise ConfigError(f"{source} is not valid:\n  " + "\n  ".join(lines))
    return config


def load_config(path: str | os.PathLike[str] | None = None, schema_path: str | os.PathLike[str] | None = None) -> dict:
    """Return the workflow's config file (default ``config/config.yaml``), validated, with the schema's defaults.

    For callers outside Snakemake (tests, benchmarks, examples) that need the same values
    the workflow uses. Paths default to the repository checkout this package lives in.
    """
    from pathlib import Path

    import yaml

    root = Path(__file__).resolve().parents[3]
    path = Path(path) if path else root / "config" / "config.yaml"
    schema_path = Path(schema_path) if schema_path else root / "workflow" / "schemas" / "config.schema.yaml"
    with open(schema_path) as fh:
        schema = yaml.safe_load(fh)
    with open(path) as fh:
        config = yaml.safe_load(fh)
    return validate_config(config, schema, source=str(path))


#: Where each config block that becomes typed settings lives in the schema (:func:`checked_block`).
SCHEMA_BLOCKS = {
    "render": ("$defs", "dataset", "properties", "render"),
    "tracks": ("$defs", "dataset", "properties", "tracks"),
    "synthetic": ("$defs", "dataset", "properties", "synthetic"),
    "render_camera": ("$defs", "render_camera"),
    "track_camera": ("$defs", "track_camera"),
    "min_frames": ("$defs", "min_frames"),
    "study": ("properties", "studies", "additionalProperties"),
    "stronge": ("properties", "stronge"),
    "normalize": ("properties", "normalize"),
    "analysis": ("properties", "analysis"),
    "implications": ("properties", "implications"),
    "league": ("properties", "league"),
}


def packaged_schema() -> dict:
    """Return the config schema shipped with the package (``data/config.schema.yaml``; a fresh copy)."""
    from pathlib import Path

    import yaml

    path = Path(__file__).resolve().parents[1] / "data" / "config.schema.yaml"
    with open(path) as fh:
        return yaml.load(fh, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))


def block_schema(kind: str, schema: dict | None = None) -> dict:
    """Return the schema of one config block (a key of :data:`SCHEMA_BLOCKS`), with the ``$defs`` it refers to."""
    schema = packaged_schema() if schema is None else schema
    node = schema
    for part in SCHEMA_BLOCKS[kind]:
        node = node[part]
    return {**_resolve(node, schema), "$defs": schema["$defs"]}


def checked_block(block: dict, kind: str, where: str | None = None, schema: dict | None = None) -> dict:
    """Return a copy of one config block, checked against its part of the schema, with the schema's defaults filled.

    For callers that hold one block rather than the whole workflow config (``ballbat check
    --config``, tests, benchmarks): the block then carries every default, as the validated
    config's does, and the settings built from it (``settings_from_config``...) need no
    defaults of their own.

    Raises
    ------
    ConfigError
        Every problem, each naming its key under ``where`` (default: ``kind``).
    """
    import jsonschema

    sub = block_schema(kind, schema)
    out = copy.deepcopy(block)
    where = where or kind
    errors = sorted(
        jsonschema.Draft202012Validator(sub).iter_errors(out),
        key=lambda e: (list(map(str, e.absolute_path)), e.message),
    )
    lines = [f"{where}.{m}" if not m.startswith("<top level>") else where + m[11:] for m in map(_message, errors)]
    lines += _finite(out, where)
    if lines:
        raise ConfigError(f"{where} is not valid:\n  " + "\n  ".join(lines))
    return fill_defaults(out, sub, sub)


def _dataset_balls(dataset: dict) -> set[str] | None:
    """Return the balls a validated dataset has impacts of (None when its file cannot tell: its own job will)."""
    from ..properties import InputError

    if "synthetic" in dataset:
        return {str(b) for b, bats in dataset["synthetic"]["impacts"].items() if any((bats or {}).values())}
    path = dataset["impacts"] if "impacts" in dataset else dataset.get("tracks", {}).get("impacts")
    if path is None:
        return None  # rendered tracks come from a synthetic block (above)
    try:
        if "impacts" in dataset:
            from ..ingest import read_impacts_table

            _, rows = read_impacts_table(path)
        else:
            from ..properties import read_table

            _, rows = read_table(path, ("impact_id", "bat", "ball"), "impact")
    except (InputError, OSError, ValueError):
        return None
    balls = {row.get("ball", "").strip() for _, row in rows}
    return (balls - {""}) or None


def _table_names(path: str, loader) -> set[str] | None:
    """Names of a property table's entries (None when it cannot be read: the jobs that read it say why)."""
    from ..properties import InputError

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
    from ..properties import load_balls, load_bats

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
    from ..properties import load_balls, load_bats

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
