"""The contact times' likelihood, compiled with numba (issue 39's speed).

Each impact's likelihood of each of the 181 contact times of the grid
(:func:`ballbat.tracks.fit_contact._contact_loglik`) sums the squared misfit of the ball's
frames in the window about the contact: in numpy, arrays of impact x grid x frame and several
temporaries of each, 34 ms of a 242 ms replicate at the robustness grid's costliest point (5 px,
60 impacts per bat). Here it is one loop (:func:`loglik`) with the same formula, summed frame by
frame, so it agrees with numpy to round-off (``tests/tracks/test_fit_contact.py``): 16 ms there.
numpy's stays the reference (``fit_contact.CONTACT_COMPILED = False``).

The population's likelihood (Nelder-Mead's objective) was compiled too and left numpy's: the
search's path, and with it its optimum within the search's tolerance (1e-3 in the beta
parameters), turns on the objective's last bits, and numpy's sums keep these the same
wherever the impacts are held (blocks of them, a study's replicate, the workflow's files); the
compiled sum moved a ball type's contact durations by 2.5e-9 between blocks and one block.

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
                dist = x * x / (2 * tc) + tc * (math.cos(two_pi * x / tc) - 1) / four_pi2
                e = sw[i, f] - v[i] * (dist + max(d - 0.5 * tc, 0.0))
                ss += e * e
            out[i, g] = -0.5 * ss / s2
    return out
