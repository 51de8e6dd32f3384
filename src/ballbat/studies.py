"""Replicate studies: the whole chain on many synthetic experiments (coverage and design).

A study takes a synthetic dataset's settings and runs the stages the workflow runs
(:mod:`ballbat.stages`: simulate; when the dataset renders camera tracks, render and reduce;
normalize, reconstruct, fit_ex; and Stronge's eta^2 fit,
:func:`ballbat.stronge.fit.fit_eta2`) on independent replicate experiments, in memory and
in batches (:func:`run_batch`: one process per batch, one NetCDF file per batch, nothing per
replicate). Seeds: replicate ``k`` draws its experiment and its tracks from
``numpy.random.SeedSequence(seed, spawn_key=(k,))``, the same ``k`` at every sweep point
(common random numbers: the sweep's points differ by their setting, not by their luck).

Every quantity of ``paper_comparison.csv`` with an uncertainty and a synthetic truth is
recorded (value, standard error, truth, degrees of freedom) in SI, as ``fit_ex.nc`` holds it,
with its unit (the coordinate ``units`` of the study's files); the tables (coverage.csv) print
them in paper_comparison.csv's units (:func:`display_unit`). The truth
of a fitted quantity is, as in the workflow, the same estimator applied to the noise-free
truth of the same replicate with the same weights; for eta^2 it is the eta^2 fitted to the
noise-free impacts (the synthetic experiment is not drawn from Stronge's model, so eta^2 has
no truth of its own).

:func:`coverage` measures, per sweep point and quantity: the bias in units of the standard
error, the ratio of the empirical spread to the mean reported standard error, and the
fraction of 68 % and 95 % intervals (Student's t with the fit's degrees of freedom) that
cover the truth, each with its uncertainty. :func:`design` turns a sweep into what a lab
needs before it books the machine: the spread of e_x per bat at each setting and the number
of impacts per bat needed to tell two bats ``delta_e_x`` apart.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from .pipeline.products import Var, build_dataset
from .study_settings import StudySettings
from .sweeps import point_dataset, renders

if TYPE_CHECKING:
    from collections.abc import Iterable, Iterator, Sequence

    from numpy.typing import ArrayLike

    from .chain import DatasetSettings
    from .properties import Ball, Bat

#: The quantities of paper_comparison.csv a study records (those with an uncertainty and a truth).
STUDY_QUANTITIES = (
    "e_x",
    "e_x_pooled",
    "spin_theta_slope",
    "speed_theta_slope",
    "tan_ratio_slope",
    "e_y_implied",
    "mu_k_lower_bound",
    "eta2",
)


def replicate_seeds(seed: int, replicate: int) -> tuple[int, int]:
    """Seeds of one replicate's experiment and tracks, independent streams of the study's seed."""
    state = np.random.SeedSequence(seed, spawn_key=(replicate,)).generate_state(2, dtype=np.uint32)
    return int(state[0]), int(state[1])


# ---------------------------------------------------------------------------------------
# one replicate


def chain_settings(
    settings: StudySettings | None, dataset: dict, seeds: tuple[int, int], where: str = "render", check: bool = True
) -> DatasetSettings:
    """Return the chain's settings of one replicate (:class:`ballbat.chain.DatasetSettings`).

    The dataset block at the replicate's sweep point (:func:`point_dataset`), drawn from the
    replicate's seeds (experiment, tracks). A study records every replicate's numbers as they
    come (no refusal of an unphysical e_x) and fits no systematic (:func:`run_replicate` asks
    for the calibration's where the replicate draws its calibration); the tracks are reduced
    again at +-1 sigma of each stated calibration uncertainty only where the calibration is drawn
    (the workflow's reduce always does). ``check=False``: no cross-checks and no reruns (the truth
    job's large experiment, whose truth needs neither; :attr:`ReduceSettings.cross_check`).
    ``settings`` None: the reference bat speed and the example's friction are the schema's (they
    do not enter the source, :func:`replicate_source`).
    """
    from .chain import DatasetSettings, schema_settings
    from .stages import fit_ex, normalize

    drawn = renders(dataset) and bool(dataset["render"]["draw_calibration"])
    if settings is None:
        defaults = schema_settings({}, "study")
        norm, mu_k = defaults.normalize, defaults.fit_ex.mu_k_example
    else:
        norm, mu_k = normalize.NormalizeSettings(v_ref_mph=settings.v_ref_mph), settings.mu_k_example
    base = DatasetSettings.from_block(
        dataset,
        "study",
        norm,
        fit_ex.FitExSettings(mu_k, systematic=False, check_physical=False),
        systematics=drawn,
        where=where,
    ).with_seeds(*seeds)
    if check or base.reduce is None:
        return base
    return replace(base, reduce=replace(base.reduce, cross_check=False, systematics=False))


def replicate_source(
    dataset: dict,
    seeds: tuple[int, int],
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    where: str = "render",
    check: bool = True,
) -> xr.Dataset:
    """Return one replicate's impacts: the chain's source (simulate; render and reduce) on :func:`chain_settings`."""
    from . import chain

    return chain.source(chain_settings(None, dataset, seeds, where, check), balls, bats)


def _truth_source(src: xr.Dataset) -> xr.Dataset:
    """Return the same impacts with their noise-free truth in place of the measured values."""
    from .designs import MEASURED

    out = src.copy()
    for k in MEASURED:
        out[k] = src[f"truth_{k}"]
    return out


def _eta2(rec: xr.Dataset, rec_truth: xr.Dataset, ball: str, stronge: dict) -> tuple[float, float, float, float]:
    """eta^2 of one ball (value, standard error, truth, degrees of freedom); NaN if not fitted."""
    from .linefit import MIN_FIT_IMPACTS
    from .stronge.analysis import fit_ball, vtf_data

    sel = (rec["flag"].values == 0) & (rec["ball"].values.astype(str) == ball)
    if sel.sum() < MIN_FIT_IMPACTS:
        return math.nan, math.nan, math.nan, 0
    kw = {k: stronge[k] for k in ("e_y", "mu", "vary_e_y", "vary_mu")}
    d = vtf_data(rec, sel)
    try:
        fit = fit_ball(d, interval=False, **kw)  # the study keeps the value, error and dof, not the interval
        truth = fit_ball(
            vtf_data(rec_truth, sel),
            sigma=d.sigma,
            interval=False,
            errors_in_variables=False,
            finite_sample=False,
            **kw,
        ).eta2
    except (ValueError, RuntimeError):
        return math.nan, math.nan, math.nan, 0
    return fit.eta2, fit.eta2_err, truth, fit.dof


def run_replicate(
    settings: StudySettings,
    dataset: dict,
    replicate: int,
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    check: bool = True,
) -> list[dict]:
    """Run the chain on one replicate experiment; return one row per recorded quantity.

    Parameters
    ----------
    settings : StudySettings
    dataset : dict
        The dataset's config block at this sweep point (:func:`point_dataset`).
    replicate : int
        Replicate number within the point (seeds: :func:`replicate_seeds`).
    balls, bats : dict
        Property tables.
    check : bool
        Cross-check the reduced tracks' settings (:func:`chain_settings`; off for the truth job).

    Returns
    -------
    list of dict
        ``quantity, ball, bat, value, uncertainty, truth, dof, units, systematic,
        calibration_effect`` (SI, as fit_ex.nc holds them; systematic NaN where there is none;
        calibration_effect, where the calibration is drawn, the first-order change the draw made:
        :func:`_calibration_effect`).
    """
    from . import chain
    from .systematics import has_shifts

    seeds = replicate_seeds(settings.seed, replicate)
    cs = chain_settings(settings, dataset, seeds, f"render (replicate {replicate})", check)
    # the true properties: the tables' (or, with draw_properties, drawn from their stated uncertainties)
    true_balls, true_bats, z_props = drawn_tables(settings, replicate, balls, bats)
    src = chain.source(cs, true_balls, true_bats)
    # the systematics where the replicate draws its calibration or its properties (the combined
    # interval's coverage); every replicate's numbers are recorded as they come
    drawn = has_shifts(src) or bool(z_props)
    run = chain.run(replace(cs, fit_ex=replace(cs.fit_ex, systematic=drawn)), src, balls, bats)
    rec, fit, fs = run.reconstruct, run.fit_ex, run.fit_systematics
    z = source_draws(rec, dataset, seeds, z_props) if drawn else None
    if z_props:  # the truth: the same estimator on the noise-free values with the true properties
        fit = with_true_truth(fit, cs, src, true_balls, true_bats)
    rows = fit_quantity_rows(fit, None if fs is None else _calibration_effect(fit, fs.signed, z))
    if "eta2" in STUDY_QUANTITIES:
        rec_truth = chain.reconstructed(cs, _truth_source(src), true_balls, true_bats)
        balls_fitted = fit["ball"].values.astype(str)
        nan = np.full(balls_fitted.size, np.nan)
        syst, effect = _eta2_systematic(rec, balls_fitted, settings.stronge, z) if drawn else (nan, nan)
        for ball, sy, ef in zip(balls_fitted, syst, effect, strict=True):
            v, e, t, dof = _eta2(rec, rec_truth, ball, settings.stronge)
            rows.append(
                {
                    "quantity": "eta2",
                    "ball": ball,
                    "bat": "",
                    "value": v,
                    "uncertainty": e,
                    "truth": t,
                    "dof": dof,
                    "units": "1",
                    "systematic": float(sy) if math.isfinite(v) else math.nan,
                    "calibration_effect": float(ef) if math.isfinite(v) else math.nan,
                }
            )
    return rows


#: spawn_key tail of a replicate's stream of drawn properties (independent of its experiment's and tracks').
PROPERTY_STREAM = 1


def drawn_tables(
    settings: StudySettings, replicate: int, balls: dict[str, Ball], bats: dict[str, Bat]
) -> tuple[dict[str, Ball], dict[str, Bat], dict[str, float]]:
    """Return a replicate's true balls and bats and each property source's draw z (empty: the tables as they are).

    With ``settings.draw_properties`` every stated uncertainty of the tables is drawn
    (:func:`ballbat.properties.drawn_properties`) from ``SeedSequence(seed, spawn_key=(replicate,
    PROPERTY_STREAM))``; a table without any is a ValueError (nothing to draw).
    """
    from .properties import drawn_properties

    if not settings.draw_properties:
        return balls, bats, {}
    rng = np.random.default_rng(np.random.SeedSequence(settings.seed, spawn_key=(replicate, PROPERTY_STREAM)))
    true_bats, true_balls, z = drawn_properties(bats, balls, rng)
    if not z:
        raise ValueError("draw_properties: the bat and ball tables state no uncertainty (no *_err column)")
    return true_balls, true_bats, z


def source_draws(rec: xr.Dataset, dataset: dict, seeds: tuple[int, int], z_props: dict[str, float]) -> np.ndarray:
    """Return each systematic source's draw in standard uncertainties, in the order of ``rec``'s sources.

    The cameras' from the drawn calibration (:func:`ballbat.tracks.render.calibration_draws`; 0 where
    the calibration is not drawn), the properties' from ``z_props``.
    """
    from .systematics import SOURCES, source_names
    from .tracks.render import calibration_draws

    names = source_names(rec)
    calib = {}
    if renders(dataset) and dataset["render"]["draw_calibration"]:
        calib = dict(zip(SOURCES, calibration_draws({**dataset["render"], "seed": seeds[1]}), strict=True))
    return np.array([z_props.get(n, calib.get(n, 0.0)) for n in names], dtype=float)


def with_true_truth(
    fit: xr.Dataset, cs: DatasetSettings, src: xr.Dataset, balls: dict[str, Ball], bats: dict[str, Bat]
) -> xr.Dataset:
    """Return ``fit`` with its ``truth_*`` the estimator's on the noise-free values analysed with the true tables.

    fit_ex's own ``truth_*`` analyse the noise-free values with the tables' (nominal) properties,
    so they share the estimate's property error; the truth of a replicate whose properties are
    drawn is the analysis with the properties it was drawn with.
    """
    from . import chain

    quiet = replace(cs, fit_ex=replace(cs.fit_ex, systematic=False))
    true = chain.run(quiet, _truth_source(src), balls, bats).fit_ex
    return fit.assign({k: true[k.removeprefix("truth_")] for k in fit.data_vars if k.startswith("truth_")})


def _calibration_effect(fit: xr.Dataset, signed: dict[str, np.ndarray], z: np.ndarray) -> xr.Dataset:
    """Each quantity's first-order change under the drawn calibration: sum over sources of z_k times its signed shift.

    ``signed[q]``: half of (q at +1 sigma) - (q at -1 sigma) of each source (first axis, dims of
    ``fit[q]`` after it); ``z``: the replicate's drawn calibration in stated uncertainties
    (:func:`ballbat.tracks.render.calibration_draws`). The replicate's value plus this is, to
    first order in the calibration errors, the value the chain gives with the true calibration.
    """
    return xr.Dataset({q: (fit[q].dims, np.tensordot(z, v, axes=1)) for q, v in signed.items()}, coords=fit.coords)


def _eta2_systematic(rec: xr.Dataset, balls: np.ndarray, stronge: dict, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return eta^2's calibration systematic of each ball and its change under the drawn calibration.

    The systematic: every source in quadrature (as stronge.nc's ``eta2_syst``); the change: first
    order, under the drawn calibration ``z`` (:func:`_calibration_effect`).
    """
    from .stages.stronge import stronge_shifts
    from .stages.systematics import combine_sources

    kw = {k: stronge[k] for k in ("e_y", "mu", "vary_e_y", "vary_mu")}
    signed = stronge_shifts(rec, list(balls), ["eta2"], **kw)["eta2"]
    with np.errstate(invalid="ignore"):
        return combine_sources(signed), np.tensordot(z, signed, axes=1)


class _Numbers:
    """The numbers of a ``fit_ex.nc``-like Dataset by variable, ball and bat, read into plain arrays once.

    A replicate reads some 150 single numbers of its fit; xarray's label indexing costs about
    0.1 ms each, a plain array's index nothing. The values are the Dataset's own.
    """

    def __init__(self, ds: xr.Dataset) -> None:
        self.ds = ds
        self.ball = {str(b): i for i, b in enumerate(ds["ball"].values)}
        self.bat = {str(b): i for i, b in enumerate(ds["bat"].values)} if "bat" in ds.coords else {}
        self.arrays: dict[str, tuple[np.ndarray, bool]] = {}

    def __call__(self, var: str, ball: str, bat: str) -> float | None:
        """One number (None when the Dataset has no such variable)."""
        if var not in self.arrays:
            if var not in self.ds:
                return None
            da = self.ds[var]
            per_bat = "bat" in da.dims
            self.arrays[var] = (da.transpose("ball", "bat").values if per_bat else da.values, per_bat)
        values, per_bat = self.arrays[var]
        i = self.ball[ball]
        return float(values[i, self.bat[bat]] if per_bat else values[i])


def fit_quantity_rows(fit: xr.Dataset, effect: xr.Dataset | None = None) -> list[dict]:
    """Return the study's quantities of ``fit_ex.nc`` (:func:`ballbat.fitting.results_dataset`), SI as it holds them.

    One row per quantity, ball and bat (a per-bat quantity of a pair without impacts is left
    out, as in paper_comparison.csv): ``quantity, ball, bat, value, uncertainty, truth, dof``,
    ``units`` (the file's units attribute of the quantity), ``systematic`` and
    ``calibration_effect`` (from ``effect``, :func:`_calibration_effect`; NaN without it).
    """
    dof_of = {"spin_theta_slope": 2, "speed_theta_slope": 2}  # fitted parameters; others: 1
    balls = [str(b) for b in fit["ball"].values]
    bats = [str(b) for b in fit["bat"].values]
    at = _Numbers(fit)
    effect_at = None if effect is None else _Numbers(effect)
    rows = []
    for q in STUDY_QUANTITIES:
        if q not in fit:  # eta2: Stronge's fit (_eta2)
            continue
        per_bat = "bat" in fit[q].dims
        for ball in balls:
            for bat in bats if per_bat else [""]:
                val = at(q, ball, bat)
                if per_bat and not math.isfinite(val) and at(f"{q}_n", ball, bat) == 0:
                    continue
                var = "tan_ratio_slope" if q == "e_y_implied" else q
                n = at(f"{var}_n", ball, bat) if q != "mu_k_lower_bound" else None
                dof = math.inf if n is None else int(n) - dof_of.get(var, 1)
                if q == "e_y_implied":  # Student's t with n - k for the k = bats + 1 slopes its sandwich rests on
                    dof = int(n) - (sum(at("e_x_n", ball, b) > 0 for b in bats) + 1)
                rows.append(
                    {
                        "quantity": q,
                        "ball": ball,
                        "bat": bat,
                        "value": val,
                        "uncertainty": at(f"{q}_err", ball, bat),
                        "truth": at(f"truth_{q}", ball, bat),
                        "dof": dof,
                        "units": str(fit[q].attrs["units"]),
                        "systematic": _systematic(fit, at, q, ball, bat),
                        "calibration_effect": math.nan if effect_at is None else effect_at(q, ball, bat),
                    }
                )
    return rows


def _systematic(fit: xr.Dataset, at: _Numbers, q: str, ball: str, bat: str) -> float:
    """Return the systematic uncertainty of a quantity of ``fit_ex.nc`` (SI; NaN: none).

    ``{q}_syst`` (every calibration source) or, in files without it, ``{q}_err_scale``
    (:func:`ballbat.compare.systematic_var`).
    """
    from .compare import systematic_var

    name = systematic_var(fit, q)
    v = None if name is None else at(name, ball, bat)
    return math.nan if v is None else float(v)


# ---------------------------------------------------------------------------------------
# a batch: the file of one job

#: Attributes of a variable whose values along ``quantity`` are in different units: SI, the unit of each
#: quantity in the coordinate ``units`` (CF has no units attribute for such a variable; ``units_from``
#: names the coordinate, :func:`ballbat.pipeline.ncio.check_metadata`).
PER_QUANTITY_UNITS = {"units_from": "units"}


def row_labels(rows: list[dict]) -> list[str]:
    """Return ``quantity:ball:bat`` of each row of :func:`run_replicate` (the batches' quantity labels)."""
    return [f"{r['quantity']}:{r['ball']}:{r['bat']}" for r in rows]


#: Largest fraction of a batch's replicates whose data the chain may refuse before the batch stops.
REFUSED_FRACTION_MAX = 0.05


class TooManyRefused(ValueError):
    """More of a batch's replicates were refused than a false alarm explains: a setting is wrong."""


def run_replicates(
    settings: StudySettings, batch: int, balls: dict[str, Ball], bats: dict[str, Bat]
) -> Iterator[tuple[int, int, int, list[dict], str]]:
    """Run the replicates of batch ``batch`` one after the other (the file: :func:`ballbat.study_batch.run`).

    Yields, per replicate: its number over the whole study, its sweep point, its number within
    the point (:meth:`StudySettings.batch_range`), its rows (:func:`run_replicate`) and, when the
    chain refused its data, why ("" otherwise; no rows then).

    A check of the data (:func:`ballbat.tracks.verdict.cross_check`) refuses a lab's dataset at
    a false-alarm rate of about 1e-3 per test; over a study's thousands of replicates some are
    refused by chance, and a lab whose data were refused would not report them either. They
    are counted (``n_refused`` of the coverage table), not hidden. More than
    :data:`REFUSED_FRACTION_MAX` of a batch (at least 2 replicates) is no false alarm but a
    wrong setting: :class:`TooManyRefused`, with the first reason.
    """
    from .properties import InputError

    todo = settings.batch_range(batch)
    allowed = max(1, math.floor(REFUSED_FRACTION_MAX * len(todo)))
    reasons = []
    for g in todo:
        point, rep = divmod(g, settings.replicates)
        dataset = point_dataset(settings.dataset, settings.parameter, settings.values[point])
        try:
            rows, why = run_replicate(settings, dataset, rep, balls, bats), ""
        except InputError as err:
            rows, why = [], f"replicate {g} (point {point}, replicate {rep}): {err}"
            reasons.append(why)
            if len(reasons) > allowed:
                raise TooManyRefused(
                    f"batch {batch}: the chain refused {len(reasons)} of its first {g - todo[0] + 1} replicates "
                    f"(at most {allowed} of {len(todo)} are put down to false alarms); the first: {reasons[0]}"
                ) from err
        yield g, point, rep, rows, why


def quantity_coords(labels: list[str], parts: list[list[str]], units: list[str]) -> dict:
    """Return the ``quantity`` coordinate and its companions (name, ball, bat, SI unit) of a study's files."""
    return {
        "quantity": (Var(("quantity",), None, "quantity:ball:bat, as in paper_comparison.csv"), np.array(labels)),
        "quantity_name": (Var(("quantity",), None, "quantity"), np.array([p[0] for p in parts])),
        "ball": (Var(("quantity",), None, "ball type"), np.array([p[1] for p in parts])),
        "bat": (Var(("quantity",), None, "bat (empty: per ball)"), np.array([p[2] for p in parts])),
        "units": (Var(("quantity",), None, "SI unit of the quantity (UDUNITS)"), np.array(units, dtype=str)),
    }


def display_unit(quantity: str) -> str:
    """Return the unit the tables print a study quantity in (paper_comparison.csv's: rpm/deg, mph/deg; else 1)."""
    from .compare import FIT_QUANTITIES

    return FIT_QUANTITIES[quantity][1] if quantity in FIT_QUANTITIES else "1"


def study_attrs(settings: StudySettings, batch: int | None = None) -> dict:
    """Return the study's attributes: a grid's settings are comma-joined, its values flattened point by point."""
    attrs = {
        "study_seed": settings.seed,
        "replicates_per_point": settings.replicates,
        "sweep_parameter": ",".join(settings.parameters),
        "sweep_values": settings.point_settings().ravel(),
    }
    if batch is not None:
        attrs["batch"] = batch
    return attrs


def sweep_table(attrs: dict) -> tuple[tuple[str, ...], np.ndarray]:
    """Return the swept settings' names and their values at every point (point x setting) from a file's attrs.

    Without a sweep: no name and one point of NaN.
    """
    names = tuple(n for n in str(attrs.get("sweep_parameter", "")).split(",") if n)
    flat = np.atleast_1d(np.asarray(attrs["sweep_values"], dtype=float))
    return names, flat.reshape(-1, max(1, len(names)))


def _setting_column(names: tuple[str, ...], table: np.ndarray) -> np.ndarray:
    """Return the ``setting`` of a file: the swept value at each point; NaN for a grid (see ``grid_setting``)."""
    return table[:, 0] if len(names) <= 1 else np.full(table.shape[0], np.nan)


def _grid_coords(names: tuple[str, ...], table: np.ndarray) -> dict:
    """Return a grid's coordinates: ``parameter`` (its settings) and ``grid_setting`` (point x parameter), or none."""
    if len(names) <= 1:
        return {}
    return {
        "parameter": (Var(("parameter",), None, "swept setting of the grid"), np.array(names)),
        "grid_setting": (Var(("point", "parameter"), "1", "value of each swept setting at each point"), table),
    }


def combined_dof(uncertainty: ArrayLike, systematic: ArrayLike, dof: ArrayLike) -> np.ndarray:
    """Degrees of freedom of sqrt(uncertainty^2 + systematic^2) (Welch-Satterthwaite; GUM, JCGM 100:2008, G.4).

    The systematic is a stated calibration uncertainty, known exactly (infinite degrees of
    freedom), so nu_eff = nu (u^2 + s^2)^2 / u^4: where the systematic dominates, the combined
    interval's quantile tends to the normal one. Holding the statistical t quantile for the
    combined uncertainty widened it by up to 14 % at 12 impacts per bat and over-covered (99-100 %
    at 1-3 px in the robustness grid).
    """
    u2 = np.asarray(uncertainty, dtype=float) ** 2
    total = u2 + np.asarray(systematic, dtype=float) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(u2 > 0, np.asarray(dof, dtype=float) * (total / u2) ** 2, np.inf)


def point_label(names: Sequence[str], values: Sequence[float]) -> str:
    """``name = value, ...`` of a sweep point (empty without a sweep)."""
    return ", ".join(f"{n} = {v:g}" for n, v in zip(names, values, strict=True) if np.isfinite(v))


# ---------------------------------------------------------------------------------------
# the truth a replicate's estimate is judged against

#: Quantities judged against the truth of their own replicate (the same impacts noise-free):
#: the largest tan(psi - theta) of the impacts is a property of those impacts only.
CONDITIONAL_TRUTH = ("mu_k_lower_bound",)


def population_truth(settings: StudySettings, point: int, balls: dict[str, Ball], bats: dict[str, Bat]) -> dict:
    """Truth of every quantity for the experiment design at sweep point ``point`` (SI; :func:`_population_rows`).

    Returns
    -------
    dict
        ``quantity:ball:bat`` label -> truth.
    """
    rows = _population_rows(settings, point, balls, bats)
    return dict(zip(row_labels(rows), (r["truth"] for r in rows), strict=True))


def truth_scale(settings: StudySettings, point: int) -> int:
    """How many times the truth job's experiment repeats a replicate's design at sweep point ``point``.

    :meth:`StudySettings.truth_counts` (one rule for the truth's size). The truth's own
    sampling error is about that of a replicate's noise-free estimate over the square root of
    this number, for every pair alike (:func:`coverage`).
    """
    return settings.truth_counts(point)[0]


def _population_rows(settings: StudySettings, point: int, balls: dict[str, Ball], bats: dict[str, Bat]) -> list[dict]:
    """Return the rows of the design's large noise-free experiment at sweep point ``point`` (:func:`run_replicate`'s).

    A pooled e_x, a slope or eta^2 describes the population the impacts are drawn from (the
    bats in the design's proportions, psi and bat speed drawn as configured), not the handful
    of impacts of one replicate: where the model does not describe each bat exactly (pooled
    over bats of different e_x, a straight line through curved data), the impacts a replicate
    happens to draw move the estimate as much as the noise does, and the standard error from
    the scatter accounts for both. The truth is therefore the estimator on a large noise-free
    experiment of the same design (about ``settings.truth_impacts`` impacts per ball and bat on
    average, in the design's proportions: :meth:`StudySettings.truth_counts`), the same for
    every replicate of the point. e_x of one bat is the same either way (the model is exact);
    :data:`CONDITIONAL_TRUTH` keep their own.
    """
    ds = settings.point_dataset(point)
    ds["synthetic"]["impacts"] = settings.truth_counts(point)[1]
    # the design's truth is the tables' bat (a drawn one's e_x is the same: drawing moves the analysis, not e_x)
    seed = int(np.random.SeedSequence(settings.seed, spawn_key=(2**31 - 1, point)).generate_state(1)[0])
    big = replace(settings, seed=seed, draw_properties=False)
    return run_replicate(big, ds, 0, balls, bats, check=False)


#: The truth file of a study (``results/{study}/truth.nc``; dims point x quantity).
TRUTH_TABLE = {
    "truth": Var(
        ("point", "quantity"),
        None,
        "the estimator on the design's large noise-free experiment (SI: unit of its quantity in units; NaN: none)",
        PER_QUANTITY_UNITS,
    ),
    "setting": Var(("point",), "1", "value of the swept setting (NaN: no sweep)"),
    "truth_scale": Var(
        ("point",), "1", "how many times the truth's experiment repeats a replicate's design (truth_scale())"
    ),
}


def truth_dataset(
    settings: StudySettings, balls: dict[str, Ball], bats: dict[str, Bat], points: Sequence[int] | None = None
) -> xr.Dataset:
    """:func:`population_truth` of every sweep point, as a dataset (its own job: it runs beside the batches).

    ``points``: only these sweep points (one job per point, :func:`merge_truths` joins them);
    None: every point.

    Returns
    -------
    xarray.Dataset
        ``truth`` (point x quantity, labels as the batches'), ``setting``.
    """
    points = list(range(settings.n_points)) if points is None else [int(p) for p in points]
    rows_of = [_population_rows(settings, p, balls, bats) for p in points]
    truths = [dict(zip(row_labels(rows), (r["truth"] for r in rows), strict=True)) for rows in rows_of]
    units = {lab: r["units"] for rows in rows_of for lab, r in zip(row_labels(rows), rows, strict=True)}
    labels = list(dict.fromkeys(lab for t in truths for lab in t))
    names, table = sweep_table(study_attrs(settings))
    table = table[points]
    values = {
        "truth": np.array([[np.nan if t.get(lab) is None else float(t[lab]) for lab in labels] for t in truths]),
        "setting": _setting_column(names, table),
        "truth_scale": np.array([truth_scale(settings, p) for p in points], dtype=float),
    }
    coords = quantity_coords(labels, [lab.split(":") for lab in labels], [units[lab] for lab in labels])
    coords["point"] = (Var(("point",), "1", "sweep point"), np.asarray(points, dtype=np.int64))
    coords.update(_grid_coords(names, table))
    return build_dataset(
        TRUTH_TABLE, values, coords, {**study_attrs(settings), "truth_impacts": settings.truth_impacts}
    )


def merge_truths(parts: Iterable[xr.Dataset]) -> xr.Dataset:
    """Join the truth files of single sweep points (:func:`truth_dataset` with ``points``) into the study's.

    Quantities are aligned by label (NaN where a point has none); every point of the study must
    be there exactly once, or a :class:`ValueError` names the missing or repeated ones.
    """
    parts = list(parts)
    if not parts:
        raise ValueError("no truth files to merge")
    n = int(np.asarray(parts[0].attrs["sweep_values"]).size // max(1, len(sweep_table(parts[0].attrs)[0])))
    have = [int(p) for part in parts for p in part["point"].values]
    if sorted(have) != list(range(n)):
        missing = sorted(set(range(n)) - set(have))
        repeated = sorted({p for p in have if have.count(p) > 1})
        raise ValueError(f"truth files of {n} sweep points: missing {missing}, repeated {repeated}")
    labels = list(dict.fromkeys(lab for b in parts for lab in b["quantity"].values.tolist()))
    aligned = [b.reindex(quantity=labels) for b in parts]
    out = xr.concat(aligned, dim="point", data_vars="minimal", coords="minimal", compat="override", join="outer")
    out = out.sortby("point")
    out.attrs = {k: v for k, v in parts[0].attrs.items() if k in (*_TRUTH_ATTRS, "truth_impacts")}
    return out


#: The attributes a truth file carries from its study (:func:`_attrs`).
_TRUTH_ATTRS = ("study_seed", "replicates_per_point", "sweep_parameter", "sweep_values")


def truths_from_dataset(ds: xr.Dataset) -> list[dict]:
    """Return the per-point ``label -> truth`` mappings of :func:`truth_dataset` (what :func:`coverage` takes)."""
    labels = ds["quantity"].values.astype(str)
    return [dict(zip(labels, map(float, row), strict=True)) for row in ds["truth"].values]


def truth_scales_from_dataset(ds: xr.Dataset) -> np.ndarray:
    """Return the per-point ``truth_scale`` of :func:`truth_dataset` (what :func:`coverage` takes as ``truth_scale``).

    Raises
    ------
    ValueError
        A truth file without it (written before it was recorded): run its truth jobs again.
    """
    if "truth_scale" not in ds:
        raise ValueError(
            f"{ds.encoding.get('source', 'the truth file')}: no truth_scale variable (written by an older ballbat); "
            "delete the study's truth files and run its truth jobs again"
        )
    return ds["truth_scale"].values.astype(float)


# ---------------------------------------------------------------------------------------
# aggregation


def combine(batches: Iterable[xr.Dataset]) -> xr.Dataset:
    """Concatenate batch datasets along ``replicate`` (sorted; quantities aligned by label)."""
    batches = list(batches)
    if not batches:
        raise ValueError("no batches to combine")
    labels = list(dict.fromkeys(lab for b in batches for lab in b["quantity"].values.tolist()))
    parts = [b.reindex(quantity=labels) for b in batches]
    out = xr.concat(parts, dim="replicate", data_vars="minimal", coords="minimal", compat="override", join="outer")
    return out.sortby("replicate")


def _t(q: float, dof: np.ndarray) -> np.ndarray:
    from scipy import stats

    dof = np.asarray(dof, dtype=float)
    z = stats.norm.ppf(0.5 + q / 2)
    with np.errstate(all="ignore"):
        t = stats.t.ppf(0.5 + q / 2, np.where(np.isfinite(dof) & (dof > 0), dof, 1.0))
    return np.where(np.isfinite(dof), np.where(dof > 0, t, np.nan), z)


#: The coverage table (dims point x quantity).
COVERAGE_TABLE = {
    "n_replicates": Var(("point", "quantity"), "1", "replicates with a value, an uncertainty and a truth"),
    "n_refused": Var(
        ("point", "quantity"),
        "1",
        "replicates of the point whose data the chain refused (a check's false alarm; not in n_replicates)",
    ),
    "bias_over_se": Var(("point", "quantity"), "1", "mean of (value - truth) / uncertainty"),
    "bias_over_se_err": Var(
        ("point", "quantity"),
        "1",
        "standard error of bias_over_se: the replicates' scatter and the truth's own sampling error "
        "(truth_error_over_se) in quadrature",
    ),
    "truth_error_over_se": Var(
        ("point", "quantity"),
        "1",
        "sampling error of the design's truth (its large noise-free experiment) over the mean uncertainty "
        "(NaN: judged against each replicate's own truth, or no truth_scale)",
    ),
    "spread_over_se": Var(("point", "quantity"), "1", "standard deviation of (value - truth) / mean uncertainty"),
    "spread_over_se_err": Var(("point", "quantity"), "1", "standard error of spread_over_se"),
    "coverage_68": Var(("point", "quantity"), "1", "fraction of 68 % intervals (t quantile) that cover the truth"),
    "coverage_68_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68"),
    "coverage_95": Var(("point", "quantity"), "1", "fraction of 95 % intervals (t quantile) that cover the truth"),
    "coverage_95_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95"),
    "mean_uncertainty": Var(
        ("point", "quantity"), None, "mean reported uncertainty (SI: unit of the quantity in units)", PER_QUANTITY_UNITS
    ),
    "spread": Var(
        ("point", "quantity"), None, "standard deviation of value - truth (SI: unit in units)", PER_QUANTITY_UNITS
    ),
    "mean_value": Var(("point", "quantity"), None, "mean estimate (SI: unit in units)", PER_QUANTITY_UNITS),
    "mean_truth": Var(("point", "quantity"), None, "mean truth (SI: unit in units)", PER_QUANTITY_UNITS),
    "mean_dof": Var(("point", "quantity"), "1", "mean degrees of freedom of the uncertainty"),
    "n_systematic": Var(("point", "quantity"), "1", "replicates of n_replicates with a systematic uncertainty"),
    "mean_systematic": Var(
        ("point", "quantity"), None, "mean reported systematic uncertainty (SI: unit in units)", PER_QUANTITY_UNITS
    ),
    "coverage_68_combined": Var(
        ("point", "quantity"),
        "1",
        "fraction of 68 % combined intervals (t quantile x sqrt(uncertainty^2 + systematic^2), Welch-Satterthwaite "
        "degrees of freedom) that cover the truth "
        "(NaN: no systematic)",
    ),
    "coverage_68_combined_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68_combined"),
    "coverage_95_combined": Var(
        ("point", "quantity"),
        "1",
        "fraction of 95 % combined intervals (t quantile x sqrt(uncertainty^2 + systematic^2), Welch-Satterthwaite "
        "degrees of freedom) that cover the truth "
        "(NaN: no systematic)",
    ),
    "coverage_95_combined_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95_combined"),
    "n_calibrated": Var(("point", "quantity"), "1", "replicates of n_replicates with a drawn calibration's effect"),
    "bias_over_se_calibrated": Var(
        ("point", "quantity"),
        "1",
        "mean of (value + calibration_effect - truth) / uncertainty: the bias with the drawn calibration's "
        "first-order effect taken out (NaN: calibration not drawn)",
    ),
    "bias_over_se_calibrated_err": Var(
        ("point", "quantity"), "1", "standard error of bias_over_se_calibrated (as bias_over_se_err)"
    ),
    "spread_over_se_calibrated": Var(
        ("point", "quantity"),
        "1",
        "standard deviation of value + calibration_effect - truth / mean uncertainty (NaN: calibration not drawn)",
    ),
    "spread_over_se_calibrated_err": Var(("point", "quantity"), "1", "standard error of spread_over_se_calibrated"),
    "coverage_68_calibrated": Var(
        ("point", "quantity"),
        "1",
        "fraction of 68 % statistical intervals around value + calibration_effect that cover the truth "
        "(NaN: calibration not drawn)",
    ),
    "coverage_68_calibrated_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_68_calibrated"),
    "coverage_95_calibrated": Var(
        ("point", "quantity"),
        "1",
        "fraction of 95 % statistical intervals around value + calibration_effect that cover the truth "
        "(NaN: calibration not drawn)",
    ),
    "coverage_95_calibrated_err": Var(("point", "quantity"), "1", "binomial standard error of coverage_95_calibrated"),
    "setting": Var(("point",), "1", "value of the swept setting (NaN: no sweep, or a grid: grid_setting)"),
}


#: Fewest replicates that judge a coverage: the binomial standard error of a 95 % coverage from
#: n replicates is sqrt(0.95 x 0.05 / n), 2.2 points at n = 100. Intervals 16 % too narrow
#: (1.645 instead of 1.96 standard errors) cover 90 %, which 100 replicates tell from 95 % at
#: 2.3 standard errors; fewer cannot, and their table gets a warning (``coverage_warning``).
MIN_COVERAGE_REPLICATES = 100


def coverage_warning(n: int) -> str:
    """Return the warning a quantity with ``n`` replicates gets in the coverage table ("" when enough)."""
    if n >= MIN_COVERAGE_REPLICATES:
        return ""
    se = 100 * math.sqrt(0.95 * 0.05 / max(n, 1))
    return (
        f"only {n} replicates: a 95 % coverage is known to +-{se:.1f} points (binomial), too coarse to tell "
        f"honest intervals from intervals 16 % too narrow (90 % coverage); use at least {MIN_COVERAGE_REPLICATES}"
    )


class EmptySweepPoint(ValueError):
    """A sweep point at which no replicate gave a usable estimate of any quantity."""


def _interval_columns(ok: np.ndarray, d: np.ndarray, e: np.ndarray, dof: np.ndarray, tag: str = "") -> dict:
    """Return bias, spread and 68/95 % coverage of ``d`` (replicate x quantity in, a row per quantity out).

    ``ok``: the replicates to judge; ``d``: estimate - truth; ``e``: the statistical
    uncertainty, ``dof`` its degrees of freedom. ``tag`` goes into every column's name before
    ``_err`` (``"_calibrated"``: the columns of value + calibration_effect, the value a lab
    with the true calibration would get, so that the drawn calibration's spread, which the
    statistical error does not claim, leaves the bias and the coverage).
    """
    n = ok.sum(axis=0)
    col = {}
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a quantity no replicate judged: NaN, said by n
        d = np.where(ok, d, np.nan)
        z = d / np.where(ok, e, np.nan)
        col["bias_over_se"] = np.nanmean(z, axis=0)
        col["bias_over_se_err"] = np.nanstd(z, axis=0, ddof=1) / np.sqrt(n)
        ratio = np.nanstd(d, axis=0, ddof=1) / np.nanmean(np.where(ok, e, np.nan), axis=0)
        col["spread_over_se"] = ratio
        col["spread_over_se_err"] = ratio / np.sqrt(2.0 * np.maximum(n - 1, 1))
        for q in (68, 95):
            frac = np.where(ok, np.abs(d) <= _t(q / 100, dof) * e, False).sum(axis=0) / n
            col[f"coverage_{q}"] = frac
            col[f"coverage_{q}_err"] = np.sqrt(frac * (1 - frac) / n)
    return {(k[:-4] + tag + "_err" if k.endswith("_err") else k + tag): v for k, v in col.items()}


def _empty_point(p: int, what: str, n: int) -> EmptySweepPoint:
    """Return the error of sweep point ``p`` (``what``: its settings) whose ``n`` replicates estimated nothing."""
    return EmptySweepPoint(
        f"sweep point {p}{f' ({what})' if what else ''}: none of its {n} replicates gave a "
        "usable estimate (value, uncertainty and truth) of any quantity; the setting is beyond what the "
        "chain can fit: drop the point or change it"
    )


def _combined_columns(ok: np.ndarray, d: np.ndarray, e: np.ndarray, syst: np.ndarray, dof: np.ndarray) -> dict:
    """Return the combined interval's columns (statistical and systematic in quadrature) of one sweep point.

    Only where a systematic is reported: a quantity without one gets NaN, not the statistical
    coverage again. ``d``: estimate minus truth; ``e``, ``syst``, ``dof``: per replicate and quantity.
    """
    out = {}
    oks = ok & np.isfinite(syst) & (syst >= 0)
    ns = oks.sum(axis=0)
    out["n_systematic"] = ns
    s_used = np.where(oks, syst, 0.0)
    out["mean_systematic"] = s_used.sum(axis=0) / np.where(ns > 0, ns, np.nan)
    combined = np.hypot(e, s_used)
    dof_combined = combined_dof(e, s_used, dof)
    for q in (68, 95):
        half = _t(q / 100, dof_combined) * combined
        frac = np.where(oks, np.abs(d) <= half, False).sum(axis=0) / np.where(ns > 0, ns, np.nan)
        out[f"coverage_{q}_combined"] = frac
        out[f"coverage_{q}_combined_err"] = np.sqrt(frac * (1 - frac) / ns)
    return out


def coverage(
    rep: xr.Dataset, truths: Sequence[dict] | None = None, truth_scale: Sequence[float] | None = None
) -> xr.Dataset:
    """Coverage of every quantity at every sweep point (from :func:`combine`'s replicates).

    ``truths``: per sweep point, the design's truth of each quantity (:func:`population_truth`);
    None judges every estimate against its own replicate's truth. ``truth_scale``: per sweep
    point, how many times the truth's experiment repeats a replicate's design
    (:func:`truth_scale`). The design's truth is itself an estimate from a finite experiment:
    its sampling error is about the spread of the replicates' own noise-free estimates (their
    ``truth``) over the square root of that number. It is not negligible against a bias of a
    tenth of a standard error (up to 0.05-0.08 standard errors at 30-60 impacts per bat and
    10000 per truth, where the noise-free estimate scatters as much as the noisy one), so it
    goes into the bias's standard error (``truth_error_over_se``).

    A point at which no replicate
    has a usable estimate of any quantity raises :class:`EmptySweepPoint` naming it; a quantity
    with fewer than :data:`MIN_COVERAGE_REPLICATES` replicates gets a warning (``warning``).
    """
    swept, table = sweep_table(rep.attrs)
    npt, nq = table.shape[0], rep.sizes["quantity"]
    out = {k: np.full((npt, nq), np.nan) for k in COVERAGE_TABLE if k != "setting"}
    point = rep["point"].values
    syst_all = rep["systematic"].values if "systematic" in rep else np.full(rep["value"].shape, np.nan)
    eff_all = rep["calibration_effect"].values if "calibration_effect" in rep else np.full(rep["value"].shape, np.nan)
    refused = rep["refusal"].values.astype(str) != "" if "refusal" in rep else np.zeros(point.size, dtype=bool)
    for p in range(npt):
        sel = point == p
        v, e, t, dof = (rep[k].values[sel] for k in ("value", "uncertainty", "truth", "dof"))
        syst, eff = syst_all[sel], eff_all[sel]
        own = t
        use = np.zeros(t.shape[1], dtype=bool)
        if truths is not None:
            labels = rep["quantity"].values.astype(str)
            names = rep["quantity_name"].values.astype(str)
            pop = np.array([truths[p].get(lab, np.nan) for lab in labels])
            use = np.array([nm not in CONDITIONAL_TRUTH for nm in names])
            t = np.where(use[None, :], pop[None, :], t)
        ok = np.isfinite(v) & np.isfinite(e) & np.isfinite(t) & (e > 0)
        n = ok.sum(axis=0)
        if not n.any():
            raise _empty_point(p, point_label(swept, table[p]) if swept else "", int(sel.sum()))
        out["n_replicates"][p] = n
        out["n_refused"][p] = refused[sel].sum()
        okc = ok & np.isfinite(eff)
        out["n_calibrated"][p] = okc.sum(axis=0)
        for k, col in {
            **_interval_columns(ok, v - t, e, dof),
            **_interval_columns(okc, v + eff - t, e, dof, "_calibrated"),
        }.items():
            out[k][p] = col
        if truth_scale is not None:
            te = _truth_error_over_se(ok & use[None, :], own, e, float(truth_scale[p]))
            out["truth_error_over_se"][p] = te
            for k in ("bias_over_se_err", "bias_over_se_calibrated_err"):
                out[k][p] = np.hypot(out[k][p], np.where(np.isfinite(te), te, 0.0))
        with np.errstate(all="ignore"):
            d = np.where(ok, v - t, np.nan)
            out["spread"][p] = np.nanstd(d, axis=0, ddof=1)
            out["mean_uncertainty"][p] = np.nanmean(np.where(ok, e, np.nan), axis=0)
            for k, col in _combined_columns(ok, d, e, syst, dof).items():
                out[k][p] = col
            out["mean_value"][p] = np.nanmean(np.where(ok, v, np.nan), axis=0)
            out["mean_truth"][p] = np.nanmean(np.where(ok, t, np.nan), axis=0)
            out["mean_dof"][p] = np.nanmean(np.where(ok, dof, np.nan), axis=0)
    out["setting"] = _setting_column(swept, table)
    coords = {k: _copy_coord(rep, k) for k in ("quantity", "quantity_name", "ball", "bat", "units")}
    coords["point"] = (Var(("point",), "1", "sweep point"), np.arange(npt, dtype=np.int64))
    coords.update(_grid_coords(swept, table))
    from .compare import STANDARD_ERROR, UNCERTAINTY_NOTES

    kinds = np.array([UNCERTAINTY_NOTES.get(str(q), STANDARD_ERROR) for q in rep["quantity_name"].values])
    coords["error_kind"] = (Var(("quantity",), None, "what the quantity's uncertainty is"), kinds)
    warn = np.array([[coverage_warning(int(n)) for n in row] for row in out["n_replicates"]], dtype=str)
    coords["warning"] = (Var(("point", "quantity"), None, "why the coverage cannot be judged (empty: it can)"), warn)
    attrs = {k: rep.attrs[k] for k in ("study_seed", "replicates_per_point", "sweep_parameter") if k in rep.attrs}
    return build_dataset(COVERAGE_TABLE, out, coords, attrs)


def _truth_error_over_se(ok: np.ndarray, own: np.ndarray, e: np.ndarray, scale: float) -> np.ndarray:
    """Return the sampling error of a design's truth over the mean uncertainty (per quantity; NaN where ``ok`` has < 2).

    ``own``: each replicate's own noise-free estimate; the truth's experiment is ``scale`` times
    a replicate's, so its estimate scatters about sqrt(scale) times less.
    """
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        good = ok & np.isfinite(own)
        spread = np.nanstd(np.where(good, own, np.nan), axis=0, ddof=1)
        mean_e = np.nanmean(np.where(good, e, np.nan), axis=0)
        return spread / math.sqrt(scale) / mean_e


def _copy_coord(ds: xr.Dataset, name: str) -> tuple:
    v = ds[name]
    return (Var(("quantity",), None, v.attrs.get("long_name", name)), v.values.astype(str))


COVERAGE_COLUMNS = (
    "setting",
    "quantity",
    "ball",
    "bat",
    "unit",
    "n_replicates",
    "n_refused",
    "bias_over_se",
    "bias_over_se_err",
    "truth_error_over_se",
    "spread_over_se",
    "spread_over_se_err",
    "coverage_68",
    "coverage_68_err",
    "coverage_95",
    "coverage_95_err",
    "mean_systematic",
    "coverage_68_combined",
    "coverage_68_combined_err",
    "coverage_95_combined",
    "coverage_95_combined_err",
    "bias_over_se_calibrated",
    "bias_over_se_calibrated_err",
    "spread_over_se_calibrated",
    "spread_over_se_calibrated_err",
    "coverage_68_calibrated",
    "coverage_68_calibrated_err",
    "coverage_95_calibrated",
    "coverage_95_calibrated_err",
    "mean_uncertainty",
    "spread",
    "mean_dof",
    "error_kind",
    "warning",
)


def _csv_text(header: Sequence[str], rows: Iterable[Sequence]) -> str:
    """Return CSV text: strings as they are, numbers as in paper_comparison.csv (empty when not finite).

    The table ends in its check line (:func:`ballbat.pipeline.checked.sealed_csv`).
    """
    import csv
    import io

    from .compare import format_number
    from .pipeline.checked import sealed_csv

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)
    for row in rows:
        w.writerow([x if isinstance(x, str) else format_number(x) for x in row])
    return sealed_csv(buf.getvalue())  # its check line: a table cut short is never used


#: Columns of the coverage table in the unit of their quantity: SI in coverage.nc, the table's units in the CSV.
COVERAGE_IN_UNITS = ("mean_uncertainty", "spread", "mean_systematic")


def coverage_csv(cov: xr.Dataset) -> str:
    """Return the coverage table as CSV text (one row per sweep point and quantity).

    Values in a quantity's unit are converted from coverage.nc's SI to the unit the tables
    print (``unit``, :func:`display_unit`: rpm/deg, mph/deg as in paper_comparison.csv).
    """
    from .units import from_si

    labels = {"quantity": "quantity_name", "ball": "ball", "bat": "bat", "error_kind": "error_kind"}
    shown = [display_unit(str(q)) for q in cov["quantity_name"].values]
    for j, (unit, si) in enumerate(zip(shown, cov["units"].values.astype(str), strict=True)):
        if unit == "1" and si != "1":
            raise ValueError(
                f"coverage: quantity {cov['quantity'].values[j]} is in {si}, but the table has no unit for it"
            )

    grid = [str(n) for n in cov["parameter"].values] if "grid_setting" in cov else []

    def row(p, j):
        for k in COVERAGE_COLUMNS:
            if k == "setting" and grid:  # a grid: its settings in words, and in columns of their own at the end
                yield " ".join(f"{n}={v:g}" for n, v in zip(grid, cov["grid_setting"].values[p], strict=True))
            elif k == "setting":
                yield cov["setting"].values[p]
            elif k == "warning":
                yield str(cov["warning"].values[p, j])
            elif k == "unit":
                yield shown[j]
            elif k in labels:
                yield str(cov[labels[k]].values[j])
            elif k in COVERAGE_IN_UNITS:
                yield from_si(float(cov[k].values[p, j]), shown[j])
            else:
                yield cov[k].values[p, j]
        if grid:
            yield from cov["grid_setting"].values[p]

    header = [*COVERAGE_COLUMNS, *grid]  # "setting,quantity,ball,bat,...": the header the guards know
    points, quantities = range(cov.sizes["point"]), range(cov.sizes["quantity"])
    return _csv_text(header, (list(row(p, j)) for p in points for j in quantities))


# ---------------------------------------------------------------------------------------
# design


def impacts_required(
    sigma: float, n_at: float, delta: float, confidence: float = 0.95, power: float = 0.8, n_max: int = 100_000
) -> float:
    """Impacts per bat needed to tell two bats ``delta`` apart in e_x.

    Two bats measured with n impacts each, e_x of each with standard deviation
    ``sigma * sqrt(n_at / n)`` (the spread found with ``n_at`` impacts, scaling as 1/sqrt(n));
    a two-sided test at ``confidence`` detects a difference ``delta`` with probability
    ``power`` when ``delta >= sqrt(2) * sigma_n * (t_{(1+c)/2} + t_{power})`` with the
    Student-t quantiles of 2 (n - 1) degrees of freedom.

    Returns
    -------
    float
        The smallest such n (at least 3), NaN when ``sigma`` is not finite, inf beyond ``n_max``.
    """
    from scipy import stats

    if not (math.isfinite(sigma) and sigma > 0 and math.isfinite(n_at) and n_at > 0):
        return math.nan
    s1 = sigma * math.sqrt(n_at)

    def enough(n: int) -> bool:
        dof = 2 * (n - 1)
        k = stats.t.ppf(0.5 + confidence / 2, dof) + stats.t.ppf(power, dof)
        return math.sqrt(2.0 / n) * s1 * k <= delta

    if not enough(n_max):
        return math.inf
    lo, hi = 2, n_max  # enough(hi) holds; find the smallest
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if enough(mid) else (mid, hi)
    return float(max(hi, 3))


DESIGN_TABLE = {
    "impacts_per_bat": Var(("point", "pair"), "1", "impacts of the ball on the bat at the sweep point"),
    "sigma_e_x": Var(("point", "pair"), "1", "standard deviation of e_x over the replicates"),
    "sigma_e_x_err": Var(("point", "pair"), "1", "standard error of sigma_e_x"),
    "mean_se_e_x": Var(("point", "pair"), "1", "mean reported standard error of e_x"),
    "impacts_required": Var(
        ("point", "pair"), "1", "impacts per bat to tell two such bats delta_e_x apart (confidence, power)"
    ),
    "setting": Var(("point",), "1", "value of the swept setting"),
}


def design(cov: xr.Dataset, settings: StudySettings) -> xr.Dataset:
    """Spread of e_x per bat and ball at each sweep point and the impacts a lab would need.

    Parameters
    ----------
    cov : xarray.Dataset
        :func:`coverage` of the study.
    settings : StudySettings
        Its sweep, and the difference in e_x between two bats to detect (``delta_e_x``) with
        the ``confidence`` and ``power`` of the two-sided test.

    Returns
    -------
    xarray.Dataset
        Dims point x pair (a pair is one ball on one bat).
    """
    sel = np.flatnonzero(cov["quantity_name"].values == "e_x")
    balls = cov["ball"].values[sel].astype(str)
    bats = cov["bat"].values[sel].astype(str)
    npt = cov.sizes["point"]
    out = {k: np.full((npt, sel.size), np.nan) for k in DESIGN_TABLE if k != "setting"}
    for p in range(npt):
        ds = point_dataset(settings.dataset, settings.parameter, settings.values[p])
        for j, q in enumerate(sel):
            n_at = float(ds["synthetic"]["impacts"][balls[j]][bats[j]])
            sigma = float(cov["spread"].values[p, q])
            n = float(cov["n_replicates"].values[p, q])
            out["impacts_per_bat"][p, j] = n_at
            out["sigma_e_x"][p, j] = sigma
            out["sigma_e_x_err"][p, j] = sigma / math.sqrt(2 * max(n - 1, 1))
            out["mean_se_e_x"][p, j] = float(cov["mean_uncertainty"].values[p, q])
            out["impacts_required"][p, j] = impacts_required(
                sigma, n_at, settings.delta_e_x, settings.confidence, settings.power
            )
    out["setting"] = cov["setting"].values
    coords = {
        "point": (Var(("point",), "1", "sweep point"), np.arange(npt, dtype=np.int64)),
        "pair": (Var(("pair",), None, "ball:bat"), np.array([f"{b}:{t}" for b, t in zip(balls, bats, strict=True)])),
        "ball": (Var(("pair",), None, "ball type"), balls),
        "bat": (Var(("pair",), None, "bat"), bats),
    }
    attrs = {
        "sweep_parameter": settings.parameter or "",
        "delta_e_x": settings.delta_e_x,
        "confidence": settings.confidence,
        "power": settings.power,
    }
    return build_dataset(DESIGN_TABLE, out, coords, attrs)


DESIGN_COLUMNS = (
    "parameter",
    "setting",
    "ball",
    "bat",
    "impacts_per_bat",
    "sigma_e_x",
    "sigma_e_x_err",
    "mean_se_e_x",
    "impacts_required",
)


def design_csv(des: xr.Dataset) -> str:
    """Return the design table as CSV text (one row per sweep point, ball and bat)."""

    def row(p, j):
        head = [des.attrs["sweep_parameter"], des["setting"].values[p], str(des["ball"].values[j])]
        return head + [str(des["bat"].values[j])] + [des[k].values[p, j] for k in DESIGN_COLUMNS[4:]]

    return _csv_text(DESIGN_COLUMNS, (row(p, j) for p in range(des.sizes["point"]) for j in range(des.sizes["pair"])))
