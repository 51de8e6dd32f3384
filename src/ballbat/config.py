"""Validation of the workflow config against its JSON schema, with messages that name keys.

Used by ``workflow/rules/common.smk`` when the workflow starts. Every problem is reported
at once, each with the dotted path of the offending key (``datasets.synthetic.seed: 'x'
is not of type 'integer'``). Missing keys that the schema gives a ``default`` are filled in.
"""

from __future__ import annotations

import copy


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
    if error.validator in ("oneOf", "anyOf") and error.context:
        inner = sorted({_message(e) for e in error.context})
        return f"{_path(error)}: matches none of the allowed forms: " + " | ".join(inner)
    return f"{_path(error)}: {error.message}"


def fill_defaults(instance, schema):
    """Fill missing keys that have a ``default`` in ``schema`` (recursively, in place)."""
    if not isinstance(instance, dict) or schema.get("type") != "object":
        return instance
    for key, sub in schema.get("properties", {}).items():
        if key not in instance and "default" in sub:
            instance[key] = copy.deepcopy(sub["default"])
        if key in instance:
            fill_defaults(instance[key], sub)
    for sub in schema.get("patternProperties", {}).values():
        for key, val in instance.items():
            if key not in schema.get("properties", {}):
                fill_defaults(val, sub)
    if isinstance(schema.get("additionalProperties"), dict):
        for key, val in instance.items():
            if key not in schema.get("properties", {}):
                fill_defaults(val, schema["additionalProperties"])
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
