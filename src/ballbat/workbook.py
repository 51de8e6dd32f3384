"""Results workbooks: a dataset's (or the implications') results as a spreadsheet in the field's units.

A bat-testing lab writes its report in a spreadsheet, in mph, degrees, rpm, inches and feet.
:func:`dataset_workbook` gathers the NetCDF results of one dataset (impacts, e_x per bat and
ball, the Sec. IV quantities, eta^2) and its paper comparison into one ``.xlsx`` file, one sheet
per table; :func:`implications_workbook` does the same for the batted-ball scenarios. Every
sheet has the column names of ``docs/nomenclature.md`` in its first row and, in the second, what
each is in words with the unit it is shown in (both rows frozen, the columns sized); the
``legend`` sheet explains every code of every status and flag column; the last sheet records the
provenance of every file it was made from.

Units ``1`` (dimensionless numbers) are shown as a blank unit cell. Cells keep the full
precision of the NetCDF files; number formats show them as the field rounds them: an estimate
and its errors with the error to two significant digits (the finest error of the row setting
the decimals), other numbers to a fixed number of decimals per unit. Every estimate of a
dataset reduced from camera tracks has its statistical standard error, its systematic error
(``<name>_syst``: every stated calibration uncertainty in quadrature, :mod:`ballbat.systematics`)
and their total (``<name>_err_total``); the ``systematics`` sheet gives each calibration
source's part.

The workbook is byte-identical on rerun: its document properties and the zip entries carry the
date of the git commit the results were made with (``SOURCE_DATE_EPOCH`` when set; the paper's
publication date when neither is known), not the clock (openpyxl would write the current time).
Its custom document properties carry its provenance: every input file with its sha256, the
ballbat version, the sha256 of the package's and the workflow's source, the git commit.

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017).
"""

from __future__ import annotations

import datetime as _dt
import io
import json
import zipfile
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .compare import NO_SYSTEMATIC_NOTE, systematic_var, total_uncertainty
from .pipeline.atomic import atomic_target
from .units import from_si

if TYPE_CHECKING:
    import os
    from collections.abc import Mapping, Sequence

    import xarray as xr

#: The time written into the workbook's properties and zip entries when no commit date is known.
FIXED_TIME = _dt.datetime(2017, 5, 3)  # the paper's publication month
#: Decimals shown for a number without an error of its own, by unit.
UNIT_DECIMALS = {"mph": 1, "deg": 1, "rpm": 0, "in": 2, "ft": 1, "s": 2, "mph/deg": 3, "rpm/deg": 1, "1": 3}


def _number_format(decimals: int | None) -> str:
    """Return an Excel number format with ``decimals`` decimals ("General" for None)."""
    if decimals is None:
        return "General"
    return "0" if decimals <= 0 else "0." + "0" * decimals


def _unit_label(unit: str) -> str:
    """Return the unit as the header shows it: blank for dimensionless numbers ("1")."""
    return "" if unit == "1" else unit


def document_time(fit_attrs: dict | None = None) -> _dt.datetime:
    """Return the time the workbook's properties carry.

    That is ``SOURCE_DATE_EPOCH`` when set, else the date of the git commit recorded in the
    results (``provenance_git``), else :data:`FIXED_TIME`.
    """
    import os

    if os.environ.get("SOURCE_DATE_EPOCH", "").strip().isdigit():
        stamp = _dt.datetime.fromtimestamp(int(os.environ["SOURCE_DATE_EPOCH"]), tz=_dt.UTC)
        return stamp.replace(tzinfo=None)
    from .pipeline.provenance import commit_time

    commit = json.loads((fit_attrs or {}).get("provenance_git", "{}")).get("commit", "unknown")
    when = commit_time(commit)
    return when if when is not None else FIXED_TIME


@dataclass(frozen=True)
class Column:
    """One column of a sheet: the results variable, its header, and the unit it is shown in."""

    var: str
    unit: str  # a unit of ballbat.units.TO_SI ("1" for numbers without units, "" for text)
    header: str | None = None  # default: ``var``

    @property
    def name(self) -> str:
        """Return the header of the column."""
        return self.header or self.var


#: The impacts sheet (reconstruct.nc), paper units.
IMPACT_COLUMNS = (
    Column("impact", "1"),
    Column("impact_id", ""),
    Column("ball", ""),
    Column("bat", ""),
    Column("v_bat", "mph"),
    Column("v_bat_err", "mph"),
    Column("v_ball", "mph"),
    Column("v_ball_err", "mph"),
    Column("theta", "deg"),
    Column("theta_err", "deg"),
    Column("omega", "rpm"),
    Column("omega_err", "rpm"),
    Column("omega_norm", "rpm"),
    Column("v_ball_norm", "mph"),
    Column("psi", "deg"),
    Column("D", "in"),
    Column("r_x", "1"),
    Column("r_y", "1"),
    Column("flag", "1"),
    Column("flag_reason", ""),
)

#: e_x per bat x ball and pooled (fit_ex.nc): the fields of each fit (value, standard error,
#: 95 % interval, impacts, reduced chi-square), headed by their names in fit_ex.nc.
FIT_FIELDS = (
    Column("", "1", "e_x"),
    Column("_err", "1", "e_x_err"),
    Column("_ci_low", "1", "e_x_ci_low"),
    Column("_ci_high", "1", "e_x_ci_high"),
    Column("_n", "1", "e_x_n"),
    Column("_redchi", "1", "e_x_redchi"),
)

#: Sec. IV quantities per ball (fit_ex.nc): (variable, unit, its standard error or None).
SEC4_COLUMNS = (
    ("tan_ratio_slope", "1", "tan_ratio_slope_err"),
    ("e_y_implied", "1", "e_y_implied_err"),
    ("mu_k_lower_bound", "1", "mu_k_lower_bound_err"),
    ("spin_theta_slope", "rpm/deg", "spin_theta_slope_err"),
    ("spin_theta_slope_intercept", "rpm", None),
    ("speed_theta_slope", "mph/deg", "speed_theta_slope_err"),
    ("speed_theta_slope_intercept", "mph", None),
    ("gross_slip_psi", "deg", None),
    ("gross_slip_theta", "deg", None),
    ("gross_slip_omega", "rpm", None),
)

#: Stronge's model per ball (stronge.nc).
STRONGE_COLUMNS = (
    Column("eta2", "1"),
    Column("eta2_err", "1"),
    Column("eta2_syst", "1"),
    Column("eta2_err_total", "1"),
    Column("eta2_ci_low", "1"),
    Column("eta2_ci_high", "1"),
    Column("eta2_dof", "1"),
    Column("eta2_n", "1"),
    Column("eta2_redchi", "1"),
    Column("e_y", "1"),
    Column("e_y_syst", "1"),
    Column("mu", "1"),
    Column("mu_syst", "1"),
    Column("omega_ratio", "1"),
    Column("psi_stick_boundary", "deg"),
    Column("psi_gross_slip_boundary", "deg"),
)

#: A batted-ball scenario's cases (implications/{scenario}.nc); the 68 % and 95 % bands from e_x's
#: uncertainty where the scenario takes e_x from a dataset (:mod:`ballbat.scenario_bands`).
SCENARIO_COLUMNS = (
    Column("case", "1"),
    Column("D", "in"),
    Column("psi", "deg"),
    Column("exit_speed", "mph"),
    Column("exit_speed_low68", "mph"),
    Column("exit_speed_high68", "mph"),
    Column("exit_speed_low95", "mph"),
    Column("exit_speed_high95", "mph"),
    Column("launch_angle", "deg"),
    Column("launch_angle_low68", "deg"),
    Column("launch_angle_high68", "deg"),
    Column("launch_angle_low95", "deg"),
    Column("launch_angle_high95", "deg"),
    Column("spray_angle", "deg"),
    Column("backspin", "rpm"),
    Column("backspin_low68", "rpm"),
    Column("backspin_high68", "rpm"),
    Column("backspin_low95", "rpm"),
    Column("backspin_high95", "rpm"),
    Column("sidespin", "rpm"),
    Column("carry", "ft"),
    Column("carry_low68", "ft"),
    Column("carry_high68", "ft"),
    Column("carry_low95", "ft"),
    Column("carry_high95", "ft"),
    Column("apex", "ft"),
    Column("hang_time", "s"),
    Column("landing_x", "ft"),
    Column("landing_y", "ft"),
    Column("exceeds_mu", "1"),
)


def _cell(value: object, unit: str) -> object:
    """Return a spreadsheet cell value: numbers in ``unit`` (NaN as an empty cell), text as is."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]  # a 0-d array (one cell of a .sel): its scalar, so that counts stay integers
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, str):
        return value
    v = float(value)
    if not np.isfinite(v):
        return None
    if unit in ("", "1", "s"):
        return int(v) if float(v).is_integer() and isinstance(value, np.integer | int) else v
    return float(from_si(v, unit))


#: Words for the columns that are no variable of the sheet's NetCDF source (a variable's long_name otherwise).
WORDS = {
    "ball": "ball type",
    "bat": "bat",
    "quantity": "quantity",
    "paper": "the paper's value",
    "paper_uncertainty": "the paper's uncertainty",
    "value": "value",
    "uncertainty": "our statistical standard error",
    "systematic": "our calibration systematic",
    "truth": "the true value (synthetic data)",
    "unit": "unit of the row's numbers",
    "source": "calibration source",
    "source_rel_sigma": "relative standard uncertainty of the calibration source",
    "warning": "warning of the measured file",
    "file": "results file",
    "record": "kind of record",
    "key": "input, config key or software",
    "sheet": "sheet",
    "column": "column (code name)",
    "meaning": "what the value means",
    "e_x_err_total": "total error of e_x: statistical and systematic in quadrature",
    "e_x_status": "why e_x has no value (0: it has one)",
}
#: Widest and narrowest column (characters); the words row wraps within it.
COLUMN_WIDTH = (10, 32)


def _words(name: str, unit: str, sources: Sequence[xr.Dataset] = ()) -> str:
    """Return a column's header in words, with its unit: the long_name of its variable, else :data:`WORDS`."""
    text = WORDS.get(name, name.replace("_", " "))
    for ds in sources:
        if name in ds.variables and "long_name" in ds[name].attrs:
            text = str(ds[name].attrs["long_name"])
            break
    label = _unit_label(unit)
    return f"{text} ({label})" if label else text


def _header(ws: object, names: Sequence[str], units: Sequence[str], sources: Sequence[xr.Dataset] = ()) -> None:
    """Write the two header rows, frozen: the code names, then each in words with its unit; set the widths.

    The code names (``docs/nomenclature.md``) are the first row, so that a program finds a column by
    name; the second says what it is, with the unit it is shown in (none for text and for "1").
    """
    from openpyxl.styles import Alignment, Font
    from openpyxl.utils import get_column_letter

    ws.append(list(names))
    ws.append([_words(n, u, sources) for n, u in zip(names, units, strict=True)])
    ws.freeze_panes = "A3"
    low, high = COLUMN_WIDTH
    for i, name in enumerate(names, start=1):
        ws.cell(1, i).font = Font(bold=True)
        ws.cell(2, i).alignment = Alignment(wrap_text=True, vertical="top")
        ws.column_dimensions[get_column_letter(i)].width = min(max(len(name) + 2, low), high)


def _format_row(ws: object, row: Sequence[object], units: Sequence[str], groups: Sequence[Group]) -> None:
    """Append ``row`` and give its number cells their formats.

    Each group's columns are shown with the decimals of its errors (:func:`ballbat.compare.
    uncertainty_decimals`); other number columns with :data:`UNIT_DECIMALS` of their unit.
    """
    from .compare import uncertainty_decimals

    ws.append(list(row))
    cells = ws[ws.max_row]
    done = set()
    for errors, members in groups:
        d = uncertainty_decimals(*(row[c] for c in errors if isinstance(row[c], float)))
        for c in members:
            if isinstance(row[c], float):
                cells[c].number_format = _number_format(d)
                done.add(c)
    for c, value in enumerate(row):
        if c in done or isinstance(value, str) or value is None:
            continue
        if isinstance(value, int):
            cells[c].number_format = "0"
        else:
            cells[c].number_format = _number_format(UNIT_DECIMALS.get(units[c], 3))


#: (columns of the errors that set the decimals, columns shown with them)
Group = tuple[list[int], list[int]]


def _error_groups(names: Sequence[str]) -> list[Group]:
    """Return the groups of each estimate with an error column among ``names``: value, errors, interval.

    The errors that set the decimals are the standard error ``<name>_err`` and the systematic
    ``<name>_syst``; the total ``<name>_err_total`` and the interval are shown with them.
    """
    index = {n: i for i, n in enumerate(names)}
    groups = []
    for name, i in index.items():
        errors = [index[f"{name}{s}"] for s in ("_err", "_syst") if f"{name}{s}" in index]
        if errors:
            others = ("_err", "_syst", "_err_total", "_ci_low", "_ci_high")
            members = [i] + [index[f"{name}{s}"] for s in others if f"{name}{s}" in index]
            groups.append((errors, members))
    return groups


def _table_sheet(wb: object, title: str, ds: xr.Dataset, columns: Sequence[Column], dim: str) -> None:
    """Add a sheet with one row per element of ``dim`` and the ``columns`` present in ``ds``."""
    cols = [c for c in columns if c.var in ds.variables]
    ws = wb.create_sheet(title)
    names, units = [c.name for c in cols], [c.unit for c in cols]
    _header(ws, names, units)
    for i, c in enumerate(cols, start=1):  # each column's words from its own variable's long_name
        if "long_name" in ds[c.var].attrs:
            ws.cell(2, i).value = _words(c.var, c.unit, [ds])
    groups = _error_groups(names)
    for i in range(ds.sizes[dim]):
        row = [_cell(ds[c.var].values[i] if ds[c.var].dims else ds[c.var].values, c.unit) for c in cols]
        _format_row(ws, row, units, groups)


def _provenance_sheet(wb: object, sources: dict[str, xr.Dataset]) -> None:
    """Add the provenance sheet: for every source file its rule, inputs (with sha256), config and software."""
    ws = wb.create_sheet("provenance")
    _header(ws, ["file", "record", "key", "value"], ["", "", "", ""])
    for name, ds in sources.items():
        ws.append([name, "title", "", str(ds.attrs.get("title", ""))])
        ws.append([name, "rule", "", str(ds.attrs.get("provenance_rule", ""))])
        for f in json.loads(ds.attrs.get("provenance_inputs", "[]")):
            ws.append([name, "input", str(f.get("path")), str(f.get("sha256"))])
        for record in ("config", "software", "git"):
            values = json.loads(ds.attrs.get(f"provenance_{record}", "{}"))
            for key in sorted(values):
                ws.append([name, record, key, json.dumps(values[key], sort_keys=True)])


def custom_properties(inputs: Mapping[str, str | os.PathLike[str]]) -> dict[str, str]:
    """Return the workbook's provenance as custom document properties (name -> text, each under 255 characters).

    ``inputs`` maps a name to each file the workbook is made from; each is recorded with its
    sha256, beside the ballbat version, the sha256 of the package's and the workflow's source,
    and the git commit (with whether the tree had uncommitted changes).
    """
    from .pipeline.provenance import git_state, sha256_file, software_versions

    versions = software_versions()
    git = git_state()
    props = {
        "ballbat version": str(versions["ballbat"]),
        "ballbat source sha256": str(versions["ballbat_source_sha256"]),
        "workflow source sha256": str(versions["workflow_source_sha256"]),
        "git commit": str(git["commit"]),
        "git dirty": str(git["dirty"]),
    }
    for name, path in inputs.items():
        props[f"input {name}"] = f"{path} sha256:{sha256_file(path)}"[-255:]
    return props


def _fixed_bytes(wb: object, when: _dt.datetime, properties: Mapping[str, str] | None = None) -> bytes:
    """Return the workbook as bytes with the time ``when`` (properties and zip entries) and custom properties."""
    from openpyxl.packaging.custom import StringProperty

    wb.properties.created = when
    wb.properties.modified = when
    wb.properties.creator = "ballbat"
    wb.properties.lastModifiedBy = "ballbat"
    for name, value in (properties or {}).items():
        wb.custom_doc_props.append(StringProperty(name=name, value=value))
    raw = io.BytesIO()
    wb.save(raw)
    out = io.BytesIO()
    with zipfile.ZipFile(raw) as zin, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in sorted(zin.infolist(), key=lambda i: i.filename):
            data = zin.read(info.filename)
            if info.filename == "docProps/core.xml":  # openpyxl stamps "modified" with the clock on save
                data = _fix_core_times(data, when)
            fixed = zipfile.ZipInfo(info.filename, date_time=max(when, _dt.datetime(1980, 1, 1)).timetuple()[:6])
            fixed.compress_type = zipfile.ZIP_DEFLATED
            fixed.external_attr = 0o644 << 16
            zout.writestr(fixed, data)
    return out.getvalue()


def _fix_core_times(xml: bytes, when: _dt.datetime) -> bytes:
    """Return docProps/core.xml with its created/modified times set to ``when``."""
    import re

    stamp = when.strftime("%Y-%m-%dT%H:%M:%SZ").encode()
    return re.sub(rb"(<dcterms:(?:created|modified)[^>]*>)[^<]*(</dcterms:)", rb"\g<1>" + stamp + rb"\g<2>", xml)


def _write(wb: object, path: str | os.PathLike[str], when: _dt.datetime, properties: Mapping[str, str] | None) -> None:
    data = _fixed_bytes(wb, when, properties)
    with atomic_target(path) as tmp:
        tmp.write_bytes(data)


def dataset_workbook(
    path: str | os.PathLike[str],
    impacts: xr.Dataset,
    fit: xr.Dataset,
    stronge: xr.Dataset,
    comparison: list[dict],
    properties: Mapping[str, str] | None = None,
) -> None:
    """Write one dataset's results workbook.

    Parameters
    ----------
    path : str or path-like
        The ``.xlsx`` file to write (atomically).
    impacts, fit, stronge : xarray.Dataset
        ``reconstruct.nc``, ``fit_ex.nc`` and ``stronge.nc`` of the dataset.
    comparison : list of dict
        The rows of ``paper_comparison.csv`` (:func:`ballbat.compare.read_csv`).
    properties : mapping, optional
        Custom document properties (its provenance: :func:`custom_properties`).

    Notes
    -----
    Sheets: ``impacts`` (one row per impact, flags and reasons kept), ``e_x`` (per bat and
    ball, then pooled per ball as bat ``pooled``), ``sec4`` (Eq. ratio, implied e_y, the mu_k
    bound, Figs. 3-4 slopes, the gross-slip example), ``eta2`` (Stronge's model),
    ``paper_comparison``, ``warnings`` (those of a measured file) and ``provenance``.
    """
    from openpyxl import Workbook

    wb = Workbook()
    wb.remove(wb.active)
    _table_sheet(wb, "impacts", impacts, IMPACT_COLUMNS, "impact")

    ws = wb.create_sheet("e_x")
    names = ["ball", "bat", *(c.name for c in FIT_FIELDS[:2]), "e_x_syst", "e_x_err_total"]
    names += [*(c.name for c in FIT_FIELDS[2:]), "e_x_status"]
    units = ["", "", *("1" for _ in names[2:])]
    _header(ws, names, units, [fit])
    # decimals from the statistical and systematic errors; value, errors and interval shown with them
    groups = [([3, 4], [2, 3, 4, 5, 6, 7])]
    for ball in fit["ball"].values.astype(str):
        for bat in [*fit["bat"].values.astype(str), "pooled"]:
            f = fit.sel(ball=ball) if bat == "pooled" else fit.sel(ball=ball, bat=bat)
            pre = "e_x_pooled" if bat == "pooled" else "e_x"
            if int(f[f"{pre}_n"]) == 0:
                continue
            stat = _cell(f[f"{pre}_err"].values, "1")
            syst_var = systematic_var(f, pre)
            syst = _cell(f[syst_var].values, "1") if syst_var else None
            total = None if stat is None else total_uncertainty(stat, syst)
            row = [ball, bat, _cell(f[pre].values, "1"), stat, syst, total]
            row += [_cell(f[f"{pre}{c.var}"].values, "1") for c in FIT_FIELDS[2:]]
            _format_row(ws, [*row, int(f[f"{pre}_status"])], units, groups)

    ws = wb.create_sheet("sec4")
    names, units = ["ball"], [""]
    # each quantity: value, standard error, and where the dataset has them its systematic and total
    cols = []
    for var, unit, err in SEC4_COLUMNS:
        cols += [(var, unit)] + ([(err, unit)] if err else [])
        cols += [(f"{var}{s}", unit) for s in ("_syst", "_err_total") if f"{var}{s}" in fit]
    names += [c for c, _ in cols]
    units += [u for _, u in cols]
    _header(ws, names, units, [fit])
    groups = _error_groups(names)
    for ball in fit["ball"].values.astype(str):
        f = fit.sel(ball=ball)
        _format_row(ws, [ball, *(_cell(f[c].values, u) for c, u in cols)], units, groups)

    _table_sheet(
        wb,
        "eta2",
        stronge.assign_coords(ball_name=stronge["ball"]),
        (Column("ball_name", "", "ball"), *STRONGE_COLUMNS),
        "ball",
    )

    _systematics_sheet(wb, fit, stronge)

    ws = wb.create_sheet("paper_comparison")
    if comparison:
        keys = list(comparison[0])
        _header(ws, keys, ["" for _ in keys])
        for row in comparison:
            ws.append([_number_or_text(row[k]) for k in keys])
    ws = wb.create_sheet("warnings")
    _header(ws, ["warning"], [""])
    for text in (w for w in impacts.attrs.get("ingest_warnings", "").split("\n") if w):
        ws.append([text])
    _legend_sheet(wb, [impacts, fit, stronge])
    _provenance_sheet(wb, {"reconstruct.nc": impacts, "fit_ex.nc": fit, "stronge.nc": stronge})
    _write(wb, path, document_time(fit.attrs), properties)


#: Units in the field's units of the quantities with systematics (fit_ex.nc, stronge.nc).
SYSTEMATIC_UNITS = {
    **{var: unit for var, unit, _ in SEC4_COLUMNS},
    "e_x": "1",
    "e_x_pooled": "1",
    "eta2": "1",
    "e_y": "1",
    "mu": "1",
}


def _systematics_sheet(wb: object, fit: xr.Dataset, stronge: xr.Dataset) -> None:
    """Add the ``systematics`` sheet: each quantity's systematic from each calibration source (tracked data).

    One row per quantity, ball (and bat), and source with a stated uncertainty, with its
    relative standard uncertainty (empty for an absolute one, the angle offset); a dataset with
    none has one row saying so (source ``none stated``, the reason in the unit column's place).
    """
    ws = wb.create_sheet("systematics")
    _header(ws, ["quantity", "ball", "bat", "source", "source_rel_sigma", "systematic", "unit"], [""] * 5 + ["1", ""])
    if not any("systematic" in ds.coords for ds in (fit, stronge)):  # "syst. —", and why
        ws.append(["e_x", "", "", "none stated", None, None, NO_SYSTEMATIC_NOTE])
    for ds in (fit, stronge):
        if "systematic" not in ds.coords:
            continue
        sources = ds["systematic"].values.astype(str)
        rel = dict(zip(sources, ds["systematic_rel_sigma"].values.astype(float), strict=True))
        for q, unit in SYSTEMATIC_UNITS.items():
            if f"{q}_syst_by_source" not in ds:
                continue
            per = ds[f"{q}_syst_by_source"]
            for idx in np.ndindex(per.shape[1:]):
                where = {d: str(ds[d].values[i]) for d, i in zip(per.dims[1:], idx, strict=True)}
                for k, src in enumerate(sources):
                    if rel[src] == 0 or not np.isfinite(per.values[(k, *idx)]):
                        continue  # (a NaN relative sigma, an absolute one such as angle_offset, is kept)
                    row = [q, where.get("ball", ""), where.get("bat", ""), src, _cell(rel[src], "1")]
                    row += [_cell(per.values[(k, *idx)], unit), _unit_label(unit)]
                    _format_row(ws, row, ["", "", "", "", "1", unit, ""], [([5], [5])])


#: Legends of the status and flag columns whose variable states no CF ``flag_values``/``flag_meanings``
#: (the league's entry_status and pair_differs; a file of an older format). entry_status is fit_ex.nc's
#: e_x_status (``fitting.FitStatus``, not imported: the workbook rules would then follow the fitting code;
#: tests/test_workbook.py checks the two agree).
LEGENDS = {
    "entry_status": {0: "ok", 1: "no impacts", 2: "too few impacts", 3: "fit failed"},
    "exceeds_mu": {0: "within friction", 1: "needs more friction than mu"},
    "tost_equivalent": {-1: "not tested", 0: "not shown equivalent", 1: "equivalent"},
    "pair_differs": {
        0: "not shown to differ at the family-wise level alpha (pair_p_holm >= alpha)",
        1: "the bats differ at the family-wise level alpha (pair_p_holm < alpha)",
    },
}


def is_status_column(name: str) -> bool:
    """Whether a column is a status or flag column (its values are codes, explained in the legend sheet)."""
    return name in ("flag", "exceeds_mu") or name.endswith(("_status", "_flag", "_differs", "_equivalent"))


def _legend(name: str, sources: Sequence[xr.Dataset]) -> dict[int, str]:
    """Return a status column's codes and their meanings: its variable's flag_values/flag_meanings, else LEGENDS."""
    for var in (name, name.replace("e_x_status", "e_x_pooled_status")):
        for ds in sources:
            attrs = ds[var].attrs if var in ds.variables else {}
            if "flag_values" in attrs and "flag_meanings" in attrs:
                values = np.atleast_1d(attrs["flag_values"]).astype(int)
                meanings = str(attrs["flag_meanings"]).split()
                return {int(v): m.replace("_", " ") for v, m in zip(values, meanings, strict=True)}
    return LEGENDS.get(name, {})


def _legend_sheet(wb: object, sources: Sequence[xr.Dataset]) -> None:
    """Add the ``legend`` sheet: for every status and flag column of every sheet, each code and what it means.

    A status column with no legend (no flag meanings in its file) is an error: its codes would be unexplained.
    """
    ws = wb.create_sheet("legend")
    _header(ws, ["sheet", "column", "value", "meaning"], ["", "", "1", ""])
    for sheet in wb.worksheets[:-1]:
        for name in [c.value for c in sheet[1]] if sheet.max_row else []:
            if not isinstance(name, str) or not is_status_column(name):
                continue
            legend = _legend(name, sources)
            if not legend:
                raise ValueError(f"workbook sheet {sheet.title}: column {name} has no legend of its codes")
            for value, meaning in sorted(legend.items()):
                ws.append([sheet.title, name, value, meaning])


def _number_or_text(value: object) -> object:
    if value is None or value == "":
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        return value


def implications_workbook(
    path: str | os.PathLike[str], scenarios: dict[str, xr.Dataset], properties: Mapping[str, str] | None = None
) -> None:
    """Write the batted-ball scenarios' workbook: one sheet per scenario, then the provenance.

    Each case is a row: D and psi (D sweeps), exit speed, launch and spray angles, backspin and
    sidespin, carry, apex, hang time and landing point, in mph, deg, rpm, in, ft and s.
    """
    from openpyxl import Workbook

    wb = Workbook()
    wb.remove(wb.active)
    for name in sorted(scenarios):
        _table_sheet(wb, name[:31], scenarios[name], SCENARIO_COLUMNS, "case")
    _legend_sheet(wb, [scenarios[name] for name in sorted(scenarios)])
    _provenance_sheet(wb, {f"{name}.nc": ds for name, ds in sorted(scenarios.items())})
    first = scenarios[sorted(scenarios)[0]].attrs if scenarios else {}
    _write(wb, path, document_time(first), properties)


#: The league table's sheets (results/league.nc; :mod:`ballbat.league`): sheet -> (dimension, columns).
LEAGUE_SHEETS = {
    "league": (
        "row",
        tuple(
            Column(v, "1")
            for v in (
                "ball",
                "bat",
                "e_x",
                "e_x_stat",
                "e_x_syst",
                "e_x_err_total",
                "n",
                "n_sessions",
                "sessions",
                "consistency_chi2",
                "consistency_dof",
                "consistency_p",
                "tost_difference",
                "tost_se",
                "tost_dof",
                "tost_p",
                "tost_equivalent",
            )
        ),
    ),
    "pairs": (
        "pair",
        tuple(
            Column(v, "1")
            for v in (
                "pair_ball",
                "pair_bat_a",
                "pair_bat_b",
                "pair_difference",
                "pair_stat",
                "pair_syst",
                "pair_se",
                "pair_dof",
                "pair_t",
                "pair_p",
                "pair_p_holm",
                "pair_differs",
            )
        ),
    ),
    "sessions": (
        "entry",
        tuple(
            Column(v, "1")
            for v in (
                "entry_ball",
                "entry_bat",
                "entry_session",
                "entry_dataset",
                "entry_folder",
                "entry_e_x",
                "entry_e_x_stat",
                "entry_e_x_syst",
                "entry_e_x_scatter",
                "entry_n",
                "entry_status",
            )
        ),
    ),
}


def league_workbook(
    path: str | os.PathLike[str], league: xr.Dataset, properties: Mapping[str, str] | None = None
) -> None:
    """Write the bats league table's workbook: the table, the pairs, the sessions' entries, the provenance."""
    from openpyxl import Workbook

    wb = Workbook()
    wb.remove(wb.active)
    for title, (dim, columns) in LEAGUE_SHEETS.items():
        _table_sheet(wb, title, league, columns, dim)
    _legend_sheet(wb, [league])
    _provenance_sheet(wb, {"league.nc": league})
    _write(wb, path, document_time(league.attrs), properties)
