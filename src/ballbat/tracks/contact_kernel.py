"""The contact times' likelihood and its population's sums, compiled with numba (issue 39's speed).

Each impact's likelihood of each of the 181 contact times of the grid
(:func:`ballbat.tracks.fit_contact._contact_loglik`) sums the squared misfit of the ball's
frames in the window about the contact: in numpy, arrays of impact x grid x frame and several
temporaries of each, 34 ms of a 242 ms replicate at the robustness grid's costliest point (5 px,
60 impacts per bat). Here it is one loop (:func:`loglik`) with the same formula, summed frame by
frame, so it agrees with numpy to round-off (``tests/tracks/test_fit_contact.py``): 16 ms there;
13.6 -> 9.0 ms (CPU a replicate there, ``profile_study.py``'s timers) since its cosine is skipped for
the frames before and after the contact, where it is 1 to the bit (the same bits as with it, checked
against the formula in Python's floats: ``tests/tracks/test_contact_kernel.py``).
numpy's stays the reference (``fit_contact.CONTACT_COMPILED = False``).

The population's likelihood (Nelder-Mead's objective, ``fit_contact._population_nll``, some 850
calls a replicate there on 180-240 impacts x 181 grid points, 22.4 ms) keeps numpy's bits: the
search's path, and with it its optimum within the search's tolerance (1e-3 in the beta parameters),
turns on the objective's last bits, and numpy's keep these the same wherever the impacts are held
(blocks of them, a study's replicate, the workflow's files); a compiled objective with its own sums
moved a ball type's contact durations by 2.5e-9 between blocks and one block. So only its costliest
step is compiled, the likelihood of each impact under the weights, ``(L * w).sum(axis=1)``
(:func:`weighted_row_sums`): each product rounded as numpy's and each row summed in numpy's pairwise
order, without the product's temporary, the same bits (``tests/tracks/test_contact_kernel.py`` checks them
against numpy's on random rows of 1-1000 terms, and the fitted population with and without); the
beta weights and the logarithm stay numpy's (its SIMD exp and log are not libm's, which numba calls:
5 % and 0.1 % of random arguments differ in the last bit). 21 -> 4.7 us a call on 240 impacts held
in Fortran order, the objective 22.4 -> 11.1 ms a replicate (``fit_contact.POPULATION_COMPILED =
False``: numpy's sum).

Compiled once per machine (``cache=True``: kept in ``__pycache__`` beside this file or in
``NUMBA_CACHE_DIR``); imported where contacts are fitted, never when the Snakefile is read.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_jit = njit(cache=True, nogil=True, error_model="numpy")


@_jit
def loglik(dtw, sw, ww, v, sigma, grid) -> np.ndarray:
    """Return the log-likelihood (impact, grid) of each contact time of ``grid`` (``fit_contact._contact_loglik``).

    ``dtw``: the window's frames' times from the contact's middle; ``sw``: the ball's distance
    along its flight from rest; ``ww``: the frames in the window (impact, frame); ``v`` the
    exit speed and ``sigma`` the track's noise per impact. The model: under a sin^2 force the
    ball is ``v (contact_distance(x, t_c) + max(d - t_c/2, 0))`` from rest, ``x = clip(d + t_c/2, 0, t_c)``.
    """
    n, nf = dtw.shape
    out = np.empty((n, grid.size))
    two_pi, four_pi2 = 2 * np.pi, 4 * np.pi**2
    for i in range(n):
        s2 = sigma[i] ** 2
        for g in range(grid.size):
            tc = grid[g]
            ss = 0.0
            for f in range(nf):
                if not ww[i, f]:
                    continue
                d = dtw[i, f]
                x = min(max(d + 0.5 * tc, 0.0), tc)
                dist = x * x / (2 * tc)
                if 0.0 < x < tc:  # before the contact and after it the cosine is 1 (to the bit): its term is 0
                    dist += tc * (math.cos(two_pi * x / tc) - 1) / four_pi2
                e = sw[i, f] - v[i] * (dist + max(d - 0.5 * tc, 0.0))
                ss += e * e
            out[i, g] = -0.5 * ss / s2
    return out


#: numpy's pairwise summation: blocks of at most this many terms are summed in eight running sums.
PAIRWISE_BLOCK = 128


@_jit
def _leaf(L, w, lo, n, out):
    """Write into ``out`` each row's sum of ``L[i, lo:lo + n] * w[lo:lo + n]`` (n <= 128) in numpy's order.

    numpy's ``pairwise_sum`` on a block: under 8 terms one running sum from 0; else eight, one per
    term modulo 8, added as ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7)), then the rest in
    order. The rows are the innermost loop (each row's sums in that order: the loop runs across
    independent rows, vectorised, and along memory where L is in Fortran order).
    """
    rows = L.shape[0]
    if n < 8:
        for i in range(rows):
            out[i] = 0.0
        for j in range(lo, lo + n):
            for i in range(rows):
                out[i] += L[i, j] * w[j]
        return
    m = n - n % 8
    acc = np.empty((8, rows))
    for k in range(8):
        for i in range(rows):
            acc[k, i] = L[i, lo + k] * w[lo + k]
    for j in range(lo + 8, lo + m, 8):
        for k in range(8):
            wk = w[j + k]
            for i in range(rows):
                acc[k, i] += L[i, j + k] * wk
    for i in range(rows):
        out[i] = ((acc[0, i] + acc[1, i]) + (acc[2, i] + acc[3, i])) + (
            (acc[4, i] + acc[5, i]) + (acc[6, i] + acc[7, i])
        )
    for j in range(lo + m, lo + n):
        for i in range(rows):
            out[i] += L[i, j] * w[j]


@_jit
def _pairwise(L, w, out):
    """Write into ``out`` each row's sum of ``L[i] * w`` as numpy's ``pairwise_sum`` adds it.

    Over :data:`PAIRWISE_BLOCK` terms numpy halves the range (the first half cut to a multiple of 8) and adds the
    halves' sums. Here that recursion runs off a stack (numba's cached code of a recursive function crashed
    when it was loaded again): the ranges are taken left before right, each block's sums pushed, and a range's
    two halves added where both are done.
    """
    rows = L.shape[0]
    depth, m = 1, L.shape[1]  # the levels of halving: at most depth + 1 sums held, 2 depth + 1 ranges
    while m > PAIRWISE_BLOCK:
        m -= m // 2 - (m // 2) % 8
        depth += 1
    lo_, n_, split = (
        np.empty(2 * depth + 1, np.int64),
        np.empty(2 * depth + 1, np.int64),
        np.empty(2 * depth + 1, np.bool_),
    )
    sums = np.empty((depth + 1, rows))
    lo_[0], n_[0], split[0] = 0, L.shape[1], False
    tasks, done = 1, 0
    while tasks:
        tasks -= 1
        lo, n = lo_[tasks], n_[tasks]
        if n <= PAIRWISE_BLOCK:
            _leaf(L, w, lo, n, sums[done])
            done += 1
        elif split[tasks]:  # both halves done: their sums added
            done -= 1
            for i in range(rows):
                sums[done - 1, i] += sums[done, i]
        else:
            n2 = n // 2
            n2 -= n2 % 8
            for k, (a, m, s) in enumerate(((lo, n, True), (lo + n2, n - n2, False), (lo, n2, False))):
                lo_[tasks + k], n_[tasks + k], split[tasks + k] = a, m, s
            tasks += 3
    for i in range(rows):
        out[i] = sums[0, i]


@_jit
def weighted_row_sums(L, w) -> np.ndarray:
    """Return ``(L * w[None, :]).sum(axis=1)`` with numpy's bits, without the product's temporary.

    The population's marginal likelihood of each impact (``fit_contact._population_nll``): each
    product rounded alone, as numpy's elementwise product, and each row summed in the order of
    numpy's pairwise summation along a contiguous axis (:func:`_pairwise`).
    """
    out = np.empty(L.shape[0])
    _pairwise(L, w, out)
    return out
