"""The package's import graph has no cycle (issue 33): every import, at the top or inside a function.

A cycle means two modules each need the other, so neither can be read, tested or moved alone;
it hides behind imports inside functions. The graph is read from the source (ast), so a lazy
import counts as much as one at the top; imports under ``if TYPE_CHECKING:`` do not (they never run).
"""

from __future__ import annotations

import ast
from pathlib import Path

import ballbat

ROOT = Path(ballbat.__file__).parent


def _modules() -> dict[str, Path]:
    out = {}
    for path in ROOT.rglob("*.py"):
        parts = path.relative_to(ROOT.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _runtime_imports(tree: ast.Module):
    """Every Import/ImportFrom node, skipping the bodies of ``if TYPE_CHECKING:`` blocks."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", getattr(node.test, "attr", None)) == "TYPE_CHECKING":
            skip.update(id(n) for child in node.body for n in ast.walk(child))
    return [n for n in ast.walk(tree) if isinstance(n, ast.Import | ast.ImportFrom) and id(n) not in skip]


def _targets(module: str, path: Path, node, modules: dict) -> list[str]:
    if isinstance(node, ast.Import):
        names = [a.name for a in node.names]
    else:
        package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
        base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
        stem = ".".join([*base, node.module] if node.module else base)
        names = [f"{stem}.{a.name}" if f"{stem}.{a.name}" in modules else stem for a in node.names]
    out = []
    for name in names:
        while name not in modules and "." in name:
            name = name.rsplit(".", 1)[0]
        if name in modules and name != module and name != "ballbat":
            out.append(name)
    return out


def import_graph() -> dict[str, set[str]]:
    """Module -> the package's modules it imports at run time."""
    modules = _modules()
    graph = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        graph[name] = {t for node in _runtime_imports(tree) for t in _targets(name, path, node, modules)}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_package_has_no_import_cycle():
    graph = import_graph()
    assert len(graph) > 80 and "ballbat.tracks.verdict" in graph["ballbat.stages.reduce"]  # the graph is read
    assert cycles(graph) == [], "import cycles (cut each along its seam: docs/nomenclature.md)"


def test_a_cycle_is_found():
    """The check can fail: two modules importing each other, or three in a ring, are cycles."""
    assert cycles({"a": {"b"}, "b": {"a"}, "c": set()}) == [["a", "b"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


#: The orchestration above the stages: the chain, the studies and the command line (a package: every module in it).
ORCHESTRATION = (
    "ballbat.chain",
    "ballbat.studies",
    "ballbat.cli",
)

#: Layers that import nothing of the orchestration (issue 33: no upward imports).
BELOW_ORCHESTRATION = ("ballbat.stages", "ballbat.tracks", "ballbat.stronge", "ballbat.pipeline")


def upward_imports(graph: dict[str, set[str]]) -> list[tuple[str, str]]:
    """Every (module, target) where a layer below the orchestration imports it, or the plumbing anything but itself."""
    return sorted(
        (module, target)
        for module, targets in graph.items()
        if module.startswith(BELOW_ORCHESTRATION)
        for target in targets
        if target in ORCHESTRATION
        or target.startswith(tuple(f"{o}." for o in ORCHESTRATION))
        or (module.startswith(PLUMBING) and not target.startswith(PLUMBING))
    )


#: The plumbing (atomic writes, checked files, NetCDF, provenance, the crate, the schema): it
#: knows nothing of the domain, so it imports no module of the package outside itself.
PLUMBING = "ballbat.pipeline"


def test_no_upward_import():
    """The stage layer, the tracks, Stronge's model and the plumbing import no orchestrator; the plumbing no domain."""
    assert upward_imports(import_graph()) == []


def test_an_upward_import_is_found():
    """The check can fail: a stage importing the chain or a study, the plumbing importing any domain module."""
    graph = {
        "ballbat.stages.fit_ex": {"ballbat.chain", "ballbat.fitting"},
        "ballbat.tracks.reduce": {"ballbat.studies.sweeps"},
        "ballbat.pipeline.config": {"ballbat.pipeline.ncio", "ballbat.datasets"},
        "ballbat.studies.truth": {"ballbat.chain", "ballbat.pipeline.products"},
    }
    assert upward_imports(graph) == [
        ("ballbat.pipeline.config", "ballbat.datasets"),
        ("ballbat.stages.fit_ex", "ballbat.chain"),
        ("ballbat.tracks.reduce", "ballbat.studies.sweeps"),
    ]
