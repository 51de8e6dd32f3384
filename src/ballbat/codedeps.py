"""Which package modules a workflow script depends on (so results never outlive code).

Snakemake reruns a job when its script changes, but not when a module the script imports
changes. The workflow therefore lists, as inputs of every rule, the source files of the
ballbat modules its script imports, directly or through other ballbat modules. Editing
one of them makes exactly the dependent outputs out of date; an unrelated edit (README,
another module) does not. Standard library only: this runs when the Snakefile is parsed.
"""

from __future__ import annotations

import ast
from functools import cache
from pathlib import Path

PACKAGE = "ballbat"
PACKAGE_DIR = Path(__file__).resolve().parent


def _imports(path: Path, module: str | None) -> set[str]:
    """ballbat submodule names imported anywhere in ``path`` (``module`` is its own name)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == PACKAGE or alias.name.startswith(PACKAGE + "."):
                    found.add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:  # relative import inside the package
                base = PACKAGE if module is None else module.rsplit(".", node.level)[0]
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            if target == PACKAGE or target.startswith(PACKAGE + "."):
                found.add(target)
                for alias in node.names:  # from ballbat import kinematics
                    cand = f"{target}.{alias.name}"
                    if _module_file(cand) is not None:
                        found.add(cand)
    return found


def _module_file(name: str) -> Path | None:
    parts = name.split(".")[1:]
    if not parts:
        return PACKAGE_DIR / "__init__.py"
    p = PACKAGE_DIR.joinpath(*parts)
    if p.with_suffix(".py").is_file():
        return p.with_suffix(".py")
    if (p / "__init__.py").is_file():
        return p / "__init__.py"
    return None


@cache
def module_files(script: str) -> tuple[str, ...]:
    """Source files of every ballbat module ``script`` imports, transitively (sorted)."""
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
    return tuple(sorted(str(p) for p in seen.values()))
