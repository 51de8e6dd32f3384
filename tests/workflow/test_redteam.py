"""Red-team table of issue 19 (config, measured data, command line, install): every case and its outcome.

Each row below is a case a new user or a hostile review tried; before issue 19 each one lost a
key silently, gave a wrong number with exit status 0, or ended in a traceback. The expected
outcome is in the row: the message (or its start) and, for the command line, the exit status
(2: a bad argument, one line; 1: ``check`` found the file not usable).

The command line runs as ``python -m ballbat.cli`` so that these rows can be run against any
checkout (``PYTHONPATH=<checkout>/src``).
"""

import copy
import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import forked
import numpy as np
import pytest
import yaml
from conftest import ROOT

from ballbat.config_checks import validate_config
from ballbat.pipeline.config import ConfigError
from ballbat.studies.coverage import MIN_COVERAGE_REPLICATES, EmptySweepPoint, coverage, coverage_csv

MAPLE = ROOT / "config" / "examples" / "maple_impacts.csv"
MAPLE_BATS = ROOT / "config" / "examples" / "maple_bats.csv"
KMH = 1.609344
RPM_PER_RAD_S = 60 / (2 * math.pi)


def ballbat(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    """Run the command line in a process of its own (forked: :mod:`forked`)."""
    return forked.ballbat(*args, cwd=cwd, timeout=120)


# ---------------------------------------------------------------------------------------
# Config: (case, edit of the default config, message)


def _syn(c):
    return c["datasets"]["synthetic"]["synthetic"]


def _paper(c):
    return c["implications"]["scenarios"]["paper"]


def _launch(c, **kw):
    c["implications"]["scenarios"]["fly"] = {"ball": "baseball", "launch": {"exit_speed_mph": 100, "launch_deg": 25}}
    c["implications"]["scenarios"]["fly"]["launch"].update(kw)


CONFIG_CASES = [
    ("misspelt ball in psi_deg", lambda c: _syn(c)["psi_deg"].update(basebal=[0, 60]), "psi_deg.basebal: unknown ball"),
    ("misspelt ball in e_y", lambda c: _syn(c)["e_y"].update(sofball=0.3), "e_y.sofball: unknown ball"),
    ("misspelt bat in e_x", lambda c: _syn(c)["e_x"]["baseball"].update(wod=0.4), "e_x.baseball.wod: unknown bat"),
    ("misspelt ball in e_x", lambda c: _syn(c)["e_x"].update(basebal={"wood": 0.4}), "e_x.basebal: unknown ball"),
    (
        "dataset named 123",
        lambda c: c["datasets"].update({123: c["datasets"]["synthetic"]}),
        "datasets.123: YAML reads this name as a number, not text",
    ),
    (
        "dataset named yes",
        lambda c: c["datasets"].update({True: c["datasets"]["synthetic"]}),
        "datasets.True: YAML reads this name as a boolean",
    ),
    (
        "scenario named 123",
        lambda c: c["implications"]["scenarios"].update({123: _paper(c)}),
        "implications.scenarios.123: YAML reads this name as a number",
    ),
    ("exit speed -100", lambda c: _launch(c, exit_speed_mph=-100), "launch.exit_speed_mph: -100 is less than or equal"),
    ("exit speed 0", lambda c: _launch(c, exit_speed_mph=[0, 90]), "launch.exit_speed_mph.0: 0 is less than or equal"),
    ("launch angle 95", lambda c: _launch(c, launch_deg=95), "launch.launch_deg: 95 is greater than the maximum of 90"),
    ("launch angle 180", lambda c: _launch(c, launch_deg=[20, 180]), "launch_deg.1: 180 is greater than the maximum"),
    ("spin 1e6 rpm", lambda c: _launch(c, backspin_rpm=1e6), "backspin_rpm: 1000000.0 is greater than the maximum"),
    (
        "temperature -1000 F",
        lambda c: c["implications"]["air"].update(temperature_F=-1000),
        "implications.air.temperature_F: -1000 is less than the minimum of -40",
    ),
    (
        "elevation 200000 ft",
        lambda c: c["implications"]["air"].update(elevation_ft=200000),
        "implications.air.elevation_ft: 200000 is greater than the maximum of 15000",
    ),
    (
        "bat speed 1e6 mph",
        lambda c: _paper(c)["sweep"].update(bat_mph=1e6),
        "sweep.bat_mph: 1000000.0 is greater than the maximum of 150",
    ),
    (
        "wind 1e6 mph",
        lambda c: _paper(c)["flight"].update(wind_mph=[1e6, 0]),
        "flight.wind_mph.0: 1000000.0 is greater than the maximum of 100",
    ),
    (
        "camera at 1e9 fps",
        lambda c: c["datasets"]["synthetic"]["render"]["cameras"]["swing"].update(fps=1e9),
        "cameras.swing.fps: 1000000000.0 is greater than the maximum of 1000000",
    ),
    ("bat speed nan", lambda c: _paper(c)["sweep"].update(bat_mph=float("nan")), "sweep.bat_mph: nan is not a finite"),
    ("D_in.num 1 drops stop", lambda c: _paper(c)["sweep"]["D_in"].update(num=1), "stop = 2.5 would be dropped"),
    (
        "replicates 10000000",
        lambda c: c["studies"]["calibration"].update(replicates=10_000_000),
        "studies.calibration.replicates: 10,000,000 replicates (all sweep points) need about 37.3 GiB",
    ),
    (
        "replicates 10000000: the job graph",
        lambda c: c["studies"]["calibration"].update(replicates=10_000_000),
        "make 80,000 batch jobs, more than the 10,000",  # batches of 125
    ),
    (
        "impacts_per_bat 1e6",
        lambda c: c["studies"]["design"]["sweep"].update(values=[5, 1e6]),
        "studies.design.sweep.values: 7,000,000 impacts in one replicate need about",
    ),
]


@pytest.fixture
def base():
    return yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.mark.parametrize(("case", "edit", "message"), CONFIG_CASES, ids=[c[0] for c in CONFIG_CASES])
def test_config_case_is_refused_naming_the_key(base, schema, case, edit, message):
    edit(base)
    with pytest.raises(ConfigError) as err:
        validate_config(base, schema, available=24 * 2**30)
    assert message in str(err.value), str(err.value)


def test_default_config_still_validates(base, schema):
    cfg = validate_config(copy.deepcopy(base), schema, available=24 * 2**30)
    assert cfg["implications"]["air"]["pressure_inHg"] == 29.92 and cfg["studies"]["calibration"]["replicates"] == 1000


def test_range_message_says_why(base, schema):
    base["implications"]["air"]["elevation_ft"] = 200000
    with pytest.raises(ConfigError, match=r"elevation above sea level \(ft\), -1500 \(the Dead Sea\) to 15000"):
        validate_config(base, schema, available=24 * 2**30)


# ---------------------------------------------------------------------------------------
# Studies: too few replicates warned in the table; a sweep point with no replicate an error


def _replicates(n, value=np.nan, parameter=""):
    """Replicates (n) of one quantity with honest errors, at a sweep point of ``parameter = value``."""
    from helpers import fake_replicates

    ds = fake_replicates(n, se=0.01, spread=0.01)
    ds.attrs.update(sweep_values=np.array([value]), sweep_parameter=parameter)
    return ds


def test_study_of_4_replicates_warns_in_its_table():
    cov = coverage(_replicates(4))
    text = coverage_csv(cov)
    assert "only 4 replicates: a 95 % coverage is known to +-10.9 points" in text
    assert text.splitlines()[0].endswith(",warning")
    assert coverage(_replicates(MIN_COVERAGE_REPLICATES))["warning"].values[0, 0] == ""


def test_sweep_point_without_replicates_is_an_error_naming_it():
    rep = _replicates(6, value=7.0, parameter="impacts_per_bat")
    rep["value"][:] = np.nan
    with pytest.raises(EmptySweepPoint, match=r"sweep point 0 \(impacts_per_bat = 7\): none of its 6"):
        coverage(rep)


# ---------------------------------------------------------------------------------------
# Measured data


def _maple(tmp_path, name="impacts.csv", errs=True, edit=None, bat_of=None):
    """The maple example, optionally without its uncertainty columns, each row passed through ``edit(i, row)``."""
    with MAPLE.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    cols = [c for c in rows[0] if errs or not c.endswith("_err")]
    for i, row in enumerate(rows):
        if bat_of:
            row["bat"] = bat_of(i)
        if edit:
            edit(i, row)
    path = tmp_path / name
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, cols, extrasaction="ignore", lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    return path


def _two_bats(tmp_path):
    """A bat table with the maple bat twice (maple, maple2): the second gets a group of 5 impacts."""
    lines = MAPLE_BATS.read_text().splitlines()
    path = tmp_path / "bats.csv"
    path.write_text("\n".join([*lines, lines[1].replace("maple,", "maple2,", 1)]) + "\n")
    return path


def _scale(cols, factor, rows):
    def edit(i, row):
        if i in rows:
            for c in cols:
                row[c] = f"{float(row[c]) * factor:.1f}"

    return edit


def _swap(i, row):
    row["v_bat_mph"], row["v_ball_mph"] = row["v_ball_mph"], row["v_bat_mph"]


def _zero(i, row):
    for c in ("v_bat_mph_err", "v_ball_mph_err", "theta_deg_err", "omega_rpm_err"):
        row[c] = "0"


def _reverse_spin(i, row):
    row["omega_rpm"] = str(-float(row["omega_rpm"]))


SMALL = {19, 22, 26, 27, 29}  # the 5 rows on maple2 (slow swings: in km/h still below 110 mph)

#: (case, file options, exit status of `ballbat check`, text in its output)
DATA_CASES = [
    ("v_bat and v_ball swapped (gave e_x 0.28 vs 0.42)", {"edit": _swap}, 1, "v_bat_mph and v_ball_mph swapped"),
    ("swapped, no _err columns", {"edit": _swap, "errs": False}, 1, "v_bat_mph and v_ball_mph swapped"),
    (
        "one km/h row in a group of 5, no _err columns",
        {"errs": False, "edit": _scale(["v_bat_mph", "v_ball_mph"], KMH, {29}), "bats": True},
        0,
        "excluded: impact MP30 (row 31): implausible",
    ),
    (
        "two rad/s rows in a group of 5, no _err columns",
        {"errs": False, "edit": _scale(["omega_rpm"], 1 / RPM_PER_RAD_S, {22, 27}), "bats": True},
        0,
        "excluded: impact MP23 (row 24): implausible",
    ),
    ("all uncertainties 0", {"edit": _zero}, 1, "column omega_rpm_err: zero uncertainty in every row"),
    (
        "one uncertainty 0",
        {"edit": lambda i, r: r.update(theta_deg_err="0") if i == 3 else None},
        1,
        "column theta_deg_err: zero uncertainty in row 5:",
    ),
    ("spin sign reversed: fit_ex refuses, so check does", {"edit": _reverse_spin}, 1, "fitted e_x outside"),
]


@pytest.mark.parametrize(("case", "opts", "status", "text"), DATA_CASES, ids=[c[0] for c in DATA_CASES])
def test_measured_data_case(tmp_path, case, opts, status, text):
    opts = dict(opts)
    bats = _two_bats(tmp_path) if opts.pop("bats", False) else MAPLE_BATS
    bat_of = (lambda i: "maple2" if i in SMALL else "maple") if bats != MAPLE_BATS else None
    path = _maple(tmp_path, bat_of=bat_of, **opts)
    out = ballbat("check", path, "--bats", bats)
    assert out.returncode == status, out.stdout + out.stderr
    assert text in out.stdout + out.stderr, out.stdout + out.stderr


def test_the_clean_file_with_a_small_group_stays_usable(tmp_path):
    bats = _two_bats(tmp_path)
    path = _maple(tmp_path, errs=False, bat_of=lambda i: "maple2" if i in SMALL else "maple")
    out = ballbat("check", path, "--bats", bats)
    assert out.returncode == 0 and "implausible" not in out.stdout, out.stdout


def test_one_impact_label():
    """Its id and the file line where there is a file; an impact without an id is numbered from 1."""
    import xarray as xr

    from ballbat.analysis import impact_labels

    ds = xr.Dataset(
        {"impact_id": ("impact", ["MP31", "row 3"]), "source_row": ("impact", ["row 32", "row 3"])},
        coords={"impact": [0, 1]},
    )
    assert list(impact_labels(ds)) == ["impact MP31 (row 32)", "impact at row 3"]
    assert list(impact_labels(xr.Dataset(coords={"impact": [0, 30]}))) == ["impact #1", "impact #2"]


def test_netcdf_rows_are_counted_from_one(tmp_path):
    import xarray as xr

    from ballbat.ingest import read_impacts_table

    with MAPLE.open(newline="") as fh:
        rows = list(csv.DictReader(fh))

    ds = xr.Dataset({k: ("impact", [r[k] for r in rows]) for k in ("impact_id", "bat", "ball")})
    for k in ("v_bat_mph", "v_ball_mph", "theta_deg", "omega_rpm"):
        ds[k] = ("impact", [float(r[k]) for r in rows], {"units": k.rsplit("_", 1)[1]})
    ds.to_netcdf(tmp_path / "m.nc")
    _, table = read_impacts_table(tmp_path / "m.nc")
    assert table[0][0] == "entry 1" and table[30][0] == "entry 31"


# ---------------------------------------------------------------------------------------
# Command line: (args, exit status, text of the one line on stderr)

FLY = ["fly", "--speed", "100", "--angle", "25"]
CLI_CASES = [
    (["fly", "--speed", "1e300", "--angle", "20"], 2, "argument --speed: 1e+300 mph is outside (0, 200] mph"),
    (["fly", "--speed", "100", "--angle", "nan"], 2, "argument --angle: 'nan' is not a finite number"),
    ([*FLY, "--sidespin", "inf"], 2, "argument --sidespin: 'inf' is not a finite number"),
    ([*FLY, "--wind", "nan,0"], 2, "argument --wind: invalid wind 'nan,0'"),
    ([*FLY, "--temperature", "-1000"], 2, "argument --temperature: -1000 deg F is outside [-40, 130] deg F"),
    ([*FLY, "--pressure", "nan"], 2, "argument --pressure: 'nan' is not a finite number"),
    ([*FLY, "--elevation", "1e6"], 2, "argument --elevation: 1e+06 ft is outside [-1500, 15000] ft"),
    ([*FLY, "--spin-decay", "nan"], 2, "argument --spin-decay: 'nan' is not a finite number"),
    (["fly", "--speed", "1e6", "--angle", "20"], 2, "argument --speed: 1e+06 mph is outside"),
    ([*FLY, "--backspin", "1e6"], 2, "argument --backspin: 1e+06 rpm is outside [-10000, 10000] rpm"),
    ([*FLY, "--wind", "1e6,0"], 2, "argument --wind: 1e+06 mph is outside [-100, 100] mph"),
    (["fly", "--speed", "100", "--angle", "95"], 2, "argument --angle: 95 deg is outside [-90, 90] deg"),
    (["fly", "--speed", "100", "--angle", "180"], 2, "argument --angle: 180 deg is outside [-90, 90] deg"),
    ([*FLY, "--elevation", "-1e6"], 2, "argument --elevation: -1e+06 ft is outside [-1500, 15000] ft"),
    ([*FLY, "--elevation", "-1e2"], 0, ""),
    ([*FLY, "--wind", "-5,3"], 0, ""),
    (["check", "/dev/null"], 1, "/dev/null: empty file (expected a header line"),
]


@pytest.mark.parametrize(("args", "status", "text"), CLI_CASES, ids=[" ".join(c[0][1:]) for c in CLI_CASES])
def test_cli_case(args, status, text):
    out = ballbat(*args)
    assert out.returncode == status, out.stderr
    assert "Traceback" not in out.stderr
    if status == 2:
        assert len(out.stderr.strip().splitlines()) == 1 and text in out.stderr, out.stderr
    elif text:
        assert text in out.stdout + out.stderr


#: ``fly --csv`` files: (case, content, exit status, text of the one line)
CSV_CASES = [
    ("row longer than the header", "speed,angle,backspin\n100,25,2000,7\n", 2, "row 2: 1 more cell(s) than the header"),
    ("nan", "speed,angle\nnan,25\n", 2, "row 2, column speed: 'nan' is not a finite number"),
    ("1e400", "speed,angle\n100,1e400\n", 2, "row 2, column angle: '1e400' is not a finite number"),
    ("blank backspin (flew with 0 rpm)", "speed,angle,backspin\n103,27.5,\n", 2, "row 2, column backspin: empty"),
    ("1e6 mph", "speed,angle\n1e6,20\n", 2, "row 2, column speed: 1e+06 mph is outside (0, 200] mph"),
    ("semicolons, decimal commas", "speed;angle;backspin\n103;27,5;2500\n", 0, "422.6"),
]


@pytest.mark.parametrize(("case", "content", "status", "text"), CSV_CASES, ids=[c[0] for c in CSV_CASES])
def test_fly_csv_case(tmp_path, case, content, status, text):
    path = tmp_path / "balls.csv"
    path.write_text(content)
    out = ballbat("fly", "--csv", path)
    assert out.returncode == status and "Traceback" not in out.stderr, out.stderr
    if status == 2:
        assert len(out.stderr.strip().splitlines()) == 1 and text in out.stderr, out.stderr
    else:
        assert text in out.stdout


def test_fly_csv_binary_file(tmp_path):
    path = tmp_path / "balls.csv"
    path.write_bytes(bytes(range(256)) * 4)
    out = ballbat("fly", "--csv", path)
    assert out.returncode == 2 and len(out.stderr.strip().splitlines()) == 1 and "not UTF-8 text" in out.stderr


def test_summary_of_a_truncated_file(tmp_path):
    import xarray as xr

    ds = xr.Dataset({"x": ("impact", np.arange(5000.0))})
    for name in ("reconstruct", "fit_ex", "stronge"):
        ds.to_netcdf(tmp_path / f"{name}.nc", engine="netcdf4")
    whole = (tmp_path / "stronge.nc").read_bytes()
    (tmp_path / "stronge.nc").write_bytes(whole[: len(whole) // 3])  # cut short, as a killed copy leaves it
    out = ballbat("summary", tmp_path)
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and "stronge.nc cannot be read" in out.stderr, out.stderr


def test_summary_of_files_without_the_variables(tmp_path):
    import xarray as xr

    for name in ("reconstruct", "fit_ex", "stronge"):
        xr.Dataset({"x": ("impact", [1.0])}).to_netcdf(tmp_path / f"{name}.nc", engine="netcdf4")
    out = ballbat("summary", tmp_path)
    assert out.returncode == 2 and "Traceback" not in out.stderr and "lacks" in out.stderr, out.stderr


def test_closed_pipe_is_quiet(tmp_path):
    """`ballbat ... | head`: the reader has gone before the output is written."""
    path = tmp_path / "balls.csv"
    path.write_text("speed,angle\n" + "".join(f"{90 + i % 20},{20 + i % 10}\n" for i in range(40)))
    r, w = os.pipe()
    os.close(r)  # nobody reads
    proc = subprocess.run(
        [sys.executable, "-m", "ballbat.cli", "fly", "--csv", str(path), "--method", "calculator"],
        stdout=w,
        stderr=subprocess.PIPE,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    os.close(w)
    assert "Traceback" not in proc.stderr and "BrokenPipeError" not in proc.stderr, proc.stderr
    assert proc.returncode == 141


# ---------------------------------------------------------------------------------------
# Install: the schema and the tables ship with the package


def test_package_data_is_declared():
    data = ROOT / "src" / "ballbat" / "data"
    for name in ("config.schema.yaml", "balls.csv", "bats.csv"):
        assert (data / name).resolve().is_file(), name
    assert 'ballbat = ["data/*.yaml", "data/*.csv"]' in (ROOT / "pyproject.toml").read_text()


@pytest.mark.slow
def test_pip_install_outside_the_checkout(tmp_path):
    """`pip install .` into a fresh venv (dependencies from this environment), then `ballbat fly` elsewhere."""
    import shutil

    src = tmp_path / "checkout"  # a copy: setuptools builds in the source tree (build/)
    for part in ("pyproject.toml", "README.md", "src", "config", "workflow/schemas"):
        copy = shutil.copytree if (ROOT / part).is_dir() else shutil.copy2
        (src / part).parent.mkdir(parents=True, exist_ok=True)
        copy(ROOT / part, src / part, **({"symlinks": True} if copy is shutil.copytree else {}))
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    subprocess.run(
        [str(py), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-deps", str(src)],
        check=True,
        timeout=300,
        capture_output=True,
    )
    site = subprocess.run(
        [str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    here = subprocess.run(
        [sys.executable, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip()
    # the dependencies from this environment: a path line (not its .pth files: no editable ballbat)
    (Path(site) / "zz_dependencies.pth").write_text(here + "\n")
    where = tmp_path / "elsewhere"
    where.mkdir()
    out = subprocess.run(
        [str(venv / "bin" / "ballbat"), "fly", "--speed", "103", "--angle", "27.5", "--backspin", "2500"],
        capture_output=True,
        text=True,
        cwd=where,
        timeout=120,
    )
    assert out.returncode == 0 and out.stdout.startswith("carry 422.6 ft"), out.stderr
    installed = Path(site) / "ballbat" / "data" / "config.schema.yaml"
    assert installed.is_file() and not installed.is_symlink()
    loc = subprocess.run([str(py), "-c", "import ballbat; print(ballbat.__file__)"], capture_output=True, text=True)
    assert loc.stdout.startswith(site)


# ---------------------------------------------------------------------------------------
# A missing tracks file fails its own dataset's job, not the whole run (--keep-going)


@pytest.mark.slow
def test_missing_tracks_file_stops_only_its_dataset(lab_run, tmp_path):
    from workflow_helpers import copy_run, snakemake

    wd = copy_run(lab_run, tmp_path / "wd")
    (wd / "results" / "maple" / "ingest.nc").unlink()  # the good dataset has a job to run
    tracked = yaml.safe_load((ROOT / "config" / "examples" / "tracked.yaml").read_text())["datasets"]["tracked"]
    tracked["tracks"]["file"] = "nothere_tracks.csv"
    (wd / "gone.yaml").write_text(yaml.safe_dump({"datasets": {"gone": tracked}}))
    dry = snakemake(wd, "-n", "--configfile", "gone.yaml", check=False)
    assert dry.returncode == 0 and "MissingInputException" not in dry.stderr, dry.stderr[-2000:]
    out = snakemake(
        wd,
        "-c1",
        "--keep-going",
        "results/gone/reduce.nc",
        "results/maple/ingest.nc",
        "--configfile",
        "gone.yaml",
        check=False,
    )
    assert out.returncode != 0
    assert "nothere_tracks.csv: file not found" in (wd / "results" / "gone" / "logs" / "reduce.log").read_text()
    assert (wd / "results" / "maple" / "ingest.nc").is_file()  # the other dataset went on
