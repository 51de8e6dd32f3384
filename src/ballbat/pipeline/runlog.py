"""Logging for workflow jobs: timestamps go to the job's log file, never into data files."""

from __future__ import annotations

import logging
import time
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import os
    from collections.abc import Iterator


@contextmanager
def logged(log_path: str | os.PathLike[str], rule: str) -> Iterator[logging.Logger]:
    """Log a job's start, end and any exception (with traceback) to ``log_path``."""
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
