"""Unit conversions (ballbat.units) are exact."""

from __future__ import annotations

import math

import pytest

from ballbat.units import INCH, MPH, OUNCE, RPM, from_si, to_si


def test_unit_factors_exact():
    # NIST SP 811 Appendix B: exact definitions.
    assert MPH == pytest.approx(1609.344 / 3600, rel=1e-15)
    assert OUNCE == 0.028349523125
    assert INCH == 0.0254
    assert RPM * 60 == pytest.approx(2 * math.pi, rel=1e-15)
    assert to_si(77, "mph") == pytest.approx(34.42208, rel=1e-6)  # Sec. II: 77 mph ~ 34 m/s
    assert from_si(to_si(179.0, "rpm/deg"), "rpm/deg") == pytest.approx(179.0, rel=1e-14)
    with pytest.raises(ValueError, match="unknown unit 'furlong'"):
        to_si(1.0, "furlong")
