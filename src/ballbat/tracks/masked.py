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
