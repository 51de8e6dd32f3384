"""Dataset assembly (ballbat.pipeline.products): add_variables and build_dataset skip xarray's merge, same result."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from ballbat.pipeline import products
from ballbat.pipeline.products import Var, add_variables


def _dataset() -> xr.Dataset:
    n = 5
    return xr.Dataset(
        {"a": ("impact", np.arange(n, dtype=float), {"units": "m"}), "b": ("impact", np.ones(n), {"units": "1"})},
        coords={"impact": ("impact", [f"i{k}" for k in range(n)]), "ball": ("impact", ["x"] * n)},
        attrs={"title": "t"},
    )


TABLE = {
    "c": Var(("impact",), "m s-1", "a new variable"),
    "a": Var(("impact",), "m", "a replaced one"),
    "d": Var(("impact",), "1", "another"),
}


def _merged(ds, table, values):
    new = {k: (v.dims, np.asarray(values[k]), v.attributes()) for k, v in table.items() if k in values}
    out = ds.copy()
    out.update(new)
    return out


def test_added_as_update_adds_them_in_the_same_order_and_the_input_untouched():
    ds = _dataset()
    before = ds.copy(deep=True)
    values = {"c": np.linspace(0, 1, 5), "a": np.full(5, 2.0), "d": np.zeros(5)}
    fast = add_variables(ds, TABLE, values)
    slow = _merged(ds, TABLE, values)
    assert fast.identical(slow)
    assert list(fast.variables) == list(slow.variables) and list(fast.data_vars) == ["a", "b", "c", "d"]
    assert fast["c"].attrs == slow["c"].attrs and fast["c"].attrs["units"] == "m s-1"
    assert ds.identical(before) and "c" not in ds  # a copy: the input is not changed
    fast["b"].attrs["units"] = "changed"
    assert ds["b"].attrs["units"] == "1"


@pytest.mark.parametrize(
    "table, values",
    [
        ({"ball": Var(("impact",), None, "a coordinate")}, {"ball": np.array(["y"] * 5)}),  # a coordinate replaced
        ({"e": Var(("bat",), "1", "a new dimension")}, {"e": np.zeros(3)}),  # a dimension of its own
        ({"e": Var(("impact",), "1", "the wrong length")}, {"e": np.zeros(4)}),
    ],
)
def test_anything_else_goes_through_xarrays_merge(table, values, monkeypatch):
    ds = _dataset()
    assert not products._plain_additions(ds, {k: (v.dims, values[k], {}) for k, v in table.items()})
    try:
        want = _merged(ds, table, values)
    except ValueError:
        with pytest.raises(ValueError):
            add_variables(ds, table, values)
        return
    assert add_variables(ds, table, values).identical(want)


def test_a_replicates_stages_add_the_same_variables_either_way(monkeypatch):
    """The normalize, reconstruct and fit_ex Datasets of a rendered replicate: the same with and without the merge."""
    from helpers import BALLS, BATS, SMALL

    from ballbat import chain
    from ballbat.config_checks import load_config
    from ballbat.studies.replicates import chain_settings, replicate_seeds
    from ballbat.studies.settings import StudySettings

    cfg = load_config()
    settings = StudySettings.from_config(cfg, "calibration")
    dataset = {
        **cfg["datasets"]["synthetic"],
        "synthetic": {**cfg["datasets"]["synthetic"]["synthetic"], "impacts": SMALL},
    }
    cs = chain_settings(settings, dataset, replicate_seeds(settings.seed, 1))
    src = chain.source(cs, BALLS, BATS)
    fast = chain.run(cs, src, BALLS, BATS)
    monkeypatch.setattr(products, "_plain_additions", lambda ds, new: False)
    slow = chain.run(cs, src, BALLS, BATS)
    for stage in ("normalize", "reconstruct", "fit_ex"):
        a, b = getattr(fast, stage), getattr(slow, stage)
        assert a.identical(b) and list(a.variables) == list(b.variables), stage


def _same(a: xr.Dataset, b: xr.Dataset) -> None:
    assert a.identical(b)
    assert list(a.variables) == list(b.variables) and list(a.data_vars) == list(b.data_vars)
    assert dict(a.sizes) == dict(b.sizes) and list(a.dims) == list(b.dims) and list(a.xindexes) == list(b.xindexes)
    assert set(a.coords) == set(b.coords)


def test_a_replicates_stages_build_the_same_datasets_either_way(monkeypatch):
    """simulate's, reduce's and fit_ex's Datasets of a rendered replicate (with the calibration drawn): the same,
    variables, order, dimensions and indexes, with and without the constructor's merge (issue 39).
    """
    from helpers import BALLS, BATS, SMALL

    from ballbat import chain
    from ballbat.config_checks import load_config
    from ballbat.studies.replicates import chain_settings, replicate_seeds
    from ballbat.studies.settings import StudySettings

    cfg = load_config()
    settings = StudySettings.from_config(cfg, "robustness")
    dataset = settings.point_dataset(0)
    dataset["synthetic"]["impacts"] = SMALL
    cs = chain_settings(settings, dataset, replicate_seeds(settings.seed, 1))
    built = []
    real = products._plain_data_vars
    monkeypatch.setattr(products, "_plain_data_vars", lambda *a: built.append(real(*a)) or built[-1])
    fast_src = chain.source(cs, BALLS, BATS)
    fast = chain.run(cs, fast_src, BALLS, BATS)
    assert built.count(True) >= 3  # simulate, reduce and fit_ex took the path
    monkeypatch.setattr(products, "_plain_data_vars", lambda *a: False)
    slow_src = chain.source(cs, BALLS, BATS)
    slow = chain.run(cs, slow_src, BALLS, BATS)
    _same(fast_src, slow_src)
    _same(fast.fit_ex, slow.fit_ex)


@pytest.mark.parametrize(
    "table, values",
    [
        ({"impact": Var(("impact",), "1", "a coordinate's name")}, {"impact": np.zeros(3)}),
        ({"bat": Var(("bat",), "1", "a dimension's name")}, {"bat": np.zeros(2)}),
        ({"e": Var(("impact",), "1", "the wrong length")}, {"e": np.zeros(4)}),
        (
            {"e": Var(("bat",), "1", "one length"), "f": Var(("bat",), "1", "another")},
            {"e": np.ones(2), "f": np.ones(3)},
        ),
    ],
)
def test_build_dataset_leaves_anything_else_to_the_constructor(table, values):
    """A data variable named as a coordinate or a dimension, or dimensions of two sizes: the constructor's own result
    (or its error).
    """
    coords = {"impact": (Var(("impact",), None, "impact"), np.arange(3))}
    base = xr.Dataset(coords={"impact": ("impact", np.arange(3))})
    spec = {k: (v.dims, np.asarray(values[k]), {}) for k, v in table.items()}
    assert not products._plain_data_vars(base, spec)
    try:
        want = xr.Dataset(
            {k: (v.dims, np.asarray(values[k]), v.attributes()) for k, v in table.items()},
            coords={"impact": (("impact",), np.arange(3), Var(("impact",), None, "impact").attributes())},
        )
    except ValueError:
        with pytest.raises(ValueError):
            products.build_dataset(table, values, coords)
        return
    _same(products.build_dataset(table, values, coords), want)
