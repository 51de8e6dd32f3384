"""ballbat.batched.nanmedian_rows gives numpy.nanmedian's numbers, row by row (issue 39)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from ballbat.batched import nanmedian_rows


def _reference(a: np.ndarray) -> np.ndarray:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN rows
        return np.nanmedian(a, axis=1)


@pytest.mark.parametrize("seed", range(8))
def test_nanmedian_rows_equals_numpy_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    n, m = 30, int(rng.integers(2, 700))  # both of numpy's paths (masked arrays below 600 columns)
    a = rng.normal(size=(n, m)) * 10.0 ** rng.uniform(-6, 6, (n, 1))
    a[rng.random((n, m)) < rng.uniform(0.0, 0.9)] = np.nan
    a[0] = np.nan  # a row without values
    a[1, 0], a[1, 1:] = 0.25, np.nan  # a row of one value
    a[2] = np.round(a[2], 1)  # ties
    got, ref = nanmedian_rows(a), _reference(a)
    assert np.isnan(got[0]) and got[1] == a[1, 0]
    assert np.array_equal(got, ref, equal_nan=True)


def test_nanmedian_rows_of_even_and_odd_counts():
    a = np.array([[3.0, np.nan, 1.0, 2.0], [4.0, 1.0, np.nan, np.nan], [np.nan] * 4])
    np.testing.assert_array_equal(nanmedian_rows(a), [2.0, 2.5, np.nan])
    assert nanmedian_rows(np.empty((3, 0))).shape == (3,)
