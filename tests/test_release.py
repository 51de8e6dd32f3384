"""The citable release: version, LICENSE, CITATION.cff, CHANGELOG."""

import subprocess
import tomllib

import pytest
import yaml

import ballbat


def test_version_through_the_entry_point(root):
    """`ballbat --version` (the installed command) prints the package version, 0.2.0."""
    out = subprocess.run([str(root / ".venv" / "bin" / "ballbat"), "--version"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"ballbat {ballbat.__version__}"
    assert ballbat.__version__ == "0.2.0"


def test_license_is_the_one_pyproject_names(root):
    """LICENSE holds the MIT licence that pyproject.toml and CITATION.cff declare."""
    project = tomllib.loads((root / "pyproject.toml").read_text())["project"]
    assert project["license"] == "MIT"
    assert (root / "LICENSE").read_text().startswith("MIT License\n")
    assert yaml.safe_load((root / "CITATION.cff").read_text())["license"] == "MIT"


def test_citation_names_version_and_paper(root):
    """CITATION.cff carries the package version and cites the paper (Am. J. Phys. 85, 503 (2017))."""
    cff = yaml.safe_load((root / "CITATION.cff").read_text())
    assert cff["version"] == ballbat.__version__
    paper = cff["references"][0]
    assert [a["family-names"] for a in paper["authors"]] == ["Kensrud", "Nathan", "Smith"]
    assert (paper["journal"], paper["volume"], paper["start"], paper["year"]) == (
        "American Journal of Physics",
        85,
        503,
        2017,
    )


def test_changelog_has_this_version(root):
    """CHANGELOG.md has an entry for the package's version."""
    assert f"## {ballbat.__version__} (" in (root / "CHANGELOG.md").read_text()


@pytest.mark.slow
def test_citation_validates_with_cffconvert(root):
    """`cffconvert --validate` accepts CITATION.cff (cffconvert in its own environment: make test-citation)."""
    out = subprocess.run(["make", "-s", "test-citation"], cwd=root, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "valid" in out.stdout
