"""Habits enforced, not offered (issue 9): type hints on the public API, the conda file in step
with the lock file. `make lint` runs ruff, snakefmt and `snakemake --lint`; these checks are the
ones no linter does.
"""

import importlib
import inspect
import pkgutil

import yaml

import ballbat


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
