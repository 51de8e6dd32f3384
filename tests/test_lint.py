"""Habits enforced, not offered (issue 9): type hints on the public API, the conda file in step
with the lock file. `make lint` runs ruff, snakefmt and `snakemake --lint`; these checks are the
ones no linter does.
"""

import ast
import importlib
import inspect
import pkgutil
from pathlib import Path

import yaml

import ballbat

#: The plotting layer: the only modules of the package that may import matplotlib (issue 20).
PLOTTING_LAYER = {"ballbat.plotting", "ballbat.plotting_tracks", "ballbat.plotting_league"}


def _imported_top_packages(source: str) -> set[str]:
    """The top-level packages a module's source imports (anywhere in it, also inside functions)."""
    found = set()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
    return found


def test_import_scan_sees_every_form_of_import():
    """The scan below finds matplotlib however it is imported, and not where it is only named."""
    for source in (
        "import matplotlib",
        "import matplotlib.pyplot as plt",
        "from matplotlib.figure import Figure",
        "def f():\n    from matplotlib import cm\n",
    ):
        assert "matplotlib" in _imported_top_packages(source), source
    assert "matplotlib" not in _imported_top_packages('"""Nothing here imports matplotlib."""\nimport numpy')


def test_only_the_plotting_layer_imports_matplotlib():
    """No module under src/ballbat except the plotting layer imports matplotlib: figures sit on top."""
    root = Path(ballbat.__file__).parent
    importers = set()
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        if "matplotlib" in _imported_top_packages(path.read_text(encoding="utf-8")):
            importers.add(name)
    assert importers - PLOTTING_LAYER == set(), f"modules below the plotting layer import matplotlib: {importers}"
    assert importers == PLOTTING_LAYER  # the scan does see the layer's own imports


def _public_functions():
    for mod in pkgutil.walk_packages(ballbat.__path__, "ballbat."):
        if mod.name.split(".")[-1].startswith("_"):
            continue
        module = importlib.import_module(mod.name)
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if inspect.isfunction(obj):
                yield f"{module.__name__}.{name}", obj
            elif inspect.isclass(obj):
                for meth_name, meth in vars(obj).items():
                    if inspect.isfunction(meth) and not meth_name.startswith("_"):
                        yield f"{module.__name__}.{name}.{meth_name}", meth


def test_public_functions_have_type_hints():
    """Every public function and method of the package annotates its parameters and its return."""
    missing = []
    for qualname, fn in _public_functions():
        sig = inspect.signature(fn)
        params = [p for p in sig.parameters.values() if p.name not in ("self", "cls")]
        lacking = [p.name for p in params if p.annotation is inspect.Parameter.empty]
        if sig.return_annotation is inspect.Signature.empty:
            lacking.append("return")
        if lacking:
            missing.append(f"{qualname}: {', '.join(lacking)}")
    assert not missing, "public functions without type hints:\n" + "\n".join(missing)


def test_conda_environment_matches_the_lock_file(root):
    """workflow/envs/ballbat.yaml (each rule's `conda:`) installs exactly requirements.lock."""
    lock = {line.strip() for line in (root / "requirements.lock").read_text().splitlines() if line.strip()}
    env = yaml.safe_load((root / "workflow" / "envs" / "ballbat.yaml").read_text())
    pip = next(d["pip"] for d in env["dependencies"] if isinstance(d, dict))
    assert {p for p in pip if not p.startswith("-e")} == lock
    py = next(d for d in env["dependencies"] if isinstance(d, str) and d.startswith("python="))
    assert py == "python=3.11"


def test_functions_stay_short():
    """No function in src/ballbat has more than 60 lines of code (issues 20, 33; bench/function_lengths.py counts)."""
    import importlib.util

    root = Path(ballbat.__file__).parent
    spec = importlib.util.spec_from_file_location("function_lengths", root.parents[1] / "bench" / "function_lengths.py")
    lengths = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(lengths)
    long = {}
    for path in sorted(root.rglob("*.py")):
        module = ".".join(path.relative_to(root.parent).with_suffix("").parts)
        for n, _line, name in lengths.function_lengths(path):
            if n > 60:
                long[f"{module}.{name}"] = n
    assert not long, f"functions over 60 lines of code (split them into named steps): {long}"
    assert lengths.function_lengths(root / "tracks" / "reduce.py")  # the count sees the functions


def _test_module_imports(source: str) -> list[str]:
    """The modules a source imports that are test modules (a dotted part named test_*: ``stages.test_ingest``)."""
    names = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.append(node.module)
    return [n for n in names if any(part.startswith("test_") for part in n.split("."))]


def test_the_scan_sees_test_modules_in_subfolders():
    """Whatever the folder, an import of a test module is found, and one of a helper is not."""
    for source in ("import test_lint", "from stages.test_ingest import ROOT", "import workflow.test_outputs as w"):
        assert _test_module_imports(source), source
    assert _test_module_imports("import helpers\nfrom workflow_helpers import snakemake\nimport forked") == []


def test_no_test_module_imports_another(root):
    """Shared test helpers live in conftest.py or helpers.py / workflow_helpers.py, not in a test module."""
    found = []
    for path in sorted((root / "tests").rglob("*.py")):
        rel = path.relative_to(root / "tests").as_posix()
        found += [f"{rel}: {name}" for name in _test_module_imports(path.read_text())]
    assert found == []


#: Test modules under tests/ that check the project as a whole, not one module of the package.
PROJECT_CHECKS = {"test_docs.py", "test_import_graph.py", "test_lint.py", "test_release.py", "test_example_scripts.py"}


def layout_problems(tests: Path, package: Path) -> list[str]:
    """The test modules under ``tests`` (outside workflow/) not named after a package module at the mirrored path.

    ``tests/SUB/test_X.py`` tests ``src/ballbat/SUB/X.py``; the Snakemake runs live under ``tests/workflow/``.
    """
    problems = []
    for path in sorted(tests.rglob("test_*.py")):
        rel = path.relative_to(tests)
        if rel.parts[0] in ("workflow", "data") or rel.as_posix() in PROJECT_CHECKS:
            continue
        module = package.joinpath(*rel.parts[:-1], rel.name.removeprefix("test_"))
        if not module.is_file():
            problems.append(f"tests/{rel.as_posix()}: no src/ballbat/{module.relative_to(package).as_posix()}")
        elif rel.parts[:-1] and not (path.parent / "__init__.py").is_file():
            problems.append(f"tests/{rel.as_posix()}: its folder has no __init__.py (module names would clash)")
    return problems


def test_tests_mirror_the_package(root):
    """Every test module outside tests/workflow/ is named after a package module at the mirrored path (issue 33)."""
    assert layout_problems(root / "tests", root / "src" / "ballbat") == []
    assert (root / "tests" / "workflow" / "__init__.py").is_file()


def test_the_layout_check_finds_a_stray_module(tmp_path):
    """A test module named after no module, or in a folder the package has not, is named."""
    package = tmp_path / "src" / "ballbat"
    (package / "stages").mkdir(parents=True)
    (package / "collision.py").write_text("")
    (package / "stages" / "ingest.py").write_text("")
    tests = tmp_path / "tests"
    (tests / "stages").mkdir(parents=True)
    (tests / "stages" / "__init__.py").write_text("")
    for name in ("test_collision.py", "test_redteam.py", "stages/test_ingest.py", "stages/test_collision.py"):
        (tests / name).write_text("")
    assert layout_problems(tests, package) == [
        "tests/stages/test_collision.py: no src/ballbat/stages/collision.py",
        "tests/test_redteam.py: no src/ballbat/redteam.py",
    ]


def test_the_module_order_names_existing_modules(root):
    """The module order (conftest's FIRST and LAST) names test modules that exist (by their path relative to tests/)."""
    import conftest

    missing = [name for name in conftest.FIRST + conftest.LAST if not (root / "tests" / name).is_file()]
    assert missing == []
