"""Dataset assembly (ballbat.pipeline.products): add_variables without xarray's merge is Dataset.update's result."""

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
