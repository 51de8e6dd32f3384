"""Logging for workflow jobs: timestamps go to the job's log file, never into data files."""

from __future__ import annotations

import logging
import time
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from .checked import DamagedFileError

if TYPE_CHECKING:
    import os
    from collections.abc import Iterator


def _remove_damaged_input(err: DamagedFileError) -> DamagedFileError:
    """Remove the damaged input ``err`` names when the workflow wrote it (so that the next run rebuilds it).

    A file without the workflow's provenance record (a user's), or outside ``results/``, is never removed.
    """
    from .guards import written_by_workflow

    path = Path(err.path)
    try:
        inside = Path("results").resolve() in path.resolve().parents
        ours = inside and path.is_file() and written_by_workflow(path)
    except OSError:
        ours = False
    if not ours:
        return DamagedFileError(path, f"{err.problem}; not written by this workflow, so left alone: move it away")
    try:
        path.unlink()
    except OSError as unlink_err:
        return DamagedFileError(path, f"{err.problem}; could not be removed ({unlink_err.strerror}): delete it")
    return DamagedFileError(path, f"{err.problem}; removed (this workflow wrote it): run again to rebuild it")


@contextmanager
def logged(log_path: str | os.PathLike[str], rule: str) -> Iterator[logging.Logger]:
    """Log a job's start, end and any exception (with traceback) to ``log_path``.

    A job that finds one of its inputs damaged (:class:`~ballbat.pipeline.checked.DamagedFileError`)
    removes it if the workflow wrote it, and fails with one line naming it.
    """
    Path(log_path).parent.mkdir(parents=True, exist_ok=True)
    handler = logging.FileHandler(log_path, mode="w")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger()
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    log = logging.getLogger(f"ballbat.{rule}")
    log.info("rule %s started", rule)
    t0 = time.perf_counter()
    try:
        yield log
    except DamagedFileError as err:
        err = _remove_damaged_input(err)
        log.error("rule %s failed: %s", rule, err)
        raise err from None
    except BaseException:
        log.exception("rule %s failed", rule)
        raise
    else:
        log.info("rule %s finished in %.3f s", rule, time.perf_counter() - t0)
    finally:
        root.removeHandler(handler)
        handler.close()


def log_exclusions(log: logging.Logger, excluded: list[str], n_impacts: int) -> None:
    """Log how many impacts a stage excluded (kept in its file, flagged) and one line per impact."""
    log.info("%d of %d impacts excluded (kept in the file, flagged)", len(excluded), n_impacts)
    for line in excluded:
        log.info("excluded: %s", line)
