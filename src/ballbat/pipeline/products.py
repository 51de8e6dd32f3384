"""Results datasets built from declared tables of variables (the one attribute helper).

Every stage declares, once, what it writes: a mapping from variable name to :class:`Var`
(dimensions, units, long_name and any further CF attributes). Compute functions return
plain arrays or small dataclasses; :func:`build_dataset` joins those values to the table,
so the attribute text lives in one place per stage and every file is shaped the same way.

CF conventions handled here, so that no stage has to remember them:

* categorical variables are integer codes with ``flag_values`` and ``flag_meanings``
  (:func:`flag_attrs`, from an :class:`enum.IntEnum`);
* an estimate and its uncertainty and interval are linked by ``ancillary_variables``
  (:func:`estimate_vars`);
* text (labels, readable reasons) carries ``long_name`` only: CF has no units for text.
"""

from __future__ import annotations

import enum
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import xarray as xr


@dataclass(frozen=True)
class Var:
    """Declaration of one variable of a results file.

    Parameters
    ----------
    dims : tuple of str
        The variable's dimensions (``()`` for a scalar).
    units : str or None
        UDUNITS string (``"1"`` for dimensionless numbers); ``None`` for text.
    long_name : str
        What the variable is, in words.
    attrs : mapping
        Further attributes (``flag_values``, ``ancillary_variables``, ``ballbat_role``...).
    """

    dims: tuple[str, ...]
    units: str | None
    long_name: str
    attrs: Mapping[str, Any] = field(default_factory=dict)

    def attributes(self) -> dict[str, Any]:
        """All attributes of the variable, ``units`` first."""
        out: dict[str, Any] = {} if self.units is None else {"units": self.units}
        out["long_name"] = self.long_name
        out.update(self.attrs)
        return out


def variable(dims: str | tuple[str, ...], data: Any, units: str | None, long_name: str, **attrs: Any) -> tuple:
    """One variable as the ``(dims, values, attributes)`` tuple xarray takes.

    For stages whose variables depend on the case at hand (a D sweep or launch conditions,
    synthetic truth); the attributes come from :class:`Var`, as in the declared tables.
    """
    dims = (dims,) if isinstance(dims, str) else tuple(dims)
    return (dims, np.asarray(data), Var(dims, units, long_name, attrs).attributes())


def _flag_word(text: str) -> str:
    """Return a flag meaning as CF wants it: one blank-free word per value."""
    return re.sub(r"[^A-Za-z0-9_.+-]+", "_", text).strip("_")


def flag_attrs(flags: type[enum.IntEnum]) -> dict[str, Any]:
    """``flag_values`` and ``flag_meanings`` of a categorical variable coded by ``flags``."""
    members = list(flags)
    return {
        "flag_values": np.array([int(m) for m in members], dtype=np.int8),
        "flag_meanings": " ".join(_flag_word(m.name.lower()) for m in members),
    }


def estimate_vars(
    name: str,
    dims: tuple[str, ...],
    units: str,
    what: str,
    *,
    fit: bool = True,
    interval: bool = True,
) -> dict[str, Var]:
    """Declare an estimate and its uncertainty family, linked as CF ancillaries.

    Returns ``name`` (the value), ``name_err`` (standard error), optionally
    ``name_ci_low``/``name_ci_high`` (95 % interval), and, for fits, ``name_n`` (impacts
    in the fit) and ``name_redchi`` (reduced chi-square).
    """
    out = {
        f"{name}_err": Var(dims, units, f"standard error of {what}"),
    }
    if interval:
        out[f"{name}_ci_low"] = Var(dims, units, f"lower end of the 95 % confidence interval of {what}")
        out[f"{name}_ci_high"] = Var(dims, units, f"upper end of the 95 % confidence interval of {what}")
    if fit:
        out[f"{name}_n"] = Var(dims, "1", f"number of impacts in the fit of {what}")
        out[f"{name}_redchi"] = Var(dims, "1", f"reduced chi-square of the fit of {what}")
    return {name: Var(dims, units, what, {"ancillary_variables": " ".join(out)}), **out}


def build_dataset(
    table: Mapping[str, Var],
    values: Mapping[str, Any],
    coords: Mapping[str, tuple] | None = None,
    attrs: Mapping[str, Any] | None = None,
) -> xr.Dataset:
    """Return an :class:`xarray.Dataset` of ``values`` described by ``table``.

    Every key of ``values`` must be declared in ``table`` and every declared variable
    given (a :class:`KeyError` names the difference): the table is the file's contents.
    ``coords`` maps a coordinate name to its declaration and values, ``(Var, values)``, or to
    a coordinate already in xarray's form, ``(dims, values, attributes)``
    (:func:`ballbat.stages.impacts.impact_coords`).
    """
    undeclared = sorted(set(values) - set(table))
    missing = sorted(set(table) - set(values))
    if undeclared or missing:
        raise KeyError(f"values do not match the declared table: undeclared {undeclared}, missing {missing}")
    data_vars = {name: (var.dims, np.asarray(values[name]), var.attributes()) for name, var in table.items()}
    coord_vars = {
        name: (c[0].dims, np.asarray(c[1]), c[0].attributes()) if isinstance(c[0], Var) else c
        for name, c in (coords or {}).items()
    }
    base = xr.Dataset(coords=coord_vars, attrs=dict(attrs or {}))
    if not _plain_data_vars(base, data_vars):
        return xr.Dataset(data_vars, coords=coord_vars, attrs=dict(attrs or {}))
    # the coordinates built (their indexes), the data variables put before them as xarray's merge
    # puts them: the Dataset the constructor gives (a test compares them), without its merge
    from xarray.core.variable import calculate_dimensions

    variables = {name: xr.Variable(*spec) for name, spec in data_vars.items()}
    variables.update(base._variables)
    return base._replace(variables=variables, dims=calculate_dimensions(variables))


def _plain_data_vars(base: xr.Dataset, data_vars: Mapping[str, tuple]) -> bool:
    """Whether :func:`build_dataset` may put ``data_vars`` beside the coordinates of ``base`` without xarray's merge.

    None is a coordinate or names a dimension (which would make it one), and every dimension
    has one size across the coordinates and the variables.
    """
    sizes = dict(base.sizes)
    for name, (dims, values, _) in data_vars.items():
        if name in base.variables or len(dims) != np.ndim(values):
            return False
        for d, n in zip(dims, np.shape(values), strict=True):
            if sizes.setdefault(d, n) != n:
                return False
    names = set(data_vars)
    return not any(d in names for d in sizes)


def add_variables(ds: xr.Dataset, table: Mapping[str, Var], values: Mapping[str, Any]) -> xr.Dataset:
    """Return a copy of ``ds`` with the declared variables of ``table`` that ``values`` gives, in table order.

    For stages that extend their input file (normalize, reconstruct); a value not declared
    in ``table`` is a :class:`KeyError`.
    """
    undeclared = sorted(set(values) - set(table))
    if undeclared:
        raise KeyError(f"values not declared in the table: {undeclared}")
    new = {
        name: (var.dims, np.asarray(values[name]), var.attributes()) for name, var in table.items() if name in values
    }
    out = ds.copy()
    if not _plain_additions(ds, new):
        out.update(new)  # one merge for all of them (one per variable is most of a replicate study's time)
        return out
    # variables of the dataset's own dimensions that are no coordinate: Dataset.update's result (the
    # same variables in the same order, a test compares them) without its merge, 0.6 of 0.75 ms a call
    variables = dict(out._variables)
    variables.update({name: xr.Variable(*spec) for name, spec in new.items()})
    return out._replace(variables=variables)


def _plain_additions(ds: xr.Dataset, new: Mapping[str, tuple]) -> bool:
    """Whether :func:`add_variables` may add ``new`` (name -> (dims, values, attributes)) without xarray's merge.

    Each variable lies on ``ds``'s dimensions, at their sizes, and is none of its coordinates.
    """
    for name, (dims, values, _) in new.items():
        if name in ds.coords or name in ds.dims or len(dims) != np.ndim(values):
            return False
        if any(ds.sizes.get(d) != n for d, n in zip(dims, np.shape(values), strict=True)):
            return False
    return True


#: Attributes carried from a dataset's first files to every later file: a measured dataset's
#: warnings (ingest.nc) and its bats as given and as used (``bat_properties``, reconstruct.nc;
#: :func:`ballbat.properties.bat_record`).
WARNING_ATTRS = ("ingest_warnings", "n_warnings", "bat_properties")


def carried_warnings(source: xr.Dataset) -> dict[str, Any]:
    """Return the carried attributes of ``source`` (:data:`WARNING_ATTRS`) to pass on."""
    return {k: source.attrs[k] for k in WARNING_ATTRS if k in source.attrs}
