"""Bat properties as labs measure them (ASTM F2398 / F2219) and as the model needs them (Table II).

The model (Eqs. rx, ry) needs a bat in the paper's convention: mass M, moment of inertia I0
about the centre of mass, Iz about the long axis, the impact point b from the centre of mass
and the bat's radius R there. Bat labs measure the length L, the weight M, the balance point
x_cm from the knob end, the moment of inertia I_p about a pivot x_p from the knob end (6 in
in ASTM F2398), or the period T of the bat swinging about that pivot, the impact point from
the barrel tip or the knob, and the barrel diameter. :func:`paper_row` converts the one into
the other (docs/model.md, "Bat properties in a lab's terms"):

* I_p from a period (physical pendulum): I_p = M g (x_cm - x_p) T^2 / (4 pi^2);
* I0 by the parallel-axis theorem: I0 = I_p - M (x_cm - x_p)^2;
* b = x_impact - x_cm, with x_impact = L - (distance from the tip) when given from the tip;
* R = diameter / 2; Iz as measured.

:func:`row_problems` checks a bat row of either convention against what real bats are, with
the likely mistake named (grams as ounces, cm as inches, an MOI about the pivot given as
about the centre of mass); :func:`ballbat.properties.load_bats` runs it on every row, so the
workflow and ``ballbat check`` check alike. Everything here is in the tables' units (oz, in,
oz in^2, s).

References
----------
.. [1] ASTM F2398-11, Standard Test Method for Measuring Moment of Inertia and Center of
   Percussion of a Baseball or Softball Bat (pivot 6 in from the knob end; I_p from the period).
.. [2] ASTM F2219, Standard Test Methods for Measuring High-Speed Bat Performance (balance
   point and impact location measured from the knob end / barrel tip).
.. [3] J. R. Kensrud, A. M. Nathan and L. V. Smith, Am. J. Phys. 85, 503 (2017), Table II.
"""

from __future__ import annotations

import math

from .units import INCH, OUNCE, G

#: Standard acceleration of gravity in in/s^2 (the pendulum's g in the tables' units).
G_IN = G / INCH
#: Grams per ounce and centimetres per inch (for naming unit mistakes).
GRAM_PER_OZ = OUNCE * 1000.0
CM_PER_IN = INCH * 100.0
#: ASTM F2398's pivot, in from the knob end.
PIVOT_ASTM_IN = 6.0

#: Columns of the paper's convention (Table II) beyond ``bat`` and ``name``.
PAPER = ("M_oz", "I0_oz_in2", "Iz_oz_in2", "b_in", "R_in")
#: Columns of the lab convention: always, then one of each alternative pair, then optional.
LAB_REQUIRED = ("length_in", "weight_oz", "balance_in", "pivot_in", "diameter_in", "Iz_oz_in2")
LAB_EITHER = (("moi_oz_in2", "period_s"), ("impact_from_tip_in", "impact_from_knob_in"))
LAB_OPTIONAL = ("cop_in",)
LAB = (*LAB_REQUIRED, *(c for pair in LAB_EITHER for c in pair), *LAB_OPTIONAL)
#: The two conventions' names, as the ``convention`` column states them.
CONVENTIONS = {"paper": "paper (Table II: I0 about the centre of mass, b from it)", "lab": "lab (ASTM F2398/F2219)"}

#: What real baseball and softball bats are (tables' units): weight, length, barrel radius
#: at the impact point, impact point from the centre of mass, the radius of gyration about the
#: centre of mass (absolute, and per length where the length is known), that about the long
#: axis per barrel radius, and the balance point per length. The paper's bats (Table II):
#: 28.3-31.6 oz, R 1.13-1.29 in, b 5.8-6.8 in, sqrt(I0/M) 9.0-10.1 in, sqrt(Iz/M)/R 0.48-0.60;
#: wood bats of 34 in and 32 oz have I_p about 10500-12500 oz in^2 about the 6-in pivot
#: (sqrt(I0/M)/L 0.22-0.27; a uniform rod 0.29).
RANGES = {
    "M_oz": (15.0, 45.0),
    "length_in": (20.0, 40.0),
    "R_in": (0.75, 1.5),
    "b_in": (0.0, 14.0),
    "k0_in": (4.5, 12.0),
    "k0_per_L": (0.17, 0.33),
    "kz_per_R": (0.25, 0.9),
    "balance_per_L": (0.45, 0.85),
}
#: Largest difference, in, between a given centre of percussion and the one the MOI implies.
COP_TOLERANCE_IN = 0.5


def moi_from_period(weight: float, balance: float, pivot: float, period: float) -> float:
    """Return the MOI about the pivot, oz in^2, from a pendulum's period (s): M g d T^2 / (4 pi^2)."""
    return weight * G_IN * (balance - pivot) * period**2 / (4.0 * math.pi**2)


def pivot_moi(row: dict) -> float:
    """Return a lab row's MOI about its pivot, oz in^2 (given, or from the period)."""
    if row.get("moi_oz_in2") is not None:
        return row["moi_oz_in2"]
    return moi_from_period(row["weight_oz"], row["balance_in"], row["pivot_in"], row["period_s"])


def impact_from_knob(row: dict) -> float:
    """Return a lab row's impact point from the knob end, in."""
    if row.get("impact_from_knob_in") is not None:
        return row["impact_from_knob_in"]
    return row["length_in"] - row["impact_from_tip_in"]


def paper_row(row: dict) -> dict[str, float]:
    """Return a lab row (tables' units) in the paper's convention: M_oz, I0_oz_in2, Iz_oz_in2, b_in, R_in.

    I0 = I_p - M d^2 with d = x_cm - x_p (parallel-axis theorem), b = x_impact - x_cm, R = D / 2.
    """
    d = row["balance_in"] - row["pivot_in"]
    return {
        "M_oz": row["weight_oz"],
        "I0_oz_in2": pivot_moi(row) - row["weight_oz"] * d**2,
        "Iz_oz_in2": row["Iz_oz_in2"],
        "b_in": impact_from_knob(row) - row["balance_in"],
        "R_in": row["diameter_in"] / 2.0,
    }


def centre_of_percussion(row: dict) -> float:
    """Return a lab row's centre of percussion for its pivot, in from the knob: x_p + I_p / (M d) (ASTM F2398)."""
    return row["pivot_in"] + pivot_moi(row) / (row["weight_oz"] * (row["balance_in"] - row["pivot_in"]))


def header_convention(path: object, header: list[str], stated: set[str]) -> tuple[str, list[str]]:
    """Return a bat table's convention from its header and its ``convention`` cells, and the problems.

    ``stated`` holds the ``convention`` column's values (empty: no such column). A paper table
    may leave the convention unstated (Table II's columns say it); a lab table must state it.
    Columns of the other convention, of neither, or a missing alternative are problems naming them.
    """
    paper_only = [c for c in header if c in PAPER and c not in LAB]
    lab_only = [c for c in header if c in LAB and c not in PAPER]
    names = " or ".join(repr(c) for c in CONVENTIONS)
    if len(stated) > 1 or not stated <= set(CONVENTIONS):
        return "", [f"{path}: column convention: {sorted(stated)}; one of {names} for the whole table"]
    if stated:
        conv = next(iter(stated))
    elif lab_only and not paper_only:
        return "", [
            f"{path}: columns {', '.join(lab_only)} are the lab convention's (ASTM F2398): state it with a column "
            "convention holding 'lab' in every row, so that no table's convention is guessed"
        ]
    else:
        conv = "paper"
    wrong = lab_only if conv == "paper" else paper_only
    if wrong or not (paper_only if conv == "paper" else lab_only):
        other = "lab" if conv == "paper" else "paper"
        return "", [
            f"{path}: the columns fit neither convention or mix them: "
            + (f"{', '.join(wrong)} belong to the {CONVENTIONS[other]} convention, " if wrong else "")
            + f"the table is in the {CONVENTIONS[conv]} convention; its columns: "
            + ", ".join(PAPER if conv == "paper" else LAB)
        ]
    if conv == "lab":
        for pair in LAB_EITHER:
            n = sum(c in header for c in pair)
            if n != 1:
                return "", [f"{path}: give exactly one of the columns {' or '.join(pair)} (the table has {n})"]
    return conv, []


# ---------------------------------------------------------------------------------------
# Checks: each returns the problems of one row, ``at`` naming the file and the row.


def _mass_problems(at: str, col: str, m: float) -> list[str]:
    lo, hi = RANGES["M_oz"]
    if lo <= m <= hi:
        return []
    hint = ""
    if lo <= m / GRAM_PER_OZ <= hi:
        hint = f": grams typed as ounces? ({m:g} g = {m / GRAM_PER_OZ:.1f} oz)"
    elif lo <= m * 1000 / GRAM_PER_OZ <= hi:
        hint = f": kilograms typed as ounces? ({m:g} kg = {m * 1000 / GRAM_PER_OZ:.1f} oz)"
    elif lo <= m * 16 <= hi:
        hint = f": pounds typed as ounces? ({m:g} lb = {m * 16:g} oz)"
    return [f"{at}, column {col}: {m:g} oz is outside what any bat weighs ({lo:g}-{hi:g} oz){hint}"]


def _length_problems(at: str, col: str, value: float, lo: float, hi: float, what: str) -> list[str]:
    if lo <= value <= hi:
        return []
    hint = ""
    if lo <= value / CM_PER_IN <= hi:
        hint = f": centimetres typed as inches? ({value:g} cm = {value / CM_PER_IN:.2f} in)"
    elif lo <= value / 10 / CM_PER_IN <= hi:
        hint = f": millimetres typed as inches? ({value:g} mm = {value / 10 / CM_PER_IN:.2f} in)"
    return [f"{at}, column {col}: {value:g} in is outside {what} ({lo:g}-{hi:g} in){hint}"]


def _radius_problems(at: str, col: str, radius: float, given: float) -> list[str]:
    """Check the barrel radius at the impact point (``given`` is the column's own value: R or D)."""
    lo, hi = RANGES["R_in"]
    if lo <= radius <= hi:
        return []
    if col == "R_in" and lo <= radius / 2 <= hi:
        return [
            f"{at}, column R_in: {given:g} in is outside any bat's barrel radius ({lo:g}-{hi:g} in): "
            f"the barrel's diameter given as its radius? (R = {radius / 2:.2f} in)"
        ]
    if col == "diameter_in" and lo <= radius * 2 <= hi:
        return [
            f"{at}, column diameter_in: {given:g} in is outside any bat's barrel diameter "
            f"({2 * lo:g}-{2 * hi:g} in): the radius given as the diameter?"
        ]
    f = 2.0 if col == "diameter_in" else 1.0
    return _length_problems(at, col, given, f * lo, f * hi, "any bat's barrel " + ("diameter" if f == 2 else "radius"))


def _iz_problems(at: str, col: str, iz: float, m: float, radius: float) -> list[str]:
    lo, hi = RANGES["kz_per_R"]
    kz = math.sqrt(iz / m)
    if lo <= kz / radius <= hi:
        return []
    return [
        f"{at}, column {col}: {iz:g} oz in^2 gives a radius of gyration about the long axis sqrt(Iz/M) = "
        f"{kz:.2f} in, {kz / radius:.2f} of the barrel radius {radius:.2f} in, where bats have {lo:g}-{hi:g} "
        "(a wood bat ~0.5, a hollow one ~0.6): Iz in other units, or about another axis?"
    ]


def _cm_moi_problems(at: str, col: str, i0: float, m: float, length: float | None, lab: bool) -> list[str]:
    """I0 about the centre of mass: positive, and a radius of gyration real bats have."""
    if i0 <= 0:
        return [
            f"{at}, column {col}: the MOI about the centre of mass, I_p - M (x_cm - x_p)^2 = {i0:.0f} oz in^2, is not "
            "positive: an MOI about the centre of mass given as about the pivot (then use the paper convention's "
            "I0_oz_in2), or the balance point or pivot from the other end?"
        ]
    k0 = math.sqrt(i0 / m)
    lo, hi = RANGES["k0_per_L"] if length else RANGES["k0_in"]
    k = k0 / length if length else k0
    if lo <= k <= hi:
        return []
    where = f"{k:.2f} of the length {length:g} in" if length else f"{k0:.1f} in"
    about = "after the parallel-axis theorem " if lab else ""
    hint = ""
    if not lab and k0 > hi:
        hint = (
            ": an MOI about the knob or the 6-in pivot (the lab convention of ASTM F2398) given as about the "
            "centre of mass? Give such a table in the lab convention (convention = lab; columns "
            f"{', '.join(LAB_REQUIRED)}, moi_oz_in2 or period_s, impact_from_tip_in or impact_from_knob_in)"
        )
    elif not lab and lo <= k0 / CM_PER_IN <= hi:
        hint = f": oz cm^2 typed as oz in^2? (sqrt(I0/M) would be {k0 / CM_PER_IN:.1f} in)"
    elif lab:
        hint = (
            ": an MOI about the knob end (not the pivot_in one), or in oz cm^2?"
            if k > hi
            else ": an MOI about the centre of mass given as about the pivot, or the balance point or pivot wrong?"
        )
    rng = f"{lo:g}-{hi:g}" + ("" if length else " in")
    return [
        f"{at}, column {col}: {about}the radius of gyration about the centre of mass sqrt(I0/M) is {where}, "
        f"where bats have {rng}{hint}"
    ]


def paper_problems(at: str, row: dict) -> list[str]:
    """Problems of a paper-convention row (Table II, tables' units)."""
    problems = _mass_problems(at, "M_oz", row["M_oz"]) + _radius_problems(at, "R_in", row["R_in"], row["R_in"])
    lo, hi = RANGES["b_in"]
    if not lo <= row["b_in"] <= hi:
        problems.append(
            f"{at}, column b_in: {row['b_in']:g} in is outside any bat's barrel ({lo:g}-{hi:g} in beyond the centre "
            "of mass): b is from the centre of mass in the paper convention; an impact point from the knob or the "
            "tip? Give it in the lab convention (convention = lab, with impact_from_knob_in or impact_from_tip_in "
            "and balance_in)"
        )
    if problems:  # the ratios below need a sane mass and radius
        return problems
    problems += _cm_moi_problems(at, "I0_oz_in2", row["I0_oz_in2"], row["M_oz"], None, lab=False)
    return problems + _iz_problems(at, "Iz_oz_in2", row["Iz_oz_in2"], row["M_oz"], row["R_in"])


def _lab_geometry_problems(at: str, row: dict) -> list[str]:
    """Balance point, pivot and impact point of a lab row: inside the bat and on the barrel."""
    length, x_cm, x_p = row["length_in"], row["balance_in"], row["pivot_in"]
    lo, hi = RANGES["balance_per_L"]
    if not lo * length <= x_cm <= hi * length:
        flip = " (measured from the barrel tip?)" if lo * length <= length - x_cm <= hi * length else ""
        return [
            f"{at}, column balance_in: the balance point {x_cm:g} in from the knob is {x_cm / length:.2f} of the "
            f"length, where bats balance at {lo:g}-{hi:g}{flip}"
        ]
    if not 0 <= x_p < x_cm:
        return [
            f"{at}, column pivot_in: the pivot {x_p:g} in from the knob must lie between the knob and the balance point"
        ]
    col = "impact_from_knob_in" if row.get("impact_from_knob_in") is not None else "impact_from_tip_in"
    b = impact_from_knob(row) - x_cm
    blo, bhi = RANGES["b_in"]
    if not (blo <= b <= bhi and impact_from_knob(row) <= length):
        other = "tip" if col == "impact_from_knob_in" else "knob"
        return [
            f"{at}, column {col}: the impact point is {b:.1f} in from the centre of mass, not on the barrel "
            f"(0-{min(bhi, length - x_cm):.1f} in beyond the balance point): measured from the {other}?"
        ]
    return []


def lab_problems(at: str, row: dict) -> list[str]:
    """Problems of a lab-convention row (ASTM F2398/F2219, tables' units)."""
    problems = _mass_problems(at, "weight_oz", row["weight_oz"])
    problems += _length_problems(at, "length_in", row["length_in"], *RANGES["length_in"], "any bat's length")
    problems += _radius_problems(at, "diameter_in", row["diameter_in"] / 2, row["diameter_in"])
    problems = problems or _lab_geometry_problems(at, row)
    if problems:
        return problems
    col = "moi_oz_in2" if row.get("moi_oz_in2") is not None else "period_s"
    i0 = paper_row(row)["I0_oz_in2"]
    problems += _cm_moi_problems(at, col, i0, row["weight_oz"], row["length_in"], lab=True)
    problems += _iz_problems(at, "Iz_oz_in2", row["Iz_oz_in2"], row["weight_oz"], row["diameter_in"] / 2)
    if row.get("cop_in") is not None and not problems:
        cop = centre_of_percussion(row)
        if abs(cop - row["cop_in"]) > COP_TOLERANCE_IN:
            problems.append(
                f"{at}, column cop_in: {row['cop_in']:g} in from the knob, but the MOI, weight and balance point "
                f"put the centre of percussion for the {row['pivot_in']:g}-in pivot at {cop:.2f} in (ASTM F2398: "
                f"x_p + I_p/(M d)); one of them is wrong"
            )
    return problems


def row_problems(at: str, row: dict, convention: str) -> list[str]:
    """Problems of one bat row of either convention (``row``: column -> number in the tables' units)."""
    return lab_problems(at, row) if convention == "lab" else paper_problems(at, row)


# ---------------------------------------------------------------------------------------
# Uncertainties: an optional ``<column>_err`` beside a numeric column, in the column's unit.

#: Suffix of a column's standard uncertainty (same unit as the column).
ERR = "_err"
#: Largest relative uncertainty accepted: a larger one is a unit mistake or a percentage, not a measurement.
MAX_REL_ERR = 0.5


def err_columns(header: list[str], numeric: tuple[str, ...] | list[str]) -> list[str]:
    """Return the ``<column>_err`` columns of ``header`` that belong to a numeric column of the table."""
    return [f"{c}{ERR}" for c in numeric if f"{c}{ERR}" in header]


def err_problems(at: str, row: dict) -> list[str]:
    """Problems of a row's uncertainties (``<column>_err``): negative, or larger than half the value."""
    problems = []
    for col, sigma in row.items():
        if not col.endswith(ERR) or sigma is None:
            continue
        base = col.removesuffix(ERR)
        value = row.get(base)
        if sigma < 0:
            problems.append(f"{at}, column {col}: {sigma:g} is negative (a standard uncertainty is 0 or more)")
        elif value is not None and value != 0 and sigma > MAX_REL_ERR * abs(value):
            problems.append(
                f"{at}, column {col}: {sigma:g} is {sigma / abs(value):.0%} of {base} = {value:g}, more than "
                f"{MAX_REL_ERR:.0%}: the uncertainty in another unit, or a percentage? Give it in {base}'s unit"
            )
    return problems


def moved_row(row: dict, deltas: dict[str, float], convention: str) -> dict[str, float]:
    """Return a row (``<column>_err`` ignored) with each column of ``deltas`` moved by it, in the paper's convention.

    A lab row is converted again (:func:`paper_row`), so the moves carry the conversion's
    correlations exactly (e.g. the balance point moves both I0 and b).
    """
    moved = {k: v for k, v in row.items() if not k.endswith(ERR)}
    for col, delta in deltas.items():
        moved[col] = row[col] + delta
    return paper_row(moved) if convention == "lab" else {c: moved[c] for c in PAPER}


def shifted_rows(row: dict, convention: str) -> list[tuple[str, float, dict, dict]]:
    """Per stated uncertainty (``<column>_err`` > 0): (column, sigma, paper row at +1 sigma, at -1 sigma).

    The measured value alone is moved by one standard uncertainty (:func:`moved_row`).
    """
    out = []
    for col in sorted(c for c in row if c.endswith(ERR)):
        sigma, base = row[col], col.removesuffix(ERR)
        if sigma:
            sides = [moved_row(row, {base: side * sigma}, convention) for side in (1.0, -1.0)]
            out.append((base, sigma, sides[0], sides[1]))
    return out
