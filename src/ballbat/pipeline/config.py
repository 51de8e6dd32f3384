"""Validation of the workflow config against its JSON schema, with messages that name keys.

Plumbing only: the schema, its defaults (:func:`fill_defaults`), the names a result folder may
take and a config's size. The rules of the domain (studies, sweeps, memory, scenarios) and the
whole check the workflow runs when it starts (``validate_config``, ``load_config``) are in
:mod:`ballbat.config_checks`. Every problem is reported at once, each with the dotted path of
the offending key (``datasets.synthetic.seed: 'x' is not of type 'integer'``). Missing keys
that the schema gives a ``default`` are filled in.
"""

from __future__ import annotations

import copy
import math
import re
from typing import ClassVar, Self


class SectionSettings:
    """A stage's settings read from one section of the validated config (``SECTION``), as its rule's params.

    Subclasses (frozen dataclasses) define ``from_params(params)``: the section itself, which
    is what the rule passes as params; ``from_config`` is then the same values from the config.
    """

    SECTION: ClassVar[str] = ""

    @classmethod
    def from_config(cls, config: dict) -> Self:
        """Return the workflow's settings from the validated config (its section ``SECTION``)."""
        return cls.from_params(config[cls.SECTION])


class ConfigError(ValueError):
    """The config does not match the schema."""


#: Names the workflow uses for folders and files of its own under ``results/`` (and ``all``,
#: the default rule): a dataset may not take them, nor, in ``results/implications/``, a scenario.
RESERVED_DATASET_NAMES = ("all", "benchmarks", "figures", "implications", "logs", "report", "studies", "tracks")
RESERVED_SCENARIO_NAMES = ("benchmarks", "figures", "logs", "paper_comparison", "results")

#: What a dataset or scenario may be called: letters, digits, _ and - (a folder and file name).
NAME = re.compile(r"[A-Za-z0-9_-]+")


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


def schema_problems(config: dict, schema: dict, source: str = "config") -> list[str]:
    """Return every problem of ``config`` against ``schema``, its names and its numbers that are not finite.

    Raises :class:`ConfigError` at once for a config too large or deep once its YAML aliases are
    expanded (:func:`alias_problem`): no other check could finish on it.
    """
    import jsonschema

    bomb = alias_problem(config, source)
    if bomb:
        raise ConfigError(f"{source} is not valid:\n  {bomb}")
    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(config), key=lambda e: (list(map(str, e.absolute_path)), e.message))
    return [_message(e) for e in errors] + _names(config) + _finite(config)


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
