"""The raw tracks' QA figures (ballbat.plotting_tracks) draw the fits."""

from __future__ import annotations

import numpy as np
import pytest
from helpers import experiment, render, render_cfg
from helpers import reduce_tracks_of as reduce

from ballbat.stages.reduce import reduction_dataset
from ballbat.tracks.reduce import FLAG_VAR


@pytest.mark.slow  # about 3 s: render, reduce and draw the QA figures
def test_qa_figures_draw_the_fits(tmp_path):
    """The QA figure shows usable and excluded impacts with fitted lines through the tracked points."""
    from ballbat.plotting_tracks import impacts_figure, pick_impacts, save_figure, summary_figure

    tr, s = render(experiment(11, per_bat=3), render_cfg(tilted_fraction=0.3))
    red = reduction_dataset(reduce(tr, s))
    idx = pick_impacts(red)
    assert [red[FLAG_VAR].values[i] == 0 for i in idx] == [True, True, False]
    fig = impacts_figure(red, tr, idx)
    assert len(fig.axes) == 9
    # the ball's fitted flight passes through its tracked points (swing camera, first impact)
    line = next(ln for ln in fig.axes[0].lines if ln.get_label() == "ball flight fit")
    x, y = line.get_xdata(), line.get_ydata()
    ct = tr.cameras["swing"]
    ok = np.isfinite(x) & np.isfinite(ct.x["ball"][idx[0]])
    assert ok.sum() > 10
    assert np.max(np.hypot(x[ok] - ct.x["ball"][idx[0]][ok], y[ok] - ct.y["ball"][idx[0]][ok])) < 3.0
    a = save_figure(fig, tmp_path / "a.png").read_bytes()
    b = save_figure(impacts_figure(red, tr, idx), tmp_path / "b.png").read_bytes()
    assert a == b  # deterministic
    assert len(summary_figure(red).axes) == 5


def test_qa_figure_reads_the_blocks_it_shows(tmp_path, monkeypatch):
    """Tracks held in blocks: each shown impact's points come from its own block, the same as from one block."""
    from helpers import BALLS, BATS, one_long_track

    from ballbat.plotting_tracks import impacts_figure
    from ballbat.tracks import data
    from ballbat.tracks.io import load_tracks

    s = one_long_track(tmp_path / "tracks.nc", factor=5)
    one = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)
    red = reduction_dataset(reduce(one, s))
    monkeypatch.setattr(data, "BLOCK_BYTES", 100_000)
    blocks = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)
    idx = [4, 0, 28]  # one impact of each block: the long track alone, the 25 short ones, the 4 longer ones
    assert len({id(blocks.locate(i)[0]) for i in idx}) == 3
    fa, fb = impacts_figure(red, one, idx), impacts_figure(red, blocks, idx)
    for ax_a, ax_b in zip(fa.axes, fb.axes, strict=True):
        for ca, cb in zip(ax_a.collections, ax_b.collections, strict=True):
            pa, pb = (np.ma.filled(c.get_offsets(), np.nan) for c in (ca, cb))
            pa, pb = (p[np.isfinite(p).all(axis=1)] for p in (pa, pb))  # the points drawn (not the padding)
            assert pa.shape[0] > 3
            np.testing.assert_array_equal(pb, pa)
