"""Blocks of impacts (ballbat.tracks.data.plan_blocks, TrackBlocks): padding bounded per block (issue 34)."""

from __future__ import annotations

import numpy as np

from ballbat.tracks.data import BLOCK_BYTES, POINTS, TrackBlocks, Tracks, plan_blocks, to_dense

#: Bytes per frame column of one impact: 2 points in the swing camera, 3 in the spin one, x and y, 8 bytes.
PER = {"swing": 2 * 16, "spin": 3 * 16}


def _padded(spans: dict, idx: np.ndarray) -> int:
    return idx.size * sum(PER[c] * int(np.maximum(spans[c][idx], 1).max()) for c in spans)


def _own(spans: dict, idx: np.ndarray) -> int:
    return sum(PER[c] * int(np.maximum(spans[c][idx], 1).sum()) for c in spans)


def test_one_block_when_padding_is_cheap():
    """The paper's 108 impacts at 400 frames (2 MB padded): one block of every impact, in order, as before."""
    spans = {"swing": np.full(108, 400), "spin": np.full(108, 120)}
    spans["swing"][7] = 4000  # ten times longer: still within the budget
    (only,) = plan_blocks(spans)
    np.testing.assert_array_equal(only, np.arange(108))
    assert _padded(spans, only) <= BLOCK_BYTES


def test_a_long_track_gets_a_block_of_its_own():
    """Thousands of impacts, one track ten times longer: padding costs at most as much again as the tracks."""
    rng = np.random.default_rng(0)
    n = 3000
    spans = {"swing": rng.integers(80, 120, n), "spin": rng.integers(30, 40, n)}
    spans["swing"][1234] = 1200
    budget = _padded(spans, np.arange(n)) // 4  # one block would take four budgets
    blocks = plan_blocks(spans, budget)
    # every impact in exactly one block, each block in the dataset's order
    np.testing.assert_array_equal(np.sort(np.concatenate(blocks)), np.arange(n))
    assert all(np.all(np.diff(b) > 0) for b in blocks)
    for b in blocks:
        assert _padded(spans, b) <= budget and _padded(spans, b) <= 2 * _own(spans, b)
    (long_block,) = [b for b in blocks if 1234 in b]
    assert long_block.size == 1
    total = sum(_padded(spans, b) for b in blocks)
    assert total <= 2 * _own(spans, np.arange(n))
    # padded to the longest, every impact would have taken about ten times its tracks
    assert _padded(spans, np.arange(n)) > 8 * _own(spans, np.arange(n))


def test_track_blocks_keep_the_dataset_order():
    """TrackBlocks gives ids, balls, truth and frame origins in the dataset's order; locate finds an impact's row."""
    n, index = 5, [np.array([0, 2, 3]), np.array([1, 4])]
    ids = np.array([f"I{i}" for i in range(n)])
    rng = np.random.default_rng(1)
    blocks = []
    for idx in index:
        rows = [(j, c, p, f) for j in range(idx.size) for c in POINTS for p in POINTS[c] for f in range(3 + idx[j])]
        ii, cam, pt, fr = (np.array(v) for v in zip(*rows, strict=True))
        fr = fr + 10 * idx[ii]
        cams = to_dense(ii, cam, pt, fr, rng.normal(size=ii.size), rng.normal(size=ii.size), idx.size)
        blocks.append(Tracks(ids[idx], ids[idx], ids[idx], cams, {"truth_v": idx.astype(float)}))
    tb = TrackBlocks(blocks, index)
    assert tb.n == n and tb.impact_id.tolist() == ids.tolist() and tb.ball.tolist() == ids.tolist()
    np.testing.assert_array_equal(tb.truth["truth_v"], np.arange(n, dtype=float))
    np.testing.assert_array_equal(tb.frame0("swing"), 10 * np.arange(n))
    block, k = tb.locate(4)
    assert block is blocks[1] and k == 1 and block.impact_id[k] == "I4"
    assert block.cameras["swing"].n_columns == 3 + 4  # padded to its own longest (impact 4), not beyond
