"""The tracker's compiled kernels (ballbat.video.kernels; issue 38's speed, docs/video.md) against the numpy and
scipy they replace, on random inputs and on rendered frames; and the numpy shortcuts the speed work took.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage
from video_clips import BUSY, M_PER_PX, RADIUS_PX, spin_truth, swing_truth, two_impact_truths

from ballbat.video import edge, kernels, search, track
from ballbat.video.render import Look, render_frames


def _noisy_disc(rng, dtype, size=(120, 160)):
    """A bright disc with a dark spot on a ramp, with noise, as ``dtype``: what the rays and searches see."""
    yy, xx = np.mgrid[0 : size[0], 0 : size[1]].astype(float)
    img = 40 + 0.2 * xx + rng.normal(0, 3, size)
    img += 150 * (np.hypot(xx - 80.3, yy - 60.7) < 30.2)
    img -= 90 * (np.hypot(xx - 72.1, yy - 55.4) < 3.5)
    return np.clip(img, 0, 255).astype(dtype)


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.float32])
def test_profiles_are_map_coordinates_bilinear_samples(dtype):
    """The rays' samples are scipy's (map_coordinates, order 1) to the last bit, in every frame type."""
    rng = np.random.default_rng(1)
    img = _noisy_disc(rng, dtype)
    cos, sin, _, _ = edge._rays((1.3, -2.2))
    for _ in range(20):
        cx, cy, r = rng.uniform(45, 115), rng.uniform(45, 75), rng.uniform(5, 30)
        for rad in (edge._WIDE, edge._SAMPLES):
            got = kernels.profiles(img, cx, cy, r, rad, cos, sin)
            np.testing.assert_array_equal(got, edge.profiles(img, cx, cy, r, rad, cos, sin))


def test_the_ray_pieces_are_the_numpy_ones():
    """The steps, the gradient's edges, the model's edges and chi-squares, and the robust circle, on random rays."""
    rng = np.random.default_rng(2)
    img = _noisy_disc(rng, np.uint8)
    cos, sin, groups, starts = edge._rays((2.1, 0.7))
    sigma = 3.0
    for cx, cy, r in rng.uniform((78, 58, 28), (83, 63, 33), (10, 3)):
        wide = edge.profiles(img, cx, cy, r, edge._WIDE, cos, sin)
        ends, step = kernels.ends_step(wide)
        np.testing.assert_array_equal(ends, np.add.reduce(wide[:, :4], axis=1) - np.add.reduce(wide[:, -4:], axis=1))
        np.testing.assert_array_equal(step, np.abs(ends) / 4)
        got = kernels.edges_gradient(wide, edge._WIDE, ends)
        np.testing.assert_array_equal(got, edge._edges_gradient(wide, edge._WIDE, np.sign(ends)))
        prof = edge.profiles(img, cx, cy, r, edge._SAMPLES, cos, sin)
        step = kernels.ends_step(prof)[1]
        y, yy = kernels.centred(prof)
        bases, past = edge._group_bases(round(2 * r) / 2, tuple(b for _, b in groups))
        p = np.empty((y.shape[0], bases.shape[2]))
        for g, (sel, _) in enumerate(groups):
            p[sel] = y[sel] @ bases[g]
        m1, m2 = np.full(48, -1), np.full(48, -1)
        for models in (m1, m1):  # each ray's model chosen, then held
            e1, c1 = kernels.edges_model(p, y, yy, past, starts, edge._CAND, step, sigma, edge._SAMPLES.size, models)
            e2, c2 = edge._edges_model(prof, r, np.maximum(sigma, 0.02 * step), groups, m2)
            np.testing.assert_allclose(e1, e2, rtol=0, atol=1e-9)
            np.testing.assert_allclose(c1, c2, rtol=1e-9)
            np.testing.assert_array_equal(m1, m2)
    a = np.linspace(0, 2 * np.pi, 48, endpoint=False)
    for _ in range(20):
        px, py = 300.2 + 25.1 * np.cos(a) + rng.normal(0, 0.1, 48), 99.7 + 25.1 * np.sin(a) + rng.normal(0, 0.1, 48)
        px[rng.integers(0, 48, 4)] += rng.normal(0, 3, 4)  # the barrel, a dot on the limb
        keep = rng.random(48) > 0.2
        fitted, fx, fy, fr, res, kept = kernels.circle_robust(px, py, keep, 24)
        ref, ref_kept = edge._fit_circle_robust(np.stack([px, py]), keep)
        assert fitted is (ref is not None)
        np.testing.assert_array_equal(kept, ref_kept)
        if fitted:
            np.testing.assert_allclose((fx, fy, fr), ref[:3], rtol=0, atol=1e-9)
            np.testing.assert_allclose(res, ref[3], rtol=0, atol=1e-9)
    assert kernels.circle_robust(px, py, np.arange(48) < 23, 24)[0] is False  # too few rays kept


def test_uniform_filter_label_and_closing_are_scipys():
    """Box filter, 4-connected labels (scipy's numbers) and grey closing, to the last bit, down to 1 x n arrays."""
    rng = np.random.default_rng(3)
    for t in range(200):
        h, w = rng.integers(1, 40, 2)
        a = (rng.random((h, w)) * 255).astype(np.float32)
        if t % 3 == 0:
            a = np.round(a / 40)  # ties
        size = int(rng.integers(1, 40))
        np.testing.assert_array_equal(kernels.uniform_filter(a, size), ndimage.uniform_filter(a, size))
        odd = 2 * int(rng.integers(0, 10)) + 1
        np.testing.assert_array_equal(kernels.grey_closing(a, odd), ndimage.grey_closing(a, size=(odd, odd)))
        mask = rng.random((h, w)) < rng.uniform(0.2, 0.7)
        lab, n = kernels.label(mask)
        ref, n_ref = ndimage.label(mask)
        assert n == n_ref
        np.testing.assert_array_equal(lab, ref)


def _frames(truth, n):
    return [img for _, img in zip(range(n), render_frames(truth, BUSY, M_PER_PX), strict=False)]


def test_fit_ball_compiled_is_the_numpy_fit():
    """On rendered frames (busy look), from a guess 1.5 px off: the same fit to 1e-9 px, or the same reason."""
    truth = spin_truth(n=4, v_px=8.0)
    reasons = set()
    for k, img in enumerate(_frames(truth, 4)):
        for blur in ((0.0, 0.0), (0.4, 0.0), (2.6, -1.1)):
            for dx, dy, r in ((1.5, -1.0, RADIUS_PX), (0.0, 0.0, 0.8 * RADIUS_PX), (-200.0, 0.0, RADIUS_PX)):
                x, y = truth.x["ball"][k] + dx, truth.y["ball"][k] + dy
                fast, why = edge.fit_ball(img, x, y, r, 2.0, blur)
                ref, ref_why = edge.fit_ball(img, x, y, r, 2.0, blur, compiled=False)
                assert why == ref_why
                np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-9)
                reasons.add(why.split(" (")[0].split(" on ")[0] if why else None)
    assert reasons == {None, "ball touches the frame's border", "ball edge seen", "ball edge fit did not settle"}
    # the ball 9.7 px from the left border, found from a guess 1.5 px small in radius: the model's passes
    # (their rays 5 px beyond the radius) run nearer the border than the gradient's (10 px) may
    near = _frames(truth, 1)[0][:, 46:]
    x, y = truth.x["ball"][0] - 46, truth.y["ball"][0]
    for dx, dr, why in ((0.5, -1.5, None), (0.0, 0.0, "ball touches the frame's border")):
        ref = edge.fit_ball(near, x + dx, y, RADIUS_PX + dr, 2.0, compiled=False)
        assert ref[1] == why and (why or ref[0][0] - ref[0][2] < 10)
        fast = edge.fit_ball(near, x + dx, y, RADIUS_PX + dr, 2.0)
        assert fast[1] == why
        np.testing.assert_allclose(fast[0], ref[0], rtol=0, atol=1e-9)


def test_a_frame_of_another_layout_or_byte_order_is_fitted_alike():
    """A frame upside down in memory (a cine stored bottom-up) or big-endian is fitted as the same frame in C order."""
    truth = spin_truth(n=1)
    img = _frames(truth, 1)[0].astype(np.uint16)
    guess = (truth.x["ball"][0] + 1.0, truth.y["ball"][0], RADIUS_PX, 1.0)
    ref = edge.fit_ball(img, *guess)
    assert ref[1] is None
    bottom_up = np.ascontiguousarray(img[::-1])[::-1]  # the same frame, its rows backwards in memory
    assert not bottom_up.flags.c_contiguous and edge.fit_ball(bottom_up, *guess) == ref
    assert edge.fit_ball(img.astype(">u2"), *guess) == ref


def test_marker_and_dots_searches_compiled_are_the_numpy_ones():
    """The tip marker near a guess (and none where there is none), and the dots in the ball, to 1e-9 px."""
    truth = swing_truth(n=4)
    mr = 0.006 / M_PER_PX
    found = []
    for k, img in enumerate(_frames(truth, 4)):
        for dx, dy, top in ((3.0, -2.0, None), (0.0, 0.0, float(img.max())), (-60.0, 40.0, None)):
            args = (img, truth.x["bat_tip"][k] + dx, truth.y["bat_tip"][k] + dy, 4 * mr + 20, mr, 1.0, top)
            fast, ref = search.find_marker(*args), search.find_marker(*args, compiled=False)
            assert (fast is None) == (ref is None)
            if ref is not None:
                np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-9)
            found.append(ref is not None)
    assert 0 < sum(found) < len(found)
    spin = spin_truth(n=4)
    seen = set()
    for k, img in enumerate(_frames(spin, 4)):
        for r in (RADIUS_PX, 0.5 * RADIUS_PX):
            ball = (spin.x["ball"][k], spin.y["ball"][k], r)
            for sigma in (1.0, 60.0):  # dots seen; nothing dark enough
                fast, why = search.find_dots(img, ball, 0.008 / M_PER_PX, sigma)
                ref, ref_why = search.find_dots(img, ball, 0.008 / M_PER_PX, sigma, compiled=False)
                assert why == ref_why and len(fast) == len(ref)
                np.testing.assert_allclose(np.reshape(fast, (-1, 4)), np.reshape(ref, (-1, 4)), rtol=0, atol=1e-9)
                seen.add((len(ref), ref_why))
    assert {(2, None), (1, None), (0, "no dot seen on the ball")} <= seen


def test_the_numpy_shortcuts_are_numpys():
    """The exact median, the two dilations as one, the noise's histogram medians and the trail's running median."""
    rng = np.random.default_rng(4)
    for n in (1, 2, 7, 8, 301):
        for dtype in (np.float32, np.float64):
            v = np.round(rng.normal(0, 5, n)).astype(dtype)  # ties
            assert search.median_of(v) == float(np.median(v))
    for _ in range(50):
        mask = rng.random(rng.integers(1, 12, 2)) < 0.2
        np.testing.assert_array_equal(search._grown2(mask), ndimage.binary_dilation(mask, iterations=2))

    def noise(img):  # the tracker's measure before its histograms
        d = np.diff(img[::4, :].astype(np.float32), axis=1)
        return max(float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2)), 1 / np.sqrt(12))

    for t in range(40):
        img = rng.integers(0, 4000 if t % 2 else 255, rng.integers(4, 60, 2)).astype(np.uint16 if t % 2 else np.uint8)
        if t % 5 == 0:
            img[:] = img[0, 0]
        assert track._noise_sigma(img) == noise(img)
    assert track._noise_sigma(img.astype(np.float32)) == noise(img)
    trail, seen = track._Trail(), []
    for c in rng.normal(100, 10, 41):
        trail.found(float(c))
        seen.append(float(c))
        assert trail.usual() == float(np.median(seen))


def test_the_dots_refinement_compiled_is_the_numpy_one():
    """A dot's centroid against the fitted shading, from the search's spots on rendered frames, to 1e-9 px."""
    done = 0
    for c in two_impact_truths(7):
        if c.camera != "spin":
            continue
        for k, img in enumerate(render_frames(c, Look(), 0.00125)):
            if not np.isfinite(c.x["ball"][k]) or k % 3:
                continue
            ball = (c.x["ball"][k], c.y["ball"][k], c.ball_radius_px)
            for x, y, *_ in search.find_dots(img, ball, 3.2, 0.004)[0]:
                fast = search.refine_dot(img, x, y, ball, 3.2)
                ref = search.refine_dot(img, x, y, ball, 3.2, compiled=False)
                np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-9)
                done += 1
    assert done > 20
