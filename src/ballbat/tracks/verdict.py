"""The dataset's verdict on its reduced tracks: the cross-checks judged together (docs/tracks.md, "Cross-checks").

:func:`cross_check` runs the detectors of :mod:`.checks` on a reduction (:mod:`.reduce`), excludes
impacts no collision can give, and stops a dataset that a wrong setting spoils, naming the setting
(:func:`~.checks.diagnose`). The reduce stage calls it after the reduction; the detectors are
called by the reduction itself, so this module, not :mod:`.checks`, sits above :mod:`.reduce`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

import numpy as np

from ..units import INCH, G
from .checks import (
    ARC_TOLERANCE,
    DATASET_FRACTION,
    DATASET_Z,
    FLIP_Z,
    IMPACT_Z,
    FreeFall,
    diagnose,
    frame_steps,
    free_fall,
    tip_arc,
    weighted_mean,
)
from .fit_contact import fit_contact
from .fit_swing import TAU_PRIOR_FRAMES
from .reduce import STAGE, ReduceFlag

if TYPE_CHECKING:
    from .reduce import Reduction


@dataclass
class Verdict:
    """What the cross-checks found: pooled observables (for messages) and warnings."""

    observed: dict
    lines: list
    warnings: list


def _fmt_ratio(val: float, rel: float) -> str:
    return f"{val:.3g} +- {abs(val) * rel:.2g}"


def cross_check(red: Reduction, balls: dict, bats: dict, where: str = "tracks") -> Verdict:
    """Check a reduction against physics; exclude implausible impacts; stop a dataset a setting spoils.

    Changes ``red.flag`` and ``red.reason`` in place: impacts whose reduced values no collision
    gives (the ranges of a measured file, :func:`ballbat.ingest.implausible_rows`: speeds, the
    exit-to-bat speed ratio, the e_x the spin implies).

    Raises
    ------
    ballbat.properties.InputError
        A setting wrong for the whole dataset (g, the two cameras, the tip's arc, the spin dots),
        more than half the impacts implausible, every impact excluded, or no ball x bat pair
        with enough usable impacts. The messages give the numbers, the setting most likely
        wrong, and the count of every exclusion reason.
    """
    tr = red.tracks
    ball_ids = tr.ball.astype(str)
    r = np.array([balls[b].r for b in ball_ids])
    m = np.array([balls[b].m for b in ball_ids])
    flag = red.flag
    fitted = ~np.isin(flag, [ReduceFlag.NO_IMPACT, ReduceFlag.TOO_FEW_FRAMES])
    disagree = flag == ReduceFlag.CAMERAS_DISAGREE
    n_test = int(fitted.sum())
    setting_wrong = n_test > 0 and disagree.sum() > DATASET_FRACTION * n_test
    pool = fitted & (~disagree | setting_wrong)
    found = _Findings({}, [], [])
    _check_free_fall(red, pool, r, m, where, found)
    _check_two_cameras(red, pool, fitted & disagree, n_test, setting_wrong, where, found)
    _check_tip_arc(red, pool, where, found)
    _check_spin_dots(red, pool, ball_ids, balls, where, found)
    _check_direction(red, pool, found)
    _check_aspect(red, pool, where, found)
    if found.failed or found.shape:
        _raise_setting(found, red.cameras, where, frame_steps(red.tracks))
    pairs = _exclude_implausible(red, r, balls, bats, where)
    return Verdict(found.observed, found.lines, _usable_pairs(red, pairs, where))


@dataclass
class _Findings:
    """What the dataset checks of :func:`cross_check` found so far (filled in place)."""

    observed: dict  # pooled observable -> (value, relative error), for :func:`diagnose`
    lines: list  # one line per check, for the log
    failed: list  # the checks that stop the dataset, each naming the setting
    shape: list = field(default_factory=list)  # failures no setting of :func:`hypotheses` explains (the aspect)


def _check_free_fall(red: Reduction, pool, r, m, where: str, found: _Findings) -> None:
    """Check g, fitted free in each camera's ball flight, against G (allowing for Magnus lift)."""
    observed, lines, failed = found.observed, found.lines, found.failed
    for c in ("swing", "spin"):
        ff = FreeFall(
            *_per_impact(
                red,
                lambda b, idx, c=c: _fields(
                    free_fall(*b.phys[(c, "ball")], b.times[c], b.flight[c], r[idx], m[idx], b.values["omega"])
                ),
            )
        )
        sel = pool & np.isfinite(ff.g)
        g, se, k = weighted_mean(ff.g[sel], ff.g_err[sel])
        if k == 0:
            continue
        w = 1 / ff.g_err[sel] ** 2
        lift = float(np.sum(w * ff.lift_max[sel]) / np.sum(w))
        allowed = lift + DATASET_Z * se
        observed[f"g_{c}"] = (g / G, math.hypot(se, lift) / max(abs(g), 1e-9))
        line = (
            f"g in the {c} camera's ball flight, fitted free: {g:.2f} +- {se:.2f} m/s^2 over {k} impacts "
            f"(expected {G:.2f}, allowing {lift:.1f} for Magnus lift)"
        )
        lines.append(line)
        if abs(g - G) > allowed:
            failed.append(
                f"{where}.cameras.{c}: {line}: g scales as m_per_px x fps^2 and changes sign when y points up"
            )
        elif g < 0 and g < G - lift - FLIP_Z * se:
            failed.append(
                f"{where}.cameras.{c}: {line}: g is negative, {(G - lift - g) / se:.1f} standard errors below "
                "the least a camera with y pointing down shows (g less the largest lift): y points up"
            )


def _check_two_cameras(red: Reduction, pool, disagreeing, n_test: int, setting_wrong, where: str, found) -> None:
    """Check the ball's speed in the swing camera over that in the spin camera against 1."""
    observed, lines, failed = found.observed, found.lines, found.failed
    ag = red.agreement
    sel = pool & np.isfinite(ag.ratio)
    ratio, se, k = weighted_mean(ag.ratio[sel], ag.ratio_err[sel])
    if k:
        observed["speed"] = (ratio, se / ratio)
        n_bad = int(disagreeing.sum())
        line = (
            f"the ball's speed in swing / in spin: {ratio:.4f} +- {se:.4f} over {k} impacts (expected 1); "
            f"{n_bad} of {n_test} impacts disagree beyond z = {IMPACT_Z}"
        )
        lines.append(line)
        if setting_wrong:
            failed.append(
                f"{where}.cameras: {line}: the speed scales as m_per_px x fps in each camera, and the launch "
                "direction with mirror and the direction of y"
            )


def _check_tip_arc(red: Reduction, pool, where: str, found: _Findings) -> None:
    """Check the radius of the bat tip's arc in the swing camera against the rig's pivot_to_tip."""
    observed, lines, failed = found.observed, found.lines, found.failed
    kap, kap_err = _per_impact(red, _tip_arc)
    sel = pool & np.isfinite(kap)
    kh, se, k = weighted_mean(kap[sel], kap_err[sel])
    if k:
        L = red.rig.pivot_to_tip
        if kh > 0:
            arc = 1 / math.sqrt(kh)
            observed["arc"] = (arc, 0.5 * se / kh + ARC_TOLERANCE)
            arc_text = f"{arc * L / INCH:.1f} in ({arc:.3g} x pivot_to_tip; 1/kappa^0.5, kappa = {kh:.3f} +- {se:.3f})"
        else:
            observed["arc"] = (1 / math.sqrt(max(kh + se, 1e-12)), 0.5 + ARC_TOLERANCE)
            arc_text = f"beyond {L / INCH / math.sqrt(max(kh + DATASET_Z * se, 1e-12)):.0f} in (straight)"
        line = (
            f"the bat tip's arc radius in the swing camera: {arc_text} over {k} impacts, against "
            f"pivot_to_tip_in {L / INCH:g}"
        )
        lines.append(line)
        lo, hi = (1 + ARC_TOLERANCE) ** -2 - DATASET_Z * se, (1 - ARC_TOLERANCE) ** -2 + DATASET_Z * se
        if not lo <= kh <= hi:
            failed.append(
                f"{where}.rig / {where}.cameras.swing.m_per_px: {line}: the radius seen scales with m_per_px, "
                "not with fps"
            )


def _tip_arc(red: Reduction, idx) -> tuple[np.ndarray, np.ndarray]:
    """Return kappa and its error of each impact of one block (:func:`.checks.tip_arc`)."""
    cams = red.cameras
    contact = red.contact or fit_contact(
        *red.phys[("swing", "ball")], red.times["swing"], red.onset["swing"], red.flight["swing"], red.tracks.ball
    )
    return tip_arc(
        red.swing,
        *red.phys[("swing", "bat_tip")],
        red.times["swing"],
        contact.t_start,
        red.rig.pivot_to_tip,
        cams["swing"].fps,
        np.hypot(TAU_PRIOR_FRAMES, np.nan_to_num(contact.t_start_err) * cams["swing"].fps),
    )


def _fields(obj) -> tuple:
    """Return a dataclass' fields as a tuple (the arrays themselves, not copies)."""
    return tuple(getattr(obj, f.name) for f in fields(obj))


def _per_impact(red: Reduction, fn):
    """Return ``fn(block's reduction, its impacts' positions)`` of every block, in the dataset's order.

    ``fn`` returns an array or a tuple of arrays, impact first. One block: ``fn(red, all)`` as it is.
    """
    parts = [fn(b, idx) for b, idx in red.parts()]
    if red.blocks is None:
        return parts[0]
    if isinstance(parts[0], tuple):
        return tuple(red.tracks.gather([p[k] for p in parts]) for k in range(len(parts[0])))
    return red.tracks.gather(parts)


def _check_spin_dots(red: Reduction, pool, ball_ids, balls: dict, where: str, found: _Findings) -> None:
    """Check the spin dots' mean distance from the ball's centre against its radius (Table I)."""
    lines, failed = found.lines, found.failed
    for b in sorted(set(ball_ids)):
        sel = pool & (ball_ids == b)
        rho = np.concatenate([red.spin.radius[p][sel] for p in ("dot_a", "dot_b")])
        rho = rho[np.isfinite(rho)]
        if rho.size < 2:
            continue
        mean, se = float(rho.mean()), float(rho.std(ddof=1) / math.sqrt(rho.size))
        rb = balls[b].r
        line = (
            f"the spin dots' mean distance from the {b}'s centre: {1e3 * mean:.1f} +- {1e3 * se:.1f} mm over "
            f"{rho.size // 2} impacts, against its radius {1e3 * rb:.1f} mm (Table I)"
        )
        lines.append(line)
        if mean > rb + DATASET_Z * se:
            failed.append(
                f"{where}.cameras.spin.m_per_px: {line}: a dot on the ball cannot be further than its radius "
                "(the distance scales with the spin camera's m_per_px)"
            )


def _check_direction(red: Reduction, pool, found: _Findings) -> None:
    """Record which way the ball flies along X in each camera (+1: the swing's direction), for :func:`diagnose`."""
    for c in ("swing", "spin"):
        vx = red.flight[c].vx
        vx = vx[pool & np.isfinite(vx)]
        if vx.size:
            found.observed[f"dir_{c}"] = (1.0 if np.median(vx) > 0 else -1.0, 1e-3)


#: Stretch of y against x that the spin dots' circles may show, pooled over impacts, beyond its error.
ASPECT_TOLERANCE = 0.05


def dot_aspect(red: Reduction) -> np.ndarray:
    """Return each impact's and dot's y/x stretch of the circle the dot traces about the ball's centre, (impact, 2).

    Fits A dx^2 + B dy^2 = 1 (an ellipse along the image axes) to the dot's offsets from the fitted
    centre after separation; the stretch is (A / B)^0.5 (1: a circle; NaN: fewer than 6 frames).
    Block by block for tracks held in blocks.
    """
    return _per_impact(red, lambda b, idx: _dot_aspect(b))


def _dot_aspect(red: Reduction) -> np.ndarray:
    """:func:`dot_aspect` of one block."""
    t = red.times["spin"]
    fl = red.flight["spin"]
    cx, cy = fl.centre(t)
    cols = np.arange(t.shape[1])[None, :]
    after = (cols >= fl.separation[:, None]) & (fl.separation[:, None] >= 0)
    out = []
    with np.errstate(all="ignore"):
        for p in ("dot_a", "dot_b"):
            X, Y = red.phys[("spin", p)]
            dx, dy = X - cx, Y - cy
            m = after & np.isfinite(dx) & np.isfinite(dy)
            a, b = np.where(m, dx**2, 0.0), np.where(m, dy**2, 0.0)
            saa, sab, sbb = (a * a).sum(1), (a * b).sum(1), (b * b).sum(1)
            sa, sb = a.sum(1), b.sum(1)
            det = saa * sbb - sab**2
            A, B = (sa * sbb - sb * sab) / det, (sb * saa - sa * sab) / det
            ok = (m.sum(1) >= 6) & (A > 0) & (B > 0)
            out.append(np.where(ok, np.sqrt(A / B), np.nan))
    return np.stack(out, axis=1)


def _check_aspect(red: Reduction, pool, where: str, found: _Findings) -> None:
    """Check that the spin dots trace circles: unequal x and y scales stretch every one along an axis."""
    q = dot_aspect(red)[pool].ravel()
    q = q[np.isfinite(q)]
    if q.size < 6:
        return
    med = float(np.median(q))
    se = float(1.4826 * np.median(np.abs(q - med)) * 1.253 / math.sqrt(q.size))
    line = (
        f"the spin dots' circles about the ball's centre, y over x: {med:.3f} +- {se:.3f} (median over {q.size} "
        "dots; 1 for equal scales)"
    )
    found.lines.append(line)
    if abs(math.log(med)) > math.log1p(ASPECT_TOLERANCE) and abs(med - 1) > DATASET_Z * se:
        found.shape.append(
            f"{where}.cameras.spin: {line}: every dot traces an ellipse along the image's axes, so the x and y "
            "scales differ (non-square pixels, or x_px and y_px scaled apart in an export); a tilted spin axis "
            "would tilt the ellipses every way"
        )


def _raise_setting(found: _Findings, cams, where: str, steps: dict | None = None) -> None:
    """Stop the dataset: the failed checks, and the setting that most likely explains them."""
    from ..properties import InputError

    failed, observed = found.failed, found.observed
    if not failed:
        raise InputError(found.shape)
    likely = diagnose(observed, cams, steps)
    tail = []
    if likely is not None:
        name, chi2, none = likely
        ok = chi2 < DATASET_Z**2 * max(len(observed), 1) and chi2 < none
        tail = [
            f"{where}: most likely {name}"
            if ok
            else f"{where}: no single setting explains these; check fps, m_per_px, mirror and the direction of y "
            "of both cameras, and the rig's units (inches)"
        ]
    raise InputError([*failed, *found.shape, *tail])


def _exclude_implausible(red: Reduction, r, balls: dict, bats: dict, where: str) -> dict:
    """Flag the impacts whose reduced values no collision gives, as for a measured file.

    Returns the recoil factors of each (ball, bat) pair; more than half the live impacts
    implausible stops the dataset.
    """
    from ..ingest import Measured, implausible_rows
    from ..properties import InputError, recoil_factors

    tr, flag = red.tracks, red.flag
    ball_ids, bat_ids = tr.ball.astype(str), tr.bat.astype(str)
    pairs = {(b, t): recoil_factors(balls[b], bats[t]) for b, t in set(zip(ball_ids, bat_ids, strict=True))}
    r_x = np.array([pairs[(b, t)][0] for b, t in zip(ball_ids, bat_ids, strict=True)])
    r_y = np.array([pairs[(b, t)][1] for b, t in zip(ball_ids, bat_ids, strict=True)])
    alpha = np.array([balls[b].alpha for b in ball_ids])
    v = red.values
    live = (flag == 0) & np.all([np.isfinite(v[k]) for k in ("v_bat", "v_ball", "theta", "omega")], axis=0)
    if live.any():
        measured = Measured(v["v_bat"], v["v_ball"], v["theta"], v["omega"], r, alpha, r_x, r_y)
        why = implausible_rows(
            measured.take(live),
            # one group per impact: the group-outlier test (a unit mistake in some rows of a file)
            # does not apply to a reduction, whose rows share their settings; the ranges do
            np.arange(int(live.sum())),
        )
        idx = np.flatnonzero(live)[why != ""]
        for i, w in zip(idx, why[why != ""], strict=True):
            flag[i] = ReduceFlag.IMPLAUSIBLE
            red.reason[i] = f"{STAGE}: implausible: {w}"
        if idx.size > DATASET_FRACTION * live.sum():
            raise InputError(
                [
                    f"{where}: {idx.size} of {int(live.sum())} reduced impacts are measurements no ball-bat collision "
                    "gives, more than half: check the camera settings (fps, m_per_px) and the rig",
                    *[f"{where}: impact {tr.impact_id[i]}: {red.reason[i]}" for i in idx[:10]],
                ]
            )

    return pairs


def _usable_pairs(red: Reduction, pairs: dict, where: str) -> list[str]:
    """Stop a dataset with no ball x bat pair to fit; return a warning per pair with too few impacts."""
    from ..linefit import MIN_FIT_IMPACTS
    from ..properties import InputError

    tr, flag = red.tracks, red.flag
    ball_ids, bat_ids = tr.ball.astype(str), tr.bat.astype(str)
    usable = flag == 0
    counts = {(b, t): int((usable & (ball_ids == b) & (bat_ids == t)).sum()) for b, t in sorted(pairs)}
    if not usable.any() or not any(k >= MIN_FIT_IMPACTS for k in counts.values()):
        reasons: dict[str, int] = {}
        for i in np.flatnonzero(~usable):
            key = ReduceFlag(int(flag[i])).name.lower()
            reasons[key] = reasons.get(key, 0) + 1
        listing = ", ".join(f"{k}: {n}" for k, n in sorted(reasons.items(), key=lambda kv: -kv[1]))
        first = [f"{where}: impact {tr.impact_id[i]}: {red.reason[i]}" for i in np.flatnonzero(~usable)[:10]]
        raise InputError(
            [
                f"{where}: {int(usable.sum())} of {tr.n} impacts usable, no ball x bat pair with {MIN_FIT_IMPACTS} "
                f"({', '.join(f'{b} on {t}: {k}' for (b, t), k in counts.items())}): nothing to fit. "
                f"Excluded: {listing or 'none'}",
                *first,
            ]
        )
    warnings = [
        f"{where}: ball {b!r} on bat {t!r}: {k} usable impact(s), fewer than {MIN_FIT_IMPACTS}: e_x of this bat is "
        "not fitted (reported as NaN)"
        for (b, t), k in counts.items()
        if k < MIN_FIT_IMPACTS
    ]
    return warnings
