"""The tracker's fast paths (issue 38's speed; docs/video.md): each gives what the slow way it replaced gives.

The edge model's bases against the pseudo-inverse residual makers they replaced; the quarter
resolution search's block sums and histogram median against numpy's; the whole-frame search
for the tip marker against the search in a region about it; and a ball lost for longer than
the prediction holds, found again by the whole-frame search.
"""

from __future__ import annotations

import numpy as np
import pytest
from video_clips import BUSY, M_PER_PX, PLAIN, RADIUS_PX, spin_truth, swing_truth

from ballbat.video.edge import _CAND, _SAMPLES, _circle_fit, edge_bases, fit_ball
from ballbat.video.io import open_clip, write_clip
from ballbat.video.render import render_frames
from ballbat.video.search import _median_top, block_sum, find_balls, find_marker, find_marker_whole
from ballbat.video.track import TrackOptions, track_clip


def _residual_makers(radius: float, blur: float) -> np.ndarray:
    """I - D pinv(D) of the ray model at each tried edge, built term by term (np.convolve, np.interp)."""
    fine = np.arange(-9.0, 9.0, 0.05)
    box = np.ones(20) / 20
    kern = np.convolve(box, np.convolve(box, box))
    if blur >= 0.5:
        kern = np.convolve(kern, np.ones(round(blur / 0.05)))
    kern /= kern.sum()
    out = []
    for e in _CAND:
        inside = fine < e
        rho = (radius + fine) / (radius + e)
        basis = [np.ones_like(fine), np.where(inside, 0.0, fine - e), inside * 1.0]
        basis += [np.sqrt(np.clip(1 - rho * rho, 0, None)), inside * rho]
        d = np.column_stack([np.interp(_SAMPLES, fine, np.convolve(b, kern, mode="same")) for b in basis])
        out.append(np.eye(_SAMPLES.size) - d @ np.linalg.pinv(d))
    return np.array(out)


@pytest.mark.parametrize(("radius", "blur"), [(14.5, 0.0), (24.5, 1.5), (49.5, 3.0)])
def test_edge_bases_give_the_pseudo_inverse_residual_of_every_tried_edge(radius, blur):
    y = np.random.default_rng(1).normal(100, 30, (48, _SAMPLES.size))
    y -= y.mean(axis=1, keepdims=True)
    p = y @ edge_bases(radius, blur)
    fast = (y * y).sum(axis=1)[:, None] - (p * p).reshape(48, _CAND.size, 5).sum(axis=2)
    slow = np.einsum("ij,ejk,ik->ie", y, _residual_makers(radius, blur), y)
    np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-6 * slow.max())


def test_circle_fit_recovers_a_circle():
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    cx, cy, r = _circle_fit(512.3 + 30.7 * np.cos(a), 201.9 + 30.7 * np.sin(a))
    assert (cx, cy, r) == pytest.approx((512.3, 201.9, 30.7), abs=1e-9)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_block_sums_and_histogram_median_are_numpys(dtype):
    rng = np.random.default_rng(2)
    img = rng.integers(0, 255 if dtype == np.uint8 else 4000, (130, 259), dtype=dtype)
    sums = block_sum(img, 4)
    np.testing.assert_array_equal(sums, img[:128, :256].reshape(32, 4, 64, 4).sum(axis=(1, 3)))
    for v in (sums, sums[:, :-1], img[:5, :7]):  # an even and an odd number of values
        med, top = _median_top(v, 99.9)
        assert med == pytest.approx(np.median(v), abs=1e-9) and top == pytest.approx(np.percentile(v, 99.9), abs=1e-9)


def test_a_ball_found_in_a_region_or_in_the_whole_frame_is_fitted_to_the_same_point():
    truth = spin_truth(n=1)
    img = next(render_frames(truth, BUSY, M_PER_PX))
    (whole,) = find_balls(img, RADIUS_PX, 0.3)
    x0, y0 = 30, 41  # a region about the ball, its blocks not the whole frame's
    (part,) = find_balls(img[y0 : y0 + 100, x0 : x0 + 120], RADIUS_PX, 0.3)
    assert np.hypot(part[0] + x0 - whole[0], part[1] + y0 - whole[1]) < 2
    a = fit_ball(img, *whole, RADIUS_PX, 1.0)[0]
    b = fit_ball(img, part[0] + x0, part[1] + y0, RADIUS_PX, 1.0)[0]
    assert a[:3] == pytest.approx(b[:3], abs=0.005)
    assert np.hypot(a[0] - truth.x["ball"][0], a[1] - truth.y["ball"][0]) < 0.5


def test_the_whole_frame_search_finds_the_tip_marker_the_predicted_search_finds():
    truth = swing_truth(n=6, width=480, height=240)
    mr = 0.006 / M_PER_PX
    for k, img in enumerate(render_frames(truth, BUSY, M_PER_PX)):
        x, y = truth.x["bat_tip"][k], truth.y["bat_tip"][k]
        near = find_marker(img, x + 3, y - 2, 4 * mr + 20, mr, 1.0, float(img.max()))
        whole = find_marker_whole(img, mr, 1.0)
        assert near is not None and whole == pytest.approx(near, abs=1e-9)
        assert np.hypot(whole[0] - x, whole[1] - y) < 0.2


def test_a_ball_lost_for_longer_than_the_prediction_holds_is_found_again(tmp_path):
    truth = spin_truth(n=12, width=320)
    truth.x["ball"][3:8] = np.nan  # not drawn for 5 frames: more than the 3 a prediction holds
    clip = write_clip(tmp_path / "c.tif", render_frames(truth, PLAIN, M_PER_PX), truth.fps, frame_numbers=truth.frames)
    found = track_clip(open_clip(clip), TrackOptions(RADIUS_PX))
    assert [(k, why) for _, k, why in found.left_out] == [(k, "no ball found") for k in range(103, 108)]
    got = dict(zip(found.rows["frame"], zip(found.rows["x_px"], found.rows["y_px"], strict=True), strict=True))
    assert sorted(got) == [100, 101, 102, *range(108, 112)]
    for k, (x, y) in got.items():
        assert np.hypot(x - truth.x["ball"][k - 100], y - truth.y["ball"][k - 100]) < 0.3
