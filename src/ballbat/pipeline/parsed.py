"""Snakemake's translation of the workflow's rule files into Python, kept by their content (issue 39's no-op).

Snakemake reads every rule file of the workflow at every start, a no-op rerun and every cluster
job included, and translates it into Python with its tokenizer (``snakemake.parser.parse``):
about 26 ms for our fifteen files, a fifth of what a no-op rerun spends beyond Snakemake's own
no-op of a one-rule workflow (issue 39: within 1.2x of it). The translation is a pure function
of the file's text, its path, the rule count it starts from and the shell command override;
so :func:`keep_parsed` wraps Snakemake's ``parse`` with a record of translations by the sha256
of exactly these (and Snakemake's version), in ``.snakemake/ballbat/parsed.json``; a file whose
key is recorded is not tokenized again: the same code, rule count and line map. A changed file
(one byte), another Snakemake or another override makes another key. :func:`save_parsed`
writes the record (atomically; the entries this start used, then the newest others, at most
:data:`KEEP`).

Where Snakemake's layout is not the one this was written for (``snakemake.workflow.parse`` not
``snakemake.parser.parse``, or a record it cannot read), nothing is wrapped or read, and
Snakemake parses as it always does.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

#: The record's format (a change discards older records).
FORMAT = 1

#: Translations kept in the record at most (those of this start first).
KEEP = 64

_STATE: dict = {"path": None, "original": None, "version": None, "entries": {}, "used": [], "changed": False}


def keep_parsed(record: str | os.PathLike[str]) -> bool:
    """Wrap Snakemake's translation of rule files with the record ``record``; return whether it is wrapped."""
    import snakemake
    import snakemake.parser as parser
    import snakemake.workflow as workflow

    if _STATE["original"] is None:
        if getattr(workflow, "parse", None) is not parser.parse:
            return False
        _STATE["original"] = parser.parse
    _STATE.update(path=Path(record), version=str(snakemake.__version__), used=[], changed=False)
    try:
        data = json.loads(Path(record).read_text())
        ok = data.get("format") == FORMAT and data.get("snakemake") == _STATE["version"]
        _STATE["entries"] = dict(data["entries"]) if ok else {}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        _STATE["entries"] = {}
    workflow.parse = _parse
    return True


def _key(path, text: str, rulecount: int, overwrite_shellcmd) -> str:
    head = repr((FORMAT, _STATE["version"], path.get_path_or_uri(secret_free=True), rulecount, overwrite_shellcmd))
    return hashlib.sha256(head.encode() + b"\0" + text.encode()).hexdigest()


def _parse(path, workflow, linemap, overwrite_shellcmd=None, rulecount=0):
    """Snakemake's ``parse``, or its recorded result for the same text, path, rule count and override."""
    original = _STATE["original"]
    try:
        with workflow.sourcecache.open(path) as fh:
            key = _key(path, fh.read(), rulecount, overwrite_shellcmd)
    except Exception:  # any trouble reading it: Snakemake's own parse says what it is
        return original(path, workflow, linemap, overwrite_shellcmd=overwrite_shellcmd, rulecount=rulecount)
    hit = _STATE["entries"].get(key)
    _STATE["used"].append(key)
    if hit is None:
        code, count = original(path, workflow, linemap, overwrite_shellcmd=overwrite_shellcmd, rulecount=rulecount)
        _STATE["entries"][key] = [code, count, sorted(linemap.items())]
        _STATE["changed"] = True
        return code, count
    from snakemake.parser import Shell

    Shell.overwrite_cmd = overwrite_shellcmd  # what parse sets before it reads the file
    code, count, lines = hit
    linemap.update((int(a), int(b)) for a, b in lines)
    return code, count


def save_parsed() -> None:
    """Write the record where a file was translated anew (this start's entries first; a failure only costs time)."""
    path = _STATE["path"]
    if path is None or not _STATE["changed"]:
        return
    entries = _STATE["entries"]
    order = list(dict.fromkeys(_STATE["used"])) + [k for k in reversed(list(entries)) if k not in _STATE["used"]]
    kept = {k: entries[k] for k in order[:KEEP] if k in entries}
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"format": FORMAT, "snakemake": _STATE["version"], "entries": kept}))
        os.replace(tmp, path)
        _STATE["changed"] = False
    except OSError:
        return
