"""Provenance: what produced a results file (inputs, config, code, software).

Every NetCDF file the workflow writes carries these records as JSON-string attributes
(NetCDF attributes cannot hold dicts, bools or None). Nothing here reads the clock:
the same inputs, config and code give byte-identical files.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import platform
import subprocess
from functools import lru_cache
from importlib import metadata
from pathlib import Path
from typing import TYPE_CHECKING

from .. import __version__

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping

#: Distributions whose versions every file records.
STACK = ("numpy", "scipy", "xarray", "netCDF4", "lmfit", "matplotlib", "snakemake")

PACKAGE_DIR = Path(__file__).resolve().parent.parent  # src/ballbat
#: What of a workflow checkout is the workflow's own source (beside the package).
WORKFLOW_PARTS = ("Snakefile", "workflow")


def sha256_file(path: str | os.PathLike[str], chunk: int = 1 << 20) -> str:
    """Hex sha256 of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        while block := fh.read(chunk):
            h.update(block)
    return h.hexdigest()


def package_sources(package_dir: Path = PACKAGE_DIR) -> list[Path]:
    """Return the package's Python source files, sorted."""
    return sorted(p for p in package_dir.rglob("*.py") if "__pycache__" not in p.parts)


@lru_cache(maxsize=1)
def package_source_hash() -> str:
    """sha256 over the package's source files (relative path and bytes of each)."""
    h = hashlib.sha256()
    for p in package_sources():
        h.update(str(p.relative_to(PACKAGE_DIR)).encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def workflow_root() -> Path | None:
    """Return the directory holding ``Snakefile`` and ``workflow/``.

    That is the working directory of a workflow job, else the checkout the package was installed
    from; ``None`` if neither has them.
    """
    for where in (Path.cwd(), PACKAGE_DIR.parent.parent):
        if (where / "Snakefile").is_file() and (where / "workflow" / "rules").is_dir():
            return where.resolve()
    return None


def workflow_sources(root: Path) -> list[Path]:
    """Return the workflow's own files under ``root`` (Snakefile, rules, scripts, schemas, envs, report), sorted."""
    files = [root / "Snakefile"]
    files += [p for p in (root / "workflow").rglob("*") if p.is_file() and "__pycache__" not in p.parts]
    return sorted(files)


@lru_cache(maxsize=4)
def workflow_source_hash(root: str | None = None) -> str:
    """sha256 over the workflow's own files (relative path and bytes of each), like the package's.

    ``"unknown"`` when no workflow checkout is found (ballbat used as a library).
    """
    top = Path(root) if root else workflow_root()
    if top is None:
        return "unknown"
    h = hashlib.sha256()
    for p in workflow_sources(top):
        h.update(p.relative_to(top).as_posix().encode())
        h.update(b"\0")
        h.update(p.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def git_blob_id(path: str | os.PathLike[str]) -> str:
    """Return the id git gives a file's content (``git hash-object``): sha1 of "blob <size>", a zero byte, the bytes."""
    data = Path(path).read_bytes()
    return hashlib.sha1(b"blob %d\0" % len(data) + data, usedforsecurity=False).hexdigest()


def workflow_matches_commit(root: Path, repo: str, commit: str) -> bool:
    """Whether the workflow's own files under ``root`` (:func:`workflow_sources`) are those of ``commit``.

    ``root`` need not be the git checkout ``repo``: a copied checkout's workflow is compared with the
    commit's, file by file (the same paths, each with the commit's content; a file added, removed or
    edited differs). False when git cannot list the commit's files.
    """
    try:
        top = Path(_git(["rev-parse", "--show-toplevel"], repo).strip())
        base = Path(repo).resolve()
        while base != top and not (base / "Snakefile").is_file() and base.parent != base:
            base = base.parent  # the checkout's workflow: where its Snakefile is, at or above ``repo``
        prefix = base.relative_to(top).as_posix()
        parts = [p if prefix == "." else f"{prefix}/{p}" for p in WORKFLOW_PARTS]
        out = _git(["ls-tree", "-r", "-z", "--full-tree", commit, "--", *parts], str(top))
    except (OSError, ValueError, subprocess.SubprocessError):
        return False
    blobs = {}
    for entry in filter(None, out.split("\0")):
        meta, _, name = entry.partition("\t")
        blobs[name if prefix == "." else name.removeprefix(f"{prefix}/")] = meta.split()[-1]
    files = {p.relative_to(root).as_posix(): p for p in workflow_sources(root)}
    return set(files) == set(blobs) and all(git_blob_id(files[k]) == v for k, v in blobs.items())


def _git(args: list[str], cwd: str) -> str:
    """Return the output of ``git ARGS`` run in ``cwd`` (raises on failure)."""
    out = subprocess.run(["git", *args], cwd=cwd, capture_output=True, timeout=10, check=True).stdout
    return out.decode("utf-8", "surrogateescape")


def git_state(where: str | None = None) -> dict:
    """Commit and dirtiness of the git checkout holding ``where`` (default: the package).

    ``dirty`` is true when git has uncommitted changes there, and also when the workflow that runs
    (:func:`workflow_root`: the working directory's, which may be a copy outside the checkout) is not
    the commit's (:func:`workflow_matches_commit`): the recorded commit alone would not reproduce it.
    """
    root = workflow_root()
    return _git_state(str(where or PACKAGE_DIR), str(root) if root else None)


@lru_cache(maxsize=4)
def _git_state(cwd: str, root: str | None) -> dict:
    try:
        commit = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=cwd, capture_output=True, text=True, timeout=10, check=True
        ).stdout.strip()
        status = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout
    except (OSError, subprocess.SubprocessError):
        return {"commit": "unknown", "dirty": "unknown"}
    dirty = bool(status.strip()) or (root is not None and not workflow_matches_commit(Path(root), cwd, commit))
    return {"commit": commit, "dirty": dirty}


@lru_cache(maxsize=8)
def commit_time(commit: str, where: str | None = None) -> datetime.datetime | None:
    """Return the committer date of ``commit`` (naive UTC), or ``None`` when git does not know it."""
    if not commit or commit == "unknown":
        return None
    try:
        out = subprocess.run(
            ["git", "show", "-s", "--format=%ct", commit],
            cwd=str(where or PACKAGE_DIR),
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    if not out.isdigit():
        return None
    return datetime.datetime.fromtimestamp(int(out), tz=datetime.UTC).replace(tzinfo=None)


def software_versions() -> dict:
    """Versions of ballbat, Python and the scientific stack (read from metadata, no imports)."""
    out = {
        "ballbat": __version__,
        "ballbat_source_sha256": package_source_hash(),
        "workflow_source_sha256": workflow_source_hash(),
        "python": platform.python_version(),
    }
    for dist in STACK:
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def _jsonable(obj):
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, Path):
        return str(obj)
    if hasattr(obj, "item") and callable(obj.item):  # numpy scalars
        return obj.item()
    return obj


def dumps(obj: object) -> str:
    """Canonical JSON (sorted keys) of a provenance record."""
    return json.dumps(_jsonable(obj), sort_keys=True, separators=(",", ": "))


def provenance_attrs(
    rule: str, inputs: dict | list, config: dict, workdir: str | os.PathLike[str] | None = None
) -> dict:
    """NetCDF global attributes recording what produced a file.

    Parameters
    ----------
    rule : name of the workflow rule (or function) that wrote the file.
    inputs : input files (a list, or a mapping name -> path or list of paths); each is
        recorded with its sha256 (a folder: each file in it).
    config : the config values the rule used.
    workdir : where to look for the git checkout (default: the package's own).
    """
    if isinstance(inputs, dict):
        items = []
        for name, val in inputs.items():
            vals = [val] if isinstance(val, str | Path) else list(val)
            items += [(name, v) for v in vals]
    else:
        items = [(None, v) for v in inputs]
    # a folder input (a directory() output, such as a dataset's clips): each of its files
    items = [(n, f) for n, v in items for f in (sorted(_files_in(v)) if Path(v).is_dir() else [v])]
    files = [{"name": name, "path": str(path), "sha256": sha256_file(path)} for name, path in items]
    git = git_state(str(workdir) if workdir else None)
    return {
        "provenance_rule": rule,
        "provenance_inputs": dumps(files),
        "provenance_config": dumps(config),
        "provenance_software": dumps(software_versions()),
        "provenance_git": dumps(git),
    }


def _files_in(folder: str | os.PathLike[str]) -> list[str]:
    """Every file under ``folder`` (its subfolders too), as paths."""
    return [str(p) for p in Path(folder).rglob("*") if p.is_file()]


def data_inputs(named_input: Mapping[str, object]) -> dict:
    """Return a Snakemake job's named inputs without the code files (recorded by the source hash)."""
    return {k: v for k, v in named_input.items() if k != "code"}


def provenance_record(rule: str, inputs: dict | list, config: dict) -> dict:
    """Return the provenance of :func:`provenance_attrs` as one JSON-ready dict (keys without the prefix)."""
    attrs = provenance_attrs(rule, inputs, config)
    return {
        "rule": rule,
        **{k.removeprefix("provenance_"): json.loads(v) for k, v in attrs.items() if k != "provenance_rule"},
    }


def job_provenance(job: object) -> tuple[str, dict, dict]:
    """Return a Snakemake job's (rule, data inputs, params): what the provenance of its products records."""
    return job.rule, data_inputs(job.input), dict(job.params)


def png_text(rule: str, inputs: dict | list, config: dict) -> dict[str, str]:
    """Return a figure's provenance as PNG text chunks (``provenance_*`` keys, JSON values; no time)."""
    return provenance_attrs(rule, inputs, config)


def write_sidecar(
    path: str | os.PathLike[str], products: list[str | os.PathLike[str]], rule: str, inputs: dict | list, config: dict
) -> Path:
    """Write the provenance of text tables (CSV, Markdown) to the JSON file ``path``, atomically.

    The tables stay plain for every reader (a comment line is not CSV); the sidecar names each
    table with its sha256, so that a reader can check the pair belongs together.
    """
    from .atomic import atomic_target

    record = {
        "describes": [{"path": str(p), "sha256": sha256_file(p)} for p in products],
        **provenance_record(rule, inputs, config),
    }
    path = Path(path)
    with atomic_target(path) as tmp:
        tmp.write_text(dumps(record) + "\n")
    return path
