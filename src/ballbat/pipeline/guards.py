"""Guards of the results folder: nothing deleted behind the user's back, nothing damaged used.

Results are written atomically (:mod:`.atomic`): a finished file is complete, and carries
a record of what wrote it (the ``provenance_rule`` attribute of every NetCDF file, the
checked last line of every CSV table: :mod:`.checked`). A file can still be damaged
afterwards (a full disk, a copy cut short, a hand edit), or a user's own file can sit
where the workflow writes. The guards:

* never delete or write while Snakemake parses the workflow (a dry run, ``--lint``,
  ``--summary`` and every cluster job parse it too). :func:`damaged_products` only reads:
  a damaged product is named, with the command that rebuilds it;
* remove a file only when the workflow wrote it: a job that finds its input damaged
  (:func:`ballbat.pipeline.checked.DamagedFileError`) removes it if, and only if, it
  carries the workflow's provenance record, so that the next run rebuilds it;
* never let a run overwrite a file the workflow did not write: :func:`foreign_outputs`,
  called when a real run starts (``onstart``), names each such file and the run stops;
* remove only the temporaries of dead jobs on this host (:func:`remove_temporaries`): a
  second run in the same folder never removes a live job's temporary file;
* name a folder the run cannot write (:func:`unwritable`), in one line.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from .atomic import hostname, temporary_owner
from .checked import csv_problem, hdf5_problem

if TYPE_CHECKING:
    from collections.abc import Iterable

#: The attribute name every NetCDF file of the workflow carries (:mod:`.provenance`); netCDF
#: writes the global attributes near the start of the file (byte ~10000 in ours).
PROVENANCE_MARK = b"provenance_rule"
MARK_WINDOW = 1 << 16
#: How the workflow's CSV tables begin (paper_comparison.csv, a study's coverage.csv and design.csv;
#: tests/workflow/test_guards.py holds them to the writers' columns): a table written before tables
#: carried their check line is still recognised as the workflow's.
TABLE_HEADERS = ("quantity,ball,bat,paper,", "setting,quantity,ball,bat,", "parameter,setting,ball,bat,")


#: The products guarded by the record of what wrote them, by suffix (:func:`written_by_workflow`): a file
#: of these kinds at an output path that has none is a user's, never replaced nor listed as a job's result.
#: Figures carry a record too (their PNG text), but Snakemake replaces them: a figure is no one's data.
RECORDED_SUFFIXES = (".nc", ".csv", ".xlsx", ".md")


def written_by_workflow(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` carries the workflow's record of having written it.

    NetCDF and PNG: the ``provenance_rule`` attribute or text chunk (looked for in the file's first
    64 KiB, so that a truncated file is still recognised); CSV: the check line at its end
    (:mod:`.checked`) or the header of one of the workflow's tables (:data:`TABLE_HEADERS`); a
    workbook (``.xlsx``): its ``rule`` custom document property; Markdown: its provenance sidecar
    (``<name>.provenance.json`` beside it) lists it with its present sha256.
    """
    path = Path(path)
    if path.suffix == ".xlsx":
        return _workbook_has_record(path)
    if path.suffix == ".md":
        return _sidecar_describes(path)
    with open(path, "rb") as fh:
        if path.suffix == ".csv":
            head = fh.read(256).decode("utf-8", errors="replace")
            fh.seek(max(0, path.stat().st_size - 4096))
            return head.startswith(TABLE_HEADERS) or b"\n# ballbat table: " in b"\n" + fh.read()
        return PROVENANCE_MARK in fh.read(MARK_WINDOW)


def _workbook_has_record(path: Path) -> bool:
    """Whether a workbook has the ``rule`` custom property the workflow's workbooks carry (ballbat.workbook)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as zf:
            info = zf.getinfo("docProps/custom.xml")
            if info.file_size > MARK_WINDOW:
                return False
            return b'name="rule"' in zf.read(info)
    except (zipfile.BadZipFile, KeyError, OSError):
        return False


def _sidecar_describes(path: Path) -> bool:
    """Whether the provenance sidecar beside ``path`` (:func:`.provenance.write_sidecar`) lists it with its sha256."""
    import json

    from .provenance import sha256_file

    sidecar = path.with_name(f"{path.stem}.provenance.json")
    try:
        described = json.loads(sidecar.read_text(encoding="utf-8")).get("describes", [])
        digest = sha256_file(path)
        return any(Path(d["path"]).name == path.name and d["sha256"] == digest for d in described)
    except (OSError, ValueError, TypeError, KeyError, AttributeError):
        return False


def product_problem(path: str | os.PathLike[str]) -> str | None:
    """Why the product ``path`` (NetCDF or CSV) cannot be used, from a quick look; None when none is seen."""
    path = Path(path)
    if path.suffix == ".nc":
        return hdf5_problem(path)
    if path.suffix == ".csv":
        return csv_problem(path)
    return None


def damaged_products(paths: Iterable[str | os.PathLike[str]]) -> list[str]:
    """Return a line for each existing product among ``paths`` that is damaged or not the workflow's.

    Reads only (a few bytes of each NetCDF file, each CSV table whole): safe while Snakemake
    parses the workflow, in a dry run or a cluster job. Nothing is removed.
    """
    lines = []
    for path in sorted({str(p) for p in paths}):
        p = Path(path)
        if p.suffix not in (".nc", ".csv") or not p.is_file():
            continue
        problem = product_problem(p)
        if problem is None:
            continue
        if written_by_workflow(p):
            lines.append(f"{path}: {problem}; rebuild it with: snakemake --forcerun {path}")
        else:
            lines.append(
                f"{path}: {problem}, and not written by this workflow (no provenance record); "
                "it is left alone: move it out of results/"
            )
    return lines


def foreign_outputs(paths: Iterable[str | os.PathLike[str]]) -> list[str]:
    """Return a line for each existing product among ``paths`` that the workflow did not write.

    ``paths`` are the outputs of the jobs a run is about to start: Snakemake would remove each
    before its job runs. A run that finds any stops before that (``onstart``). The kinds checked
    are those that carry a record (:data:`RECORDED_SUFFIXES`).
    """
    return [
        f"{path}: not written by this workflow (no provenance record), and this run would replace it; "
        "nothing was changed: move it out of results/ and run again"
        for path in _not_written(paths, RECORDED_SUFFIXES)
    ]


def users_files(paths: Iterable[str | os.PathLike[str]], kinds: tuple[str, ...] = (".xlsx", ".md")) -> list[str]:
    """Return a line for each file among the products ``paths`` that the workflow did not write (of ``kinds``).

    Reads only (run while Snakemake parses the workflow). Such a file (a user's workbook or notes
    saved at a product's path) is left alone: a run that would replace it stops (:func:`foreign_outputs`),
    and the crate lists it as not the workflow's. NetCDF and CSV products are named by
    :func:`damaged_products` when damaged.
    """
    return [
        f"{path}: not written by this workflow (no provenance record, or changed since it was written); "
        "it is left alone, and is not listed as the workflow's result: move it out of results/"
        for path in _not_written(paths, kinds)
    ]


def _not_written(paths: Iterable[str | os.PathLike[str]], kinds: tuple[str, ...]) -> list[str]:
    """Return the existing files among ``paths`` (sorted, once each) of ``kinds`` that the workflow did not write."""
    return [
        path
        for path in sorted({str(p) for p in paths})
        if Path(path).suffix in kinds and Path(path).is_file() and not written_by_workflow(Path(path))
    ]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's live process
        return True
    return True


def remove_temporaries(results: str | os.PathLike[str], host: str | None = None) -> list[str]:
    """Remove the temporary files of dead jobs on this host under ``results``; return a line for each.

    A temporary file names its owner (:func:`ballbat.pipeline.atomic.temporary_owner`). One
    whose process still lives, or that was made on another host (a cluster's shared folder),
    is left alone: it may belong to a job of another run in the same folder.
    """
    host = host or hostname()
    lines = []
    root = Path(results)
    if not root.is_dir():
        return lines
    for path in sorted(root.rglob(".*")):
        owner = temporary_owner(path.name)
        if owner is None or not path.is_file():
            continue
        pid, where = owner
        if where != host or _alive(pid):
            continue
        size = path.stat().st_size
        try:
            path.unlink()
        except FileNotFoundError:  # its job finished meanwhile
            continue
        lines.append(f"{path}: temporary file of a job that died (pid {pid}, {size} bytes); removed")
    return lines


def unwritable(folder: str | os.PathLike[str]) -> str | None:
    """Return a line naming ``folder`` (or the first existing folder above it) when it cannot be written."""
    p = Path(folder)
    while not p.exists() and p != p.parent:
        p = p.parent
    if p.is_dir() and not os.access(p, os.W_OK | os.X_OK):
        where = Path.cwd() if p == Path(".") else p
        return f"{where}: folder is read-only; the workflow writes its results and Snakemake its records here"
    return None


def unwritable_folders(folders: Iterable[str | os.PathLike[str]]) -> list[str]:
    """:func:`unwritable` of each folder, and of each folder under them (the results of a dataset)."""
    lines = []
    for folder in folders:
        line = unwritable(folder)
        if line:
            lines.append(line)
            continue
        root = Path(folder)
        if root.is_dir():
            for sub in sorted(p for p in root.rglob("*") if p.is_dir()):
                line = unwritable(sub)
                if line:
                    lines.append(line)
    return lines


def warnings_summary(
    results: str | os.PathLike[str], datasets: list[str], others: list[str] | tuple[str, ...] = ()
) -> list[str]:
    """Return the warnings in the job logs of the given results folders, each with its log file."""
    lines = []
    for name in [*datasets, *others]:
        for log in sorted((Path(results) / name / "logs").glob("*.log")):
            for line in log.read_text(errors="replace").splitlines():
                if " WARNING " in line or line.startswith("WARNING"):
                    lines.append(f"{log}: {line.split('WARNING', 1)[1].strip(' :')}")
    return lines


def configfile_targets(configfiles: Iterable[str | os.PathLike[str]], results: str = "results") -> list[str]:
    """Return a line for each ``--configfile`` that is a file of the results folder (a target put after it).

    ``snakemake -c2 --configfile my.yaml results/lab/fit_ex.nc`` reads the target as a second config
    file: Snakemake itself stops when it is missing or not YAML, but a results file it can read (a
    provenance sidecar is JSON) would be merged into the config. A config file inside ``results`` (or
    the default ``results/``) is such a target.
    """
    here = Path.cwd().resolve()
    roots = {Path(results).resolve(), Path("results").resolve()}
    lines = []
    for f in configfiles:
        path = Path(f).resolve()
        if any(path == r or path.is_relative_to(r) for r in roots):
            name = path.relative_to(here).as_posix() if path.is_relative_to(here) else str(f)
            lines.append(
                f"--configfile {name}: a file of the results folder, not a config file; a target goes before "
                f"--configfile (snakemake -c2 {name} --configfile my.yaml): it takes every name after it as a "
                "config file"
            )
    return lines


def results_root(config: dict) -> str:
    """Return the run's results folder (config ``results``, default ``results``), without a trailing slash."""
    return str(config.get("results") or "results").rstrip("/") or "results"
