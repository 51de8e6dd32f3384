"""Ball and bat properties (Tables I and II of Kensrud et al. 2017) and recoil factors.

The property tables live in CSV files in the paper's units (``config/balls.csv`` and
``config/bats.csv``); :func:`load_balls` and :func:`load_bats` read them, check every row
and return SI dataclasses. :func:`recoil_normal` and :func:`recoil_tangential` are the
kinematic recoil factors r_y (Eq. ry) and r_x (Eq. rx).

References
----------
.. [1] J. R. Kensrud, A. M. Nathan and L. V. Smith, "Oblique collisions of baseballs and
   softballs with a bat", Am. J. Phys. 85, 503 (2017).
"""

from __future__ import annotations

import csv
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from . import batlab
from .units import INCH, OUNCE, OZ_IN2

if TYPE_CHECKING:
    import os
    from collections.abc import Sequence

    import numpy as np
    from numpy.typing import ArrayLike


class InputError(ValueError):
    """Bad user input; the message names the file, the row, the column and the problem.

    ``problems`` holds every problem found (a file is checked whole, not up to the first
    problem).
    """

    def __init__(self, problems: list[str]):
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))


@dataclass(frozen=True)
class Ball:
    """A ball type, SI units. ``alpha`` is I_ball / (m r^2) (Eq. iball)."""

    ball: str
    name: str
    m: float  # kg
    r: float  # m
    alpha: float = 0.4
    psi_max: float = math.nan  # rad, Table I (experiment's range, not a property)
    D_max: float = math.nan  # m, Table I
    err: str = ""  # JSON {column: [value, standard uncertainty]}, tables' units, of each stated *_err (empty: none)


@dataclass(frozen=True)
class Bat:
    """A bat at its impact location, SI units (Table II)."""

    bat: str
    name: str
    M: float  # kg
    I0: float  # kg m^2, about the centre of mass, perpendicular to the axis
    Iz: float  # kg m^2, about the long axis
    b: float  # m, impact location from the centre of mass
    R: float  # m, bat radius at the impact location
    convention: str = "paper"  # the table's convention (ballbat.batlab.CONVENTIONS)
    given: str = ""  # JSON of the row's cells as given in its table (empty: not from a table)
    err: str = ""  # JSON {column: standard uncertainty}, tables' units, of each stated *_err (empty: none)


#: Columns of the ball table: name -> (unit factor to SI, required, must be positive).
BALL_COLUMNS = {
    "ball": (None, True, False),
    "name": (None, False, False),
    "m_oz": (OUNCE, True, True),
    "m_oz_sd": (OUNCE, False, False),
    "r_in": (INCH, True, True),
    "r_in_sd": (INCH, False, False),
    "alpha": (1.0, False, True),
    "psi_max_deg": (math.pi / 180, False, True),
    "D_max_in": (INCH, False, True),
    # standard uncertainties of the table's values (not the ball-to-ball spread *_sd): optional, >= 0
    "m_oz_err": (OUNCE, False, False),
    "r_in_err": (INCH, False, False),
    "alpha_err": (1.0, False, False),
}
#: A ball's uncertain properties: table column -> (Ball field, unit factor to SI).
BALL_ERR_FIELDS = {"m_oz": ("m", OUNCE), "r_in": ("r", INCH), "alpha": ("alpha", 1.0)}


#: A number written with a decimal comma (European spreadsheets), e.g. ``68,7`` or ``-1,5e3``.
_DECIMAL_COMMA = re.compile(r"^[+-]?\d*,\d+([eE][+-]?\d+)?$")


def without_check_line(path: Path, text: str) -> str:
    """``text`` without ballbat's check line at its end (``ballbat import-tracks`` writes one), verified.

    A table that ends in the check line but no longer matches it was cut short or edited after
    ballbat wrote it: refused, naming the file (an edit on purpose: delete the last line).
    """
    from .pipeline.checked import csv_problem, split_check_line

    body, trailer = split_check_line(text)
    if trailer is None:
        return text
    problem = csv_problem(path)
    if problem:
        raise InputError(
            [
                f"{path}: ends in ballbat's check line, which does not hold ({problem}): cut short, or "
                "edited after ballbat wrote it (if you edited it on purpose, delete its last line "
                "'# ballbat table: ...')"
            ]
        )
    return body


def read_csv_rows(path: str | os.PathLike[str]) -> tuple[list[str], list[tuple[int, list[str]]]]:
    """Return the header and the non-blank rows (line number, cells) of a CSV file as labs make them.

    Accepted as they come from spreadsheets: a UTF-8 byte-order mark (Excel's "CSV UTF-8"),
    semicolon-separated files with decimal commas (European Excel: the commas are read as
    decimal points), and trailing columns with neither a name nor a value (Excel's stray
    separators). Refused with one message that says what the file is: a directory, a file
    that is not UTF-8 (naming the line and byte), a column with values but no name.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError([f"{path}: is a directory, not a CSV file"])
    if not path.exists():
        raise InputError([f"{path}: file not found"])
    raw = path.read_bytes()  # /dev/null and other non-regular files are read as they are
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise InputError(
            [
                f"{path}: not UTF-8 text: byte 0x{raw[exc.start]:02x} on line {line} cannot be decoded "
                "(a Latin-1 or Windows export?); save the file as 'CSV UTF-8'"
            ]
        ) from None
    lines = without_check_line(path, text).splitlines()
    first = next((ln for ln in lines if ln.strip()), "")
    semicolon = first.count(";") > first.count(",")
    reader = csv.reader(lines, delimiter=";" if semicolon else ",")
    header = None
    rows: list[tuple[int, list[str]]] = []
    for cells in reader:
        if not any(c.strip() for c in cells):
            continue
        cells = [c.strip() for c in cells]
        if semicolon:  # decimal commas: 68,7 -> 68.7
            cells = [c.replace(",", ".") if _DECIMAL_COMMA.match(c) else c for c in cells]
        if header is None:
            header = cells
            continue
        rows.append((reader.line_num, cells))
    if header is None:
        return [], []
    # Trailing columns without a name: dropped when they hold nothing, refused when they hold values.
    while header and header[-1] == "":
        k = len(header) - 1
        filled = [line for line, cells in rows if k < len(cells) and cells[k] != ""]
        if filled:
            raise InputError([f"{path}: column {k + 1} has values (line {filled[0]}, ...) but no name in the header"])
        header = header[:-1]
        rows = [(line, cells[:k] if len(cells) > k else cells) for line, cells in rows]
    return header, rows


#: Key of a row's surplus cells in :func:`read_csv_table` (cannot clash with a column name).
EXTRA = "\0extra"


def read_csv_table(path: str | os.PathLike[str], required: Sequence[str]) -> tuple[list[str], list[tuple[str, dict]]]:
    """Return the header and the rows (``"row N"``, {column: text}) of a CSV file as labs make them.

    :func:`read_csv_rows` reads the file; a row with more cells than the header has columns
    keeps their number under :data:`EXTRA`. An empty file is an :class:`InputError` that names
    the ``required`` columns.
    """
    header, lines = read_csv_rows(path)
    if not header:
        raise InputError([f"{path}: empty file (expected a header line with {', '.join(required)})"])
    rows = []
    for line, cells in lines:
        row = {h: (cells[i] if i < len(cells) else "") for i, h in enumerate(header)}
        if len(cells) > len(header):
            row[EXTRA] = str(len(cells) - len(header))
        rows.append((f"row {line}", row))
    return header, rows


#: Suffixes of a table given as NetCDF (variables along one dimension) rather than CSV.
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf")


def _read_nc(path: Path, dim: str, columns) -> tuple[list[str], list[tuple[str, dict]]]:
    """Header and rows of a NetCDF table: the variables along ``dim`` (``columns`` for messages)."""
    import xarray as xr

    try:
        with xr.open_dataset(path) as ds:
            ds = ds.load()
    except (OSError, ValueError) as exc:
        raise InputError([f"{path}: cannot be read as NetCDF ({exc})"]) from None
    if dim not in ds.dims:
        raise InputError([f"{path}: no dimension {dim!r} (expected variables {', '.join(columns)} along it)"])
    header = [str(k) for k, v in ds.variables.items() if v.dims == (dim,) and k != dim]
    cols = {k: ds[k].values for k in header}
    if dim == "impact" and "impact_id" not in header and "impact" in ds.coords:
        header.insert(0, "impact_id")  # rendered tracks: the impact ids are the dimension's coordinate
        cols["impact_id"] = ds["impact"].values
    rows = [(f"{dim} {i}", {k: cell_text(v[i]) for k, v in cols.items()}) for i in range(ds.sizes[dim])]
    return header, rows


def read_table(
    path: str | os.PathLike[str], required: Sequence[str], dim: str
) -> tuple[list[str], list[tuple[str, dict]]]:
    """Header and rows (label, {column: text}) of a CSV or NetCDF file; problems raised whole."""
    path = Path(path)
    if not path.is_file():
        raise InputError([f"{path}: file not found"])
    if path.suffix.lower() in NETCDF_SUFFIXES:
        return _read_nc(path, dim, required)
    return read_csv_table(path, required)


def header_problems(
    path: str | os.PathLike[str], header: list[str], required: Sequence[str], optional: Sequence[str] = ()
) -> list[str]:
    """Return the problems of a table's header: missing, unknown and repeated columns."""
    problems = []
    allowed = (*required, *optional)
    missing = [c for c in required if c not in header]
    if missing:
        also = f"; optional: {', '.join(optional)}" if optional else ""
        problems.append(f"{path}: missing column(s) {', '.join(missing)} (required: {', '.join(required)}{also})")
    unknown = [c for c in header if c not in allowed]
    if unknown:
        problems.append(f"{path}: unknown column(s) {', '.join(map(repr, unknown))} (allowed: {', '.join(allowed)})")
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated:
        problems.append(f"{path}: column(s) {', '.join(repeated)} appear more than once")
    return problems


def cell_number(raw: str, at: str, problems: list[str], empty: str = "empty", integer: bool = False) -> float:
    """Return a table cell's text as a finite number, or NaN with the problem added to ``problems``.

    ``at`` names the file, the row and the column; ``empty`` is the message for an empty
    cell; ``integer`` also requires a whole number (a frame number).
    """
    if raw == "":
        problems.append(f"{at}: {empty}")
        return math.nan
    try:
        val = float(raw)
    except ValueError:
        problems.append(f"{at}: {raw!r} is not a number")
        return math.nan
    if not math.isfinite(val):
        problems.append(f"{at}: {raw!r} is not finite")
        return math.nan
    if integer and val != int(val):
        problems.append(f"{at}: {raw!r} is not a whole frame number")
        return math.nan
    return val


def check_impact_id(iid: str, at: str, label: str, seen: dict[str, str], problems: list[str]) -> None:
    """Record an impact id in ``seen`` (id -> row label), or add why it cannot be: empty or repeated."""
    if not iid:
        problems.append(f"{at}, column impact_id: empty")
    elif iid in seen:
        problems.append(f"{at}, column impact_id: {iid!r} duplicates {seen[iid]}")
    else:
        seen[iid] = label


def table_keys(row: dict, at: str, balls: dict | None, bats: dict | None, problems: list[str]) -> dict[str, str]:
    """Return a row's ``bat`` and ``ball`` cells, each checked against its property table.

    An empty cell, or a name not in its table, is added to ``problems`` (``at`` names the
    file and row); a table that is None (itself bad) is not checked against.
    """
    names = {}
    for key, table in (("bat", bats), ("ball", balls)):
        name = row.get(key, "")
        if not name:
            problems.append(f"{at}, column {key}: empty")
        elif table is not None and name not in table:
            problems.append(
                f"{at}, column {key}: {key} {name!r} is not in the {key} table (known: {', '.join(sorted(table))})"
            )
        names[key] = name
    return names


def cell_text(v: object) -> str:
    """Return a NetCDF cell as the text a CSV cell would hold (NaN and None as empty)."""
    if isinstance(v, bytes):
        v = v.decode()
    if isinstance(v, str):
        return v.strip()
    if v is None or (isinstance(v, float | np.floating) and math.isnan(v)):
        return ""
    if isinstance(v, np.integer | int):
        return str(int(v))
    return repr(float(v))


#: Keys of a row's line label and its cells as given in :func:`_read_table`'s records.
ROW, GIVEN = "\0row", "\0given"


def _read_table(path: Path, columns: dict, key: str) -> list[dict]:
    """Read a property CSV, checking every row; raise one InputError listing all problems.

    Each record also holds its line label under :data:`ROW` and its cells as given under :data:`GIVEN`.
    """
    path = Path(path)
    problems: list[str] = []
    header, lines = read_csv_rows(path)
    missing = [c for c, (_, req, _) in columns.items() if req and c not in header]
    unknown = [c for c in header if c not in columns]
    if missing:
        problems.append(f"{path}: missing column(s) {', '.join(missing)}")
    if unknown:
        problems.append(f"{path}: unknown column(s) {', '.join(unknown)}; expected {', '.join(columns)}")
    if missing:
        raise InputError(problems)
    out, seen = [], {}
    for i, cells in lines:
        row = dict(zip(header, cells, strict=False))
        rec = {ROW: f"row {i}", GIVEN: {c: row.get(c, "") for c in header}}
        for col, (factor, req, positive) in columns.items():
            rec[col] = _cell(row.get(col, ""), f"{path}: row {i}, column {col}", factor, req, positive, problems)
        k = rec.get(key)
        if k:
            if k in seen:
                problems.append(f"{path}: row {i}, column {key}: {k!r} duplicates row {seen[k]}")
            seen[k] = i
        out.append(rec)
    if not lines:
        problems.append(f"{path}: no rows")
    if problems:
        raise InputError(problems)
    return out


def _cell(raw: str, at: str, factor: float | None, req: bool, positive: bool, problems: list[str]) -> object:
    """Return a property cell: text (``factor`` None), None (empty, optional) or the number times ``factor``."""
    if factor is None:
        if req and not raw:
            problems.append(f"{at}: empty")
        return raw
    if raw == "":
        if req:
            problems.append(f"{at}: empty")
        return None
    try:
        val = float(raw)
    except ValueError:
        problems.append(f"{at}: {raw!r} is not a number")
        return None
    if not math.isfinite(val):
        problems.append(f"{at}: {raw!r} is not finite")
    elif positive and val <= 0:
        problems.append(f"{at}: {raw} must be positive")
    return val * factor


def _ball_err(path: object, rec: dict, problems: list[str]) -> str:
    """JSON {column: [value, sigma]} (tables' units) of a ball row's stated uncertainties; bad ones to ``problems``."""
    row = {c: rec[c] / f for c, (_, f) in BALL_ERR_FIELDS.items() if rec[c] is not None}
    row.update(
        {f"{c}_err": rec[f"{c}_err"] / f for c, (_, f) in BALL_ERR_FIELDS.items() if rec[f"{c}_err"] is not None}
    )
    problems += batlab.err_problems(f"{path}: {rec[ROW]}", row)
    alpha = rec["alpha"] if rec["alpha"] is not None else 0.4
    row.setdefault("alpha", alpha)
    err = {c: [row[c], row[f"{c}_err"]] for c in BALL_ERR_FIELDS if row.get(f"{c}_err")}
    return json.dumps(err, sort_keys=True) if err else ""


def load_balls(path: str | os.PathLike[str]) -> dict[str, Ball]:
    """Read a ball table (Table I layout, paper units) into SI :class:`Ball` records.

    Optional ``m_oz_err``, ``r_in_err`` and ``alpha_err`` are the standard uncertainties of the
    table's values (their systematics: :func:`ball_variants`); Table I's ``*_sd`` is the spread
    from ball to ball, not an uncertainty of the values used, and gives no systematic.
    """
    balls = {}
    problems: list[str] = []
    for rec in _read_table(path, BALL_COLUMNS, "ball"):
        err = _ball_err(path, rec, problems)
        balls[rec["ball"]] = Ball(
            ball=rec["ball"],
            name=rec["name"] or rec["ball"],
            m=rec["m_oz"],
            r=rec["r_in"],
            alpha=rec["alpha"] if rec["alpha"] is not None else 0.4,
            psi_max=rec["psi_max_deg"] if rec["psi_max_deg"] is not None else math.nan,
            D_max=rec["D_max_in"] if rec["D_max_in"] is not None else math.nan,
            err=err,
        )
    if problems:
        raise InputError(problems)
    return balls


def ball_variants(ball: Ball) -> list[tuple[str, float, float, Ball, Ball]]:
    """Per stated uncertainty: (column, value, sigma, the ball at +1 sigma, at -1 sigma), tables' units."""
    from dataclasses import replace

    out = []
    for col, (value, sigma) in sorted(json.loads(ball.err).items()) if ball.err else ():
        field, factor = BALL_ERR_FIELDS[col]
        sides = [replace(ball, **{field: (value + s * sigma) * factor}) for s in (1.0, -1.0)]
        out.append((col, value, sigma, sides[0], sides[1]))
    return out


def _bat_columns(path: Path, header: list[str], lines: list) -> tuple[str, dict]:
    """Return a bat table's convention and its columns (name -> (factor, required, positive), tables' units).

    The convention is the ``convention`` column's (one for the whole table), else ``paper`` for a
    table with Table II's columns (as before the lab convention existed). A lab table must
    state it; a table whose columns fit neither convention, or mix them, is an InputError naming them.
    """
    conv_at = header.index("convention") if "convention" in header else None
    stated = {cells[conv_at] for _, cells in lines if conv_at is not None and conv_at < len(cells)}
    convention, problems = batlab.header_convention(path, header, stated)
    if problems:
        raise InputError(problems)
    text = {"bat": (None, True, False), "name": (None, False, False), "convention": (None, False, False)}
    if convention == "paper":
        cols = {c: (1.0, True, c != "b_in") for c in batlab.PAPER}
    else:
        chosen = [c for pair in batlab.LAB_EITHER for c in pair if c in header]
        cols = {c: (1.0, True, c != "pivot_in") for c in (*batlab.LAB_REQUIRED, *chosen)}
        cols.update({c: (1.0, False, True) for c in batlab.LAB_OPTIONAL})
    errs = {c: (1.0, False, False) for c in batlab.err_columns(header, list(cols))}
    return convention, {**text, **cols, **errs}


def load_bats(path: str | os.PathLike[str]) -> dict[str, Bat]:
    """Read a bat table in the paper's convention (Table II) or a lab's (ASTM F2398) into SI :class:`Bat` records.

    Every row is checked against what real bats are (:func:`ballbat.batlab.row_problems`); a lab
    row is converted to the paper's convention (:func:`ballbat.batlab.paper_row`). Each record
    keeps its convention, its cells as given and the values used (:func:`bat_record`).
    """
    path = Path(path)
    header, lines = read_csv_rows(path)
    convention, columns = _bat_columns(path, header, lines)
    problems: list[str] = []
    bats = {}
    for rec in _read_table(path, columns, "bat"):
        nums = {c: v for c, v in rec.items() if isinstance(v, float)}
        found = batlab.row_problems(f"{path}: {rec[ROW]}", nums, convention)
        found += batlab.err_problems(f"{path}: {rec[ROW]}", nums)
        problems += found
        if found:
            continue
        used = batlab.paper_row(nums) if convention == "lab" else {c: nums[c] for c in batlab.PAPER}
        given = {c: v for c, v in rec[GIVEN].items() if c not in ("bat", "name")}
        err = {c.removesuffix(batlab.ERR): v for c, v in nums.items() if c.endswith(batlab.ERR) and v > 0}
        bats[rec["bat"]] = Bat(
            bat=rec["bat"],
            name=rec["name"] or rec["bat"],
            M=used["M_oz"] * OUNCE,
            I0=used["I0_oz_in2"] * OZ_IN2,
            Iz=used["Iz_oz_in2"] * OZ_IN2,
            b=used["b_in"] * INCH,
            R=used["R_in"] * INCH,
            convention=convention,
            given=json.dumps(given),
            err=json.dumps(err, sort_keys=True) if err else "",
        )
    if problems:
        raise InputError(problems)
    return bats


def _bat_from_paper_row(bat: Bat, used: dict[str, float]) -> Bat:
    from dataclasses import replace

    return replace(
        bat,
        M=used["M_oz"] * OUNCE,
        I0=used["I0_oz_in2"] * OZ_IN2,
        Iz=used["Iz_oz_in2"] * OZ_IN2,
        b=used["b_in"] * INCH,
        R=used["R_in"] * INCH,
    )


def bat_variants(bat: Bat) -> list[tuple[str, float, float, Bat, Bat]]:
    """Per stated uncertainty (``<column>_err``): (column, value, sigma, the bat at +1 sigma, at -1 sigma).

    The measured value of that column alone moves by one standard uncertainty, and a lab row is
    converted again (:func:`ballbat.batlab.shifted_rows`); tables' units for value and sigma.
    """
    if not bat.err:
        return []
    row = _table_row(bat)
    return [
        (col, row[col], sigma, _bat_from_paper_row(bat, plus), _bat_from_paper_row(bat, minus))
        for col, sigma, plus, minus in batlab.shifted_rows(row, bat.convention)
    ]


def _table_row(bat: Bat) -> dict[str, float]:
    """Return a bat's row as its table gave it (tables' units), with its uncertainties as ``<column>_err``."""
    given = json.loads(bat.given)
    row = {c: float(v) for c, v in given.items() if c != "convention" and not c.endswith(batlab.ERR) and v != ""}
    row.update({f"{c}{batlab.ERR}": s for c, s in json.loads(bat.err).items()})
    return row


def drawn_properties(
    bats: dict[str, Bat], balls: dict[str, Ball], rng: np.random.Generator
) -> tuple[dict[str, Bat], dict[str, Ball], dict[str, float]]:
    """Return bats and balls whose measured values are drawn from their stated uncertainties (a replicate's truth).

    Every stated ``<column>_err`` of every bat (then ball), in sorted order, draws z ~ N(0, 1) and
    the column becomes value + z sigma; a lab row is converted again with all its columns moved
    (:func:`ballbat.batlab.moved_row`). Returns the drawn tables and each source's z, by the
    source's name (``bat:<bat>:<column>``, ``ball:<ball>:<column>``, as reconstruct names them).
    """
    from dataclasses import replace

    z: dict[str, float] = {}
    out_bats = dict(bats)
    for key in sorted(bats):
        bat = bats[key]
        if not bat.err:
            continue
        row = _table_row(bat)
        deltas = {}
        for col, sigma in sorted(json.loads(bat.err).items()):
            z[f"bat:{key}:{col}"] = float(rng.standard_normal())
            deltas[col] = z[f"bat:{key}:{col}"] * sigma
        out_bats[key] = _bat_from_paper_row(bat, batlab.moved_row(row, deltas, bat.convention))
    out_balls = dict(balls)
    for key in sorted(balls):
        ball = balls[key]
        moved = {}
        for col, (value, sigma) in sorted(json.loads(ball.err).items()) if ball.err else ():
            z[f"ball:{key}:{col}"] = float(rng.standard_normal())
            field, factor = BALL_ERR_FIELDS[col]
            moved[field] = (value + z[f"ball:{key}:{col}"] * sigma) * factor
        out_balls[key] = replace(ball, **moved)
    return out_bats, out_balls, z


def bat_record(bats: dict[str, Bat]) -> str:
    """Return JSON of the bats: per bat its convention, its cells as given and the paper-convention values used."""
    used = {
        "M_oz": lambda t: t.M / OUNCE,
        "I0_oz_in2": lambda t: t.I0 / OZ_IN2,
        "Iz_oz_in2": lambda t: t.Iz / OZ_IN2,
        "b_in": lambda t: t.b / INCH,
        "R_in": lambda t: t.R / INCH,
    }
    return json.dumps(
        {
            k: {
                "convention": t.convention,
                "as_given": json.loads(t.given) if t.given else {},
                "used": {c: round(f(t), 6) for c, f in used.items()},
                **({"uncertainty": json.loads(t.err)} if t.err else {}),
            }
            for k, t in sorted(bats.items())
        },
        sort_keys=True,
    )


def recoil_normal(m: ArrayLike, M: ArrayLike, I0: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Return the normal recoil factor r_y of the bat (Eq. ry of Kensrud et al. 2017).

    Parameters
    ----------
    m : ball mass, kg.   M : bat mass, kg.
    I0 : bat moment of inertia about its centre of mass, kg m^2.
    b : impact location measured from the bat's centre of mass, m.

    Notes
    -----
    r_y = m (1/M + b^2/I0).
    """
    return m * (1.0 / M + b**2 / I0)


def recoil_tangential(
    m: ArrayLike, M: ArrayLike, I0: ArrayLike, Iz: ArrayLike, b: ArrayLike, R: ArrayLike, alpha: ArrayLike = 0.4
) -> np.ndarray:
    """Tangential recoil factor r_x of the bat (Eq. rx of Kensrud et al. 2017).

    Notes
    -----
    r_x = m alpha/(1 + alpha) (1/M + b^2/I0 + R^2/Iz), with R the bat radius at impact
    and Iz the bat's moment of inertia about its long axis.
    """
    return m * alpha / (1.0 + alpha) * (1.0 / M + b**2 / I0 + R**2 / Iz)


def recoil_factors(ball: Ball, bat: Bat) -> tuple[float, float]:
    """(r_x, r_y) for a ball hitting a bat."""
    r_x = recoil_tangential(ball.m, bat.M, bat.I0, bat.Iz, bat.b, bat.R, ball.alpha)
    r_y = recoil_normal(ball.m, bat.M, bat.I0, bat.b)
    return r_x, r_y
