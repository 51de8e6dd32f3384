"""The bats league table: every bat's e_x across test sessions, compared (docs/league.md).

A lab tests bats over a season: one test session per bat or per day, the same bat again
after 500 hits. Each session's ``fit_ex.nc`` holds e_x per ball x bat with its standard
error (``e_x_err``: the fit's, with the intrinsic impact-to-impact scatter of e_x in it), the
number of impacts and the calibration systematics by source (``e_x_syst_by_source``).
This module joins them into one table and compares the bats:

* **entries**: one row per ball x bat x session (:func:`entries`);
* **covariance** of the entries (:func:`covariance`): the statistical errors are independent;
  a calibration source's systematic is shared by every entry that shares its calibration,
  source by source (:data:`SHARING`): within a test session for a session's calibrations
  (they cancel in a within-session difference and add in quadrature across sessions);
* **per bat** (:func:`combine`): the generalised-least-squares mean of a bat's sessions,
  its standard error split into stat. and syst., and the consistency chi-square of its sessions;
* **pairwise** differences of the bats of each ball, with standard errors, two-sided
  p-values and Holm's adjustment over every pair of the run (:func:`holm`);
* **equivalence** (TOST) of each bat with the reference bat within a margin (:func:`tost`).

:func:`league` returns the whole as one Dataset (dims ``entry``, ``row``, ``pair``).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from itertools import combinations
from pathlib import Path

import numpy as np
import xarray as xr
from scipy import stats

from .pipeline.products import variable

#: How each calibration source's systematic is shared between entries: ``session`` (each test
#: session calibrates anew: shared by the entries of one session only), ``lab`` (one calibration
#: for every session: shared by every entry), ``bat`` (a property of the bat: shared by one
#: bat's entries in every session). A source not listed here is ``session``.
SHARING = {
    "swing_m_per_px": "session",
    "spin_m_per_px": "session",
    "swing_fps": "session",
    "spin_fps": "session",
    "pivot_to_tip": "session",
    "pivot_to_impact": "session",
}
SHARING_KINDS = ("session", "lab", "bat")

#: fit_ex.nc's variables the league reads (a file without them is of an older format).
REQUIRED = ("e_x", "e_x_err", "e_x_n", "e_x_status", "e_x_scatter")


class LeagueInputError(ValueError):
    """A results folder the league cannot read: no fit_ex.nc, or one of an older format."""


@dataclass(frozen=True)
class LeagueSettings:
    """Settings of the league table (config ``league``; the defaults live in the config schema).

    ``reference_bat``: the bat of the equivalence tests (None: per ball, the bat with the most
    impacts); ``margin``: the equivalence margin in e_x; ``alpha``: the level of every test;
    ``sharing``: source -> ``session``/``lab``/``bat``, overriding :data:`SHARING`.
    """

    reference_bat: str | None
    margin: float
    alpha: float
    sharing: dict

    @classmethod
    def from_config(cls, config: dict) -> LeagueSettings:
        """Return the settings of a config's ``league`` block, checked, the schema's defaults filled."""
        from .pipeline.config import checked_block

        block = checked_block(config.get("league") or {}, "league")
        return cls(block["reference_bat"], float(block["margin"]), float(block["alpha"]), dict(block["sharing"]))

    def kind(self, source: str) -> str:
        """How ``source``'s systematic is shared (``session``, ``lab`` or ``bat``).

        A property table's uncertainty (source ``bat:<bat>:<column>``, ``ball:<ball>:<column>``)
        is the same table's in every session: ``bat`` for a bat's (its entries in every session),
        ``lab`` for a ball's (every entry of that ball; the others' shift is 0).
        """
        if source in self.sharing:
            return self.sharing[source]
        if source.startswith("bat:"):
            return "bat"
        return "lab" if source.startswith("ball:") else SHARING.get(source, "session")


@dataclass(frozen=True)
class Session:
    """One dataset's fits: its test-session label, the folder and dataset it came from."""

    name: str
    folder: str
    dataset: str
    fit: xr.Dataset


# ---------------------------------------------------------------------------------------
# reading


def check_fit(ds: xr.Dataset, where: str) -> None:
    """Raise :class:`LeagueInputError` (one line naming ``where``) when ``ds`` lacks what the league reads."""
    missing = [v for v in REQUIRED if v not in ds.variables]
    if "e_x_err_scale" in ds.variables and "e_x_syst_by_source" not in ds.variables:
        missing.append("e_x_syst_by_source")
    if missing:
        raise LeagueInputError(
            f"{where}: fit_ex.nc of an older format (no {', '.join(missing)}): run the workflow again for it"
        )


def read_folder(folder: str | os.PathLike[str], session: str | None = None) -> list[Session]:
    """Return the sessions of a results folder: its ``{dataset}/fit_ex.nc`` files, or its own fit_ex.nc.

    Each dataset is a test session named by its folder as given (``results/synthetic``; two runs'
    folders of the same dataset name stay apart) unless ``session`` names them all.
    Raises :class:`LeagueInputError` naming the folder when it holds no fit_ex.nc or one the
    league cannot read.
    """
    root = Path(folder)
    if not root.is_dir():
        raise LeagueInputError(f"{folder}: no such folder")
    files = [root / "fit_ex.nc"] if (root / "fit_ex.nc").is_file() else sorted(root.glob("*/fit_ex.nc"))
    if not files:
        raise LeagueInputError(f"{folder}: no fit_ex.nc in it or in its dataset folders (run the workflow first)")
    out = []
    for path in files:
        name = str(path.parent) if path.parent != root else str(folder).rstrip("/") or str(root)
        out.append(read_session(path, session or name, str(root), where=str(folder)))
    return out


def read_session(path: str | os.PathLike[str], label: str, folder: str, where: str | None = None) -> Session:
    """Return the session of one fit_ex.nc (its dataset: the file's folder), named ``label``.

    Raises :class:`LeagueInputError` when the file cannot be read (named after ``where``, default
    the file) or lacks what the league reads (:func:`check_fit`).
    """
    from .pipeline.ncio import read_dataset

    path = Path(path)
    try:
        ds = read_dataset(path)
    except (OSError, ValueError) as exc:
        raise LeagueInputError(f"{where or path.parent}: {path.name} cannot be read: {exc}") from None
    check_fit(ds, str(path))
    return Session(label, folder, path.parent.name, ds)


def _by_source(ds: xr.Dataset, sources: list[str]) -> np.ndarray:
    """e_x's systematic of each of ``sources`` (axis 0), shape (source, ball, bat); 0 where ds has none."""
    out = np.zeros((len(sources), ds.sizes["ball"], ds.sizes["bat"]))
    if "e_x_syst_by_source" in ds:
        have = [str(s) for s in ds["systematic"].values]
        per = ds["e_x_syst_by_source"].transpose("systematic", "ball", "bat").values
        for k, s in enumerate(sources):
            if s in have:
                out[k] = per[have.index(s)]
    return out


def _sources(sessions: list[Session]) -> list[str]:
    names = [*SHARING]
    for s in sessions:
        if "systematic" in s.fit.coords:
            names += [str(v) for v in s.fit["systematic"].values if str(v) not in names]
    return names


def entries(sessions: list[Session]) -> dict[str, np.ndarray]:
    """One entry per ball x bat x session that has impacts (``e_x_n`` > 0).

    Returns arrays over the entries: ``ball``, ``bat``, ``session``, ``dataset``, ``folder``,
    ``e_x``, ``stat`` (``e_x_err``), ``n``, ``scatter``, ``status`` (``e_x_status``: 0 has a
    value; other entries keep NaN and stay out of the comparisons), ``syst_by_source``
    (entry, source) and ``sources``.
    """
    sources = _sources(sessions)
    rows: dict[str, list] = {k: [] for k in ("ball", "bat", "session", "dataset", "folder")}
    nums: dict[str, list] = {k: [] for k in ("e_x", "stat", "n", "scatter", "status", "syst_by_source")}
    for s in sessions:
        ds = s.fit.transpose("ball", "bat", ...)
        per = _by_source(ds, sources)
        for i, ball in enumerate(ds["ball"].values):
            for j, bat in enumerate(ds["bat"].values):
                if int(ds["e_x_n"].values[i, j]) == 0:
                    continue
                for k, v in zip(rows, (ball, bat, s.name, s.dataset, s.folder), strict=True):
                    rows[k].append(str(v))
                for k, var in (("e_x", "e_x"), ("stat", "e_x_err"), ("n", "e_x_n"), ("scatter", "e_x_scatter")):
                    nums[k].append(ds[var].values[i, j])
                nums["status"].append(int(ds["e_x_status"].values[i, j]))
                nums["syst_by_source"].append(per[:, i, j])
    out = {k: np.array(v, dtype=str) for k, v in rows.items()}
    out.update({k: np.array(v, dtype=float) for k, v in nums.items() if k != "syst_by_source"})
    out["syst_by_source"] = np.array(nums["syst_by_source"], dtype=float).reshape(-1, len(sources))
    out["sources"] = np.array(sources, dtype=str)
    return out


# ---------------------------------------------------------------------------------------
# statistics


def covariance(ent: dict[str, np.ndarray], settings: LeagueSettings) -> tuple[np.ndarray, np.ndarray]:
    """Return the entries' statistical and systematic covariance matrices.

    Statistical: diagonal, ``stat**2``. Systematic: for each source k, entries i and j that
    share its calibration (:meth:`LeagueSettings.kind`) covary by ``s_ik * s_jk``; others not.
    The systematics are stored as sizes; a shared calibration moves every bat's e_x the same
    way (docs/league.md), so a within-session difference keeps ``(s_ik - s_jk)**2``.
    """
    stat = np.diag(ent["stat"] ** 2)
    syst = np.zeros_like(stat)
    for k, source in enumerate(ent["sources"]):
        kind = settings.kind(str(source))
        if kind not in SHARING_KINDS:
            raise ValueError(f"league.sharing.{source}: {kind!r} is not one of {', '.join(SHARING_KINDS)}")
        key = {"session": ent["session"], "bat": ent["bat"], "lab": np.zeros(len(ent["bat"]), dtype=str)}[kind]
        shared = key[:, None] == key[None, :]
        s = ent["syst_by_source"][:, k]
        syst += shared * np.outer(s, s)
    return stat, syst


def gls_weights(cov: np.ndarray) -> np.ndarray:
    """Weights of the generalised-least-squares mean of values with covariance ``cov`` (sum 1)."""
    w = np.linalg.solve(cov, np.ones(len(cov)))
    return w / w.sum()


def combine(x: np.ndarray, stat: np.ndarray, syst: np.ndarray) -> dict[str, float]:
    """Return the GLS mean of one bat's session values ``x`` and its consistency chi-square.

    ``stat`` and ``syst``: the values' covariance matrices. Returns ``mean``, ``stat``, ``syst``
    (standard errors of the mean), ``chi2`` (the residuals' ``r' V^-1 r``, ``V = stat + syst``),
    ``dof`` (values - 1) and ``p`` (chi-square survival; NaN for one value).
    """
    cov = stat + syst
    a = gls_weights(cov)
    mean = float(a @ x)
    r = x - mean
    chi2 = float(r @ np.linalg.solve(cov, r))
    dof = len(x) - 1
    return {
        "mean": mean,
        "stat": float(np.sqrt(a @ stat @ a)),
        "syst": float(np.sqrt(max(a @ syst @ a, 0.0))),
        "chi2": chi2 if dof else np.nan,
        "dof": dof,
        "p": float(stats.chi2.sf(chi2, dof)) if dof else np.nan,
    }


def holm(p: np.ndarray) -> np.ndarray:
    """Holm's step-down adjusted p-values (family-wise error; NaN entries are not tests)."""
    p = np.asarray(p, dtype=float)
    out = np.full_like(p, np.nan)
    ok = np.flatnonzero(np.isfinite(p))
    order = ok[np.argsort(p[ok], kind="stable")]
    m = len(order)
    running = 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        out[i] = running
    return out


def tost(d: float, se: float, margin: float, dof: float = np.inf) -> tuple[float, float, float]:
    """Two one-sided tests of ``|d| < margin`` (Student t on ``dof``): ``(p, p_lower, p_upper)``, ``p`` the larger.

    ``p_lower`` tests H0 d <= -margin, ``p_upper`` H0 d >= +margin; equivalence at level
    alpha when ``p < alpha`` (the (1 - 2 alpha) interval of d inside +-margin).
    """
    p_lower = float(stats.t.sf((d + margin) / se, dof))
    p_upper = float(stats.t.cdf((d - margin) / se, dof))
    return max(p_lower, p_upper), p_lower, p_upper


# ---------------------------------------------------------------------------------------
# the table


def _bat_rows(ent: dict, stat: np.ndarray, syst: np.ndarray) -> list[dict]:
    """One row per ball x bat: the GLS mean over its sessions with a value, and its weights."""
    rows = []
    usable = np.isfinite(ent["e_x"])
    for ball in dict.fromkeys(ent["ball"]):
        for bat in sorted(set(ent["bat"][ent["ball"] == ball])):
            mine = (ent["ball"] == ball) & (ent["bat"] == bat)
            idx = np.flatnonzero(mine & usable)
            row = {"ball": ball, "bat": bat, "n": float(ent["n"][mine].sum()), "idx": idx}
            row["sessions"] = ",".join(ent["session"][np.flatnonzero(mine)])
            row["n_sessions"] = len(idx)
            if len(idx):
                sub = np.ix_(idx, idx)
                row.update(combine(ent["e_x"][idx], stat[sub], syst[sub]))
                row["weights"] = gls_weights(stat[sub] + syst[sub])
            else:
                row.update(mean=np.nan, stat=np.nan, syst=np.nan, chi2=np.nan, dof=0, p=np.nan, weights=None)
            rows.append(row)
    return rows


def _difference(a: dict, b: dict, ent: dict, stat: np.ndarray, syst: np.ndarray) -> dict[str, float]:
    """Return the difference of two bat rows' means with its stat. and syst. standard errors and its dof.

    ``dof``: Welch-Satterthwaite's effective degrees of freedom of the variance, each entry's
    statistical variance estimated on ``n - 1`` degrees of freedom, the systematics taken as known.
    """
    if a["weights"] is None or b["weights"] is None:
        return {"d": np.nan, "stat": np.nan, "syst": np.nan, "se": np.nan, "dof": np.nan}
    w = np.zeros(len(ent["e_x"]))
    w[a["idx"]] += a["weights"]
    w[b["idx"]] -= b["weights"]
    vs, vy = float(w @ stat @ w), max(float(w @ syst @ w), 0.0)
    parts = w**2 * np.diag(stat)
    denom = float(np.sum(parts**2 / np.maximum(ent["n"] - 1.0, 1.0)))
    dof = (vs + vy) ** 2 / denom if denom > 0 else np.inf
    return {"d": a["mean"] - b["mean"], "stat": np.sqrt(vs), "syst": np.sqrt(vy), "se": np.sqrt(vs + vy), "dof": dof}


def _pairs(rows: list[dict], ent: dict, stat: np.ndarray, syst: np.ndarray) -> list[dict]:
    """Every pair of bats of the same ball: difference, errors, t, two-sided p (Student t), Holm's p."""
    out = []
    for a, b in combinations(rows, 2):
        if a["ball"] != b["ball"]:
            continue
        diff = _difference(a, b, ent, stat, syst)
        z = diff["d"] / diff["se"] if diff["se"] > 0 else np.nan
        out.append({"ball": a["ball"], "bat_a": a["bat"], "bat_b": b["bat"], **diff, "z": z})
    p = np.array([2 * stats.t.sf(abs(r["z"]), r["dof"]) if np.isfinite(r["z"]) else np.nan for r in out])
    for r, pi, ph in zip(out, p, holm(p), strict=True):
        r["p"], r["p_holm"] = float(pi), float(ph)
    return out


def reference_bats(rows: list[dict], settings: LeagueSettings) -> dict[str, str | None]:
    """Return the reference bat of each ball: the configured one where measured, else the bat with the most impacts.

    A configured reference bat that no ball has raises ValueError naming it.
    """
    balls = list(dict.fromkeys(r["ball"] for r in rows))
    usable = [r for r in rows if np.isfinite(r["mean"])]
    if settings.reference_bat is not None:
        if not any(r["bat"] == settings.reference_bat for r in usable):
            have = ", ".join(sorted({str(r["bat"]) for r in usable}))
            raise ValueError(f"league.reference_bat: {settings.reference_bat!r} has no e_x here (bats: {have})")
        return {
            b: settings.reference_bat
            if any(r["bat"] == settings.reference_bat and r["ball"] == b for r in usable)
            else None
            for b in balls
        }
    out = {}
    for b in balls:
        mine = [r for r in usable if r["ball"] == b]
        out[b] = max(mine, key=lambda r: (r["n"], r["bat"]))["bat"] if mine else None
    return out


def _equivalence(rows: list[dict], refs: dict, ent: dict, stat, syst, settings: LeagueSettings) -> None:
    """Add each row's TOST against its ball's reference bat (``tost_*``; NaN where not tested)."""
    by_key = {(r["ball"], r["bat"]): r for r in rows}
    for r in rows:
        r.update(tost_d=np.nan, tost_se=np.nan, tost_dof=np.nan, tost_p=np.nan, tost_equivalent=-1)
        ref = refs.get(r["ball"])
        if ref is None or ref == r["bat"] or not np.isfinite(r["mean"]):
            continue
        diff = _difference(r, by_key[(r["ball"], ref)], ent, stat, syst)
        p = tost(diff["d"], diff["se"], settings.margin, diff["dof"])[0]
        r.update(tost_d=diff["d"], tost_se=diff["se"], tost_dof=diff["dof"], tost_p=p)
        r["tost_equivalent"] = int(p < settings.alpha)


def league(sessions: list[Session], settings: LeagueSettings | None = None) -> xr.Dataset:
    """Return the league table of ``sessions``: entries, bats (GLS over sessions), pairs and TOST, one Dataset.

    Raises ValueError when the sessions hold no entry or two sessions share a name and a bat.
    """
    settings = settings or LeagueSettings.from_config({})
    ent = entries(sessions)
    if not len(ent["e_x"]):
        raise ValueError("league: the results hold no bat with impacts")
    seen = list(zip(ent["ball"], ent["bat"], ent["session"], strict=True))
    if len(set(seen)) != len(seen):
        dup = next(k for k in seen if seen.count(k) > 1)
        raise ValueError(f"league: {dup[1]} ({dup[0]}) twice in test session {dup[2]!r}: name the sessions apart")
    stat, syst = covariance(ent, settings)
    rows = _bat_rows(ent, stat, syst)
    pairs = _pairs(rows, ent, stat, syst)
    refs = reference_bats(rows, settings)
    _equivalence(rows, refs, ent, stat, syst, settings)
    ds = xr.Dataset(
        {**_entry_vars(ent, stat, syst), **_row_vars(rows, settings), **_pair_vars(pairs, settings)},
        attrs={
            "league_margin": settings.margin,
            "league_alpha": settings.alpha,
            "league_reference_bats": "; ".join(f"{b}: {r}" for b, r in refs.items()),
            "league_sharing": "; ".join(f"{s}: {settings.kind(str(s))}" for s in ent["sources"]),
        },
    )
    return ds.assign_coords(systematic=("systematic", ent["sources"], {"long_name": "calibration source"}))


def _entry_vars(ent: dict, stat: np.ndarray, syst: np.ndarray) -> dict[str, tuple]:
    e = "entry"
    return {
        "entry_ball": variable(e, ent["ball"], None, "ball type of the entry (one bat x ball x test session)"),
        "entry_bat": variable(e, ent["bat"], None, "bat of the entry"),
        "entry_session": variable(e, ent["session"], None, "test session of the entry"),
        "entry_dataset": variable(e, ent["dataset"], None, "dataset of the entry"),
        "entry_folder": variable(e, ent["folder"], None, "results folder of the entry"),
        "entry_e_x": variable(e, ent["e_x"], "1", "e_x of the bat in this session (fit_ex.nc e_x)"),
        "entry_e_x_stat": variable(e, ent["stat"], "1", "statistical standard error of e_x (fit_ex.nc e_x_err)"),
        "entry_e_x_syst": variable(
            e, np.sqrt(np.diag(syst)), "1", "systematic error of e_x: every calibration source in quadrature"
        ),
        "entry_e_x_syst_by_source": variable(
            (e, "systematic"), ent["syst_by_source"], "1", "systematic error of e_x from each calibration source"
        ),
        "entry_e_x_scatter": variable(e, ent["scatter"], "1", "intrinsic impact-to-impact sd of e_x (in e_x_stat)"),
        "entry_n": variable(e, ent["n"].astype(np.int64), "1", "impacts in the fit of e_x"),
        "entry_status": variable(e, ent["status"].astype(np.int8), "1", "fit_ex.nc e_x_status (0: e_x has a value)"),
    }


def _row_vars(rows: list[dict], settings: LeagueSettings) -> dict[str, tuple]:
    r = "row"
    col = {k: [row[k] for row in rows] for k in rows[0] if k not in ("idx", "weights")}
    what = "of the bat over its test sessions (generalised least squares, shared systematics as covariances)"
    return {
        "ball": variable(r, np.array(col["ball"], dtype=str), None, "ball type"),
        "bat": variable(r, np.array(col["bat"], dtype=str), None, "bat"),
        "sessions": variable(r, np.array(col["sessions"], dtype=str), None, "the bat's test sessions, comma-separated"),
        "e_x": variable(r, col["mean"], "1", f"e_x {what}"),
        "e_x_stat": variable(r, col["stat"], "1", f"statistical standard error of e_x {what}"),
        "e_x_syst": variable(r, col["syst"], "1", f"systematic error of e_x {what}"),
        "e_x_err_total": variable(r, np.hypot(col["stat"], col["syst"]), "1", "stat. and syst. in quadrature"),
        "n": variable(r, np.array(col["n"], dtype=np.int64), "1", "impacts of the bat with this ball, all sessions"),
        "n_sessions": variable(r, np.array(col["n_sessions"]), "1", "test sessions with a value of e_x"),
        "consistency_chi2": variable(r, col["chi2"], "1", "chi-square of the bat's sessions about their mean"),
        "consistency_dof": variable(r, np.array(col["dof"]), "1", "degrees of freedom of consistency_chi2"),
        "consistency_p": variable(r, col["p"], "1", "p-value of consistency_chi2 (NaN: one session)"),
        "tost_difference": variable(r, col["tost_d"], "1", "e_x of the bat minus the reference bat's"),
        "tost_se": variable(r, col["tost_se"], "1", "standard error of tost_difference (stat. and syst.)"),
        "tost_dof": variable(r, col["tost_dof"], "1", "Welch-Satterthwaite degrees of freedom of tost_se"),
        "tost_p": variable(
            r, col["tost_p"], "1", f"p-value of the two one-sided tests of |difference| < {settings.margin}"
        ),
        "tost_equivalent": variable(
            r,
            np.array(col["tost_equivalent"], dtype=np.int8),
            "1",
            f"1: equivalent to the reference bat within +-{settings.margin} at alpha {settings.alpha}; "
            "0: not shown equivalent; -1: not tested (the reference bat itself, or no value)",
            flag_values=np.array([-1, 0, 1], dtype=np.int8),
            flag_meanings="not_tested not_shown_equivalent equivalent",
        ),
    }


def _pair_vars(pairs: list[dict], settings: LeagueSettings) -> dict[str, tuple]:
    p = "pair"
    keys = ("ball", "bat_a", "bat_b", "d", "stat", "syst", "se", "dof", "z", "p")
    col = {k: [row[k] for row in pairs] for k in keys}
    col["p_holm"] = [row["p_holm"] for row in pairs]
    return {
        "pair_ball": variable(p, np.array(col["ball"], dtype=str), None, "ball type of the pair"),
        "pair_bat_a": variable(p, np.array(col["bat_a"], dtype=str), None, "first bat of the pair"),
        "pair_bat_b": variable(p, np.array(col["bat_b"], dtype=str), None, "second bat of the pair"),
        "pair_difference": variable(p, np.array(col["d"], dtype=float), "1", "e_x of bat_a minus e_x of bat_b"),
        "pair_stat": variable(p, np.array(col["stat"], dtype=float), "1", "statistical standard error of it"),
        "pair_syst": variable(
            p, np.array(col["syst"], dtype=float), "1", "systematic error of it (shared calibrations cancel)"
        ),
        "pair_se": variable(p, np.array(col["se"], dtype=float), "1", "standard error of it, stat. and syst."),
        "pair_dof": variable(
            p, np.array(col["dof"], dtype=float), "1", "Welch-Satterthwaite degrees of freedom of pair_se"
        ),
        "pair_t": variable(p, np.array(col["z"], dtype=float), "1", "difference over its standard error"),
        "pair_p": variable(
            p, np.array(col["p"], dtype=float), "1", "two-sided p-value of no difference (Student t on pair_dof)"
        ),
        "pair_p_holm": variable(
            p, np.array(col["p_holm"], dtype=float), "1", "pair_p adjusted by Holm over every pair of the table"
        ),
        "pair_differs": variable(
            p,
            (np.array(col["p_holm"], dtype=float) < settings.alpha).astype(np.int8),
            "1",
            f"1: the bats differ at family-wise level {settings.alpha} (pair_p_holm < alpha)",
        ),
    }


# ---------------------------------------------------------------------------------------
# the table as text


#: league.csv's columns: header -> the league Dataset's row variable.
CSV_COLUMNS = {
    "ball": "ball",
    "bat": "bat",
    "e_x": "e_x",
    "e_x_stat": "e_x_stat",
    "e_x_syst": "e_x_syst",
    "e_x_err_total": "e_x_err_total",
    "n": "n",
    "n_sessions": "n_sessions",
    "sessions": "sessions",
    "consistency_chi2": "consistency_chi2",
    "consistency_dof": "consistency_dof",
    "consistency_p": "consistency_p",
    "tost_difference": "tost_difference",
    "tost_se": "tost_se",
    "tost_p": "tost_p",
    "tost_equivalent": "tost_equivalent",
}


def ranked(ds: xr.Dataset) -> list[int]:
    """Return the rows of the league Dataset ``ds`` in league order: per ball, e_x from the highest."""
    balls = list(dict.fromkeys(str(b) for b in ds["ball"].values))
    e = ds["e_x"].values
    key = [(balls.index(str(b)), -v if np.isfinite(v) else np.inf) for b, v in zip(ds["ball"].values, e, strict=True)]
    return sorted(range(ds.sizes["row"]), key=lambda i: key[i])


def _cell(v: object) -> str:
    if isinstance(v, float | np.floating):
        return "" if not np.isfinite(v) else f"{float(v):.6g}"
    return str(v)


def csv_text(ds: xr.Dataset) -> str:
    """league.csv: one row per ball x bat in league order (:data:`CSV_COLUMNS`)."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_COLUMNS)
    for i in ranked(ds):
        w.writerow([_cell(ds[v].values[i]) for v in CSV_COLUMNS.values()])
    return buf.getvalue()


def _fmt(v: float, digits: int = 3) -> str:
    return "   --" if not np.isfinite(v) else f"{v:.{digits}f}"


def _p(v: float) -> str:
    return "   --" if not np.isfinite(v) else ("<1e-4" if v < 1e-4 else f"{v:.4f}")


def table_lines(ds: xr.Dataset) -> list[str]:
    """Return the league table in words: e_x with stat. and syst. per bat, sessions, consistency, TOST."""
    margin, alpha = ds.attrs["league_margin"], ds.attrs["league_alpha"]
    out = [
        f"League table (e_x per bat; reference bats: {ds.attrs['league_reference_bats']}; "
        f"TOST margin +-{margin:g}, alpha {alpha:g})",
        f"{'ball':9} {'bat':20} {'e_x':>6} {'stat':>6} {'syst':>6} {'n':>5} {'sess':>4} "
        f"{'chi2/dof':>10} {'p_cons':>6} {'d_ref':>7} {'p_TOST':>6}  equivalent",
    ]
    words = {1: "yes", 0: "no", -1: "(reference)"}
    for i in ranked(ds):
        g = {k: ds[k].values[i] for k in ds.data_vars if ds[k].dims == ("row",)}
        chi = f"{g['consistency_chi2']:.2f}/{int(g['consistency_dof'])}" if g["consistency_dof"] else "--"
        eq = words[int(g["tost_equivalent"])] if np.isfinite(g["e_x"]) else "(no value)"
        out.append(
            f"{g['ball']:9} {g['bat']:20} {_fmt(g['e_x'])} {_fmt(g['e_x_stat'], 4)} {_fmt(g['e_x_syst'], 4)} "
            f"{int(g['n']):5d} {int(g['n_sessions']):4d} {chi:>10} {_p(g['consistency_p']):>6} "
            f"{_fmt(g['tost_difference']):>7} {_p(g['tost_p']):>6}  {eq}"
        )
    return out


def pair_lines(ds: xr.Dataset) -> list[str]:
    """Return the pairwise differences in words, with Holm-adjusted p-values."""
    alpha = ds.attrs["league_alpha"]
    out = [
        f"Pairwise differences (Holm over {ds.sizes['pair']} pairs; differs: adjusted p < {alpha:g})",
        f"{'ball':9} {'bat a':20} {'bat b':20} {'a - b':>7} {'stat':>6} {'syst':>6} {'p':>6} {'p_Holm':>6}  differs",
    ]
    for i in range(ds.sizes["pair"]):
        g = {k: ds[k].values[i] for k in ds.data_vars if ds[k].dims == ("pair",)}
        out.append(
            f"{g['pair_ball']:9} {g['pair_bat_a']:20} {g['pair_bat_b']:20} {_fmt(g['pair_difference']):>7} "
            f"{_fmt(g['pair_stat'], 4)} {_fmt(g['pair_syst'], 4)} {_p(g['pair_p']):>6} {_p(g['pair_p_holm']):>6}  "
            f"{'yes' if g['pair_differs'] else 'no'}"
        )
    return out
