"""Configs that passed the schema's checks, remembered by content, so that a rerun does not check them again.

Every start of the workflow checks its config against the JSON schema, and each study's sweep
points against their blocks' schemas (:func:`ballbat.pipeline.config.schema_problems`,
:func:`ballbat.config_checks.validate_config`). These checks are pure: their verdict depends
on the config, the schema and the code that checks, nothing else. A no-op rerun spent about
50 ms on them (jsonschema's import 20 ms, the checks the rest) against Snakemake's own 0.55 s
(issue 39: a no-op rerun within 1.2x of Snakemake's).

So a config that passed is remembered under the sha256 of (the config as read, the schema,
and the fingerprint of the checking code: this package's checking modules, byte for byte, and
jsonschema's files' size and modification time); a start whose key is remembered skips those
checks only. What is not pure runs every time: the memory the machine has now, the tables a
study reads, the scenarios' files, and every check that is cheap. Any change of a setting, of
the schema or of the code makes another key, so the checks run again; a config that fails is
never remembered. The record is one empty file per key in ``.snakemake/ballbat/validated``
(the newest :data:`KEEP`); a record that cannot be read or written only costs the checks.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

#: The checking modules whose bytes enter the key (relative to the package).
CHECKING_CODE = ("pipeline/config.py", "config_checks.py", "studies/sweeps.py", "pipeline/validated.py")

#: Keys kept (the newest by modification time); older ones are removed when one is added.
KEEP = 64

#: The record's folder, relative to the workflow's working directory.
FOLDER = Path(".snakemake") / "ballbat" / "validated"


def _code_fingerprint() -> bytes:
    """Return the bytes that stand for the checking code: ours verbatim, jsonschema's files by size and time."""
    import importlib.util

    root = Path(__file__).resolve().parents[1]
    parts = [(root / rel).read_bytes() for rel in CHECKING_CODE]
    spec = importlib.util.find_spec("jsonschema")
    if spec is not None and spec.origin:
        folder = Path(spec.origin).parent
        for name in ("__init__.py", "validators.py", "_keywords.py", "_format.py"):
            try:
                st = (folder / name).stat()
            except OSError:
                continue
            parts.append(f"{folder / name}:{st.st_size}:{st.st_mtime_ns}".encode())
    return b"\0".join(parts)


def config_key(config: dict, schema: dict) -> str | None:
    """Return the sha256 key of ``config`` checked against ``schema`` by this code (None: cannot be formed)."""
    try:
        text = json.dumps([config, schema], sort_keys=True, allow_nan=True, default=repr)
        return hashlib.sha256(text.encode() + b"\0" + _code_fingerprint()).hexdigest()
    except (TypeError, ValueError, OSError, RecursionError):
        return None


def seen(key: str | None, folder: Path = FOLDER) -> bool:
    """Whether ``key`` is remembered as a config that passed."""
    return key is not None and (folder / key).is_file()


def remember(key: str | None, folder: Path = FOLDER) -> None:
    """Remember ``key`` as a config that passed (atomically; the oldest beyond :data:`KEEP` removed)."""
    if key is None:
        return
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{key}.{os.getpid()}.tmp"
        tmp.write_bytes(b"")
        os.replace(tmp, folder / key)
        kept = sorted((p for p in folder.iterdir() if not p.name.startswith(".")), key=lambda p: p.stat().st_mtime_ns)
        for old in kept[:-KEEP]:
            old.unlink(missing_ok=True)
    except OSError:
        return  # no record: the next start checks again


def load_schema(path: str | os.PathLike[str], folder: Path = FOLDER.parent) -> dict:
    """Return the YAML schema at ``path``, from its JSON copy in ``folder`` where one of the same bytes is kept.

    libyaml reads the 33 kB schema in about 5 ms, JSON its copy in 0.2; the copy is named by the
    sha256 of the YAML's bytes (a changed schema is read from YAML again and copied anew).
    """
    import yaml

    raw = Path(path).read_bytes()
    copy = folder / f"schema-{hashlib.sha256(raw).hexdigest()}.json"
    try:
        return json.loads(copy.read_text())
    except (OSError, ValueError):
        pass
    schema = yaml.load(raw, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    try:
        folder.mkdir(parents=True, exist_ok=True)
        for old in folder.glob("schema-*.json"):
            old.unlink(missing_ok=True)
        tmp = folder / f".{copy.name}.{os.getpid()}.tmp"
        tmp.write_text(json.dumps(schema))
        os.replace(tmp, copy)
    except (OSError, TypeError, ValueError):
        pass
    return schema
