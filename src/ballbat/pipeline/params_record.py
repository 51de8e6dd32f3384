"""Snakemake's records of the rules' params, made without importing pandas where no param is a pandas object.

Snakemake (9.x) records the params of every job, and compares them with the record to find
changed params (rerun trigger ``params``). Its serializer is chosen once per run
(``snakemake.persistence.PersistenceBase._serialize_param``): wherever pandas is installed, the
pandas one, which imports pandas to ask whether a value is a DataFrame, Series or Index (their
hash recorded) and otherwise gives the builtin serializer's answer (``repr`` of a builtin value).
That import is about 0.15 s of every start, and more at exit: a fifth of the workflow's no-op
rerun (issue 39), for params that are all builtin values (numbers, strings, dicts of them).

A value can only be a pandas object where pandas is imported, so :func:`serialize_params_lazily`
has the serializer chosen at each use instead: Snakemake's pandas one once pandas is in
``sys.modules``, its builtin one before. Each value's record is the one Snakemake's own choice
gives, so a param that changes triggers a rerun exactly as before, and a record written by one
is read by the other. Where Snakemake's persistence is not as this module knows it (another
version), nothing is changed: the start is just slower.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any


def serializer(persistence: Any) -> Callable[[Any], str | object]:
    """Return the param serializer of ``persistence`` (Snakemake's): its pandas one where pandas is imported."""
    if sys.modules.get("pandas") is not None:
        return persistence._serialize_param_pandas
    return persistence._serialize_param_builtin


def serialize_params_lazily() -> bool:
    """Have Snakemake choose its param serializer at each use (:func:`serializer`); return whether it does.

    Returns False, changing nothing, where ``PersistenceBase`` has no ``_serialize_param``
    property beside its pandas and builtin serializers (a Snakemake this module does not know).
    """
    try:
        from snakemake.persistence import PersistenceBase
    except ImportError:
        return False
    current = PersistenceBase.__dict__.get("_serialize_param")
    if isinstance(current, property) and current.fget is serializer:
        return True  # the workflow read twice in one process (tests, the API)
    known = isinstance(current, property) and all(
        callable(PersistenceBase.__dict__.get(name)) for name in ("_serialize_param_pandas", "_serialize_param_builtin")
    )
    if known:
        PersistenceBase._serialize_param = property(serializer)
    return known
