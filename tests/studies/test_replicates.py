"""Study replicates (ballbat.studies.replicates): a replicate is the stages in memory; the calibration effect
is what the true calibration would have given (issue 22).
"""

from __future__ import annotations

import copy

import numpy as np
from helpers import SMALL

from ballbat.stages import fit_ex, normalize, reconstruct, reduce, render, simulate
from ballbat.studies import replicates
from ballbat.studies.records import row_labels
from ballbat.studies.replicates import STUDY_QUANTITIES, replicate_seeds, run_replicate
from ballbat.studies.settings import StudySettings
from ballbat.tracks.render import calibration_draws, drawn_calibration


def test_a_replicate_is_the_stages_in_memory(config, balls, bats, monkeypatch):
    """studies.run_replicate calls simulate, render, reduce, normalize, reconstruct and fit_ex's run, once each
    (fit_ex's as :func:`fit_ex.fit`, its run with the signed systematics kept).
    """
    calls = []
    for mod in (simulate, reduce, normalize, reconstruct, fit_ex):
        entry = "fit" if mod is fit_ex else "run"
        orig = getattr(mod, entry)

        def counted(*args, _orig=orig, _name=mod.__name__, **kw):
            calls.append(_name.rsplit(".", 1)[1])
            return _orig(*args, **kw)

        monkeypatch.setattr(mod, entry, counted)
    orig_render = render.render
    monkeypatch.setattr(render, "render", lambda *a, **k: calls.append("render") or orig_render(*a, **k))
    monkeypatch.setattr(replicates, "STUDY_QUANTITIES", tuple(q for q in STUDY_QUANTITIES if q != "eta2"))
    dataset = copy.deepcopy(config["datasets"]["synthetic"])
    dataset["synthetic"]["impacts"] = SMALL
    settings = StudySettings.from_config(
        {**config, "studies": {"s": {**config["studies"]["calibration"], "dataset": "synthetic"}}}, "s"
    )
    rows = run_replicate(settings, dataset, 0, balls, bats)
    assert calls == ["simulate", "render", "reduce", "normalize", "reconstruct", "fit_ex"]
    e_x = [r for r in rows if r["quantity"] == "e_x_pooled" and r["ball"] == "baseball"]
    assert len(e_x) == 1 and np.isfinite(e_x[0]["value"]) and e_x[0]["uncertainty"] > 0


def test_the_calibration_effect_is_what_the_true_calibration_would_have_given(config, balls, bats):
    """A replicate that draws its calibration reports, per quantity, the first-order change the draw made
    (_calibration_effect). Reducing the same tracks with the drawn (true) calibration instead of
    the declared one must give value + calibration_effect, up to second order: the study uses this to
    take the draw's spread out of a bias and to judge the statistical interval where calibration is drawn.
    """
    from helpers import SMALL

    dataset = copy.deepcopy(config["datasets"]["synthetic"])
    dataset["synthetic"]["impacts"] = SMALL
    cams = dataset["render"]["cameras"]
    cams["swing"].update(m_per_px_err=0.01, fps_err=0.003)
    cams["spin"].update(m_per_px_err=0.01)
    dataset["render"]["draw_calibration"] = True
    settings = StudySettings.from_config(
        {**config, "studies": {"s": {**config["studies"]["calibration"], "dataset": "synthetic"}}}, "s"
    )
    replicate = 1
    drawn = run_replicate(settings, dataset, replicate, balls, bats)
    # the lab that knows its true calibration: the drawn one declared, nothing drawn (same seeds: same tracks)
    seeds = replicate_seeds(settings.seed, replicate)
    z = calibration_draws({**dataset["render"], "seed": seeds[1]})
    assert np.all(np.abs(z[[0, 1, 2]]) > 0.2)  # swing and spin scale, swing frame rate: the draws this test needs
    known = copy.deepcopy(dataset)
    true_block = drawn_calibration({**dataset["render"], "seed": seeds[1]})
    for name, cam in known["render"]["cameras"].items():
        cam.update(m_per_px=true_block["cameras"][name]["m_per_px"], fps=true_block["cameras"][name]["fps"])
    known["render"]["draw_calibration"] = False
    plain = run_replicate(settings, known, replicate, balls, bats)
    exact = {row_labels([r])[0]: r["value"] for r in plain}
    moved, missed = [], []
    for r in drawn:
        label = row_labels([r])[0]
        if not np.isfinite(exact[label] - r["value"]):
            continue
        assert np.isfinite(r["calibration_effect"]), label
        # in SE: how far the draw moved the value, and how far value + effect is from the true calibration's
        moved.append((exact[label] - r["value"]) / r["uncertainty"])
        missed.append((exact[label] - r["value"] - r["calibration_effect"]) / r["uncertainty"])
        assert abs(missed[-1]) < 0.25, (label, moved[-1], missed[-1])
    moved, missed = np.abs(moved), np.abs(missed)
    assert len(moved) == 17 and (moved > 1).sum() >= 5 and moved.max() > 2.5  # the draw moved several by > 1 SE
    assert missed.sum() < 0.15 * moved.sum()
    # not drawn: no effect reported
    assert all(np.isnan(r["calibration_effect"]) for r in plain)
