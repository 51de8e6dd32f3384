"""The fits' designs (ballbat.designs): the Jacobian columns in order, against finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from ballbat.units import MPH


def test_measured_reads_the_jacobian_columns_in_order():
    """Measured holds v_bat, v_ball, theta, omega (MEASURED) as floats; measured_sigma needs every *_err."""
    import xarray as xr

    from ballbat.designs import MEASURED, Measured, measured_sigma

    values = {k: ("impact", np.arange(3) + 10 * i) for i, k in enumerate(MEASURED)}
    errs = {f"{k}_err": ("impact", np.full(3, 0.1 * (i + 1))) for i, k in enumerate(MEASURED)}
    ds = xr.Dataset({**values, **errs, **{f"truth_{k}": v for k, v in values.items()}})
    sel = np.array([True, False, True])
    m = Measured.from_dataset(ds, sel)
    assert m.theta.dtype == float and m.theta.tolist() == [20.0, 22.0] and m.omega.tolist() == [30.0, 32.0]
    assert np.array_equal(np.stack(Measured.from_dataset(ds, sel, "truth_")), np.stack(m))
    np.testing.assert_array_equal(measured_sigma(ds, sel), [[0.1, 0.2, 0.1 * 3, 0.4]] * 2)
    assert measured_sigma(ds.drop_vars("omega_err"), sel) is None


@pytest.mark.parametrize("design", ["spin", "tan_ratio", "vtf", "theta_spin", "theta_speed"])
def test_design_jacobians_match_finite_differences(design):
    """The effective-variance weights rest on these derivatives: check them numerically."""
    from ballbat import designs as f

    v_ref = 77 * MPH

    rng = np.random.default_rng(3)
    n = 5
    meas = [rng.uniform(28, 39, n), rng.uniform(30, 45, n), rng.uniform(0.0, 0.4, n), rng.uniform(50, 350, n)]
    r, r_x, alpha = 0.036, 0.25, 0.4
    fun = {
        "spin": lambda m: f.spin_design(f.Measured(*m), r, r_x, alpha),
        "tan_ratio": lambda m: f.tan_ratio_design(f.Measured(*m), r, alpha),
        "vtf": lambda m: f.vtf_design(f.Measured(*m), r, r_x, alpha),
        "theta_spin": lambda m: f.normalized_theta_design(m[0], m[3] * v_ref / m[0], m[2], "omega", v_ref),
        "theta_speed": lambda m: f.normalized_theta_design(m[0], m[1] * v_ref / m[0], m[2], "v_ball", v_ref),
    }[design]
    _x, _y, jx, jy = fun(meas)
    for k in range(4):
        h = 1e-6 * max(1.0, float(np.mean(np.abs(meas[k]))))
        up = [m.copy() for m in meas]
        dn = [m.copy() for m in meas]
        up[k] += h
        dn[k] -= h
        xu, yu, _, _ = fun(up)
        xd, yd, _, _ = fun(dn)
        np.testing.assert_allclose(jx[:, k], (xu - xd) / (2 * h), rtol=1e-5, atol=1e-8)
        np.testing.assert_allclose(jy[:, k], (yu - yd) / (2 * h), rtol=1e-5, atol=1e-8)
