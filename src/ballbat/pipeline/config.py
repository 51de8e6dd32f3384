"""Validation of the workflow config against its JSON schema, with messages that name keys.

Used by ``workflow/rules/common.smk`` when the workflow starts. Every problem is reported
at once, each with the dotted path of the offending key (``datasets.synthetic.seed: 'x'
is not of type 'integer'``). Missing keys that the schema gives a ``default`` are filled in.
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import os


class ConfigError(ValueError):
    """The config does not match the schema."""


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
        inner = sorted({_message(e) for e in error.context})
        return f"{_path(error)}: matches none of the allowed forms: " + " | ".join(inner)
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
    for key, sub in props.items():
        sub = _resolve(sub, root)
        if key not in instance and "default" in sub:
            instance[key] = copy.deepcopy(sub["default"])
        elif key not in instance and sub.get("type") == "object" and key not in schema.get("required", ()):
            if any("default" in _resolve(v, root) for v in sub.get("properties", {}).values()):
                instance[key] = {}
        if key in instance:
            fill_defaults(instance[key], sub, root)
    if isinstance(schema.get("additionalProperties"), dict):
        for key, val in instance.items():
            if key not in props:
                fill_defaults(val, schema["additionalProperties"], root)
    return instance


def validate_config(config: dict, schema: dict, source: str = "config") -> dict:
    """Check ``config`` against ``schema``; fill defaults; raise :class:`ConfigError` listing all problems."""
    import jsonschema

    validator = jsonschema.Draft202012Validator(schema)
    errors = sorted(validator.iter_errors(config), key=lambda e: (list(map(str, e.absolute_path)), e.message))
    if errors:
        lines = [_message(e) for e in errors]
        raise ConfigError(f"{source} is not valid:\n  " + "\n  ".join(lines))
    fill_defaults(config, schema)
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
