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
