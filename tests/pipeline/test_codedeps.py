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
