"""The contact (swing camera; step 3 of :mod:`ballbat.tracks.reduce`).

The contact's middle from the free flight extrapolated back to the rest position, its
duration a nuisance parameter fitted to the ball's departure from rest, with the contact
times' distribution among a ball type's impacts as its prior (:func:`fit_contact`); its
start, with its uncertainty.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .data import CONTACT_PRIOR
from .fit_flight import Flight, Onset
from .masked import last_true, msum
from .render import contact_distance

if TYPE_CHECKING:
    from numpy.typing import ArrayLike


#: Grid points of the contact-time posterior (10 us steps over CONTACT_PRIOR).
CONTACT_GRID = 181


#: Narrowest spread of the contact times' distribution among a ball type's impacts
#: (:func:`_contact_population`), in grid steps: a peak no narrower than the grid resolves.
CONTACT_MIN_SD_STEPS = 2.0


@dataclass
class Contact:
    """Each impact's contact, fitted from the ball's departure from rest (swing camera; s)."""

    t_mid: np.ndarray
    t_start: np.ndarray
    t_start_err: np.ndarray
    duration: np.ndarray
    duration_err: np.ndarray
    n: np.ndarray


def _beta_weights(grid: np.ndarray, p: ArrayLike) -> np.ndarray:
    """Weights on the grid of a beta distribution over its range with mean logistic(p[0]) and concentration exp(p[1]).

    Cell centres of the grid, so both ends stay finite; the concentration is held so that
    the standard deviation is at least :data:`CONTACT_MIN_SD_STEPS` grid steps.
    """
    m = 1.0 / (1.0 + np.exp(-p[0]))
    kappa = min(np.exp(p[1]), m * (1 - m) * (grid.size / CONTACT_MIN_SD_STEPS) ** 2)
    log_x, log_1mx = _beta_logs(grid.size)
    logw = (m * kappa - 1) * log_x + ((1 - m) * kappa - 1) * log_1mx
    w = np.exp(logw - logw.max())
    return w / w.sum()


@functools.lru_cache(maxsize=8)
def _beta_logs(n: int) -> tuple[np.ndarray, np.ndarray]:
    """log(x) and log(1 - x) at the cell centres x of a grid of ``n`` (read-only; computed once per n).

    :func:`_beta_weights` runs inside the Nelder-Mead search of :func:`_contact_population`, a
    hundred times a replicate, on the same grid.
    """
    x = (np.arange(n) + 0.5) / n
    logs = np.log(x), np.log1p(-x)
    for a in logs:
        a.flags.writeable = False
    return logs


def _contact_population(lik: np.ndarray, groups: np.ndarray, grid: np.ndarray) -> np.ndarray:
    """Per impact, the distribution of contact times among its group's impacts (grid weights).

    A beta distribution over the grid's range whose mean and concentration maximise the group's
    marginal likelihood, prod_i sum_j lik_ij w_j (Nelder-Mead from the uniform
    distribution, beta(1, 1); :func:`_population_fits`). Smooth on purpose: the nonparametric maximum-likelihood
    distribution is a few spikes, and posteriors under it understate their spread (by 1.2-1.7x
    in tests). A beta family holds the uniform distribution and ones piled at either end of
    the range, so likelihoods that say little leave it near uniform and many weak ones
    together still find where the contacts lie (an EM on a normal cut to the range shrank it
    towards the middle when the likelihoods were flat, and was therefore not run on them: at
    5 px and 0.5 ms contacts every duration came out 0.2-0.5 ms long). A group with no finite
    likelihood gets the uniform distribution.
    """
    prior = np.full(lik.shape, 1.0 / lik.shape[1])
    for rows, fit in _population_fits(lik, groups, grid):
        prior[rows] = _beta_weights(grid, fit.p)
    return prior


@dataclass
class _PopulationFit:
    """One group's fitted beta parameters ``p`` and its likelihoods ``L`` (rows scaled to 1 at their largest)."""

    p: np.ndarray
    L: np.ndarray
    estimated: bool  # False: the likelihoods are flat and the uniform distribution was kept


#: The contact times' likelihood (:func:`_contact_loglik`) in compiled loops (:mod:`ballbat.tracks.contact_kernel`);
#: False: numpy's.
CONTACT_COMPILED = True

#: The population likelihood's sums over the grid (:func:`_population_nll`) in a compiled loop
#: (:func:`ballbat.tracks.contact_kernel.weighted_row_sums`), numpy's bits; False: numpy's. Only the sums: Nelder-Mead's
#: path (to 1e-3 in its parameters) turns on the objective's last bits, which numpy's weights and logarithm and its
#: pairwise sums keep the same wherever the impacts are held (blocks, a study, the workflow). Compiled, a group's
#: likelihoods are held in Fortran order (:func:`_population_fits`), where the kernel's loops run along memory.
POPULATION_COMPILED = True


def _population_nll(p, L: np.ndarray, grid: np.ndarray) -> float:
    """Minus the group's marginal log-likelihood at beta parameters ``p``."""
    # elementwise and summed along rows, not a BLAS product: the same bits wherever L lies in memory
    # (ndarray.sum: np.sum's reduction without its wrapper; this runs hundreds of times a replicate)
    w = _beta_weights(grid, p)
    if POPULATION_COMPILED:
        from .contact_kernel import weighted_row_sums

        rows = weighted_row_sums(L, w)  # the product and numpy's pairwise sums in one pass, the same bits
    else:
        rows = (L * w[None, :]).sum(axis=1)
    return -float(np.log(rows + 1e-300).sum())


def _population_fits(lik: np.ndarray, groups: np.ndarray, grid: np.ndarray) -> list[tuple[np.ndarray, _PopulationFit]]:
    """Each group's rows (a mask over all impacts: its label, finite or not) and its :class:`_PopulationFit`.

    Groups labelled below 0 and groups without a finite likelihood are left out (uniform).
    """
    from scipy.optimize import minimize

    out = []
    for g in np.unique(groups):
        rows = (groups == g) & np.all(np.isfinite(lik), axis=1)
        if g < 0 or not rows.any():
            continue
        L = lik[rows] / lik[rows].max(axis=1, keepdims=True)
        # numpy sums C order's rows; the compiled sums (the same bits in any layout) run fastest down its columns
        L = np.asfortranarray(L) if POPULATION_COMPILED else np.ascontiguousarray(L)
        uniform = np.array([0.0, np.log(2.0)])  # beta(1, 1)
        simplex = uniform + np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        best = minimize(
            _population_nll,
            uniform,
            args=(L, grid),
            method="Nelder-Mead",
            options={"initial_simplex": simplex, "xatol": 1e-3, "fatol": 1e-6},
        )
        gain = best.fun < _population_nll(uniform, L, grid) - 1e-9 * len(L)
        out.append((groups == g, _PopulationFit(best.x if gain else uniform, L, bool(gain))))  # flat: uniform kept
    return out


#: Step in the beta parameters (logit of the mean, log of the concentration) of the finite differences
#: that give the population's information matrix (:func:`_population_error`).
POPULATION_STEP = 0.02
#: Newton steps from the Nelder-Mead optimum (found to ``xatol`` 1e-3 only) before the information is taken.
POPULATION_NEWTON_STEPS = 2


def _information(fit: _PopulationFit, p: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the Hessian and the gradient of :func:`_population_nll` at ``p`` (central differences)."""
    h, e = POPULATION_STEP, np.eye(2) * POPULATION_STEP

    def f(d):
        return _population_nll(p + d, fit.L, grid)

    f0, fp, fm = f(np.zeros(2)), [f(e[i]) for i in range(2)], [f(-e[i]) for i in range(2)]
    H = np.empty((2, 2))
    for i in range(2):
        H[i, i] = (fp[i] - 2 * f0 + fm[i]) / h**2
    H[0, 1] = H[1, 0] = (f(e[0] + e[1]) - f(e[0] - e[1]) - f(e[1] - e[0]) + f(-e[0] - e[1])) / (4 * h**2)
    return H, np.array([(fp[i] - fm[i]) / (2 * h) for i in range(2)])


def _covariance(H: np.ndarray, p: np.ndarray, n_grid: int) -> np.ndarray | None:
    """Return the inverse information; the mean's alone where the concentration is capped or H is not definite."""
    m = 1.0 / (1.0 + np.exp(-p[0]))
    capped = np.exp(p[1]) >= m * (1 - m) * (n_grid / CONTACT_MIN_SD_STEPS) ** 2
    if not capped and H[0, 0] > 0 and H[1, 1] > 0 and np.linalg.det(H) > 0:
        return np.linalg.inv(H)
    return np.array([[1.0 / H[0, 0], 0.0], [0.0, 0.0]]) if H[0, 0] > 0 else None


def _population_error(fit: _PopulationFit, grid: np.ndarray) -> tuple[float, float, np.ndarray]:
    """Return the group's mean contact time, its standard error and the change of ``p`` that moves the mean by +1 sigma.

    The covariance of ``p`` is the inverse of the observed information (central second differences of
    :func:`_population_nll`, step :data:`POPULATION_STEP`), taken after :data:`POPULATION_NEWTON_STEPS`
    Newton steps from the Nelder-Mead optimum (which stops anywhere within 1e-3 of it, so that the last
    bits of the data would move the information by 1e-6); the mean's error is its delta-method
    projection, sigma^2 = grad' C grad; the step C grad / sigma moves ``p`` along the direction
    where the likelihood falls least for a given change of the mean (the concentration follows the
    mean as the data tie them), and changes the mean by sigma to first order. Where the concentration
    is at its cap (:func:`_beta_weights`) or the information is not positive definite, the mean alone
    (the concentration held). Where the uniform distribution was kept, no estimate: error 0. The
    mean reported is the fitted distribution's, the one the impacts' contacts use.
    """
    mean = float(_beta_weights(grid, fit.p) @ grid)
    if not fit.estimated:
        return mean, 0.0, np.zeros(2)
    p = fit.p
    for _ in range(POPULATION_NEWTON_STEPS):
        H, g = _information(fit, p, grid)
        C = _covariance(H, p, grid.size)
        step = None if C is None else C @ g
        if step is None or not np.all(np.abs(step) < 0.1):  # not near a well-defined optimum: no polish
            break
        p = p - step
    C = _covariance(_information(fit, p, grid)[0], p, grid.size)
    if C is None:
        return mean, 0.0, np.zeros(2)
    e = np.eye(2) * POPULATION_STEP
    grad = np.array([(_beta_weights(grid, p + e[i]) - _beta_weights(grid, p - e[i])) @ grid for i in range(2)])
    grad /= 2 * POPULATION_STEP
    var = float(grad @ C @ grad)
    if not var > 0:
        return mean, 0.0, np.zeros(2)
    sigma = np.sqrt(var)
    return mean, sigma, C @ grad / sigma


#: Impacts per block of the contact-time likelihood (its arrays are impacts x grid x window frames).
CONTACT_BLOCK = 1000


def _contact_loglik(dtw, sw, ww, v, sigma, grid) -> np.ndarray:
    """Log-likelihood (impact, grid) of each contact time of ``grid`` from the window's frames.

    ``dtw`` the frames' times from the contact's middle, ``sw`` the ball's distance along its
    flight from rest, ``ww`` the frames in the window (impact, frame). All grid points at
    once, in blocks of :data:`CONTACT_BLOCK` impacts; each impact's sum over its frames runs
    along the last (contiguous) axis, as one grid point at a time summed it: the same bits.
    Compiled (:func:`ballbat.tracks.contact_kernel.loglik`, :data:`CONTACT_COMPILED`): one loop.
    """
    if CONTACT_COMPILED:
        from .contact_kernel import loglik

        arrays = (np.ascontiguousarray(a, dtype=float) for a in (dtw, sw))
        return loglik(
            *arrays, np.ascontiguousarray(ww, dtype=np.bool_), *(np.asarray(a, dtype=float) for a in (v, sigma, grid))
        )
    logl = np.empty((dtw.shape[0], grid.size))
    tc = grid[None, :, None]
    for lo in range(0, dtw.shape[0], CONTACT_BLOCK):
        b = slice(lo, lo + CONTACT_BLOCK)
        d = dtw[b][:, None, :]
        x = np.clip(d + 0.5 * tc, 0.0, tc)  # time since the start, within the contact
        model = v[b][:, None, None] * (contact_distance(x, tc) + np.maximum(d - 0.5 * tc, 0.0))
        ss = np.sum(np.where(ww[b][:, None, :], (sw[b][:, None, :] - model) ** 2, 0.0), axis=2)
        logl[b] = -0.5 * ss / sigma[b][:, None] ** 2
    return logl


def fit_contact(
    X: ArrayLike, Y: ArrayLike, t: ArrayLike, onset: Onset, flight: Flight, groups: ArrayLike | None = None
) -> Contact:
    """Each impact's contact interval from the ball's track, with its uncertainty.

    The free flight extrapolated back passes the rest position at the impulse-weighted mean
    time of the contact ``t_mid`` (its midpoint for a symmetric force pulse). The contact
    lasts ``t_c``: the ball leaves rest at ``t_mid - t_c / 2`` and, under a force that follows
    sin^2 (the shape of a ball-bat force pulse: :func:`.render.contact_distance`), is
    ``v contact_distance(t - t_mid + t_c / 2, t_c)`` along its flight direction until
    ``t_mid + t_c / 2``, then on its free flight. ``t_c`` is a nuisance parameter: its
    likelihood on a grid over :data:`CONTACT_PRIOR` from the ball's frames within the widest
    contact about ``t_mid`` (Gaussian, the flight fit's noise per coordinate). The prior is
    the distribution of contact times among the impacts of the same group (ball type),
    estimated from all their likelihoods (:func:`_contact_population`), so that the
    posterior means are unbiased on average over the group even where the frames say
    little (a uniform prior would pull every one towards the middle of its range).
    The posterior's mean and standard deviation give the contact's duration and start;
    the start's error adds the extrapolated ``t_mid``'s. With no frame inside the contact
    the posterior is the group's distribution.

    Parameters
    ----------
    X, Y : ndarray
        Ball centre (m), physical frame, NaN untracked.
    t : ndarray
        Time of each column (s).
    onset : Onset
        The impact found in this camera.
    flight : Flight
        Its free-flight fit.
    groups : ndarray, optional
        Group of each impact (its ball type); one group if None.

    Returns
    -------
    Contact
        NaN where no impact was found.
    """
    cl = contact_likelihood(X, Y, t, onset, flight)
    return contact_posterior(cl, contact_prior(cl.lik, cl.found, groups))


@dataclass
class ContactLikelihood:
    """Per impact, what its own frames say of its contact (:func:`contact_likelihood`)."""

    lik: np.ndarray  # (impact, grid): likelihood of each contact time of the grid, 1 at its largest
    t_mid: np.ndarray  # the free flight extrapolated back to the rest position (s)
    t_mid_err: np.ndarray
    n_rest: np.ndarray  # frames at rest the rest position is the mean of
    n: np.ndarray  # frames within the widest contact about t_mid
    found: np.ndarray  # an impact found (onset)


def contact_likelihood(X: ArrayLike, Y: ArrayLike, t: ArrayLike, onset: Onset, flight: Flight) -> ContactLikelihood:
    """Each impact's contact middle and the likelihood of each contact time (:func:`fit_contact`'s first step).

    Row by row: an impact's numbers depend on its own frames alone (the contact times' prior,
    :func:`contact_prior`, pools the impacts).
    """
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float)
    t = np.asarray(t, dtype=float)
    valid = np.isfinite(X) & np.isfinite(Y)
    cols = np.arange(X.shape[1])[None, :]
    at_rest = valid & (cols <= onset.rest[:, None]) & onset.found[:, None]
    w = at_rest.astype(float)
    lo, hi = CONTACT_PRIOR
    with np.errstate(all="ignore"):
        v2 = flight.vx**2 + flight.vy**2
        v = np.sqrt(v2)
        for _ in range(2):  # the rest position from frames before the longest contact can have begun
            n_rest = w.sum(axis=1)
            xr, yr = msum(X, w) / n_rest, msum(Y, w) / n_rest
            u = ((xr - flight.x0) * flight.vx + (yr - flight.y0) * flight.vy) / v2
            t_mid = flight.t_ref + u
            early = at_rest & (t < t_mid[:, None] - 0.5 * hi)
            w = np.where(early.sum(axis=1)[:, None] >= 2, early, at_rest).astype(float)
        # error of t_mid: the extrapolated line's position error along the motion at u, over the speed
        var_pos = flight.var_along * (flight.sxx / flight.n + (u - flight.u_mean) ** 2)
        t_mid_err = np.sqrt(var_pos + flight.sigma**2 / n_rest) / v
        s = ((X - xr[:, None]) * flight.vx[:, None] + (Y - yr[:, None]) * flight.vy[:, None]) / v[:, None]
        dt = t - t_mid[:, None]
        win = valid & onset.found[:, None] & (np.abs(dt) < 0.5 * hi)
        win &= np.isfinite(dt)
        # the window's columns only (a few frames per impact)
        first = np.where(win.any(axis=1), np.argmax(win, axis=1), 0)
        width = int(max(1, np.max(np.where(win.any(axis=1), last_true(win) - first + 1, 1))))
        idx = np.minimum(first[:, None] + np.arange(width)[None, :], X.shape[1] - 1)
        dtw, sw = np.take_along_axis(dt, idx, axis=1), np.take_along_axis(s, idx, axis=1)
        ww = np.take_along_axis(win, idx, axis=1) & (first[:, None] + np.arange(width)[None, :] < X.shape[1])
        logl = _contact_loglik(dtw, sw, ww, v, flight.sigma, np.linspace(lo, hi, CONTACT_GRID))
        logl -= np.max(logl, axis=1, keepdims=True)
        lik = np.exp(logl)
    return ContactLikelihood(lik, t_mid, t_mid_err, n_rest, win.sum(axis=1), onset.found)


def contact_prior(lik: np.ndarray, found: np.ndarray, groups: ArrayLike | None = None) -> np.ndarray:
    """Return per impact the distribution of contact times among its group's impacts, (impact, grid).

    :func:`_contact_population`, pooled over every impact given (all of a dataset's, whatever blocks they are held in);
    ``groups``: each impact's ball type, one group if None; impacts without ``found`` are left out.
    """
    return contact_population(lik, found, groups).prior


@dataclass
class ContactPopulation:
    """The contact times' distribution per group (:func:`contact_population`), per impact (its group's)."""

    prior: np.ndarray  # (impact, grid): the fitted distribution
    shifted: tuple[np.ndarray, np.ndarray]  # the same with every group's mean at +1 and at -1 standard error
    mean: np.ndarray  # the group's mean contact time (s); NaN for an impact in no group
    mean_err: np.ndarray  # its standard error (s): 0 where the likelihoods are flat (the uniform kept, not estimated)


def contact_population(lik: np.ndarray, found: np.ndarray, groups: ArrayLike | None = None) -> ContactPopulation:
    """Return the contact times' distribution per group (:func:`_contact_population`), its mean and its error.

    The mean's standard error comes from the pooled fit itself (the inverse of its observed
    information, :func:`_population_error`); the distributions at +-1 standard error of the
    mean (``shifted``) are what the reduction is solved again with, so that the error of this
    estimate, shared by all of a group's impacts, reaches every quantity that pools them
    (docs/model.md, "The contact population's error").
    """
    lo, hi = CONTACT_PRIOR
    grid = np.linspace(lo, hi, CONTACT_GRID)
    grp = np.zeros(lik.shape[0], dtype=int) if groups is None else np.unique(groups, return_inverse=True)[1]
    n = lik.shape[0]
    prior = np.full(lik.shape, 1.0 / lik.shape[1])
    shifted = (prior.copy(), prior.copy())
    mean, mean_err = np.full(n, np.nan), np.full(n, np.nan)
    with np.errstate(all="ignore"):
        for rows, fit in _population_fits(lik, np.where(found, grp, -1), grid):
            prior[rows] = _beta_weights(grid, fit.p)
            mean[rows], mean_err[rows], step = _population_error(fit, grid)
            for side, out in zip((1.0, -1.0), shifted, strict=True):
                out[rows] = _beta_weights(grid, fit.p + side * step)
    return ContactPopulation(prior, shifted, mean, mean_err)


def contact_posterior(cl: ContactLikelihood, prior: np.ndarray) -> Contact:
    """Each impact's contact from its likelihood and its group's prior (:func:`fit_contact`'s last step, row by row)."""
    lo, hi = CONTACT_PRIOR
    grid = np.linspace(lo, hi, CONTACT_GRID)
    with np.errstate(all="ignore"):
        post = cl.lik * prior
        post /= post.sum(axis=1, keepdims=True)
        tc_mean = post @ grid
        tc_err = np.sqrt(np.maximum(post @ grid**2 - tc_mean**2, 0.0))
    t_mid = cl.t_mid
    ok = cl.found & (cl.n_rest > 0) & np.isfinite(t_mid) & np.isfinite(tc_mean)
    nan = np.full(t_mid.shape[0], np.nan)
    return Contact(
        t_mid=np.where(ok, t_mid, nan),
        t_start=np.where(ok, t_mid - 0.5 * tc_mean, nan),
        t_start_err=np.where(ok, np.hypot(cl.t_mid_err, 0.5 * tc_err), nan),
        duration=np.where(ok, tc_mean, nan),
        duration_err=np.where(ok, tc_err, nan),
        n=np.where(ok, cl.n, 0).astype(int),
    )
