"""The model's specification lives in the repository (docs/model.md), and everything points there.

* No file of the checkout cites the specification that used to live outside the repository,
  or a path into the folder beside the checkout it came from: a clone must be complete.
* Every equation label the package, the workflow, the tests and the docs cite ("Eq. angmom",
  "Eqs. rx and ry", "Eq. (vtf)") has its own heading in docs/model.md, of the form "### Eq. angmom — ...".
* Every citation of a section of docs/model.md (``docs/model.md, "Flight"``) names a heading
  that exists, and the page's own links to its headings resolve.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "docs" / "model.md"

# Built from pieces, so that this file does not match what it forbids.
OLD_SPEC = "PHYS" + "ICS.md"
FORBIDDEN = re.compile(re.escape(OLD_SPEC) + r"|\.\./" + "shared" + r"\b|(?<![\w.-])" + "shared" + "/")

#: Folders of a checkout that are not the project's own files (when git cannot list them).
NOT_PROJECT = {".git", ".venv", ".venv-slurm", ".snakemake", "results", "__pycache__", ".pytest_cache", ".ruff_cache"}

#: An equation label, bare or in parentheses: the paper's LaTeX labels are lower case
#: (eq:angmom), except eq:D. Not a label: a word followed by "(" or "=" (a function, a
#: variable: "Eqs. omega and vtf, tan(psi - theta)", "(omega) and theta = psi - ...") and "and".
NAME = r"(?!and\b)(?:D|[a-z][a-z0-9]*)"
LABEL = r"(?:\(" + NAME + r"\)|" + NAME + r")(?!\w|\(|\s*=)"
SINGLE = re.compile(r"\bEq\.\s*\(?(" + NAME + r")\)?(?!\w|\()")
SEPARATOR = r",\s*|\s+and\s+|\s*[\u2013-]\s*"  # comma, "and", a range with an en dash
LIST = re.compile(r"\bEqs\.\s*(" + LABEL + r"(?:(?:" + SEPARATOR + r")" + LABEL + r")*)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*$", re.MULTILINE)
DEFINED = re.compile(r"^Eq\.\s+(D|[a-z][a-z0-9]*)\s")
#: A citation of a section: docs/model.md, "Flight" / [model.md](model.md) ("Flight").
CITATION = re.compile(r"model\.md(?:\]\([^)]*\))?\)?(?:,\s*|\s*\(\s*)\"([^\"]+)\"")


def project_files() -> list[Path]:
    """Return the checkout's files: tracked and new (not ignored); every file when git is absent."""
    try:
        out = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            cwd=ROOT,
            capture_output=True,
            check=True,
        ).stdout
        files = [ROOT / p for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        files = [
            p
            for p in ROOT.rglob("*")
            if p.is_file()
            and not (set(p.relative_to(ROOT).parts) & NOT_PROJECT)
            and not any(part.endswith(".egg-info") for part in p.parts)
        ]
    return [p for p in files if p.is_file()]


def text_files(suffixes: tuple[str, ...] | None = None) -> dict[Path, str]:
    """Return the project's text files (UTF-8), optionally only those with the given suffixes."""
    out = {}
    for p in project_files():
        if suffixes is not None and p.suffix not in suffixes and p.name not in suffixes:
            continue
        try:
            out[p] = p.read_text(encoding="utf-8")
        except UnicodeDecodeError:  # figures, workbooks
            continue
    return out


def labels_cited(text: str) -> set[str]:
    """Return the equation labels a text cites ("Eq. angmom", "Eqs. rx and ry", "Eqs. (D), (vxf)")."""
    found = {m.group(1) for m in SINGLE.finditer(text)}
    for m in LIST.finditer(text):
        found |= {item.strip("()") for item in re.split(SEPARATOR, m.group(1))}
    return found


def headings() -> list[str]:
    """Return the headings of docs/model.md, without their '#' marks."""
    return HEADING.findall(MODEL.read_text(encoding="utf-8"))


def labels_defined() -> set[str]:
    """Return the labels that have a heading of their own in docs/model.md, as "### Eq. angmom — ..."."""
    return {m.group(1) for h in headings() if (m := DEFINED.match(h))}


def slug(heading: str) -> str:
    """Return GitHub's anchor of a heading (lower case, punctuation dropped, spaces to hyphens)."""
    return re.sub(r"[^\w\- ]", "", heading.lower()).replace(" ", "-")


def test_no_file_cites_a_spec_outside_the_repository():
    files = text_files()
    assert ROOT / "README.md" in files and len(files) > 50, "the project's files were not found"
    hits = [
        f"{p.relative_to(ROOT)}:{n}: {line.strip()}"
        for p, text in files.items()
        for n, line in enumerate(text.splitlines(), start=1)
        if FORBIDDEN.search(line)
    ]
    assert not hits, "cite docs/model.md instead:\n" + "\n".join(hits)


@pytest.mark.parametrize(
    ("line", "bad"),
    [
        (f"Conventions ({OLD_SPEC}): n-hat points ...", True),
        ("see ../" + "shared" + "/paper for the figures", True),
        ("facts from /work/" + "shared" + "/SLURM.md", True),
        ("a systematic shared by every impact of a camera", False),
        ("Conventions (docs/model.md, 'Conventions')", False),
    ],
    ids=["old-spec", "relative-path", "absolute-path", "the-word", "model-md"],
)
def test_forbidden_pattern(line, bad):
    assert bool(FORBIDDEN.search(line)) is bad


@pytest.mark.parametrize(
    ("text", "labels"),
    [
        ("psi reconstructed from Eq. angmom", {"angmom"}),
        ("recoil factors (Eqs. rx and ry); 0 for", {"rx", "ry"}),
        ("exactly Eqs. (vballn), (omega) and (vxf) of Kensrud", {"vballn", "omega", "vxf"}),
        ("Eqs. (angmom)\u2013(vtf), Eq. (ratio), Sec. V.B", {"angmom", "vtf", "ratio"}),
        ("| Eqs. ex, muk, ratio, Figs. 3\u20136 |", {"ex", "muk", "ratio"}),
        ("the bracket terms of Eqs. omega and vtf, tan(psi - theta)", {"omega", "vtf"}),
        ("bound the exit speed (Eqs. vballn, vxf with 0 <= e_y <= 1", {"vballn", "vxf"}),
        ("D = (r + R) sin psi (Eq. D) and Eq. 8 of another paper", {"D"}),
    ],
)
def test_labels_cited(text, labels):
    assert labels_cited(text) == labels


def test_every_cited_equation_label_has_a_heading_in_model_md():
    files = text_files((".py", ".smk", ".md", ".yaml", ".rst", "Snakefile"))
    cited: dict[str, set[str]] = {}
    for p, text in files.items():
        for label in labels_cited(text):
            cited.setdefault(label, set()).add(str(p.relative_to(ROOT)))
    # the package cites the paper's central equations; finding none means the scan is broken
    assert {"angmom", "omega", "vtf", "ratio", "rx", "ry"} <= set(cited)
    defined = labels_defined()
    missing = {label: sorted(where)[:3] for label, where in cited.items() if label not in defined}
    assert not missing, f"labels cited but without a heading 'Eq. <label>' in docs/model.md: {missing}"


def test_model_md_defines_every_equation_of_the_paper_the_package_implements():
    # the paper's labels, in its order (printed equations 1-13)
    paper = ["angmom", "iball", "D", "vballn", "ry", "vballt", "rx", "omega", "vxf", "vtf", "ex", "muk", "ratio"]
    assert labels_defined() == set(paper)


def test_citations_of_model_md_sections_name_existing_headings():
    names = headings()
    cited = {}
    for p, text in text_files((".py", ".smk", ".md", ".yaml", ".sh", "Snakefile")).items():
        for m in CITATION.finditer(text):
            cited.setdefault(m.group(1), set()).add(str(p.relative_to(ROOT)))
    assert {"Conventions", "Flight"} <= set(cited), "the citations were not found: the pattern is broken"
    unknown = {c: sorted(w) for c, w in cited.items() if not any(h.startswith(c) for h in names)}
    assert not unknown, f"docs/model.md has no section of these names: {unknown}"


def test_model_md_links_to_its_own_headings_resolve():
    text = MODEL.read_text(encoding="utf-8")
    anchors = {slug(h) for h in headings()}
    links = set(re.findall(r"\]\(#([^)]+)\)", text))
    assert links, "docs/model.md has no table of contents"
    assert not links - anchors, f"links to no heading: {sorted(links - anchors)}"
