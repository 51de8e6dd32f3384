"""Hostile or careless configs are refused with the key and the reason (issue 10, items 7-9)."""

import copy

import pytest
import yaml

from ballbat.config_checks import validate_config
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
