"""Snakemake's params records without pandas (ballbat.pipeline.params_record): the same records, the same reruns."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from snakemake.persistence import PersistenceBase

from ballbat.pipeline.params_record import serialize_params_lazily, serializer

SRC = Path(__file__).resolve().parents[2] / "src"

#: Values a rule's params may hold: builtin ones (the workflow's), numpy's, and pandas objects.
VALUES = [
    None,
    1,
    1.5,
    True,
    "x",
    b"x",
    complex(1, 2),
    range(3),
    [1, 2.0, "a"],
    (1, (2, 3)),
    {"a": {"b": [1, 2]}, "c": None},
    {1, 2},
    frozenset({"a"}),
    np.float64(0.5),
    np.array([1.0, 2.0]),
    object(),
    pd.DataFrame({"a": [1, 2]}),
    pd.Series([1.0, 2.0]),
    pd.Index(["a", "b"]),
]


class _Persistence:
    """Just the serializers of Snakemake's persistence (its __init__ needs a DAG)."""

    _serialize_param_pandas = PersistenceBase._serialize_param_pandas
    _serialize_param_builtin = PersistenceBase._serialize_param_builtin


def test_the_records_are_those_of_snakemake_s_own_serializer():
    """Every value's record is the pandas serializer's (Snakemake's choice where pandas is installed)."""
    p = _Persistence()
    assert "pandas" in sys.modules
    for value in VALUES:
        assert serializer(p)(value) == p._serialize_param_pandas(value)
    # before pandas is imported the builtin serializer is used: for every value that is not a
    # pandas object (the only ones that can exist then) it answers as the pandas one does
    for value in VALUES:
        if not isinstance(value, pd.DataFrame | pd.Series | pd.Index):
            assert p._serialize_param_builtin(value) == p._serialize_param_pandas(value)


def test_snakemake_s_persistence_is_the_one_known():
    """The pinned Snakemake's persistence has the serializers this module chooses between, and takes the choice."""
    assert serialize_params_lazily()
    assert PersistenceBase.__dict__["_serialize_param"].fget is serializer
    assert serialize_params_lazily()  # a second read of the workflow in one process


SNAKEFILE = """
import sys
from ballbat.pipeline.params_record import serialize_params_lazily

serialize_params_lazily()


rule a:
    output:
        "a.txt",
    params:
        x=config["xx"],
        d={"k": [1, 2.5]},
    shell:
        "echo {params.x} > {output}"


onsuccess:
    print("pandas imported:", "pandas" in sys.modules)
"""


def _snakemake(wd: Path, *args: str) -> str:
    """Run ``python -m snakemake`` as a fresh interpreter (the suite's fork server has pandas loaded)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(SRC), os.environ.get("PYTHONPATH")) if p)}
    proc = subprocess.run(
        [sys.executable, "-m", "snakemake", "-c1", *args], cwd=wd, env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout + proc.stderr


@pytest.mark.slow
def test_a_changed_param_reruns_its_rule_without_pandas(tmp_path):
    """A run without pandas records the params; the same params are nothing to do, a changed one reruns."""
    (tmp_path / "Snakefile").write_text(SNAKEFILE)
    assert "pandas imported: False" in _snakemake(tmp_path, "--config", "xx=1")
    assert "Nothing to be done" in _snakemake(tmp_path, "--config", "xx=1")
    out = _snakemake(tmp_path, "-n", "--config", "xx=2")
    assert "params" in out.split("reason:")[1].splitlines()[0]
