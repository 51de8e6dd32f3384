"""Which ballbat modules a file imports (ballbat.pipeline.codedeps), read from its import statements."""

from __future__ import annotations

from ballbat.pipeline.codedeps import _imports

SOURCE = """import ballbat.units
from ballbat import (
    kinematics,
    fitting as fit,
)
x = "from ballbat import collision"  # not at a line's start: not an import
    import ballbat.flight as fl, os
def f():
    from .systematics import shift  # relative to the module's package
# from ballbat import league
from ballbat.stages import fit_ex  # a comment
"""


def test_the_imports_of_every_form_at_a_line_start_are_found(tmp_path):
    path = tmp_path / "m.py"
    path.write_text(SOURCE)
    assert _imports(path, "ballbat.pipeline.m") == {
        "ballbat",
        "ballbat.units",
        "ballbat.kinematics",
        "ballbat.fitting",
        "ballbat.flight",
        "ballbat.pipeline.systematics",
        "ballbat.stages",
        "ballbat.stages.fit_ex",
    }


def test_the_record_spares_reading_a_file_again_and_sees_its_change(tmp_path, monkeypatch):
    """A file read at an earlier start (the record) is not read again; one changed since is (issue 39's no-op)."""
    import os

    from ballbat.pipeline import codedeps

    monkeypatch.setattr(codedeps, "_RECORD", {"path": None, "files": {}, "changed": False})
    path = tmp_path / "m.py"
    path.write_text("import ballbat.units\n")
    record = tmp_path / "codedeps.json"
    codedeps.use_record(record)
    assert _imports(path, None) == {"ballbat.units"}
    codedeps.save_record()
    codedeps._RECORD["files"] = {}
    codedeps.use_record(record)
    reads = []
    monkeypatch.setattr(codedeps, "_imports_cached", lambda *a: reads.append(a) or frozenset())
    assert _imports(path, None) == {"ballbat.units"} and reads == []  # from the record
    path.write_text("import ballbat.flight\n")  # another size
    os.utime(path, ns=(1, 1))
    assert _imports(path, None) == set() and len(reads) == 1  # read again


def test_a_record_of_other_code_is_not_used(tmp_path, monkeypatch):
    import json

    from ballbat.pipeline import codedeps

    monkeypatch.setattr(codedeps, "_RECORD", {"path": None, "files": {}, "changed": False})
    record = tmp_path / "codedeps.json"
    record.write_text(json.dumps({"code": "another", "files": {"x|None": [1, 1, ["ballbat.units"]]}}))
    codedeps.use_record(record)
    assert codedeps._RECORD["files"] == {}
