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
    with monkeypatch.context() as m:  # numpy's arrays: the same bits
        m.setattr(fc, "CONTACT_COMPILED", False)
        assert np.array_equal(fc._contact_loglik(dtw, sw, ww, v, sigma, grid), expected)
    # the compiled loops (tracks.contact_kernel): the same sums in frame order, to round-off
    np.testing.assert_allclose(fc._contact_loglik(dtw, sw, ww, v, sigma, grid), expected, rtol=1e-12, atol=1e-12)


def _likelihoods(rng, n: int, width: float, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gaussian likelihoods of ``n`` contacts drawn from 0.45-0.55 ms, each +-``width`` (s) about a noisy centre."""
    true = rng.uniform(0.45e-3, 0.55e-3, n)
    centres = true + rng.normal(0.0, width, n)
    return np.exp(-0.5 * ((grid[None, :] - centres[:, None]) / width) ** 2), true


def test_population_mean_error_is_the_spread_of_the_mean_over_repetitions():
    """The population mean's standard error (the pooled fit's information) is what its estimates scatter by.

    60 repetitions of 300 impacts whose frames say little (each likelihood +-0.4 ms, the
    contacts 0.45-0.55 ms): the spread of the fitted means over the repetitions against the
    mean stated error, within the 20 % that 60 repetitions resolve.
    """
    from ballbat.tracks.data import CONTACT_PRIOR
    from ballbat.tracks.fit_contact import CONTACT_GRID, contact_population

    grid = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)
    rng = np.random.default_rng(11)
    means, errs = [], []
    for _ in range(60):
        lik, _ = _likelihoods(rng, 300, 0.4e-3, grid)
        pop = contact_population(lik, np.ones(300, bool))
        means.append(pop.mean[0])
        errs.append(pop.mean_err[0])
        assert np.all(pop.mean == pop.mean[0]) and np.all(pop.mean_err == pop.mean_err[0])
    ratio = np.std(means, ddof=1) / np.mean(errs)
    assert 0.8 < ratio < 1.25, ratio
    assert abs(np.mean(means) - 0.5e-3) < 3 * np.std(means) / np.sqrt(60) + 0.02e-3


def test_the_shifted_populations_move_the_mean_by_one_standard_error_each_way():
    from ballbat.tracks.data import CONTACT_PRIOR
    from ballbat.tracks.fit_contact import CONTACT_GRID, contact_population

    grid = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)
    lik, _ = _likelihoods(np.random.default_rng(12), 300, 0.4e-3, grid)
    groups = np.repeat(["baseball", "softball"], 150)
    pop = contact_population(lik, np.ones(300, bool), groups)
    for side, shifted in zip((1, -1), pop.shifted, strict=True):
        moved = shifted @ grid - pop.prior @ grid
        np.testing.assert_allclose(moved, side * pop.mean_err, rtol=0.1)
        assert np.all(pop.mean_err > 0)


def test_the_population_error_is_zero_where_the_frames_say_nothing_and_small_where_they_say_all():
    """Flat likelihoods keep the uniform distribution, not estimated: no error, no shift. Sharp ones
    (each contact to +-0.01 ms) fix every impact's contact whatever the population: shifting the
    population by its error moves each posterior mean by the likelihood's share of the posterior
    precision, sigma_lik^2 / (sigma_lik^2 + sigma_pop^2) = 0.01^2 / (0.01^2 + 0.029^2) = 0.11 of that
    error (0.029 ms: the sd of contacts uniform over 0.1 ms), while weak frames (+-0.4 ms) follow the
    population almost all the way.
    """
    from ballbat.tracks.data import CONTACT_PRIOR
    from ballbat.tracks.fit_contact import CONTACT_GRID, contact_population

    grid = np.linspace(*CONTACT_PRIOR, CONTACT_GRID)
    flat = contact_population(np.ones((40, grid.size)), np.ones(40, bool))
    assert np.all(flat.mean_err == 0.0)
    assert all(np.array_equal(s, flat.prior) for s in flat.shifted)
    rng = np.random.default_rng(13)
    for width, follows in ((0.01e-3, (0.07, 0.15)), (0.4e-3, (0.7, 1.0))):
        lik, _ = _likelihoods(rng, 300, width, grid)
        pop = contact_population(lik, np.ones(300, bool))

        def post_mean(prior, lik=lik):
            post = lik * prior
            return (post / post.sum(axis=1, keepdims=True)) @ grid

        moved = (post_mean(pop.shifted[0]) - post_mean(pop.shifted[1])) / (2 * pop.mean_err)
        assert follows[0] <= np.mean(moved) <= follows[1], (width, np.mean(moved))
