"""The config's domain rules (ballbat.config_checks): hostile or careless configs are refused with the key and
the reason, all at once (issues 10, 22, 35, 37, 40).
"""

from __future__ import annotations

import copy

import pytest
import yaml
from conftest import ROOT
from helpers import HICKORY_BATS, SWEEP, UNBALANCED
from track_files import (
    TOOL_NAMES,
)

from ballbat.config_checks import scenario_problems, validate_config
from ballbat.pipeline.config import ConfigError, drop_nulls


@pytest.fixture
def base(root):
    return yaml.safe_load((root / "config" / "config.yaml").read_text())


def problems(cfg, schema, available=24 * 2**30):
    with pytest.raises(ConfigError) as err:
        validate_config(cfg, schema, available=available)
    return str(err.value)


@pytest.mark.parametrize("name", ["implications", "studies", "logs", "figures", "report", "all"])
def test_reserved_dataset_names(base, schema, name):
    base["datasets"][name] = copy.deepcopy(base["datasets"]["synthetic"])
    text = problems(base, schema)
    assert f"datasets.{name}: '{name}' is reserved for the workflow's own results" in text


def test_reserved_scenario_names(base, schema):
    base["implications"]["scenarios"]["results"] = copy.deepcopy(base["implications"]["scenarios"]["paper"])
    assert "implications.scenarios.results: 'results' is reserved" in problems(base, schema)


def test_a_newline_does_not_pass_as_the_end_of_a_name(base, schema):
    base["datasets"]["evil\n"] = copy.deepcopy(base["datasets"]["synthetic"])
    assert "datasets.'evil\\n': a name may hold only letters, digits, _ and -" in problems(base, schema)


def test_null_drops_a_scenario_as_it_drops_a_dataset(base, schema):
    base["implications"]["scenarios"]["paper"] = None
    base["datasets"]["other"] = None
    cfg = validate_config(drop_nulls(base), schema, available=24 * 2**30)
    assert cfg["implications"]["scenarios"] == {} and "other" not in cfg["datasets"]


def test_counts_beyond_the_machine_are_refused_up_front(base, schema):
    base["implications"]["scenarios"]["paper"]["sweep"]["D_in"]["num"] = 10**6  # ate all 24 GB before
    base["datasets"]["synthetic"]["synthetic"]["impacts"]["baseball"]["wood"] = 10**12  # a bare MemoryError
    text = problems(base, schema, available=24 * 2**30)
    assert "implications.scenarios.paper.sweep.D_in.num: 1,000,000 cases need about 55.9 GiB" in text
    assert "datasets.synthetic.synthetic.impacts: 1,000,000,000,088 impacts need about" in text
    assert "more than half the 24.0 GiB this machine has available" in text


def test_launch_grids_count_every_combination(base, schema):
    base["implications"]["scenarios"]["grid"] = {
        "ball": "baseball",
        "launch": {"exit_speed_mph": [1 + i / 10 for i in range(600)], "launch_deg": [i / 10 for i in range(600)]},
    }
    assert "implications.scenarios.grid.launch: 360,000 cases" in problems(base, schema, available=24 * 2**30)


def test_an_empty_experiment_is_named(base, schema):
    syn = base["datasets"]["synthetic"]["synthetic"]
    syn["impacts"] = {ball: {bat: 0 for bat in bats} for ball, bats in syn["impacts"].items()}
    assert "datasets.synthetic.synthetic.impacts: no impacts (every count is 0): nothing to fit" in problems(
        base, schema
    )


def test_the_default_config_passes(base, schema):
    validate_config(base, schema)


@pytest.fixture(scope="module")
def schema_and_base():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    return schema, base


def test_config_measured_dataset(schema_and_base):
    schema, base = schema_and_base
    cfg = copy.deepcopy(base)
    cfg["datasets"].update(yaml.safe_load((ROOT / "config" / "examples" / "maple.yaml").read_text())["datasets"])
    validate_config(cfg, schema)
    assert cfg["datasets"]["maple"]["bats"] == "config/examples/maple_bats.csv"
    # the synthetic dataset still gets its defaults
    assert cfg["datasets"]["synthetic"]["synthetic"]["noise"]["omega_rpm"] == 75.0


@pytest.mark.parametrize(
    ("dataset", "message"),
    [
        ({"impacts": "x.csv", "synthetic": {"impacts": {}, "e_x": {}, "e_y": {}}}, "give exactly one of synthetic"),
        ({"bats": "b.csv"}, "matches none of the allowed forms"),
        ({"impacts": "x.csv", "format": "csv"}, "datasets.m.format: unknown key"),
        ({"impacts": ""}, "datasets.m.impacts"),
    ],
)
def test_config_bad_dataset_forms(schema_and_base, dataset, message):
    schema, base = schema_and_base
    cfg = copy.deepcopy(base)
    cfg["datasets"]["m"] = dataset
    with pytest.raises(ConfigError, match=r"datasets\.m"):
        validate_config(cfg, schema)
    try:
        validate_config(cfg, schema)
    except ConfigError as exc:
        assert message in str(exc)


EX = ROOT / "config" / "examples"
IMPACTS, BATS, BALLS = EX / "maple_impacts.csv", EX / "maple_bats.csv", ROOT / "config" / "balls.csv"


def test_config_calibration_keys(config):
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    maple = {"impacts": str(IMPACTS), "calibration": {"speed_scale_pct": 0.5}}
    good = {**config, "datasets": {**config["datasets"], "maple": maple}}
    assert validate_config(good, schema)["datasets"]["maple"]["calibration"] == {"speed_scale_pct": 0.5}
    for bad, words in (
        ({"impacts": str(IMPACTS), "calibration": {"speed_scale": 0.5}}, "speed_scale"),
        ({"impacts": str(IMPACTS), "calibration": {"spin_scale_pct": -1}}, "spin_scale_pct"),
        ({**config["datasets"]["synthetic"], "calibration": {"speed_scale_pct": 0.5}}, "'impacts' is a dependency"),
    ):
        with pytest.raises(ConfigError, match=words):
            validate_config({**config, "datasets": {**config["datasets"], "x": bad}}, schema)


HICKORY_IMPACTS = ROOT / "config" / "examples" / "hickory_impacts.csv"


def hickory_config(**scenario) -> dict:
    cfg = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    cfg["datasets"]["h01"] = {"impacts": str(HICKORY_IMPACTS), "bats": str(HICKORY_BATS)}
    sweep = {**SWEEP, "D_in": {"start": 0.0, "stop": 1.0, "num": 5}}
    cfg["implications"]["scenarios"] = {"mine": {"ball": "baseball", "bat": "hickory", "sweep": sweep, **scenario}}
    return cfg


def test_a_scenario_takes_its_bat_from_its_dataset(schema, monkeypatch):
    """Why: `bat: hickory` with `e_x_from_dataset: h01` was refused (hickory is in h01's bat table only)."""
    monkeypatch.chdir(ROOT)
    cfg = validate_config(hickory_config(e_x_from_dataset="h01"), schema, available=24 * 2**30)
    assert scenario_problems(cfg) == []


def test_a_bat_in_no_table_suggests_tables_bats(schema, monkeypatch):
    monkeypatch.chdir(ROOT)
    cfg = validate_config(hickory_config(), schema, available=24 * 2**30)
    (line,) = scenario_problems(cfg)
    assert line.startswith("implications.scenarios.mine.bat: 'hickory' is not in the bat table config/bats.csv")
    assert "tables.bats" in line and "e_x_from_dataset" in line


def test_config_validation_lists_all_problems(root):
    import yaml

    schema = yaml.safe_load((root / "workflow" / "schemas" / "config.schema.yaml").read_text())
    good = yaml.safe_load((root / "config" / "config.yaml").read_text())
    assert validate_config(good, schema)["normalize"]["v_ref_mph"] == 77.0
    minimal = {
        "datasets": {
            "d": {
                "synthetic": {
                    "impacts": {"baseball": {"wood": 3}},
                    "e_x": {"baseball": {"wood": 0.46}},
                    "e_y": {"baseball": 0.45},
                }
            }
        }
    }
    filled = validate_config(minimal, schema)
    assert filled["tables"]["balls"] == "config/balls.csv"  # defaults filled
    assert filled["datasets"]["d"]["synthetic"]["noise"]["omega_rpm"] == 75.0
    bad = {"datasets": {"d": {"synthetic": {"impacts": {}, "e_x": {}, "e_y": {}, "sed": 1}}}, "extra": 1}
    with pytest.raises(ConfigError) as exc:
        validate_config(bad, schema)
    assert "datasets.d.synthetic.sed: unknown key" in str(exc.value)
    assert "extra: unknown key" in str(exc.value)


def test_the_setting_is_checked(config, schema):
    """The folder is a relative path of plain names: no '..', no hidden part, no absolute path."""
    for bad in ("../elsewhere", "/tmp/x", "results/.hidden", "results/../x", ""):
        cfg = copy.deepcopy(config)
        cfg["results"] = bad
        with pytest.raises(ConfigError, match="results"):
            validate_config(cfg, schema)
    cfg = copy.deepcopy(config)
    cfg["results"] = "results/2026-11-h01"
    validate_config(cfg, schema)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda g: g.update(contact_ms=[0.5, 0.1]),
            "studies.robustness.sweep.grid.contact_ms[1]: contact_ms must lie in [0.25, 1.95] ms",
        ),
        (
            lambda g: g.update(contact_ms=[1.98]),
            "studies.robustness.sweep.grid.contact_ms[0]: contact_ms must lie in [0.25, 1.95] ms",
        ),
        (
            lambda g: g.update(impacts_per_bat=[12, 2.5]),
            "studies.robustness.sweep.grid.impacts_per_bat[1]: impacts per bat must be a whole number >= 3",
        ),
        (
            lambda g: g.update(pixel_noise_px=[0.0, 3.0]),
            "studies.robustness.sweep.grid.pixel_noise_px[0]: pixel_noise_px must be positive in a study",
        ),
        (  # the schema owns the range of a swept setting (0 to 100 px), as of any other
            lambda g: g.update(pixel_noise_px=[2.0, 150.0]),
            "studies.robustness.sweep (pixel_noise_px = 150): render.cameras.swing.pixel_noise_px: 150.0 is greater "
            "than the maximum of 100",
        ),
        (lambda g: g.update(pixel_noise_px=[1.0, 1.0]), "studies.robustness.sweep.grid.pixel_noise_px: a value is"),
        (
            lambda g: g.update(noise_scale=[2.0]),
            "studies.robustness.sweep.grid.noise_scale: noise_scale scales the direct noise",
        ),
        (lambda g: g.update(colour=[1.0]), "studies.robustness.sweep"),
        (lambda g: g.update(contact_ms=[]), "studies.robustness.sweep"),
    ],
)
def test_invalid_grid_values_are_named(raw, schema, edit, message):
    edit(raw["studies"]["robustness"]["sweep"]["grid"])
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert message in str(err.value)


def test_grid_and_one_parameter_sweep_are_exclusive(raw, schema):
    raw["studies"]["robustness"]["sweep"].update(parameter="e_x", values=[0.3])
    with pytest.raises(ConfigError, match=r"studies\.robustness\.sweep"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_contact_sweep_or_drawn_calibration_needs_rendered_tracks(raw, schema):
    raw["datasets"]["synthetic"]["render"]["enabled"] = False
    raw["studies"]["robustness"]["sweep"]["grid"] = {"contact_ms": [0.6], "impacts_per_bat": [12]}
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert "studies.robustness.sweep.grid.contact_ms: contact_ms needs a dataset that renders camera tracks" in str(
        err.value
    )
    assert "studies.robustness.draw_calibration: needs a dataset that renders camera tracks" in str(err.value)


def test_drawing_a_calibration_without_an_uncertainty_is_refused(raw, schema):
    raw["datasets"]["synthetic"]["render"]["cameras"]["swing"]["m_per_px_err"] = 0.0
    with pytest.raises(ConfigError, match=r"studies\.robustness\.draw_calibration: the dataset states no calibration"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_truth_the_machine_cannot_hold_is_refused_with_its_size(raw, schema):
    """The guard reads the same size: on a 6 GiB machine the 6-to-60 design's truth (70 176 impacts) is refused."""
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = copy.deepcopy(UNBALANCED)
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=6 * 2**30)
    assert "studies.calibration.truth_impacts: 70,176 impacts need about 3.3 GiB" in str(err.value)


POINTS = dict(TOOL_NAMES)


def test_schema_takes_a_folder_and_still_wants_settings_of_a_long_file():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    rig = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
    lab = {
        "dir": "data/trk",
        "points": POINTS,
        "impacts": "i.csv",
        "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
        "rig": rig,
    }
    cfg = validate_config({"datasets": {"lab": {"tracks": lab}}}, schema, available=10**12)
    assert cfg["datasets"]["lab"]["tracks"]["pattern"] == "{impact_id}_{camera}.{ext}"
    long = {
        "file": "t.csv",
        "impacts": "i.csv",
        "cameras": {"swing": {"mirror": False}, "spin": {"mirror": True}},
        "rig": rig,
    }
    with pytest.raises(ConfigError, match="fps"):
        validate_config({"datasets": {"lab": {"tracks": long}}}, schema, available=10**12)
    no_points = {k: v for k, v in lab.items() if k != "points"}
    with pytest.raises(ConfigError, match=r"datasets\.lab\.tracks: 'points' is a required property"):
        validate_config({"datasets": {"lab": {"tracks": no_points}}}, schema, available=10**12)
    with pytest.raises(ConfigError, match="units"):
        validate_config({"datasets": {"lab": {"tracks": {**lab, "units": {"time": "ms"}}}}}, schema, available=10**12)


def test_schema_takes_a_folder_of_clips_with_its_markers_and_no_points():
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    clips = {
        "dir": "data/clips",
        "format": "video",
        "impacts": "i.csv",
        "cameras": {"swing": {"mirror": False, "m_per_px": 0.00074}, "spin": {"mirror": False, "m_per_px": 0.00125}},
        "rig": {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0},
        "video": {"dot_radius_mm": 4.0, "marker_radius_mm": 6.0},
    }
    cfg = validate_config({"datasets": {"lab": {"tracks": clips}}}, schema, available=10**12)
    # the markers as given; the clips a tracking job takes: the schema's default
    assert cfg["datasets"]["lab"]["tracks"]["video"] == {
        "dot_radius_mm": 4.0,
        "marker_radius_mm": 6.0,
        "clips_per_job": 8,
    }
    zero = copy.deepcopy(clips)
    zero["video"]["clips_per_job"] = 0
    with pytest.raises(ConfigError, match=r"clips_per_job"):
        validate_config({"datasets": {"lab": {"tracks": zero}}}, schema, available=10**12)
    no_markers = {k: v for k, v in clips.items() if k != "video"}
    with pytest.raises(ConfigError, match=r"datasets\.lab\.tracks: 'video' is a required property"):
        validate_config({"datasets": {"lab": {"tracks": no_markers}}}, schema, available=10**12)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            lambda c: c["studies"]["calibration"].update(dataset="nope"),
            "studies.calibration.dataset: no dataset 'nope'",
        ),
        (
            lambda c: c["studies"]["design"]["sweep"].update(values=[5, 2.5]),
            "studies.design.sweep.values[1]: impacts per bat must be a whole number >= 3",
        ),
        (
            lambda c: c["studies"]["design"]["sweep"].update(parameter="noise_scale"),
            "studies.design.sweep.parameter: noise_scale scales the direct noise, but the dataset renders tracks",
        ),
        (lambda c: c["studies"]["calibration"].update(replicates=1), "studies.calibration.replicates"),
        (
            lambda c: c["studies"]["calibration"].update(truth_impacts=10**7),
            "studies.calibration.truth_impacts: 70,000,092 impacts need about",  # 108 x ceil(7e7 / 108)
        ),
        (lambda c: c["studies"]["calibration"].update(colour=1), "studies.calibration"),
    ],
)
def test_hostile_study_configs_are_named(raw, schema, edit, message):
    edit(raw)
    with pytest.raises(ConfigError) as err:
        validate_config(raw, schema, available=24 * 2**30)
    assert message in str(err.value)


def test_dropping_a_dataset_drops_its_studies(raw, schema):
    from ballbat.pipeline.config import drop_nulls

    raw["datasets"] = {"synthetic": None, "lab": {"impacts": "x.csv"}}
    cfg = validate_config(drop_nulls(raw), schema, available=24 * 2**30)
    assert cfg["studies"] == {}
    raw2 = yaml.safe_load(yaml.safe_dump(raw))
    raw2["datasets"] = {"synthetic": {"synthetic": {}}, "lab": {"impacts": "x.csv"}}
    raw2["studies"] = {"calibration": None, "design": {"dataset": "synthetic", "replicates": 3, "seed": 1}}
    assert list(drop_nulls(raw2)["studies"]) == ["design"]


def test_drawing_properties_from_tables_without_uncertainties_is_refused_before_the_dag(raw, schema):
    """draw_properties with tables that state no *_err: one line at the config check, not a failed job."""
    raw["studies"]["calibration"]["draw_properties"] = True
    with pytest.raises(ConfigError, match=r"studies.calibration.draw_properties: the tables .* state no uncertainty"):
        validate_config(raw, schema, available=24 * 2**30)
    raw["datasets"]["synthetic"]["bats"] = "config/examples/property_study_bats.csv"
    raw["datasets"]["synthetic"]["synthetic"]["impacts"] = {"baseball": {"hickory": 10}}
    raw["datasets"]["synthetic"]["synthetic"]["e_x"] = {"baseball": {"hickory": 0.455}}
    raw["datasets"]["synthetic"]["synthetic"]["e_y"] = {"baseball": 0.45}
    raw["datasets"]["synthetic"]["synthetic"]["psi_deg"] = {"baseball": [0.0, 30.0]}
    raw["studies"] = {"calibration": raw["studies"]["calibration"]}
    raw["implications"]["scenarios"] = {}
    assert validate_config(raw, schema, available=24 * 2**30)["studies"]["calibration"]["draw_properties"]


def test_a_study_of_a_measured_dataset_is_refused(raw, schema):
    raw["datasets"]["lab"] = {"impacts": "x.csv"}
    raw["studies"]["calibration"]["dataset"] = "lab"
    with pytest.raises(ConfigError, match="'lab' is not synthetic"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_frame_rate_sweep_needs_rendered_tracks(raw, schema):
    raw["datasets"]["synthetic"]["render"]["enabled"] = False
    raw["studies"]["design"]["sweep"] = {"parameter": "spin_fps", "values": [1000]}
    with pytest.raises(ConfigError, match="spin_fps needs a dataset that renders camera tracks"):
        validate_config(raw, schema, available=24 * 2**30)


def test_a_study_of_a_filmed_dataset_is_refused(raw, schema):
    """Replicates reduce rendered tracks; a dataset that films its impacts (render.video) is named."""
    raw["datasets"]["synthetic"]["render"]["video"] = {"format": "mkv"}
    with pytest.raises(ConfigError, match=r"studies\.calibration\.dataset: 'synthetic' films its impacts"):
        validate_config(raw, schema, available=10**12)


def test_a_sweep_point_two_studies_share_is_named_in_each(raw, schema):
    """A block checked once for two studies (and points that leave a block as it is) still names every study."""
    raw["studies"]["robustness"]["sweep"]["grid"]["pixel_noise_px"] = [2.0, 150.0]
    raw["studies"]["again"] = copy.deepcopy(raw["studies"]["robustness"])
    text = problems(raw, schema)
    for study in ("robustness", "again"):
        for camera in ("swing", "spin"):
            where = f"studies.{study}.sweep (pixel_noise_px = 150)"
            assert f"{where}: render.cameras.{camera}.pixel_noise_px: 150.0 is greater" in text
    assert text.count("(pixel_noise_px = 150)") == 4 and "(pixel_noise_px = 2)" not in text
