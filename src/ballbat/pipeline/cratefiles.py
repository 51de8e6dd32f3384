"""The files of a results folder as its crate must tell them (:mod:`.crate`, ``tests/validate_crate.py``).

The crate is the folder's truth: it lists every file of ``results/`` (its metadata file and
hidden temporaries aside). A file that is not a result of the run that wrote the crate (a
target-only run leaves the other products of earlier runs; a failed run leaves the outputs of
the jobs it did not finish) is listed too, and says so, with its staleness against its inputs:
Snakemake's record of the job that made it (``.snakemake/metadata``) names those inputs with
their sha256 at the time, which :class:`Staleness` compares with the files now.
:func:`crate_file_problems` checks a crate against its folder: each File listed is there with
its sha256 and size, and each file of the folder is listed.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .provenance import sha256_file

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

#: The crate's metadata file, in the results folder (the crate's root).
METADATA_NAME = "ro-crate-metadata.json"
#: The folder's earlier crate while a run changes the folder (hidden; its actions go into the next crate).
EARLIER_NAME = ".ro-crate-metadata.earlier.json"


def is_results_folder(folder: Path) -> bool:
    """Whether a folder is a results folder of its own (a run's crate, set-aside crate or snapshot is in it)."""
    return any((folder / name).exists() for name in (METADATA_NAME, EARLIER_NAME, "workflow.snapshot"))


def folder_files(results: Path) -> list[str]:
    """Return every file of the results folder, as crate paths (the metadata file and hidden ones aside).

    A results folder inside it (another test session's, e.g. ``results/2026-11-h01`` inside ``results``)
    is that folder's crate's, not this one's: it is left out.
    """
    out = []
    for dirpath, dirnames, filenames in os.walk(results):
        here = Path(dirpath)
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and not is_results_folder(here / d))
        for name in sorted(filenames):
            rel = (here / name).relative_to(results)
            if rel.as_posix() != METADATA_NAME and not name.startswith("."):
                out.append(rel.as_posix())
    return sorted(out)


def _record_value(record: Any, key: str) -> Any:
    try:
        return record[key]
    except (KeyError, TypeError):
        return None


class Staleness:
    """Say whether the files of a folder are stale against the inputs their jobs recorded.

    ``record(path)`` returns Snakemake's metadata of the job that made a workdir-relative ``path``
    (``input``, ``input_checksums``, ``log``, ``rule``), or None. An input is changed when its sha256
    differs from the one recorded (or, with none recorded, when it is newer than the file); a file is
    stale too when an input it was made from is itself stale. A log takes the state of its job's output.
    """

    def __init__(self, workdir: Path, record: Callable[[str], Any], digest: Callable[[Path], str] = sha256_file):
        self.workdir = workdir
        self.record = record
        self.digest = digest
        self._memo: dict[str, str] = {}
        self._owners: dict[str, str] | None = None

    def describe(self, path: str, others: Iterable[str] = ()) -> str:
        """Return the state of ``path`` in words (``others``: the folder's files, to find whose log a file is)."""
        if path not in self._memo:
            self._memo[path] = "checking"  # a cycle reads as not stale
            self._memo[path] = self._describe(path, others)
        return self._memo[path]

    def is_stale(self, path: str) -> bool:
        """Whether ``path`` is stale (:meth:`describe`)."""
        return self.describe(path).startswith("stale")

    def _describe(self, path: str, others: Iterable[str]) -> str:
        rec = self.record(path)
        if rec is None:
            owner = self._log_owner(path, others)
            if owner is None:
                return "no record of the job that made it (.snakemake/metadata), so its staleness is not known"
            state = self.describe(owner)
            return f"{'stale: ' if state.startswith('stale') else ''}the log of the job that made {owner} ({state})"
        inputs = _record_value(rec, "input") or []
        checksums = _record_value(rec, "input_checksums") or {}
        made = (self.workdir / path).stat().st_mtime
        for name in inputs:
            p = self.workdir / name
            if not p.is_file():
                return f"stale: its input {name} is gone"
            recorded = checksums.get(name)
            if recorded is not None and str(recorded).removeprefix("sha256:") != self.digest(p):
                return f"stale: its input {name} has changed since (sha256)"
            if recorded is None and p.stat().st_mtime > made:
                return f"stale: its input {name} is newer"
        for name in inputs:
            if self.record(name) is not None and self.is_stale(name):
                return f"stale: its input {name} is stale"
        rule = _record_value(rec, "rule") or "?"
        return f"made by rule {rule}; up to date with the {len(inputs)} inputs it recorded"

    def _log_owner(self, path: str, others: Iterable[str]) -> str | None:
        if self._owners is None:
            self._owners = {}
            for other in others:
                rec = self.record(other)
                for log in _record_value(rec, "log") or []:
                    self._owners[str(log)] = other
        return self._owners.get(path)


def crate_file_problems(results: str | os.PathLike[str]) -> list[str]:
    """Check a crate against its folder; return one line per problem, each naming the check and the file.

    Checks: every File entity of ``results/ro-crate-metadata.json`` exists, with the sha256 and
    size listed (``listed file missing``, ``sha256 differs``, ``size differs``); every file of the
    folder is listed (``file not listed``).
    """
    results = Path(results)
    meta = results / METADATA_NAME
    if not meta.is_file():
        return [f"crate present: {meta} is missing"]
    try:
        graph = json.loads(meta.read_text(encoding="utf-8"))["@graph"]
    except (ValueError, KeyError, TypeError) as exc:
        return [f"crate readable: {meta}: not a JSON-LD crate ({exc})"]
    problems = []
    listed = set()
    for entity in graph:
        types = entity.get("@type", [])
        if "File" not in (types if isinstance(types, list) else [types]):
            continue
        ident = entity["@id"]
        listed.add(ident)
        problems += _file_problems(results, ident, entity)
    problems += [f"file not listed: {rel} is in the folder but not in the crate" for rel in _unlisted(results, listed)]
    return problems


def _file_problems(results: Path, ident: str, entity: dict) -> list[str]:
    path = results / ident
    if not path.is_file():
        return [f"listed file missing: {ident} is in the crate but not in the folder"]
    problems = []
    if "sha256" in entity and entity["sha256"] != sha256_file(path):
        problems.append(f"sha256 differs: {ident}: the crate says {entity['sha256'][:12]}..., the file has another")
    if "contentSize" in entity and str(entity["contentSize"]) != str(path.stat().st_size):
        problems.append(
            f"size differs: {ident}: the crate says {entity['contentSize']} bytes, the file has {path.stat().st_size}"
        )
    return problems


def _unlisted(results: Path, listed: Iterable[str]) -> list[str]:
    known = set(listed)
    return [rel for rel in folder_files(results) if rel not in known]


def earlier_run_notes(folder: str | os.PathLike[str], names: Iterable[str]) -> list[str]:
    """Return notes on the files ``names`` of a dataset's folder (``results/<dataset>``) that the last run did not make.

    Read from the results folder's crate: no crate where one was written before (a run under way or
    cut short), a last run marked failed, a file the crate lists as not made by that run (with its
    staleness) or not at all, or one changed since. Empty when the crate vouches for every file, or
    when the folder was never described by a crate (a copy of the results).
    """
    folder = Path(folder)
    results = folder.parent
    meta = results / METADATA_NAME
    if not meta.is_file():
        if (results / "workflow.snapshot").is_dir():
            return [f"{meta} is missing: a run is under way or was cut short; these numbers may be an earlier run's"]
        return []
    try:
        graph = {e["@id"]: e for e in json.loads(meta.read_text(encoding="utf-8"))["@graph"]}
    except (ValueError, KeyError, TypeError):
        return [f"{meta} cannot be read: whether these numbers are the last run's is not known"]
    notes = []
    run = graph.get("#run", {})
    if "Failed" in str(run.get("actionStatus", "")):
        notes.append(f"the last run failed: {run.get('error', 'see its log')}")
    for name in names:
        rel = f"{folder.name}/{name}"
        entity = graph.get(rel)
        if entity is None:
            notes.append(f"{rel} is not in the last run's crate (made after it, or put there by hand)")
        elif str(entity.get("description", "")).startswith("not "):
            notes.append(f"{rel}: {entity['description']}")
        elif (results / rel).is_file() and entity.get("sha256") != sha256_file(results / rel):
            notes.append(f"{rel} has changed since the last run's crate was written")
    return notes
