"""Snakemake's translation of rule files kept by content (ballbat.pipeline.parsed): the same code, rule count and
line map as Snakemake's own parse, read again only where the file (or the rule count it starts at) changed.
"""

from __future__ import annotations

import shutil

import pytest
import snakemake.api  # noqa: F401 - snakemake.workflow's imports in their order
import snakemake.parser as parser
import snakemake.workflow as workflow
from conftest import ROOT
from snakemake.sourcecache import LocalSourceFile

from ballbat.pipeline import parsed


class _Cache:
    def open(self, source, mode="r"):
        return open(source.get_path_or_uri(secret_free=True), mode)


class _Workflow:
    sourcecache = _Cache()


def _fresh(monkeypatch):
    """A state of the module of its own (no record, nothing wrapped) for the test."""
    monkeypatch.setattr(parsed, "_STATE", {**parsed._STATE, "original": None, "entries": {}, "used": []})


@pytest.fixture
def wrapped(monkeypatch, tmp_path):
    monkeypatch.setattr(workflow, "parse", parser.parse)
    _fresh(monkeypatch)
    assert parsed.keep_parsed(tmp_path / "parsed.json")
    return workflow.parse


def _translate(fn, path, rulecount=0):
    linemap = {}
    code, count = fn(LocalSourceFile(str(path)), _Workflow(), linemap, rulecount=rulecount)
    return code, count, linemap


def test_every_rule_file_translates_as_snakemake_translates_it(wrapped, tmp_path):
    """Each of the workflow's files: recorded, then read back from a new start's record, identical to parse's."""
    files = [ROOT / "Snakefile", *sorted((ROOT / "workflow" / "rules").glob("*.smk"))]
    want = [_translate(parser.parse, f, 7) for f in files]
    assert [_translate(wrapped, f, 7) for f in files] == want  # recorded
    parsed.save_parsed()
    calls = []
    real = parsed._STATE["original"]
    parsed._STATE["original"] = lambda *a, **k: calls.append(1) or real(*a, **k)
    parsed.keep_parsed(tmp_path / "parsed.json")  # a new start reads the record
    assert [_translate(workflow.parse, f, 7) for f in files] == want
    assert calls == []  # none tokenized again


def test_a_changed_file_or_rule_count_is_translated_again(wrapped, tmp_path):
    smk = tmp_path / "rules.smk"
    shutil.copy(ROOT / "workflow" / "rules" / "fit_ex.smk", smk)
    _translate(wrapped, smk)
    n = len(parsed._STATE["entries"])
    assert _translate(wrapped, smk, rulecount=3) == _translate(parser.parse, smk, rulecount=3)
    smk.write_text(smk.read_text() + "\n# one more line\n")
    assert _translate(wrapped, smk) == _translate(parser.parse, smk)
    assert len(parsed._STATE["entries"]) == n + 2


def test_a_damaged_record_is_not_read(tmp_path, monkeypatch):
    monkeypatch.setattr(workflow, "parse", parser.parse)
    _fresh(monkeypatch)
    record = tmp_path / "parsed.json"
    record.write_text('{"format": 1, "snakemake"')
    assert parsed.keep_parsed(record) and parsed._STATE["entries"] == {}


def test_another_layout_of_snakemake_is_left_alone(monkeypatch, tmp_path):
    """Where snakemake.workflow.parse is not snakemake.parser.parse, nothing is wrapped."""
    monkeypatch.setattr(workflow, "parse", lambda *a, **k: None)
    _fresh(monkeypatch)
    assert not parsed.keep_parsed(tmp_path / "parsed.json")
