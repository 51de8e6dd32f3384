"""The report's front page: the run's headline numbers, written from its NetCDF files.

Snakemake renders the workflow description (``workflow/report/workflow.rst``) as a Jinja
template, then as reStructuredText, and shows it first when the report opens. Jinja sees the
config but not the results, so a job (rule ``report_front``) writes the page's content as a
reStructuredText fragment from the NetCDF files, and the description pulls it in with an
``.. include::`` directive, as the figure captions pull in their numbers (:mod:`ballbat.reporting`).
The replicate studies, which run only on request, write a fragment of their own
(rule ``report_front_studies``), pulled in only when the report holds their figures.

Numbers are rounded as the field does (:func:`round_pm`): each uncertainty to two significant
digits, the value to the same decimal place.

Nothing here imports matplotlib.
"""

from __future__ import annotations

import base64
import io
import math
import re
import subprocess
from typing import TYPE_CHECKING
from urllib.parse import quote

import numpy as np

from .compare import NO_SYSTEMATIC_NOTE, SYSTEMATIC_NOTE, source_parts, systematic_note, systematic_var
from .published import PUBLISHED, per_ball

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping, Sequence

    import xarray as xr

#: The dash of a range (en dash).
DASH = "\u2013"

#: Excluded impacts named one by one on the front page; more are counted and left to the workbook.
MAX_NAMED_EXCLUSIONS = 8

#: The classes of a table whose number cells do not wrap (workflow/report/workflow.rst): its numbers are short.
NUMBERS = "headline numbers"

#: Width in pixels of the Fig. 5 thumbnail embedded in the front page.
THUMBNAIL_WIDTH = 520


def decimals_for(*uncertainties: float) -> int | None:
    """Decimal places that show the smallest finite, positive uncertainty to two significant digits.

    None when no uncertainty is finite and positive. Negative for uncertainties of 100 or more
    (the value is then rounded to tens, hundreds, ...).
    """
    errs = [abs(float(e)) for e in uncertainties if e is not None and math.isfinite(float(e)) and float(e) > 0]
    if not errs:
        return None
    err = min(errs)
    d = 1 - math.floor(math.log10(err))
    rounded = round(err, d)
    if rounded >= 10.0 ** (2 - d):  # 0.0996 -> 0.10: one digit fewer
        d -= 1
    return d


def fixed(x: float, d: int) -> str:
    """``x`` rounded to ``d`` decimal places (``d`` < 0: to tens, hundreds, ...); 'n/a' if not finite."""
    x = float(x)
    if not math.isfinite(x):
        return "n/a"
    if d >= 0:
        return f"{x:.{d}f}"
    return f"{round(x, d):.0f}"


def round_pm(value: float, *uncertainties: float) -> tuple[str, ...]:
    """Value and uncertainties as strings rounded as the field does.

    The smallest uncertainty to two significant digits, the value and the other uncertainties
    to the same decimal place. Without a usable uncertainty the value gets three significant
    digits and each uncertainty 'n/a'.
    """
    d = decimals_for(*uncertainties)
    if d is None:
        v = float(value)
        return (f"{v:.3g}" if math.isfinite(v) else "n/a", *("n/a" for _ in uncertainties))
    return (fixed(value, d), *(fixed(e, d) if math.isfinite(float(e)) else "n/a" for e in uncertainties))


def pm(value: float, err: float, syst: float = math.nan) -> str:
    """``value ± err`` rounded as the field does (the value alone when the error is unusable).

    With a systematic error (finite and positive): ``value ± err ± syst syst.``.
    """
    if math.isfinite(float(syst)) and float(syst) > 0:
        v, e, y = round_pm(value, err, syst)
        return f"{v} ± {e} ± {y} syst." if e != "n/a" else f"{v} ± {y} syst."
    v, e = round_pm(value, err)
    return v if e == "n/a" else f"{v} ± {e}"


def _syst(ds: xr.Dataset, var: str) -> float:
    """Return the combined systematic of ``var`` in ``ds`` (a one-ball selection), NaN when it has none."""
    name = systematic_var(ds, var)
    return float(ds[name]) if name else math.nan


def _published(quantity: str, ball: str, bat: str = "") -> tuple[float, float | None] | None:
    for p in PUBLISHED:
        if p.quantity == quantity and p.ball == ball and p.bat == bat:
            return p.value, p.uncertainty
    return None


def _paper(quantity: str, ball: str, bat: str = "") -> str:
    pub = _published(quantity, ball, bat)
    if pub is None:
        return "—"
    value, err = pub
    if err is None:
        return f"{value:g}"
    d = max(_places(value), _places(err))  # as published: 0.405 ± 0.010, 0.130 ± 0.038
    return f"{value:.{d}f} ± {err:.{d}f}"


def _places(x: float) -> int:
    text = f"{x:g}"
    return len(text.split(".")[1]) if "." in text else 0


def _words(name: str) -> str:
    return name.replace("_", " ")


def escape(text: str) -> str:
    r"""Text as reStructuredText shows it literally (``*``, ``_``, backquotes, ``|`` and ``\`` escaped)."""
    return re.sub(r"([\\*`_|])", r"\\\1", str(text))


def _flag_meanings(var: xr.DataArray) -> dict[int, str]:
    values = np.atleast_1d(var.attrs.get("flag_values", []))
    meanings = str(var.attrs.get("flag_meanings", "")).split()
    return {int(v): m for v, m in zip(values, meanings, strict=False)}


def exclusion_reasons(impacts: xr.Dataset) -> dict[str, list[str]]:
    """Excluded impacts (``flag != 0``) grouped by their short reason, in file order: {reason: [impact ids]}.

    The reason is the flag's meaning (``flag_meanings``); an impact excluded at ingest or when the
    tracks were reduced gets the meaning of its ``ingest_flag`` instead.
    """
    flag = impacts["flag"].values
    meaning = _flag_meanings(impacts["flag"])
    ingest = impacts["ingest_flag"].values if "ingest_flag" in impacts else None
    ingest_meaning = _flag_meanings(impacts["ingest_flag"]) if ingest is not None else {}
    ids = impacts["impact_id"].values.astype(str) if "impact_id" in impacts.variables else impacts["impact"].values
    groups: dict[str, list[str]] = {}
    for i in np.flatnonzero(flag != 0):
        if ingest is not None and int(ingest[i]) != 0:
            reason = ingest_meaning.get(int(ingest[i]), f"ingest flag {int(ingest[i])}")
        else:
            reason = meaning.get(int(flag[i]), f"flag {int(flag[i])}")
        groups.setdefault(_words(reason), []).append(escape(ids[i]))
    return groups


def dataset_line(name: str, kind: str, impacts: xr.Dataset) -> str:
    """One line: the dataset, its kind, its impacts per ball and the excluded ones with why."""
    balls = impacts["ball"].values.astype(str)
    per = ", ".join(f"{int(np.count_nonzero(balls == b))} {escape(b)}" for b in dict.fromkeys(balls))
    n = impacts.sizes["impact"]
    groups = exclusion_reasons(impacts)
    k = sum(len(v) for v in groups.values())
    line = f"**{escape(name)}** ({kind}): {n} impacts ({per}); {n - k} used, {k} excluded"
    if not k:
        return line + "."
    parts = []
    for reason, ids in groups.items():
        shown = ", ".join(ids[:MAX_NAMED_EXCLUSIONS])
        more = f" and {len(ids) - MAX_NAMED_EXCLUSIONS} more" if len(ids) > MAX_NAMED_EXCLUSIONS else ""
        noun = "impact" if len(ids) == 1 else "impacts"
        parts.append(f"{reason} ({len(ids)}: {noun} {shown}{more})")
    return line + ": " + "; ".join(parts) + " (every impact and its reason: the workbook's impacts sheet)."


def scenario_line(name: str, scenario: xr.Dataset) -> str:
    """One line: a batted-ball scenario, its ball, bat, e_x and number of cases."""
    a = scenario.attrs
    kind = {"sweep": "D sweep", "launch": "launch conditions"}.get(str(a.get("kind", "")), str(a.get("kind", "")))
    e_x = a.get("e_x")
    e_x_text = f", e_x = {float(e_x):.3g}" if e_x is not None else ""
    return (
        f"**{escape(name)}** ({kind}): {escape(a.get('ball', '?'))} on the {escape(_words(str(a.get('bat', '?'))))}"
        f" bat{e_x_text};"
        f" {scenario.sizes.get('case', 0)} cases."
    )


def _table(header: Sequence[str], rows: Sequence[Sequence[str]], title: str, classes: str = "headline") -> list[str]:
    lines = [f".. list-table:: {title}", "   :header-rows: 1", f"   :class: {classes}", ""]
    for row in [header, *rows]:
        lines.append(f"   * - {row[0]}")
        lines += [f"     - {cell}" for cell in row[1:]]
    return [*lines, ""]


def e_x_rows(fit: xr.Dataset) -> list[list[str]]:
    """Rows ball, bat, e_x, stat., syst., paper (and truth for synthetic data) of the headline table.

    Per bat x ball with a value, then the pooled fit (Eq. ex) of each ball. The systematic is the
    calibration one of tracked data (``e_x_syst``: every source in quadrature); '—' where there is none.
    """
    truth = "truth_e_x" in fit
    rows = []
    for ball in fit["ball"].values.astype(str):
        cells = [(bat, fit.sel(ball=ball, bat=bat), "e_x") for bat in fit["bat"].values.astype(str)]
        cells.append(("pooled (Eq. ex)", fit.sel(ball=ball), "e_x_pooled"))
        for bat, f, var in cells:
            value = float(f[var])
            if not math.isfinite(value):
                continue
            stat = float(f[f"{var}_err"])
            syst = _syst(f, var)
            has_syst = math.isfinite(syst) and syst > 0
            v, s, y = round_pm(value, stat, syst) if has_syst else (*round_pm(value, stat), "—")
            paper = _paper("e_x", ball, bat) if var == "e_x" else _paper("e_x_pooled", ball)
            row = [escape(ball), escape(_words(bat)), f"**{v}**", f"± {s}", f"± {y}" if has_syst else "—", paper]
            if truth:
                row.append(fixed(float(f[f"truth_{var}"]), 3))
            rows.append(row)
    return rows


def per_ball_rows(fit: xr.Dataset, stronge: xr.Dataset) -> list[list[str]]:
    """Rows ball, eta^2 ± s.e., 95 % interval, paper, implied e_y, mu_k bound, paper's bound."""
    rows = []
    paper_eta2 = per_ball("eta2")
    for ball in stronge["ball"].values.astype(str):
        s = stronge.sel(ball=ball)
        eta2, err = float(s["eta2"]), float(s["eta2_err"])
        d = decimals_for(err)
        interval = "n/a" if d is None else f"{fixed(s['eta2_ci_low'], d)} {DASH} {fixed(s['eta2_ci_high'], d)}"
        paper = f"{paper_eta2[ball]:g}" if ball in paper_eta2 else "—"
        e_y = mu_k = "n/a"
        if ball in fit["ball"].values.astype(str):
            f = fit.sel(ball=ball)
            e_y = pm(float(f["e_y_implied"]), float(f["e_y_implied_err"]), _syst(f, "e_y_implied"))
            mu_k = "≥ " + pm(
                float(f["mu_k_lower_bound"]), float(f["mu_k_lower_bound_err"]), _syst(f, "mu_k_lower_bound")
            )
        paper_mu = _published("mu_k_lower_bound", ball)
        paper_mu_text = "—" if paper_mu is None else f"≥ {paper_mu[0]:g}"
        rows.append([escape(ball), f"**{pm(eta2, err, _syst(s, 'eta2'))}**", interval, paper, e_y, mu_k, paper_mu_text])
    return rows


def fit_warnings(fit: xr.Dataset) -> list[str]:
    """Return a line per e_x fit without a value for a reason other than having no impacts (status > 1)."""
    lines = []
    for name in ("e_x", "e_x_pooled"):
        var = fit.get(f"{name}_status")
        if var is None:
            continue
        meaning = _flag_meanings(var)
        for idx in zip(*np.nonzero(var.values > 1), strict=True):
            where = ", ".join(str(fit[dim].values[i]) for dim, i in zip(var.dims, idx, strict=True))
            lines.append(f"{name} ({where}): {_words(meaning.get(int(var.values[idx]), 'no value'))}")
    return lines


def thumbnail_uri(png: str | os.PathLike[str], width: int = THUMBNAIL_WIDTH) -> str:
    """Return a PNG figure shrunk to ``width`` pixels, as a data URI (for embedding in the front page)."""
    from PIL import Image

    with Image.open(png) as im:
        im = im.convert("RGB")
        if im.width > width:
            im = im.resize((width, round(im.height * width / im.width)), Image.Resampling.LANCZOS)
        buf = io.BytesIO()
        im.save(buf, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def result_link(path: str) -> str:
    """Return the report's link to a result's own page (what Snakemake's report opens for a figure)."""
    return f"javascript:app.showResultInfo('{quote(str(path))}')"


def commit_date(commit: str, repo: str | os.PathLike[str] = ".") -> str | None:
    """Return the date (YYYY-MM-DD) of a git commit, or None when git or the commit is not there."""
    if not commit or commit == "unknown":
        return None
    try:
        out = subprocess.run(
            ["git", "show", "-s", "--format=%cs", commit], cwd=repo, capture_output=True, text=True, check=False
        )
    except OSError:
        return None
    text = out.stdout.strip()
    return text if out.returncode == 0 and text else None


def provenance_line(git: Mapping[str, object], date: str | None, results: str = "results") -> str:
    """One line: the commit the results were made from, clean or not, its date, and where the full record is."""
    commit = str(git.get("commit") or "unknown")
    if commit == "unknown":
        state = "not a git checkout: the package source's sha256 identifies the code"
    else:
        state = "uncommitted changes in the tree" if git.get("dirty") else "clean tree"
        state += f", committed {date}" if date else ""
    return (
        f"**Provenance:** commit ``{commit[:12]}`` ({state}). The full record (every input with its sha256,"
        " the config values each job used, the software versions) is in the ``provenance_*`` attributes of"
        " every NetCDF file and in each workbook's provenance sheet; the run as a whole, every job with its"
        " inputs, config values and outputs, is the Provenance Run Crate "
        f"``{results}/ro-crate-metadata.json``."
    )


def source_note(fit: xr.Dataset) -> list[str]:
    """Return the pooled e_x's systematic split by source, one sentence per ball (none for tracked data alone)."""
    if systematic_note(fit) == SYSTEMATIC_NOTE:  # the default run's front page as it was
        return []
    out = []
    for ball in fit["ball"].values.astype(str):
        parts = source_parts(fit.sel(ball=ball), "e_x_pooled")
        if parts:
            split = ", ".join(f"{escape(n)} {v:.2g}" for n, v in parts)
            out.append(f"By source, pooled e_x of the {escape(ball)}: {split}.")
    return out


def dataset_section(
    name: str,
    fit: xr.Dataset,
    stronge: xr.Dataset,
    fig5: str | None = None,
    thumbnail: str | None = None,
) -> list[str]:
    """Return the headline tables of one dataset, and its Fig. 5 thumbnail linking to the figure's page."""
    title = f"Dataset {escape(name)}"
    lines = [title, "-" * len(title), ""]
    header = ["ball", "bat", "e_x", "stat.", "syst.", "paper"] + (["truth"] if "truth_e_x" in fit else [])
    lines += _table(header, e_x_rows(fit), "e_x per bat and ball (Table II) and pooled (Eq. ex)", NUMBERS)
    lines += _table(
        ["ball", "η²", "95 % interval", "paper", "e_y implied", "μ_k bound", "paper"],
        per_ball_rows(fit, stronge),
        "η² of Stronge's model (Sec. V.A); e_y implied by Eq. ratio and the μ_k bound (Sec. IV)",
    )
    has_syst = any(r[4] != "—" for r in e_x_rows(fit))
    note = ["stat.: the standard error."]
    if has_syst:
        what = "calibration systematic" if systematic_note(fit) == SYSTEMATIC_NOTE else "systematic"
        note.append(f"syst.: the {what}, {systematic_note(fit)}.")
        note += source_note(fit)
    else:
        note.append(f"syst. —: {NO_SYSTEMATIC_NOTE}.")
    if "truth_e_x" in fit:
        note.append("truth: the value the synthetic experiment was drawn with.")
    lines += [" ".join(note), ""]
    if thumbnail:
        target = f"   :target: {result_link(fig5)}\n" if fig5 else ""
        # docutils limits a source line's length (10000), so a data URI spans lines (whitespace is dropped).
        chunks = [thumbnail[i : i + 100] for i in range(0, len(thumbnail), 100)]
        lines += [
            f".. figure:: {chunks[0]}",
            *(f"   {c}" for c in chunks[1:]),
            "   :alt: Fig. 5 of dataset " + name,
            "   :figclass: thumbnail",
            *([target.rstrip("\n")] if target else []),
            "",
            f"   Fig. 5 of **{escape(name)}**: spin against the bracket of Eq. (omega), slopes 1 + e_x per ball;"
            " click it for the figure's page and caption.",
            "",
        ]
    return lines


def _league_rows(league: xr.Dataset) -> list[list[str]]:
    """Rows of the league table: per ball, the bats from the highest e_x (those with a value)."""
    balls = list(dict.fromkeys(str(b) for b in league["ball"].values))
    e_x = league["e_x"].values
    rank = [-v if math.isfinite(v) else math.inf for v in e_x.astype(float)]
    order = sorted(range(league.sizes["row"]), key=lambda i: (balls.index(str(league["ball"].values[i])), rank[i]))
    rows = []
    words = {1: "yes", 0: "not shown", -1: "reference"}
    for i in order:
        g = {k: league[k].values[i] for k in league.data_vars if league[k].dims == ("row",)}
        if not math.isfinite(float(g["e_x"])):
            continue
        v, s, y = round_pm(float(g["e_x"]), float(g["e_x_stat"]), float(g["e_x_syst"]))
        p_cons = float(g["consistency_p"])
        cons = f"{p_cons:.2g}" if math.isfinite(p_cons) else "—"
        n, sessions, eq = str(int(g["n"])), str(int(g["n_sessions"])), words[int(g["tost_equivalent"])]
        bat = escape(_words(str(g["bat"])))
        rows.append([escape(str(g["ball"])), bat, f"**{v}**", f"± {s}", f"± {y}", n, sessions, cons, eq])
    return rows


def _pair_rows(league: xr.Dataset) -> list[list[str]]:
    """Rows of the pairs: ball, bats, difference ± its standard error, Holm-adjusted p, whether they differ."""
    rows = []
    for i in range(league.sizes["pair"]):
        g = {k: league[k].values[i] for k in league.data_vars if league[k].dims == ("pair",)}
        diff, se = float(g["pair_difference"]), float(g["pair_se"])
        if not math.isfinite(diff):
            continue
        bats = f"{escape(_words(str(g['pair_bat_a'])))} − {escape(_words(str(g['pair_bat_b'])))}"
        differs = "**yes**" if int(g["pair_differs"]) else "no"
        rows.append([escape(str(g["pair_ball"])), bats, pm(diff, se), f"{float(g['pair_p_holm']):.2g}", differs])
    return rows


def league_section(league: xr.Dataset) -> list[str]:
    """Return the bats league table (league.nc, :mod:`ballbat.league`): per bat, then every pair.

    Per ball, the bats from the highest e_x: e_x with stat. and syst. over its test sessions, impacts,
    sessions, the consistency p of a bat in several sessions and the equivalence test against the
    reference bat; then each pair's difference with its standard error and Holm-adjusted p.
    """
    margin, alpha = float(league.attrs["league_margin"]), float(league.attrs["league_alpha"])
    lines = ["Bats league table", "-" * 17, ""]
    lines += _table(
        ["ball", "bat", "e_x", "stat.", "syst.", "n", "sessions", "consistency p", f"within ±{margin:g} of ref."],
        _league_rows(league),
        "e_x per bat over the run's test sessions, highest first (league.nc, league.xlsx)",
        NUMBERS,
    )
    lines += _table(
        ["ball", "bats", "difference ± s.e.", "p (Holm)", "differ"],
        _pair_rows(league),
        f"every pair of bats of a ball: difference, its standard error (stat. and syst.), Holm-adjusted p at {alpha:g}",
        NUMBERS,
    )
    refs = escape(str(league.attrs.get("league_reference_bats", "")))
    lines += [
        "A calibration systematic shared within a test session cancels in a difference of two bats of that"
        " session and adds across sessions (docs/league.md); the equivalence test is TOST against the"
        f" reference bat ({refs}).",
        "",
    ]
    return lines


def front_page(
    datasets: Mapping[str, Mapping[str, object]],
    scenarios: Mapping[str, xr.Dataset],
    warnings: Sequence[str],
    git: Mapping[str, object],
    date: str | None,
    results: str = "results",
    league: xr.Dataset | None = None,
) -> str:
    """Return the front page's reStructuredText.

    ``datasets``: name -> {"kind": str, "impacts": reconstruct.nc, "fit": fit_ex.nc,
    "stronge": stronge.nc, and optionally "fig5": the figure's path and "thumbnail": its data URI}.
    ``results``: the run's results folder (config ``results``); ``league``: the run's league table
    (league.nc), shown when the run has one (more than one bat of a ball, or more than one dataset).
    """
    lines = ["What was run", "-" * 12, ""]
    for name, d in datasets.items():
        lines.append(f"- Dataset {dataset_line(name, str(d['kind']), d['impacts'])}")
    for name, sc in scenarios.items():
        lines.append(f"- Scenario {scenario_line(name, sc)}")
    lines.append("")
    for name, d in datasets.items():
        lines += dataset_section(name, d["fit"], d["stronge"], d.get("fig5"), d.get("thumbnail"))
    if league is not None:
        lines += league_section(league)
    all_warnings = list(warnings)
    for name, d in datasets.items():
        impacts, fit = d["impacts"], d["fit"]
        noted = [w for w in str(impacts.attrs.get("ingest_warnings", "")).split("\n") if w]
        noted += fit_warnings(fit)
        # a warning the job logged is already in ``warnings`` (with its log file)
        all_warnings += [f"{name}: {w}" for w in noted if not any(w in logged for logged in warnings)]
    lines += ["Warnings and provenance", "-" * 23, ""]
    if all_warnings:
        lines += [f"**{len(dict.fromkeys(all_warnings))} warnings of this run:**", ""]
        lines += [f"- {escape(w)}" for w in dict.fromkeys(all_warnings)]
    else:
        lines.append("No warnings in this run.")
    lines += ["", provenance_line(git, date, results), ""]
    return "\n".join(lines).rstrip("\n") + "\n"


def study_line(name: str, coverage: xr.Dataset, design: xr.Dataset | None = None) -> str:
    """One line per study: replicates, the range of the 95 % coverage, and a design's impacts per bat."""
    c95 = coverage["coverage_95"].values
    ok = np.isfinite(c95)
    n_rep = coverage.attrs.get("replicates_per_point", "?")
    nq = coverage.sizes["quantity"]
    if ok.any():
        low, high = 100 * c95[ok].min(), 100 * c95[ok].max()
        cov = f"95 % intervals cover the truth in {low:.1f}{DASH}{high:.1f} % of replicates"
    else:
        cov = "no coverage (no quantity had a value, an uncertainty and a truth)"
    param = str(coverage.attrs.get("sweep_parameter") or "")
    sweep = ""
    if param and "setting" in coverage:
        values = coverage["setting"].values
        sweep = f", {escape(param)} {values.min():g}{DASH}{values.max():g}"
    line = f"**{escape(name)}** ({n_rep} replicates per point{sweep}, {nq} quantities): {cov} (target 95 %)"
    if design is None:
        return line + "."
    a = design.attrs
    req = design["impacts_required"].values[-1]
    balls = design["ball"].values.astype(str)
    parts = []
    for ball in dict.fromkeys(balls):
        r = req[(balls == ball) & np.isfinite(req)]
        if r.size:
            span = f"{r.min():.0f}{DASH}{r.max():.0f}" if r.min() != r.max() else f"{r.min():.0f}"
            parts.append(f"{escape(ball)} {span}")
    need = ", ".join(parts) if parts else "not determined"
    where = ""
    if "setting" in design and a.get("sweep_parameter"):
        where = f", from the spread at {escape(a['sweep_parameter'])} = {design['setting'].values[-1]:g}"
    return (
        f"{line}; impacts per bat to tell two bats Δe_x = {float(a['delta_e_x']):g} apart"
        f" ({100 * float(a['confidence']):g} % confidence, {100 * float(a['power']):g} % power{where}): {need}."
    )


def studies_page(studies: Mapping[str, tuple[xr.Dataset, xr.Dataset | None]]) -> str:
    """Return the studies' part of the front page: one line per study."""
    lines = ["Replicate studies", "-" * 17, ""]
    lines += [f"- {study_line(name, cov, des)}" for name, (cov, des) in studies.items()]
    return "\n".join(lines) + "\n"
