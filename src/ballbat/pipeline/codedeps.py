"""Which package modules a workflow script depends on (so results never outlive code).

Snakemake reruns a job when its script changes, but not when a module the script imports
changes. The workflow therefore lists, as inputs of every rule, the source files of the
ballbat modules its script imports, directly or through other ballbat modules. Editing
one of them makes exactly the dependent outputs out of date; an unrelated edit (README,
another module) does not. Standard library only: this runs when the Snakefile is parsed.

Each file's imports are read from its text once per modification; the workflow keeps what it
read in a record (:func:`use_record`, :func:`save_record`: ``.snakemake/ballbat/codedeps.json``),
so that a start reads again only the files changed since (by modification time and size) and
not the package's 1.4 MB (about 8 ms of every no-op rerun). The record also carries this
module's own sha256: a change of how imports are read discards it.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from functools import cache
from pathlib import Path

PACKAGE = "ballbat"
PACKAGE_DIR = Path(__file__).resolve().parent.parent  # src/ballbat


#: An import statement at the start of a line. The line's start is its newline (the text is read
#: with one put before it), not ``^`` with re.MULTILINE: a pattern that starts with a character is
#: searched for that character, not tried at every position (the package's 1.4 MB: 6.4 -> 2.7 ms,
#: part of every start of the workflow). No match ends with a newline, so none hides the next.
_IMPORT = re.compile(
    r"\n[ \t]*(?:from[ \t]+(?P<from>\.+[\w.]*|[\w.]+)[ \t]+import[ \t]+(?P<names>\([^)]*\)|[^\n#]+)"
    r"|import[ \t]+(?P<mods>[^\n#]+))",
)


@cache
def _imports_cached(path: str, mtime_ns: int, module: str | None) -> frozenset[str]:
    found: set[str] = set()
    for m in _IMPORT.finditer("\n" + Path(path).read_text()):
        if m.group("mods"):
            for part in m.group("mods").split(","):
                name = part.split(" as ")[0].strip()
                if name == PACKAGE or name.startswith(PACKAGE + "."):
                    found.add(name)
            continue
        target = m.group("from")
        if target.startswith("."):  # relative import inside the package
            level = len(target) - len(target.lstrip("."))
            base = PACKAGE if module is None else module.rsplit(".", level)[0]
            rest = target[level:]
            target = f"{base}.{rest}" if rest else base
        if target == PACKAGE or target.startswith(PACKAGE + "."):
            found.add(target)
            for part in m.group("names").strip("()").split(","):
                name = part.split(" as ")[0].strip()
                cand = f"{target}.{name}"
                if name and _module_file(cand) is not None:  # from ballbat import kinematics
                    found.add(cand)
    return frozenset(found)


def _imports(path: Path, module: str | None) -> set[str]:
    """Ballbat submodule names imported anywhere in ``path`` (``module`` is its own name).

    Reads import statements with a regular expression (this runs every time Snakemake parses
    the workflow, where a full parse of every module would cost a noticeable fraction of a
    no-op run); results are cached per file and modification time, and kept in the record
    (:func:`use_record`) with the file's size.
    """
    st = path.stat()
    key = f"{path}|{module}"
    hit = _RECORD["files"].get(key)
    if hit is not None and hit[0] == st.st_mtime_ns and hit[1] == st.st_size:
        return set(hit[2])
    found = _imports_cached(str(path), st.st_mtime_ns, module)
    _RECORD["files"][key] = [st.st_mtime_ns, st.st_size, sorted(found)]
    _RECORD["changed"] = True
    return set(found)


#: The imports read so far and at earlier starts (:func:`use_record`): file|module -> [mtime_ns, size, imports].
_RECORD: dict = {"path": None, "files": {}, "changed": False}


def _own_hash() -> str:
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


def use_record(path: str | os.PathLike[str]) -> None:
    """Take the imports read at earlier starts from the record ``path`` (JSON; missing, damaged or stale: none)."""
    _RECORD["path"] = Path(path)
    try:
        data = json.loads(Path(path).read_text())
        files = data["files"] if data.get("code") == _own_hash() else {}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        files = {}
    _RECORD["files"] = {**files, **_RECORD["files"]} if isinstance(files, dict) else dict(_RECORD["files"])


def save_record() -> None:
    """Write the record (:func:`use_record`'s path) where a file was read anew (atomic; a failure costs time only)."""
    path = _RECORD["path"]
    if path is None or not _RECORD["changed"]:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"code": _own_hash(), "files": _RECORD["files"]}))
        os.replace(tmp, path)
        _RECORD["changed"] = False
    except OSError:
        return


def _module_file(name: str) -> Path | None:
    """Return the source file of the ballbat module ``name`` (a module ``x.py`` before a package ``x/``), or None."""
    return _package_files().get(name)


@cache
def _package_files() -> dict[str, Path]:
    """Every module of the package by dotted name: one walk of its folder (not two stats per name asked)."""
    files: dict[str, Path] = {}
    for init in sorted(PACKAGE_DIR.rglob("__init__.py")):
        rel = init.parent.relative_to(PACKAGE_DIR).parts
        files[".".join((PACKAGE, *rel))] = init
    for src in sorted(PACKAGE_DIR.rglob("*.py")):
        if src.name != "__init__.py":
            files[".".join((PACKAGE, *src.relative_to(PACKAGE_DIR).with_suffix("").parts))] = src
    return files


@cache
def _modules(script: str) -> dict[str, Path]:
    """Every ballbat module ``script`` imports, transitively: name -> source file."""
    todo = sorted(_imports(Path(script), None))
    seen: dict[str, Path] = {PACKAGE: PACKAGE_DIR / "__init__.py"}
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        f = _module_file(name)
        if f is None:
            continue
        seen[name] = f
        todo += sorted(_imports(f, name if f.name != "__init__.py" else name + "._"))
    return seen


def module_files(script: str) -> tuple[str, ...]:
    """Source files of every ballbat module ``script`` imports, transitively (sorted)."""
    return tuple(sorted(str(p) for p in _modules(script).values()))


def module_names(script: str) -> tuple[str, ...]:
    """Dotted names of every ballbat module ``script`` imports, transitively (sorted)."""
    return tuple(sorted(_modules(script)))
