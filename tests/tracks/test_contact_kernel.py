"""The contact fit's compiled loops (ballbat.tracks.contact_kernel) against plain transcriptions of their formulas."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballbat.tracks.data import CONTACT_PRIOR
from ballbat.tracks.fit_contact import CONTACT_GRID

GRID = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)


def _window(rng, n: int, width: int, ends: bool = False):
    """A window's frames (impact, frame) about the contact: times, distances, mask, speed, noise.

    ``ends``: every frame exactly at a contact's start or end for one of the grid's contact times,
    its first and last among them (where the clipped time since the start is 0 or t_c).
    """
    dtw = np.sort(rng.uniform(-0.6 * CONTACT_PRIOR[1], 0.6 * CONTACT_PRIOR[1], (n, width)), axis=1)
    if ends:
        tc = rng.choice(GRID[[0, 1, 90, -2, -1]], (n, width))
        dtw = np.where(rng.uniform(size=(n, width)) < 0.5, 0.5 * tc, -0.5 * tc)
    v = rng.uniform(20.0, 50.0, n)
    sw = v[:, None] * np.maximum(dtw, 0.0) + rng.normal(0.0, 1e-3, (n, width))
    ww = rng.uniform(size=(n, width)) > 0.25
    ww[0] = False  # an impact without a frame in its window: log-likelihood 0 everywhere
    return dtw, sw, ww, v, rng.uniform(5e-4, 2e-3, n)


def _loglik_numpy(dtw, sw, ww, v, sigma, grid):
    """The contact times' log-likelihood as numpy arrays (impact, grid, frame), the formula written out."""
    tc = grid[None, :, None]
    d = dtw[:, None, :]
    x = np.clip(d + 0.5 * tc, 0.0, tc)
    dist = x**2 / (2 * tc) + tc * (np.cos(2 * np.pi * x / tc) - 1) / (4 * np.pi**2)
    model = v[:, None, None] * (dist + np.maximum(d - 0.5 * tc, 0.0))
    ss = np.where(ww[:, None, :], (sw[:, None, :] - model) ** 2, 0.0).sum(axis=2)
    return -0.5 * ss / sigma[:, None] ** 2


def _loglik_python(dtw, sw, ww, v, sigma, grid):
    """The same formula in Python's floats, frame by frame, the cosine taken at every frame (libm's, as numba's)."""
    out = np.empty((dtw.shape[0], grid.size))
    for i in range(dtw.shape[0]):
        for g, tc in enumerate(grid.tolist()):
            ss = 0.0
            for f in range(dtw.shape[1]):
                if ww[i, f]:
                    d = float(dtw[i, f])
                    x = min(max(d + 0.5 * tc, 0.0), tc)
                    dist = x * x / (2 * tc) + tc * (math.cos(2 * math.pi * x / tc) - 1) / (4 * math.pi**2)
                    e = float(sw[i, f]) - float(v[i]) * (dist + max(d - 0.5 * tc, 0.0))
                    ss += e * e
            out[i, g] = -0.5 * ss / float(sigma[i]) ** 2
    return out


@pytest.mark.parametrize("ends", [False, True])
def test_loglik_is_the_formula_to_round_off(ends):
    """The compiled likelihood against numpy's arrays: 1e-12 of the largest misfit of its impact (sums in another
    order, libm's cosine against numpy's); an impact with every frame masked has log-likelihood 0.
    """
    from ballbat.tracks.contact_kernel import loglik

    rng = np.random.default_rng(5)
    for n, width in ((40, 12), (7, 1), (3, 30)):
        args = _window(rng, n, width, ends)
        got, want = loglik(*args, GRID), _loglik_numpy(*args, GRID)
        scale = np.max(np.abs(want), axis=1, keepdims=True) + 1e-300
        assert np.max(np.abs(got - want) / scale) < 1e-12
        assert np.all(got[0] == 0.0)


@pytest.mark.parametrize("ends", [False, True])
def test_loglik_skips_only_cosines_of_one(ends):
    """The frames before and after the contact skip the cosine, which is 1 there to the bit: the same bits as the
    formula with the cosine at every frame, summed in the same order (frames at the contact's very ends included).
    """
    from ballbat.tracks.contact_kernel import loglik

    args = _window(np.random.default_rng(6), 6, 10, ends)
    np.testing.assert_array_equal(loglik(*args, GRID), _loglik_python(*args, GRID))


@pytest.mark.parametrize(
    ("rows", "cols"), [(1, 1), (3, 7), (5, 8), (60, 9), (240, 128), (240, 129), (180, 181), (9, 1000)]
)
def test_weighted_row_sums_are_numpys_bits(rows, cols):
    """The population's row sums: numpy's elementwise product summed by its pairwise summation along a contiguous
    row, bit for bit (1 to 1000 terms: one running sum, eight, halves of the range), with zeros and values spanning
    200 orders of magnitude as scaled likelihoods have. In whatever layout L lies, the bits of C order (numpy's own
    sum over the rows of a Fortran-ordered array adds in another order).
    """
    from ballbat.tracks.contact_kernel import weighted_row_sums

    rng = np.random.default_rng(rows * 1000 + cols)
    L = np.exp(-rng.uniform(0.0, 460.0, (rows, cols)))
    L[rng.uniform(size=L.shape) < 0.1] = 0.0
    w = rng.uniform(size=cols)
    w /= w.sum()
    want = (L * w[None, :]).sum(axis=1)
    for a in (L, np.asfortranarray(L), np.hstack([L, L])[:, :cols]):
        np.testing.assert_array_equal(weighted_row_sums(a, w), want)


def test_population_fit_is_the_same_compiled_or_not(monkeypatch):
    """The contact population fitted with the compiled sums and with numpy's: the same bits, through Nelder-Mead, the
    Newton steps and the shifted distributions (two ball types, informative and flat likelihoods).
    """
    from ballbat.tracks import fit_contact as fc

    rng = np.random.default_rng(7)
    centres = np.concatenate([rng.normal(0.6e-3, 0.05e-3, 150), rng.normal(0.9e-3, 0.1e-3, 90)])
    lik = np.exp(-0.5 * ((GRID[None, :] - centres[:, None]) / rng.uniform(0.05e-3, 0.5e-3, 240)[:, None]) ** 2)
    lik[-20:] = 1.0  # a third group whose frames say nothing
    groups = np.repeat(["baseball", "softball", "other"], [150, 70, 20])
    found = rng.uniform(size=240) > 0.05
    got = fc.contact_population(lik, found, groups)
    monkeypatch.setattr(fc, "POPULATION_COMPILED", False)
    want = fc.contact_population(lik, found, groups)
    for a, b in zip(
        (got.prior, *got.shifted, got.mean, got.mean_err),
        (want.prior, *want.shifted, want.mean, want.mean_err),
        strict=True,
    ):
        np.testing.assert_array_equal(a, b)
    assert np.all(got.mean_err[found & (groups != "other")] > 0)
