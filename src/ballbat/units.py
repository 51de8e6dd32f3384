"""Unit conversions at the edges of the package.

Inside the package every quantity is an SI float (m, kg, s, rad). The paper's units
(oz, in, oz-in^2, mph, rpm, deg) appear only in config tables, user files, figure axes
and the paper-comparison table; these helpers convert once at those edges.

All factors are exact by definition (NIST SP 811, Appendix B).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from numpy.typing import ArrayLike

#: 1 international inch in metres (exact).
INCH = 0.0254
#: 1 foot in metres (exact).
FOOT = 0.3048
#: 1 avoirdupois ounce in kilograms (exact).
OUNCE = 0.028349523125
#: 1 mile per hour in metres per second (exact: 1609.344 m / 3600 s).
MPH = 0.44704
#: 1 revolution per minute in radians per second.
RPM = 2.0 * np.pi / 60.0
#: 1 degree in radians.
DEGREE = np.pi / 180.0
#: Standard acceleration of gravity, m s-2 (exact by definition, NIST SP 811; the trajectory
#: calculator's 32.174 ft/s^2).
G = 9.80665
#: 1 ounce inch^2 in kg m^2.
OZ_IN2 = OUNCE * INCH**2
#: 1 mmHg in pascal (conventional, 133.322387415 Pa).
MMHG = 133.322387415
#: 1 inHg in mmHg (exact: 25.4 mm).
INHG_IN_MMHG = 25.4

#: Factors from a unit name (as used in config tables and the comparison table) to SI.
TO_SI = {
    "m": 1.0,
    "kg": 1.0,
    "s": 1.0,
    "rad": 1.0,
    "1": 1.0,
    "in": INCH,
    "ft": FOOT,
    "oz": OUNCE,
    "oz in2": OZ_IN2,
    "mph": MPH,
    "rpm": RPM,
    "deg": DEGREE,
    "m s-1": 1.0,
    "rad s-1": 1.0,
    "rpm/deg": RPM / DEGREE,
    "mph/deg": MPH / DEGREE,
}


def to_si(value: ArrayLike, unit: str) -> np.ndarray | float:
    """Convert ``value`` given in ``unit`` (a key of :data:`TO_SI`) to SI."""
    try:
        return np.asarray(value, dtype=float) * TO_SI[unit] if np.ndim(value) else float(value) * TO_SI[unit]
    except KeyError:
        raise ValueError(f"unknown unit {unit!r}; known units: {sorted(TO_SI)}") from None


def from_si(value: ArrayLike, unit: str) -> np.ndarray | float:
    """Convert an SI ``value`` to ``unit`` (a key of :data:`TO_SI`)."""
    try:
        return np.asarray(value, dtype=float) / TO_SI[unit] if np.ndim(value) else float(value) / TO_SI[unit]
    except KeyError:
        raise ValueError(f"unknown unit {unit!r}; known units: {sorted(TO_SI)}") from None


def fahrenheit_to_celsius(t_f: ArrayLike) -> np.ndarray | float:
    """Temperature in degrees Fahrenheit to degrees Celsius."""
    return (np.asarray(t_f, dtype=float) - 32.0) * 5.0 / 9.0
