"""``ballbat summary results/{dataset}``: a dataset's headline numbers."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from ..usage import UsageError

if TYPE_CHECKING:
    from collections.abc import Iterable


def _verify_results(paths: Iterable[Path]) -> None:
    """Raise a UsageError naming the first of ``paths`` that is damaged (truncated, not NetCDF)."""
    from ..pipeline.checked import verify_netcdf

    for path in paths:
        try:
            verify_netcdf(path)
        except Exception as exc:  # any damage gets the same answer
            why = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise UsageError(
                f"argument folder: {path} cannot be read ({why}): damaged or cut short; "
                "rerun the workflow to rebuild it"
            ) from None


def summary_lines(folder: Path) -> list[str]:
    """Return the headline numbers of a dataset's results folder as lines of a terminal table."""
    from ..analysis import impact_labels
    from ..pipeline.ncio import read_dataset

    need = {name: folder / f"{name}.nc" for name in ("reconstruct", "fit_ex", "stronge")}
    missing = [str(p) for p in need.values() if not p.is_file()]
    if missing:
        raise UsageError(f"argument folder: {folder} lacks {', '.join(missing)} (run the workflow first)")
    from ..pipeline.checked import DamagedFileError

    _verify_results(need.values())  # a damaged file is named first, before any file's identity
    try:
        read = [read_dataset(path) for path in need.values()]
    except DamagedFileError as exc:  # whole, but not the workflow's (no provenance record)
        raise UsageError(f"argument folder: {exc}") from None
    rec, fit, st = read
    lines = [f"{folder.name}: {rec.sizes['impact']} impacts, {int((rec['flag'].values != 0).sum())} not used (flagged)"]
    from ..compare import format_measurement, systematic_var, total_uncertainty

    scale = systematic_var(fit, "e_x") is not None
    head = f"{'ball':<10} {'bat':<20} {'e_x':>8} {'± stat':>8}"
    head += f" {'± syst':>8} {'± total':>8}" if scale else ""
    lines += ["", head + f" {'95 % interval (stat)':>22} {'n':>4}"]
    for ball in fit["ball"].values.astype(str):
        for bat in [*fit["bat"].values.astype(str), "pooled"]:
            f = fit.sel(ball=ball) if bat == "pooled" else fit.sel(ball=ball, bat=bat)
            pre = "e_x_pooled" if bat == "pooled" else "e_x"
            n = int(f[f"{pre}_n"])
            if n == 0:
                continue
            v, e = float(f[pre]), float(f[f"{pre}_err"])
            sys_ = float(f[systematic_var(f, pre)]) if scale else None
            errs = (e, sys_, total_uncertainty(e, sys_)) if scale else (e,)
            # rounded as the field does: the errors to two significant digits, the value to match
            cells = format_measurement(v, *errs)
            lo, hi = (
                format_measurement(float(f[f"{pre}_ci_low"]), e, sys_)[0],
                format_measurement(float(f[f"{pre}_ci_high"]), e, sys_)[0],
            )
            lines.append(
                f"{ball:<10} {bat:<20} " + " ".join(f"{c:>8}" for c in cells) + f" {f'[{lo}, {hi}]':>22} {n:4d}"
            )
    lines += _e_x_source_lines(fit, scale)
    lines += ["", f"{'ball':<10} {'eta^2':>7} {'± se':>7} {'95 % interval':>17} {'n':>4}"]
    for ball in st["ball"].values.astype(str):
        s = st.sel(ball=ball)
        lo, hi = float(s["eta2_ci_low"]), float(s["eta2_ci_high"])
        lines.append(
            f"{ball:<10} {float(s['eta2']):7.3f} {float(s['eta2_err']):7.3f} {f'[{lo:.3f}, {hi:.3f}]':>17} "
            f"{int(s['eta2_n']):4d}"
        )
    lines += _systematic_lines(fit, st)
    bad = rec["flag"].values != 0
    reasons = rec["flag_reason"].values[bad].astype(str)
    if reasons.size:
        labels = impact_labels(rec)[bad]
        lines += ["", "not used:"] + [f"  {lab}: {r}" for lab, r in zip(labels, reasons, strict=True)]
    return lines


def _e_x_source_lines(fit, scale: bool) -> list[str]:
    """Return what e_x's systematic holds and its split by source (per bat and ball, pooled), or why there is none."""
    from ..compare import NO_SYSTEMATIC_NOTE, source_parts, systematic_note

    if not scale:
        return [f"syst. —: {NO_SYSTEMATIC_NOTE}."]
    lines = [f"syst: {systematic_note(fit)}; total: both in quadrature."]
    if "e_x_syst_by_source" not in fit:
        return lines
    lines.append("e_x syst by source (largest first):")
    for ball in fit["ball"].values.astype(str):
        for bat in [*fit["bat"].values.astype(str), "pooled"]:
            f = fit.sel(ball=ball) if bat == "pooled" else fit.sel(ball=ball, bat=bat)
            parts = source_parts(f, "e_x_pooled" if bat == "pooled" else "e_x")
            if parts:
                lines.append(f"  {ball:<10} {bat:<20} " + ", ".join(f"{n} {v:.2g}" for n, v in parts))
    return lines


#: The per-ball quantities the summary lists with their systematics: (file, variable, unit shown).
SUMMARY_SYSTEMATICS = (
    ("fit", "tan_ratio_slope", "1"),
    ("fit", "e_y_implied", "1"),
    ("fit", "mu_k_lower_bound", "1"),
    ("fit", "spin_theta_slope", "rpm/deg"),
    ("fit", "speed_theta_slope", "mph/deg"),
    ("stronge", "eta2", "1"),
)


def _systematic_lines(fit, st) -> list[str]:
    """Lines of the per-ball quantities with stat, syst and total (datasets with calibration systematics only)."""
    from ..compare import total_uncertainty, uncertainty_decimals
    from ..units import from_si

    files = {"fit": fit, "stronge": st}
    if not any(f"{var}_syst" in files[k] for k, var, _ in SUMMARY_SYSTEMATICS):
        return []
    lines = ["", f"{'ball':<10} {'quantity':<18} {'value':>9} {'± stat':>8} {'± syst':>8} {'± total':>8}  unit"]
    for k, var, unit in SUMMARY_SYSTEMATICS:
        ds = files[k]
        if f"{var}_syst" not in ds:
            continue
        for ball in ds["ball"].values.astype(str):
            f = ds.sel(ball=ball)
            v, e, y = (from_si(float(f[n]), unit) for n in (var, f"{var}_err", f"{var}_syst"))
            total = total_uncertainty(e, y)
            # the decimals of the standard error and the total (a negligible systematic shows as 0)
            d = max(uncertainty_decimals(e, total) or 0, 0)
            cells = [f"{x:.{d}f}" if math.isfinite(x) else "" for x in (v, e, y, total)]
            lines.append(f"{ball:<10} {var:<18} " + " ".join(f"{c:>8}" for c in cells) + f"  {unit}")
    per_source = (
        [
            f"{src} ({float(r):g})" if math.isfinite(r) else f"{src} (absolute: fit_ex.nc's systematic coordinate)"
            for src, r in zip(fit["systematic"].values.astype(str), fit["systematic_rel_sigma"].values, strict=True)
            if r != 0
        ]
        if "systematic_rel_sigma" in fit
        else []
    )
    lines.append("systematic sources (relative sigma): " + (", ".join(per_source) or "none stated"))
    return lines


def cmd_summary(args: argparse.Namespace) -> int:
    """Print the headline numbers of a dataset's results."""
    folder = Path(args.folder)
    if not folder.is_dir():
        raise UsageError(f"argument folder: {folder}: not a directory")
    try:
        lines = summary_lines(folder)
    except KeyError as exc:  # a file of another version of the workflow
        raise UsageError(
            f"argument folder: {folder}: a results file lacks {exc} (made by another version?); rerun the workflow"
        ) from None
    from ..pipeline.cratefiles import earlier_run_notes

    notes = earlier_run_notes(folder, ("reconstruct.nc", "fit_ex.nc", "stronge.nc"))
    for note in notes:  # numbers an earlier run or config made are never shown without saying so
        print(f"ballbat summary: note: {note}", file=sys.stderr)
    if notes:
        print(
            "ballbat summary: these numbers may be from an earlier run or config, not the last run's", file=sys.stderr
        )
    print("\n".join(lines))
    return 0
