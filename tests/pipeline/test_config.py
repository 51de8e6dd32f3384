"""The schema and its defaults (ballbat.pipeline.config): typed settings take their defaults from the config
schema alone, and every setting is honoured (issue 20).
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import importlib
import math
import pkgutil
import re
from pathlib import Path

import numpy as np
import pytest

import ballbat
from ballbat.chain import DatasetSettings
from ballbat.config_checks import validate_config
from ballbat.datasets import renders
from ballbat.league import LeagueSettings
from ballbat.pipeline.config import block_schema, checked_block, packaged_schema
from ballbat.properties import InputError
from ballbat.stages.fit_ex import FitExSettings
from ballbat.stages.implications import ImplicationsSettings
from ballbat.stages.ingest import IngestSettings
from ballbat.stages.normalize import NormalizeSettings
from ballbat.stages.reconstruct import ReconstructSettings
from ballbat.stages.reduce import ReduceSettings, reduce_options
from ballbat.stages.stronge import StrongeSettings
from ballbat.studies.replicates import replicate_source
from ballbat.studies.settings import StudySettings
from ballbat.synthetic import SyntheticSettings
from ballbat.tracks.data import Camera, Rig, camera_block
from ballbat.tracks.formats.layout import DEFAULT_PATTERN
from ballbat.tracks.io import cameras_from_config
from ballbat.tracks.reduce import ReduceOptions
from ballbat.tracks.render import RenderCamera, RenderSettings, settings_from_config
from ballbat.units import DEGREE, INCH

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = packaged_schema()

_same = lambda v: v  # noqa: E731
_tuple = lambda v: tuple(float(x) for x in v)  # noqa: E731
_deg = lambda v: tuple(x * DEGREE for x in v)  # noqa: E731
_ms = lambda v: tuple(x * 1e-3 for x in v)  # noqa: E731
_mm = lambda v: float(v) * 1e-3  # noqa: E731

#: Every settings dataclass: the schema block it is built from and, per field, the key (path in
#: the block) and the conversion from the config's units. A field not named here has no key of
#: its own in the block (a nested dataclass, a required key, the study's sweep).
SETTINGS = {
    LeagueSettings: ("league", {}),  # every field required: the schema gives the defaults
    Camera: (
        "render_camera",
        {"fps": (("fps",), _same), "m_per_px": (("m_per_px",), _same), "mirror": (("mirror",), _same)}
        | {"m_per_px_err": (("m_per_px_err",), _same), "fps_err": (("fps_err",), _same)},
    ),
    Rig: ("render", {}),  # pivot distances: required (no default), converted from inches
    RenderCamera: (
        "render_camera",
        {k: ((k,), _same) for k in ("width_px", "height_px", "pixel_noise_px", "pre_impact_frames", "max_frames")}
        | {"tee_px": (("tee_px",), _tuple)},
    ),
    RenderSettings: (
        "render",
        {
            "seed": (("seed",), _same),
            "swing_plane": (("swing_plane_deg",), _deg),
            "contact_time": (("contact_ms",), _ms),
            "bat_slowdown": (("bat_slowdown",), _tuple),
            "bat_axis_to_ball": (("bat_axis_to_ball_mm",), _mm),
            "axis_offset": (("axis_offset_mm",), _mm),
            "tilted_fraction": (("tilted_fraction",), _same),
            "tilt": (("tilt_deg",), _deg),
        },
    ),
    ReduceOptions: (
        "min_frames",
        {"min_tip_frames": (("tip",), _same), "min_flight_frames": (("flight",), _same)}
        | {"min_spin_frames": (("spin",), _same)},
    ),
    SyntheticSettings: (
        "synthetic",
        {k: ((k,), _same) for k in ("seed", "psi_deg", "e_x_scatter", "impacts", "e_x", "e_y")}
        | {"v_bat_mph": (("v_bat_mph",), _tuple), "noise": (("noise",), _same)},
    ),
    # the stages' own settings (ballbat.stages); systematic, check_physical, where and systematics
    # are no config keys (the workflow and a replicate set them), nor are the pass-through blocks
    FitExSettings: ("analysis", {"mu_k_example": (("mu_k_example",), _same)}),
    NormalizeSettings: ("normalize", {"v_ref_mph": (("v_ref_mph",), _same)}),
    StrongeSettings: ("stronge", {k: ((k,), _same) for k in ("e_y", "mu", "vary_e_y", "vary_mu", "n_time")}),
    ReduceSettings: ("tracks", {}),
    ImplicationsSettings: ("implications", {}),
    ReconstructSettings: ("analysis", {}),  # no setting yet: the property tables are inputs
    IngestSettings: ("analysis", {}),  # no setting yet: the files are inputs
    # the chain's settings hold the stages' (above); its name and block are no config keys
    DatasetSettings: ("analysis", {}),
    StudySettings: (
        "study",
        {k: ((k,), _same) for k in ("replicates", "seed", "batch_size", "truth_impacts")}
        | {k: ((k,), _same) for k in ("delta_e_x", "confidence", "power")},
    ),
}


def _node(schema: dict, path: tuple) -> dict:
    """The schema of the key at ``path`` inside a block's schema (``$ref`` followed)."""
    from ballbat.pipeline.config import _resolve

    node = schema
    for part in path:
        node = _resolve(node, SCHEMA)["properties"][part]
    return _resolve(node, SCHEMA)


def default_problems(cls: type, kind: str, fields: dict) -> list[str]:
    """Every field default of ``cls`` that the schema does not give, or gives otherwise."""
    sub = block_schema(kind, SCHEMA)
    problems = []
    for f in dataclasses.fields(cls):
        if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            continue
        code = f.default if f.default is not dataclasses.MISSING else f.default_factory()
        if f.name not in fields:
            problems.append(
                f"{cls.__name__}.{f.name}: default {code!r} in the code; the schema's {kind} has no such key"
            )
            continue
        path, convert = fields[f.name]
        node = _node(sub, path)
        if "default" not in node:
            problems.append(f"{cls.__name__}.{f.name}: default {code!r} in the code; the schema gives none")
        elif convert(node["default"]) != code:
            problems.append(
                f"{cls.__name__}.{f.name}: default {code!r} in the code, the schema's {'.'.join(path)}: "
                f"{node['default']!r}"
            )
    return problems


def _settings_dataclasses() -> set[type]:
    """Every dataclass of the package that holds settings (named ...Settings, ...Options, or registered)."""
    found = set()
    for mod in pkgutil.walk_packages(ballbat.__path__, "ballbat."):
        module = importlib.import_module(mod.name)
        for obj in vars(module).values():
            if dataclasses.is_dataclass(obj) and isinstance(obj, type) and obj.__module__ == module.__name__:
                if obj.__name__.endswith(("Settings", "Options")) or obj in SETTINGS:
                    found.add(obj)
    return found


#: Settings classes with no config block yet, so nothing to check their defaults against. The video
#: tracker's options (issue 38, first half) are set on the command line only; the `video` block of
#: a dataset, which will own them, is still to come: then they join SETTINGS and leave this list.
NOT_YET_IN_CONFIG = {"ballbat.video.track.TrackOptions"}


def test_every_settings_dataclass_is_checked():
    """A new ...Settings or ...Options dataclass must be entered in SETTINGS (and so be checked)."""
    found = {c for c in _settings_dataclasses() if f"{c.__module__}.{c.__name__}" not in NOT_YET_IN_CONFIG}
    assert found == set(SETTINGS)


@pytest.mark.parametrize("cls", list(SETTINGS), ids=lambda c: c.__name__)
def test_settings_have_no_defaults_of_their_own(cls):
    """No settings dataclass restates a default: a field default differing from the schema's fails."""
    kind, fields = SETTINGS[cls]
    assert default_problems(cls, kind, fields) == []
    assert cls.__dataclass_params__.frozen
    assert dataclasses.fields(cls) or cls in (ReconstructSettings, IngestSettings)


def test_the_default_check_fails_on_a_wrong_default():
    """The check above catches a default that differs from the schema's and one the schema does not give."""

    @dataclasses.dataclass(frozen=True)
    class Wrong:
        pixel_noise_px: float = 3.0  # the schema's: 2.0
        max_frames: int = 200  # the schema's: fine
        zoom: float = 1.0  # no such key

    fields = {"pixel_noise_px": (("pixel_noise_px",), _same), "max_frames": (("max_frames",), _same)}
    problems = default_problems(Wrong, "render_camera", fields)
    assert len(problems) == 2
    assert "Wrong.pixel_noise_px: default 3.0 in the code, the schema's pixel_noise_px: 2.0" in problems[0]
    assert "Wrong.zoom: default 1.0 in the code; the schema's render_camera has no such key" in problems[1]


# ---------------------------------------------------------------------------------------
# every schema default arrives in the settings built from a block that leaves it out


def _defaults(kind: str) -> dict[tuple, object]:
    """Every key of a block's schema that has a default: path -> default (nested objects walked)."""
    out = {}

    def walk(node, path):
        for key, sub in (node.get("properties") or {}).items():
            sub = _node(node, (key,))
            if "default" in sub:
                out[(*path, key)] = sub["default"]
            if sub.get("type") == "object":
                walk(sub, (*path, key))

    walk(block_schema(kind, SCHEMA), ())
    return out


MINIMAL_RENDER = {
    "cameras": {"swing": {"fps": 3000, "m_per_px": 0.00074}, "spin": {"fps": 1000, "m_per_px": 0.00125}},
    "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
}


def _render_value(s: RenderSettings, path: tuple) -> object:
    """What RenderSettings holds for a key of the render block, in the config's units."""
    if path[0] == "cameras":
        cam = getattr(s, path[1])
        key = path[2]
        if key in ("fps", "m_per_px", "mirror", "m_per_px_err", "fps_err"):
            return getattr(cam.camera, key)
        return list(cam.tee_px) if key == "tee_px" else getattr(cam, key)
    if path[0] == "rig":
        return getattr(s.rig, path[1].removesuffix("_in")) / INCH
    if path == ("draw_calibration",):  # false: the settings hold the declared calibration (drawn: test_study_grid)
        return settings_from_config(checked_block(MINIMAL_RENDER, "render")) != s
    if path[0] == "min_frames":
        return getattr(reduce_options(checked_block(MINIMAL_RENDER, "render")), f"min_{path[1]}_frames")
    field = {k[0]: f for f, (k, _) in SETTINGS[RenderSettings][1].items()}[path[0]]
    value = getattr(s, field)
    to_config = {"swing_plane_deg": 1 / DEGREE, "tilt_deg": 1 / DEGREE, "contact_ms": 1e3}
    scale = to_config.get(path[0], 1e3 if path[0].endswith("_mm") else 1.0)
    return [v * scale for v in value] if isinstance(value, tuple) else value * scale


def test_every_render_default_arrives():
    """Every default of the render block (cameras and min_frames included) is what the settings hold."""
    s = settings_from_config(checked_block(MINIMAL_RENDER, "render"))
    defaults = _defaults("render")
    assert ("cameras", "swing", "pixel_noise_px") in defaults and ("min_frames", "tip") in defaults
    for path, default in defaults.items():
        if path == ("enabled",):  # chooses the chain: the dataset renders tracks
            assert renders({"render": checked_block(MINIMAL_RENDER, "render")}) is default is True
            continue
        if path[0] == "video":  # the clips' look (a filmed dataset): tests/stages/test_clips.py
            continue
        got = _render_value(s, path)
        assert got == pytest.approx(default, rel=1e-12), (path, got, default)


def test_every_other_default_arrives(config):
    """Reduce, tracks, synthetic and study settings built from blocks that leave out every key with a default."""
    mf = _defaults("min_frames")
    assert ReduceOptions.schema_defaults() == ReduceOptions(mf[("tip",)], mf[("flight",)], mf[("spin",)])
    tracks = {
        "file": "t.csv",
        "impacts": "i.csv",
        "cameras": {c: {"fps": 1000, "m_per_px": 0.001, "mirror": False} for c in ("swing", "spin")},
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
    }
    block = checked_block(tracks, "tracks")
    cams, _ = cameras_from_config(block)
    assert cams["spin"].m_per_px_err == _defaults("track_camera")[("m_per_px_err",)]
    assert reduce_options(block) == ReduceOptions.schema_defaults()
    assert block["pattern"] == DEFAULT_PATTERN == _defaults("tracks")[("pattern",)]  # the CLI's and import_files'
    syn = {"impacts": {"baseball": {"wood": 3}}, "e_x": {"baseball": {"wood": 0.4}}, "e_y": {"baseball": 0.45}}
    settings = SyntheticSettings(**checked_block(syn, "synthetic"))
    for (key, *rest), default in _defaults("synthetic").items():
        value = getattr(settings, key)
        assert (value[rest[0]] if rest else value) == default, key
    raw = copy.deepcopy(config)
    raw["studies"] = {"bare": {"dataset": "synthetic", "replicates": 5, "seed": 1}}
    study = StudySettings.from_config(validate_config(raw, SCHEMA), "bare")
    for (key,), default in _defaults("study").items():
        if key == "draw_calibration":  # carried into the replicates' render block (sweeps.study_dataset)
            assert study.dataset["render"]["draw_calibration"] == default
        elif key == "on_request":  # which target builds it (common.smk: STUDIES), no replicate's setting
            assert validate_config(copy.deepcopy(raw), SCHEMA)["studies"]["bare"]["on_request"] == default
        else:
            assert getattr(study, key) == default, key


def _schema_keys_with_defaults() -> set[str]:
    keys = set()

    def walk(node):
        if isinstance(node, dict):
            for key, sub in (node.get("properties") or {}).items():
                if isinstance(sub, dict) and "default" in _node(node, (key,)):
                    keys.add(key)
            for v in node.values():
                walk(v)
        elif isinstance(node, list):
            for v in node:
                walk(v)

    walk(SCHEMA)
    return keys


def _is_literal(node: ast.AST) -> bool:
    """A number, text, a list or tuple of them, or a module constant (``DEFAULT_PATTERN``): a restated value."""
    if isinstance(node, (ast.List, ast.Tuple)):
        return all(_is_literal(e) for e in node.elts)
    if isinstance(node, ast.UnaryOp):
        return _is_literal(node.operand)
    return isinstance(node, ast.Constant) or (isinstance(node, ast.Name) and node.id.isupper())


def _restated_defaults(text: str, path: str, keys: set[str]) -> list[str]:
    """``x.get("key", literal)`` of a key the schema gives a default (file attributes, ``.attrs``, aside)."""
    found = []
    for node in ast.walk(ast.parse(text)):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "get"
            and len(node.args) == 2
            and isinstance(node.args[0], ast.Constant)
            and node.args[0].value in keys
            and _is_literal(node.args[1])
            and not (isinstance(node.func.value, ast.Attribute) and node.func.value.attr == "attrs")
        ):
            found.append(f"{path}:{node.lineno}: {ast.unparse(node)}")
    return found


def test_no_code_restates_a_schema_default():
    """No ``.get(key, default)`` on a config block in src/ or workflow/ for a key whose default is the schema's."""
    keys = _schema_keys_with_defaults()
    assert {"pixel_noise_px", "enabled", "tip", "pattern", "combine", "m_per_px_err"} <= keys
    found = []
    for path in sorted([*(ROOT / "src").rglob("*.py"), *(ROOT / "workflow").rglob("*.py")]):
        found += _restated_defaults(path.read_text(), str(path.relative_to(ROOT)), keys)
    for path in sorted((ROOT / "workflow").rglob("*.smk")):  # Snakemake files: not Python to ast
        for i, line in enumerate(path.read_text().splitlines(), 1):
            m = re.search(r"\.get\(\s*\"(\w+)\"\s*,\s*([-\d.\"'\[(]|True|False|None|[A-Z_]+\))", line)
            if m and m.group(1) in keys:
                found.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()}")
    assert found == []
    text = 'b = cfg.get("pixel_noise_px", 2.0)\nds.attrs.get("seed", 0)\nc.get("balls", t["balls"])'
    assert _restated_defaults(text, "x.py", keys) == ["x.py:1: cfg.get('pixel_noise_px', 2.0)"]


# ---------------------------------------------------------------------------------------
# a replicate and the workflow's rules reduce alike, whichever setting is changed

#: One change of every key of a dataset's render block (cameras and min_frames included), from the
#: default config's values; ``with`` changes set first (in both runs) so that the key can bite.
RENDER_CHANGES = {
    ("rig", "pivot_to_tip_in"): 36.0,
    ("rig", "pivot_to_impact_in"): 26.0,
    ("rig", "pivot_to_tip_err_in"): 0.1,
    ("rig", "pivot_to_impact_err_in"): 0.1,
    ("min_frames", "tip"): 21,
    ("min_frames", "flight"): 20,
    ("min_frames", "spin"): 18,
    ("swing_plane_deg",): [0.0, 20.0],
    ("contact_ms",): [0.8, 1.0],
    ("bat_slowdown",): [0.2, 0.3],
    ("bat_axis_to_ball_mm",): 90.0,
    ("axis_offset_mm",): 10.0,
    ("tilted_fraction",): 0.5,
    ("tilt_deg",): [20.0, 30.0],
    ("draw_calibration",): True,
}
CAMERA_CHANGES = {
    "swing": {
        "fps": 4000.0,
        "m_per_px": 0.0008,
        "mirror": True,
        "m_per_px_err": 0.02,
        "fps_err": 0.001,
        "width_px": 1000,
        "height_px": 560,
        "tee_px": [500.0, 420.0],
        "pixel_noise_px": 3.5,
        "pre_impact_frames": 8,
        "max_frames": 60,
    },
    "spin": {
        "fps": 1500.0,
        "m_per_px": 0.0011,
        "mirror": True,
        "m_per_px_err": 0.02,
        "fps_err": 0.001,
        "width_px": 900,
        "height_px": 490,
        "tee_px": [560.0, 430.0],
        "pixel_noise_px": 3.5,
        "pre_impact_frames": 3,
        "max_frames": 30,
    },
}
RENDER_CHANGES |= {("cameras", cam, k): v for cam, kv in CAMERA_CHANGES.items() for k, v in kv.items()}
#: Stated calibration uncertainties: systematics only (ballbat.systematics), which a replicate does not
#: rerun; the workflow's reduce states them (source, relative sigma) and reduces again at +-1 sigma.
CALIBRATION_ERRORS = {
    ("cameras", "swing", "fps_err"): ("swing_fps", 0.001),
    ("cameras", "spin", "fps_err"): ("spin_fps", 0.001),
    ("rig", "pivot_to_tip_err_in"): ("pivot_to_tip", 0.1 / 34.0),
    ("rig", "pivot_to_impact_err_in"): ("pivot_to_impact", 0.1 / 28.0),
}
#: Changes that need another first: a tilt only shows on impacts whose spin axis is tilted.
WITH = {("tilt_deg",): {("tilted_fraction",): 0.5}}
#: Keys with a test of their own below: enabled (the chain) and seed (a study's replicates draw their own).
OWN_TEST = {("enabled",), ("seed",)}
#: The clips of a filmed dataset (render.video), not the replicates': tests/stages/test_clips.py changes each.
OWN_TEST |= {("video", k) for k in ("format", "crf", "exposure_us", "bit_depth", "dot_radius_mm", "marker_radius_mm")}
#: How many clips a tracking job takes: tests/video/test_plan.py (the batches) and tests/workflow/test_video.py
#: (two batches give the tracks of one job).
OWN_TEST |= {("video", "clips_per_job")}


def _leaves(kind: str) -> set[tuple]:
    """Every leaf key of a block's schema (objects walked; arrays are leaves)."""
    out = set()

    def walk(node, path):
        for key in node.get("properties") or {}:
            sub = _node(node, (key,))
            if sub.get("type") == "object" and sub.get("properties"):
                walk(sub, (*path, key))
            else:
                out.add((*path, key))

    walk(block_schema(kind, SCHEMA), ())
    return out


def test_every_render_and_reduce_setting_is_changed_below():
    assert _leaves("render") == set(RENDER_CHANGES) | OWN_TEST


def _set(block: dict, path: tuple, value) -> None:
    for part in path[:-1]:
        block = block.setdefault(part, {})
    block[path[-1]] = copy.deepcopy(value)


@pytest.fixture(scope="module")
def small(config):
    """The default synthetic dataset with 5 impacts per ball and bat on three pairs."""
    ds = copy.deepcopy(config["datasets"]["synthetic"])
    ds["synthetic"]["impacts"] = {"baseball": {"wood": 5, "metal_rough": 5}, "softball": {"wood": 5}}
    ds["synthetic"]["e_x"] = {
        b: {t: ds["synthetic"]["e_x"][b][t] for t in v} for b, v in ds["synthetic"]["impacts"].items()
    }
    return ds


def _validated(config: dict, ds: dict) -> dict:
    raw = copy.deepcopy(config)
    raw["datasets"] = {"synthetic": ds}
    raw.pop("studies", None)
    return validate_config(raw, SCHEMA)["datasets"]["synthetic"]


SEEDS = (11, 12)


def _replicate(ds: dict, balls, bats):
    """The study's replicate (replicate_source): the reduced impacts, or the problems that stop it."""
    try:
        return replicate_source(ds, SEEDS, balls, bats)
    except InputError as exc:
        return exc.problems


def _workflow(ds: dict, tmp_path: Path, balls, bats, seed: bool = True):
    """The workflow's rules, through their files: simulate.nc -> render_tracks -> tracks.nc -> reduce -> reduce.nc.

    With the study's seeds (the dataset's synthetic.seed and render.seed set to them; ``seed``
    false: the dataset's own render.seed).
    """
    from ballbat.pipeline.ncio import read_dataset, write_dataset
    from ballbat.stages import reduce, render, simulate
    from ballbat.tracks.io import load_tracks

    sim = simulate.run(SyntheticSettings(**{**ds["synthetic"], "seed": SEEDS[0]}), balls, bats)
    write_dataset(sim, tmp_path / "simulate.nc", title="simulate", rule="simulate", inputs={}, config={})
    block = {**ds["render"], "seed": SEEDS[1]} if seed else ds["render"]  # common.smk: get_render_settings
    tracks = render.run(settings_from_config(block), read_dataset(tmp_path / "simulate.nc"), balls)
    tracks.to_netcdf(tmp_path / "tracks.nc")
    try:  # common.smk: get_reduce_settings; the reduce rule
        settings = reduce.ReduceSettings.from_config(camera_block(block), "render", systematics=True)
        return reduce.run(settings, load_tracks(tmp_path / "tracks.nc", None, balls, bats), balls, bats)
    except InputError as exc:
        return exc.problems


def _same_reduction(a, b, what: str) -> None:
    assert isinstance(a, list) == isinstance(b, list), (what, a if isinstance(a, list) else b)
    if isinstance(a, list):  # both stopped: by the same problems
        assert a == b, what
        return
    # the workflow's reduce (b) also reduces again at +-1 sigma of each calibration (ballbat.systematics);
    # a replicate (a) skips those reruns: every other variable is the same
    calibration = {n for ds in (a, b) for n in ds.data_vars if "systematic" in ds[n].dims}
    assert set(a.data_vars) - calibration == set(b.data_vars) - calibration, what
    for name in set(a.data_vars) - calibration:
        x, y = a[name].values, b[name].values
        if x.dtype.kind == "f":
            # the workflow's tracks make a round trip through tracks.nc (dense columns that may start
            # elsewhere): the sums round differently in the last bit, and the contact prior's
            # Nelder-Mead optimum can carry that to about 1e-8 (relative); a setting honoured
            # differently moves the values by far more. A contact shift is a difference of two
            # reductions, the second through a contact solved again: compared as the shifted value,
            # to 1e-6 (2e-6 of a shift, 2.2e-7 of a shifted v_bat_err seen on an AMD EPYC)
            shift = name.startswith("contact_shift_")
            base = a[name.removeprefix("contact_shift_")].values if shift else 0.0
            rtol = 1e-6 if shift else 1e-7
            np.testing.assert_allclose(x + base, y + base, rtol=rtol, atol=0, err_msg=f"{what}: {name}")
        else:
            np.testing.assert_array_equal(x, y, err_msg=f"{what}: {name}")


def _differs(a, b) -> bool:
    if isinstance(a, list) or isinstance(b, list):
        return isinstance(a, list) != isinstance(b, list) or a != b
    return any(
        not np.array_equal(a[k].values, b[k].values, equal_nan=a[k].dtype.kind == "f") for k in b.data_vars
    ) or str(a.attrs) != str(b.attrs)  # the cameras' settings are attributes of reduce.nc


@pytest.fixture(scope="module")
def baselines(config, small, balls, bats, tmp_path_factory):
    """The replicate of the unchanged dataset, and of the one each WITH change sets first."""
    out = {}
    for first in [{}, *WITH.values()]:
        ds = copy.deepcopy(small)
        for path, value in first.items():
            _set(ds["render"], path, value)
        out[tuple(sorted(first.items()))] = _replicate(_validated(config, ds), balls, bats)
    return out


@pytest.mark.parametrize("path", sorted(RENDER_CHANGES), ids=lambda p: ".".join(p))
def test_a_replicate_and_the_workflow_honour_every_setting(config, small, balls, bats, baselines, tmp_path, path):
    """Each setting changed alone: the replicate and the workflow's rules reduce the same impacts.

    And the change shows in them (a setting ignored by both would pass the first check alone).
    """
    ds = copy.deepcopy(small)
    first = WITH.get(path, {})
    for p, value in first.items():
        _set(ds["render"], p, value)
    _set(ds["render"], path, RENDER_CHANGES[path])
    ds = _validated(config, ds)
    replicate = _replicate(ds, balls, bats)
    workflow = _workflow(ds, tmp_path, balls, bats)
    _same_reduction(replicate, workflow, ".".join(path))
    if path in CALIBRATION_ERRORS:  # a stated uncertainty: the workflow reduces again at +-1 sigma of it
        source, rel = CALIBRATION_ERRORS[path]
        stated = float(workflow["systematic_rel_sigma"].sel(systematic=source))
        assert stated == pytest.approx(rel), ".".join(path)
        moved = [
            k
            for k in workflow.data_vars
            if k.endswith("_shift") and np.nanmax(np.abs(workflow[k].sel(systematic=source).values)) > 0
        ]
        assert moved, ".".join(path)
        return
    assert _differs(replicate, baselines[tuple(sorted(first.items()))]), f"{'.'.join(path)} changed nothing"


def test_enabled_and_seed(config, small, balls, bats, baselines, tmp_path):
    """render.enabled false: both start from the simulated impacts; render.seed: the workflow's draws follow it.

    A replicate draws from the study's seed instead (its tracks' seed is the replicate's own).
    """
    ds = copy.deepcopy(small)
    ds["render"]["enabled"] = False
    ds = _validated(config, ds)
    replicate = replicate_source(ds, SEEDS, balls, bats)
    from ballbat.stages import simulate

    sim = simulate.run(SyntheticSettings(**{**ds["synthetic"], "seed": SEEDS[0]}), balls, bats)
    assert "truth_psi" in replicate and replicate.identical(sim)
    ds = copy.deepcopy(small)
    ds["render"]["seed"] = 999
    ds = _validated(config, ds)
    _same_reduction(_replicate(ds, balls, bats), baselines[()], "render.seed: a replicate's own")
    _same_reduction(_workflow(ds, tmp_path, balls, bats), baselines[()], "render.seed set to the replicate's")
    own = _workflow(ds, tmp_path, balls, bats, seed=False)  # the workflow draws from render.seed 999
    assert _differs(own, baselines[()])
    assert not math.isnan(float(own["v_bat"].values[0]))


def test_the_robustness_study_is_on_request(config):
    assert config["studies"]["robustness"]["on_request"] is True
    assert not config["studies"]["calibration"]["on_request"]  # the schema's default
