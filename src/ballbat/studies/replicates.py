"""One replicate of a study: the workflow's stages in memory, its rows of estimates, and a batch of them.

A replicate (:func:`run_replicate`) is simulated, rendered and reduced where its dataset renders
tracks, normalized, reconstructed, fitted (fit_ex) and given its eta^2 (:func:`ballbat.chain.run`);
:func:`run_replicates` runs a batch job's replicates one after the other.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from ..datasets import renders
from .settings import StudySettings
from .sweeps import point_dataset

if TYPE_CHECKING:
    from collections.abc import Iterator

    from ..chain import DatasetSettings
    from ..properties import Ball, Bat


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
    (the workflow's reduce always does). ``check=False``: the truth job's large experiment, whose
    truth is a value: no cross-checks, no reruns, no contact population shifts
    (:attr:`ReduceSettings.cross_check`, :attr:`ReduceSettings.population_shifts`) and no estimate
    of the bound on mu_k (:attr:`FitExSettings.mu_k_bound`).
    ``settings`` None: the reference bat speed and the example's friction are the schema's (they
    do not enter the source, :func:`replicate_source`).
    """
    from ..chain import DatasetSettings, schema_settings
    from ..stages import fit_ex, normalize

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
        fit_ex.FitExSettings(mu_k, systematic=False, check_physical=False, mu_k_bound=check),
        systematics=drawn,
        where=where,
    ).with_seeds(*seeds)
    if check or base.reduce is None:
        return base
    return replace(base, reduce=replace(base.reduce, cross_check=False, systematics=False, population_shifts=False))


def replicate_source(
    dataset: dict,
    seeds: tuple[int, int],
    balls: dict[str, Ball],
    bats: dict[str, Bat],
    where: str = "render",
    check: bool = True,
) -> xr.Dataset:
    """Return one replicate's impacts: the chain's source (simulate; render and reduce) on :func:`chain_settings`."""
    from .. import chain

    return chain.source(chain_settings(None, dataset, seeds, where, check), balls, bats)


def _truth_source(src: xr.Dataset) -> xr.Dataset:
    """Return the same impacts with their noise-free truth in place of the measured values.

    Built once from the variables (each measured one replaced by its ``truth_*``, attributes and
    all, in its place), not by assigning them one after the other: the same Dataset, without an
    xarray merge per variable.
    """
    from ..designs import MEASURED

    swap = {k: f"truth_{k}" for k in MEASURED}
    variables = {k: src.variables[swap.get(k, k)] for k in src.data_vars}
    return xr.Dataset(variables, coords=src.coords, attrs=src.attrs)


def _eta2(
    rec: xr.Dataset, rec_truth: xr.Dataset, ball: str, stronge: dict, value: bool = True
) -> tuple[float, float, float, float]:
    """eta^2 of one ball (value, standard error, truth, degrees of freedom); NaN if not fitted.

    ``value=False`` (the truth job, which reads only the truth): the truth alone, the value, its
    error and dof NaN, NaN and 0.
    """
    from ..linefit import MIN_FIT_IMPACTS
    from ..stronge.analysis import fit_ball, vtf_data

    sel = (rec.variables["flag"].values == 0) & (rec.variables["ball"].values.astype(str) == ball)
    if sel.sum() < MIN_FIT_IMPACTS:
        return math.nan, math.nan, math.nan, 0
    kw = {k: stronge[k] for k in ("e_y", "mu", "vary_e_y", "vary_mu")}
    d = vtf_data(rec, sel)
    try:
        # the study keeps the value, error and dof, not the interval
        fit = fit_ball(d, interval=False, **kw) if value else None
        truth = fit_ball(
            vtf_data(rec_truth, sel),
            sigma=d.sigma,
            interval=False,
            errors=False,  # the truth is a value; its error and dof are never read
            errors_in_variables=False,
            finite_sample=False,
            **kw,
        ).eta2
    except (ValueError, RuntimeError):
        return math.nan, math.nan, math.nan, 0
    if fit is None:
        return math.nan, math.nan, truth, 0
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
        False: the truth job's large experiment, of which only each row's ``truth`` is read: no
        cross-checks, no contact population shifts (:func:`chain_settings`), and eta^2's truth
        alone (:func:`_eta2`).

    Returns
    -------
    list of dict
        ``quantity, ball, bat, value, uncertainty, truth, dof, units, systematic,
        calibration_effect`` (SI, as fit_ex.nc holds them; systematic NaN where there is none;
        calibration_effect, where the calibration is drawn, the first-order change the draw made:
        :func:`_calibration_effect`).
    """
    from .. import chain
    from ..systematics import has_shifts

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
        fitted = [_eta2(rec, rec_truth, ball, settings.stronge, value=check) for ball in balls_fitted]
        starts = [f[0] for f in fitted]  # the refits at each source's +-1 sigma start at the value
        syst, effect = _eta2_systematic(rec, balls_fitted, settings.stronge, z, starts) if drawn else (nan, nan)
        for ball, sy, ef, (v, e, t, dof) in zip(balls_fitted, syst, effect, fitted, strict=True):
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
    from ..properties import drawn_properties

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
    from ..systematics import SOURCES, source_names
    from ..tracks.render import calibration_draws

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
    from .. import chain

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


def _eta2_systematic(
    rec: xr.Dataset, balls: np.ndarray, stronge: dict, z: np.ndarray, starts: list[float]
) -> tuple[np.ndarray, np.ndarray]:
    """Return eta^2's calibration systematic of each ball and its change under the drawn calibration.

    The systematic: every source in quadrature (as stronge.nc's ``eta2_syst``); the change: first
    order, under the drawn calibration ``z`` (:func:`_calibration_effect`). ``starts``: each ball's
    fitted eta^2, where the refits start (:func:`ballbat.stages.stronge.stronge_shifts`).
    """
    from ..stages.stronge import stronge_shifts
    from ..stages.systematics import combine_sources

    kw = {k: stronge[k] for k in ("e_y", "mu", "vary_e_y", "vary_mu")}
    signed = stronge_shifts(rec, list(balls), ["eta2"], starts=starts, **kw)["eta2"]
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
        per_bat = "bat" in fit.variables[q].dims
        units = str(fit.variables[q].attrs["units"])
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
                        "units": units,
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
    from ..compare import systematic_var

    name = systematic_var(fit, q)
    v = None if name is None else at(name, ball, bat)
    return math.nan if v is None else float(v)


REFUSED_FRACTION_MAX = 0.05


class TooManyRefused(ValueError):
    """More of a batch's replicates were refused than a false alarm explains: a setting is wrong."""


def run_replicates(
    settings: StudySettings, batch: int, balls: dict[str, Ball], bats: dict[str, Bat]
) -> Iterator[tuple[int, int, int, list[dict], str]]:
    """Run the replicates of batch ``batch`` one after the other (the file: :func:`ballbat.studies.batch.run`).

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
    from ..properties import InputError

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
