"""A Dataset's variables by name (ballbat.columns)."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.columns import Columns


def test_columns_read_the_datasets_arrays():
    """A Dataset's variables and coordinates by name, their very arrays; replacements kept apart."""
    import xarray as xr

    ds = xr.Dataset(
        {"v_bat": ("impact", np.array([30.0, 31.0])), "flag": ("impact", np.array([0, 1]))},
        coords={"impact": np.arange(2), "ball": ("impact", np.array(["a", "b"]))},
        attrs={"v_ref": 31.3},
    )
    cols = Columns(ds)
    for k in ("v_bat", "flag", "impact", "ball"):
        assert k in cols and np.shares_memory(cols[k].values, ds[k].values)
    assert "v_ball" not in cols and cols.attrs["v_ref"] == 31.3 and len(cols) == 4
    moved = Columns(cols, {"v_bat": ds["v_bat"].variable * 2.0})
    assert np.array_equal(moved["v_bat"].values, [60.0, 62.0]) and np.array_equal(cols["v_bat"].values, [30.0, 31.0])
    with pytest.raises(KeyError):
        cols["v_ball"]
