"""Reference solution of Stronge's contact model by numerical integration (for tests).

:func:`stronge_reference` integrates the equations of motion of docs/model.md, "Stronge's contact model", with
``scipy.integrate.solve_ivp`` and event detection, independently of the closed-form solver
:mod:`ballbat.stronge.model`. It is slow (a Python loop over impacts) and simple by design:
the tests and ``bench/bench_stronge.py`` compare the solver with it.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Sec. V.A.
.. [2] W. J. Stronge, *Impact Mechanics* (Cambridge University Press, 2000), Ch. 5.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .model import ContactParams

__all__ = ["stronge_reference"]


def stronge_reference(
    psi: ArrayLike, contact: ContactParams, rtol: float = 1e-12, atol: float = 1e-14
) -> dict[str, Any]:
    """Solve the same model by numerical integration, as a reference for tests.

    Integrates the equations of motion of docs/model.md ("Stronge's contact model") in physical form (unit
    ball mass, unit k_n, unit incident speed; normal compression and velocity are state
    variables, so the normal force law is integrated rather than evaluated in closed form)
    with ``scipy.integrate.solve_ivp`` (DOP853, tolerances ``rtol``/``atol``) and terminal
    events for maximum compression, separation, stick-to-slip (k_t|s| = mu N) and
    slip-to-stick (w = u - ds/dt = 0). A Python loop over impacts: slow, by design simple.

    Parameters
    ----------
    psi, contact
        As in :func:`ballbat.stronge.model.stronge_ex`; they broadcast against each other.
    rtol, atol : float
        Relative and absolute tolerances of ``solve_ivp``.

    Returns
    -------
    dict
        ``e_x`` (array of the broadcast shape), ``regime`` (array of str), ``t_c`` (the
        integrated time of maximum compression, in units of 1/Omega_n), ``events`` (list of
        lists of (t/t_c, new phase) per impact).

    Notes
    -----
    At psi = 0 the tangential motion has zero amplitude; the limit psi -> 0 is computed by
    integrating with unit tangential speed and no friction limit (stick throughout), which
    is the limit of the model as tan(psi)/(mu eta2) -> 0.
    """
    arrs = contact.broadcast(psi)
    shape = arrs[0].shape
    out = [_reference_one(*args, rtol=rtol, atol=atol) for args in zip(*(a.ravel() for a in arrs), strict=True)]
    ex = np.array([o[0] for o in out])
    return {
        "e_x": ex.reshape(shape) if shape else float(ex[0]),
        "regime": np.array([o[1] for o in out]).reshape(shape),
        "t_c": np.array([o[2] for o in out]).reshape(shape),
        "events": [o[3] for o in out],
    }


class _Contact:
    """Equations of motion of one impact in physical form (unit ball mass, k_n and incident speed).

    State ``y = (d, v, u, s)``: normal compression and its rate, the contact point's
    tangential velocity and the tangential spring's stretch. ``m_n`` and ``m_t`` are the
    effective masses (Eqs. ry and rx); the normal spring stiffens by 1/e_y^2 on unloading
    from the compression ``d_m`` reached at t_c.
    """

    def __init__(self, eta2, e, fric, r_x, r_y, alpha):
        self.m_n = 1.0 / (1.0 + r_y)
        self.m_t = alpha / ((1.0 + alpha) * (1.0 + r_x))
        self.k_n = 1.0
        self.k_t = self.k_n / eta2
        self.e, self.fric = e, fric
        self.unloading, self.d_m = False, np.nan

    def normal_force(self, d):
        if self.unloading:
            return (self.k_n / self.e**2) * (d - self.d_m * (1.0 - self.e**2))
        return self.k_n * d

    def dN_dt(self, d, v):
        return (self.k_n / self.e**2 if self.unloading else self.k_n) * v

    def rhs(self, t, y, mode):
        """Return the derivatives of the state; ``mode`` 0 sticks, +-1 slips in that direction."""
        d, v, u, s = y
        N = self.normal_force(d)
        if mode == 0:
            return [v, -N / self.m_n, -self.k_t * s / self.m_t, u]
        return [v, -N / self.m_n, -mode * self.fric * N / self.m_t, mode * self.fric * self.dN_dt(d, v) / self.k_t]

    def events(self, mode):
        """Return the terminal events of a phase: the end of compression (or separation), of stick or of slip."""

        def compression(t, y):
            return y[1]

        def separation(t, y):
            return self.normal_force(y[0])

        def stick_pos(t, y):
            return self.k_t * y[3] - self.fric * self.normal_force(y[0])

        def stick_neg(t, y):
            return -self.k_t * y[3] - self.fric * self.normal_force(y[0])

        def slip(t, y):
            return y[2] - mode * self.fric * self.dN_dt(y[0], y[1]) / self.k_t

        for f, d in ((compression, -1), (separation, -1), (stick_pos, 1), (stick_neg, 1), (slip, -mode)):
            f.terminal, f.direction = True, d
        evl = [separation if self.unloading else compression]
        if mode == 0 and np.isfinite(self.fric):
            evl += [stick_pos, stick_neg]
        elif mode != 0:
            evl.append(slip)
        return evl


def _reference_one(psi, eta2, e, mu, r_x, r_y, alpha, rtol, atol):
    """One impact of :func:`stronge_reference`: (e_x, regime, t_c, events)."""
    from scipy.integrate import solve_ivp

    v_n = np.cos(psi)
    u0 = abs(np.sin(psi))
    fric = mu
    if u0 == 0.0:
        u0, fric = 1.0, np.inf
    c = _Contact(eta2, e, fric, r_x, r_y, alpha)
    y = np.array([0.0, v_n, u0, 0.0])
    t = 0.0
    mode = 0 if (np.isinf(fric) or c.k_t * u0 < fric * c.k_n * v_n) else 1
    seq = ["stick" if mode == 0 else "slip"]
    evs = []
    t_c = np.nan
    for _ in range(200):
        sol = solve_ivp(
            lambda t, y, mode=mode: c.rhs(t, y, mode),
            (t, t + 10.0),
            y,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            events=c.events(mode),
        )
        if sol.status != 1:
            raise RuntimeError(
                f"stronge_reference: integration failed ({sol.message}) for psi={psi:g}, eta2={eta2:g},"
                f" e_y={e:g}, mu={mu:g}, r_x={r_x:g}, r_y={r_y:g}"
            )
        t, k_hit = min((te[0], k) for k, te in enumerate(sol.t_events) if te.size)
        y = sol.y_events[k_hit][0].copy()
        if k_hit == 0:
            if c.unloading:
                break  # separation
            c.unloading, c.d_m = True, y[0]
            t_c = t
            continue
        if mode == 0:
            mode = 1 if k_hit == 1 else -1
            y[3] = mode * fric * c.normal_force(y[0]) / c.k_t
            seq.append("slip")
        else:
            mode = 0
            seq.append("stick")
        evs.append((t, seq[-1]))
    else:
        raise RuntimeError(f"stronge_reference: too many phase changes for psi={psi:g}, eta2={eta2:g}")
    merged = [seq[0]] + [b for a, b in itertools.pairwise(seq) if a != b]
    regime = "gross-slip" if merged == ["slip"] else "-".join(merged)
    return -y[2] / u0, regime, t_c, [(te / t_c, ph) for te, ph in evs]
