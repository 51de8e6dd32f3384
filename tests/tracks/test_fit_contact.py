"""The contact fit (ballbat.tracks.fit_contact): its prior and its beta weights."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.tracks.fit_contact import CONTACT_MIN_SD_STEPS, _beta_logs, _beta_weights


def test_contact_prior_of_uninformative_frames_stays_uniform():
    """Flat likelihoods (no frame inside any contact) keep the uniform prior, beta(1, 1): nothing in them
    prefers another, and a narrower one would make every start overconfident.
    """
    from ballbat.tracks.data import CONTACT_PRIOR
    from ballbat.tracks.fit_contact import CONTACT_GRID, _contact_population

    grid = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)
    prior = _contact_population(np.ones((50, grid.size)), np.zeros(50, int), grid)
    np.testing.assert_allclose(prior, 1.0 / grid.size)
    # informative likelihoods about 0.9 +- 0.05 ms: the prior narrows around them
    rng = np.random.default_rng(0)
    centres = rng.normal(0.9e-3, 0.05e-3, 200)
    lik = np.exp(-0.5 * ((grid[None, :] - centres[:, None]) / 0.1e-3) ** 2)
    p = _contact_population(lik, np.zeros(200, int), grid)[0]
    mean = p @ grid
    sd = np.sqrt(p @ grid**2 - mean**2)
    assert abs(mean - 0.9e-3) < 0.03e-3 and sd < 0.1e-3, (mean, sd)


def test_contact_prior_finds_short_contacts_from_weak_frames():
    """Many impacts that each say little about their contact still say together where the contacts lie.

    At 5 px and 3000 fps a 0.5 ms contact leaves one frame or two on the ball's way out, and each
    impact's likelihood spans most of the 0.2-2.0 ms range. The EM on a normal distribution
    was not run on such likelihoods (it shrank towards the middle), so the uniform prior put
    every contact near 1.1 ms, 0.2-0.5 ms too long, and moved the bat's alignment time and v_bat
    alike in every impact (mean pull -0.12 at 5 px, 60 impacts per bat: docs/studies.md).
    """
    from ballbat.tracks.data import CONTACT_PRIOR
    from ballbat.tracks.fit_contact import CONTACT_GRID, _contact_population

    grid = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)
    rng = np.random.default_rng(3)
    true = rng.uniform(0.45e-3, 0.55e-3, 400)
    centres = true + rng.normal(0.0, 0.5e-3, 400)  # each likelihood: +-0.5 ms about a noisy centre
    lik = np.exp(-0.5 * ((grid[None, :] - centres[:, None]) / 0.5e-3) ** 2)
    p = _contact_population(lik, np.zeros(400, int), grid)[0]
    post = lik * p
    post /= post.sum(axis=1, keepdims=True)
    assert abs(post @ grid - true).mean() < 0.15e-3
    assert abs(np.mean(post @ grid - true)) < 0.05e-3, np.mean(post @ grid - true)
    uniform = lik / lik.sum(axis=1, keepdims=True)
    assert np.mean(uniform @ grid - true) > 0.2e-3  # what the uniform prior gave


def _direct(grid: np.ndarray, p) -> np.ndarray:
    """_beta_weights as it was: the logs of the cell centres computed at every call."""
    m = 1.0 / (1.0 + np.exp(-p[0]))
    kappa = min(np.exp(p[1]), m * (1 - m) * (grid.size / CONTACT_MIN_SD_STEPS) ** 2)
    x = (np.arange(grid.size) + 0.5) / grid.size
    logw = (m * kappa - 1) * np.log(x) + ((1 - m) * kappa - 1) * np.log1p(-x)
    w = np.exp(logw - logw.max())
    return w / w.sum()


@pytest.mark.parametrize("n", [7, 40, 121])
@pytest.mark.parametrize("p", [(0.0, np.log(2.0)), (1.3, 0.2), (-2.0, 4.0), (0.4, 9.0)])
def test_beta_weights_equal_the_direct_formula_bit_for_bit(n, p):
    grid = np.linspace(0.3e-3, 1.5e-3, n)
    w = _beta_weights(grid, np.array(p))
    assert w.shape == (n,) and w.sum() == pytest.approx(1.0, rel=1e-12)
    assert np.array_equal(w, _direct(grid, p))


def test_beta_logs_are_shared_and_read_only():
    a, b = _beta_logs(40)
    assert _beta_logs(40)[0] is a
    with pytest.raises(ValueError):
        a[0] = 0.0
    assert np.all(a < 0) and np.all(b < 0)


@pytest.mark.parametrize("block", [1000, 7])
def test_contact_likelihood_on_the_whole_grid_is_the_pointwise_number(monkeypatch, block):
    """All grid points at once (in blocks of impacts) give the bits of one grid point at a time."""
    from ballbat.tracks import fit_contact as fc
    from ballbat.tracks.masked import msum
    from ballbat.tracks.render import contact_distance

    monkeypatch.setattr(fc, "CONTACT_BLOCK", block)
    rng = np.random.default_rng(3)
    n, width = 30, 6
    dtw = rng.uniform(-1e-3, 1e-3, (n, width))
    v = rng.uniform(30, 50, n)
    sw = v[:, None] * np.maximum(dtw, 0) + rng.normal(0, 1e-3, (n, width))
    ww = rng.uniform(size=(n, width)) > 0.2
    sigma = rng.uniform(5e-4, 2e-3, n)
    grid = np.linspace(4e-4, 1.2e-3, fc.CONTACT_GRID)
    expected = np.empty((n, grid.size))
    for j, tc in enumerate(grid):  # the loop the stage ran before
        x = np.clip(dtw + 0.5 * tc, 0.0, tc)
        model = v[:, None] * (contact_distance(x, tc) + np.maximum(dtw - 0.5 * tc, 0.0))
        expected[:, j] = -0.5 * msum((sw - model) ** 2, ww.astype(float)) / sigma**2
    assert np.array_equal(fc._contact_loglik(dtw, sw, ww, v, sigma, grid), expected)
