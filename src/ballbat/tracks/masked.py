"""Masked helpers of the reduction's fits: arrays are (impact, column), ``w`` a 0/1 float mask."""

from __future__ import annotations

import numpy as np


def msum(a: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Sum over columns of ``a`` where ``w`` > 0."""
    return np.sum(np.where(w > 0, a, 0.0), axis=1)


def first_true(mask: np.ndarray) -> np.ndarray:
    """Index of the first True column, -1 if none."""
    any_ = mask.any(axis=1)
    return np.where(any_, np.argmax(mask, axis=1), -1)


def last_true(mask: np.ndarray) -> np.ndarray:
    """Index of the last True column, -1 if none."""
    any_ = mask.any(axis=1)
    return np.where(any_, mask.shape[1] - 1 - np.argmax(mask[:, ::-1], axis=1), -1)


def take_at(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """``a[i, idx[i]]`` for each row, ``idx`` clipped to the columns."""
    return np.take_along_axis(a, np.clip(idx, 0, a.shape[1] - 1)[:, None], axis=1)[:, 0]


#: numpy sums a row of up to this many terms in eight interleaved partial sums (its pairwise sum's block)
#: (:func:`fitted_columns`).
PAIRWISE_BLOCK = 128

#: The widest row :func:`fitted_columns` cuts: the batched matrix products (:func:`ballbat.batched.gram`)
#: were checked to keep their bits up to here (BLAS blocks longer rows).
CUT_WIDTH = 256


def _pairwise_leaves(n: int, start: int = 0) -> list[tuple[int, int]]:
    """Return the blocks numpy's pairwise sum splits a row of ``n`` terms into (start, end), in order.

    A row longer than :data:`PAIRWISE_BLOCK` is split at half its length rounded down to a
    multiple of 8, and each half again, down to blocks of at most that many terms.
    """
    if n <= PAIRWISE_BLOCK:
        return [(start, start + n)]
    half = n // 2 - (n // 2) % 8
    return _pairwise_leaves(half, start) + _pairwise_leaves(n - half, start + half)


def fitted_columns(mask: np.ndarray, *arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Return the columns of ``arrays`` and ``mask`` that hold the fitted frames, where that keeps every sum's bits.

    A fit of some frames of a track (the tip's before the contact: about a sixth of its
    columns) masks every other column, and its sums add 0 for each. numpy sums a row in
    blocks of at most :data:`PAIRWISE_BLOCK` terms (:func:`_pairwise_leaves`), each in eight
    interleaved partial sums, term k in partial sum k mod 8, the block's last (length mod 8)
    terms added one by one after them. So the columns kept lie in one block, start and end at
    multiples of 8 and stop short of its last terms: each term is added in the same place, and
    the dropped zeros change nothing (the batched matrix products alike, up to
    :data:`CUT_WIDTH` columns: both checked on 20 000 random cases). Otherwise every column is
    kept. Arrays of one dimension (a time per column) are cut alike.
    """
    width = mask.shape[1]
    cols = np.flatnonzero(mask.any(axis=0))
    if cols.size == 0 or width > CUT_WIDTH:
        return (*arrays, mask)
    c0 = int(cols[0]) - int(cols[0]) % 8
    c1 = c0 + -(-(int(cols[-1]) + 1 - c0) // 8) * 8
    if not any(lo <= c0 and c1 <= hi - (hi - lo) % 8 for lo, hi in _pairwise_leaves(width)):
        return (*arrays, mask)
    return (*(a[..., c0:c1] for a in arrays), mask[:, c0:c1])
