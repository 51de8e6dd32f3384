"""Configs remembered as passed (ballbat.pipeline.validated): the schema's checks skipped only for the very same
config, schema and code; a failing config never remembered; the schema's JSON copy (issue 39's no-op rerun).
"""

from __future__ import annotations

import copy

import pytest
import yaml
from conftest import ROOT

from ballbat import config_checks
from ballbat.config_checks import validate_config
from ballbat.pipeline import validated
from ballbat.pipeline.config import ConfigError, drop_nulls

SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"


@pytest.fixture
def cfg():
    return drop_nulls(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))


@pytest.fixture
def schema():
    return yaml.safe_load(SCHEMA.read_text())


def _counted(monkeypatch):
    calls = []
    real = config_checks.schema_problems
    monkeypatch.setattr(config_checks, "schema_problems", lambda *a: calls.append(1) or real(*a))
    return calls


def test_a_config_that_passed_skips_the_schema_checks_next_time(cfg, schema, tmp_path, monkeypatch):
    """The second check of the same config skips the schema (the first ran it), with the same filled config."""
    calls = _counted(monkeypatch)
    first = validate_config(copy.deepcopy(cfg), schema, record=tmp_path)
    assert len(calls) == 1 and len(list(tmp_path.iterdir())) == 1
    second = validate_config(copy.deepcopy(cfg), schema, record=tmp_path)
    assert len(calls) == 1 and second == first


def test_any_change_checks_again(cfg, schema, tmp_path, monkeypatch):
    """A changed setting, schema or checking code makes another key: the schema's checks run again."""
    calls = _counted(monkeypatch)
    validate_config(copy.deepcopy(cfg), schema, record=tmp_path)
    changed = copy.deepcopy(cfg)
    changed["normalize"] = {**changed.get("normalize", {}), "v_ref_mph": 71.0}
    validate_config(changed, schema, record=tmp_path)
    other_schema = copy.deepcopy(schema)
    other_schema["description"] = "another schema"
    validate_config(copy.deepcopy(cfg), other_schema, record=tmp_path)
    monkeypatch.setattr(validated, "_code_fingerprint", lambda: b"another version of the code")
    validate_config(copy.deepcopy(cfg), schema, record=tmp_path)
    assert len(calls) == 4


def test_a_failing_config_is_never_remembered(cfg, schema, tmp_path):
    """A config the schema refuses is refused every time, and leaves no record."""
    bad = copy.deepcopy(cfg)
    bad["normalize"] = {"v_ref_mph": "fast"}
    for _ in range(2):
        with pytest.raises(ConfigError, match="v_ref_mph"):
            validate_config(copy.deepcopy(bad), schema, record=tmp_path)
    assert not tmp_path.exists() or not list(tmp_path.iterdir())


def test_the_checks_that_read_the_machine_run_every_time(cfg, schema, tmp_path):
    """A remembered config is still refused where this machine's memory cannot hold it (not a pure check)."""
    validate_config(copy.deepcopy(cfg), schema, record=tmp_path)
    with pytest.raises(ConfigError, match="memory"):
        validate_config(copy.deepcopy(cfg), schema, available=10_000, record=tmp_path)


def test_the_record_keeps_its_newest_keys(tmp_path, monkeypatch):
    monkeypatch.setattr(validated, "KEEP", 3)
    for k in range(5):
        validated.remember(f"{k:064x}", tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"{k:064x}" for k in (2, 3, 4)]


def test_the_schema_s_json_copy_is_the_yaml_s(tmp_path):
    """The copy holds what the YAML holds; a changed YAML is read again (and replaces the copy)."""
    want = yaml.safe_load(SCHEMA.read_text())
    assert validated.load_schema(SCHEMA, tmp_path) == want
    (copy_file,) = tmp_path.glob("schema-*.json")
    assert validated.load_schema(SCHEMA, tmp_path) == want  # from the copy
    edited = tmp_path / "edited.yaml"
    edited.write_text(SCHEMA.read_text() + "\nx-note: edited\n")
    assert validated.load_schema(edited, tmp_path)["x-note"] == "edited"
    assert not copy_file.exists() and len(list(tmp_path.glob("schema-*.json"))) == 1
