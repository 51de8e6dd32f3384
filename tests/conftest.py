"""Shared fixtures: the repository's property tables (Tables I and II of the paper), and the suite's two
workflow runs (the default, and a lab's datasets, scenarios and studies in one folder), each built once.
"""

import os
import shutil
from pathlib import Path

import pytest
import yaml

from ballbat.config_checks import load_config
from ballbat.properties import load_balls, load_bats

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def config():
    """The default config/config.yaml, validated, with the schema's defaults (as the workflow sees it)."""
    return load_config(ROOT / "config" / "config.yaml")


@pytest.fixture
def raw():
    """The default config/config.yaml as written (not validated): a fresh copy for each test to edit."""
    return yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


@pytest.fixture(scope="module")
def schema():
    """The config schema (workflow/schemas/config.schema.yaml)."""
    return yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())


@pytest.fixture(scope="session")
def balls():
    return load_balls(ROOT / "config" / "balls.csv")


@pytest.fixture(scope="session")
def bats():
    return load_bats(ROOT / "config" / "bats.csv")


def _shared_run(tmp_path_factory, name: str, build) -> Path:
    """A workflow run built once for the whole session, whichever pytest-xdist worker asks first.

    The folder lives beside the workers' own temporary folders, and its build holds a lock:
    a worker that needs it while another builds it waits, and a finished build is marked
    (``.built``) so that no one builds it twice. A failed build is marked too, with its error,
    so that the other worker fails at once instead of building it again.

    ``BALLBAT_TEST_SHARED_RUNS`` names a folder to keep the runs in between sessions (for work on
    one test; a run built by other code is not rebuilt: remove its ``.built`` mark).
    """
    import fcntl

    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent  # shared by the session's workers
    if os.environ.get("BALLBAT_TEST_SHARED_RUNS"):  # a developer's folder of runs kept between sessions
        base = Path(os.environ["BALLBAT_TEST_SHARED_RUNS"])
    work, done, failed = base / name, base / f"{name}.built", base / f"{name}.failed"
    with open(base / f"{name}.lock", "w") as lock:  # closing the file releases the lock
        fcntl.flock(lock, fcntl.LOCK_EX)
        if failed.exists():
            raise RuntimeError(f"the shared run {name} failed to build:\n{failed.read_text()}")
        if not done.exists():
            shutil.rmtree(work, ignore_errors=True)
            work.mkdir()
            try:
                build(work)
            except BaseException as exc:
                failed.write_text(str(exc))
                raise
            done.touch()
    return work


@pytest.fixture(scope="session")
def lab_clips(tmp_path_factory):
    """A lab's folder of clips: three impacts in both cameras (video_clips.render_clip_folder), and their truth.

    Read only: a test that changes the folder copies it first.
    """
    from video_clips import render_clip_folder

    folder = tmp_path_factory.mktemp("lab_clips")
    return folder, render_clip_folder(folder)


@pytest.fixture(scope="session")
def default_run(tmp_path_factory):
    """The workflow run once with the default config (`snakemake -c2`), shared by the tests that read it.

    One of the two builds of the workflow in the suite (the other: :func:`lab_run`). Tests
    only read it; a test that changes a run works on a copy (:func:`workflow_helpers.copy_run`).
    """
    from workflow_helpers import make_workdir, snakemake

    def build(work):
        make_workdir(work)
        snakemake(work, "-c2")

    return _shared_run(tmp_path_factory, "default_run", build)


@pytest.fixture(scope="session")
def default_report(default_run, tmp_path_factory):
    """A copy of the default run with its report (`snakemake --report results/report.html`)."""
    from workflow_helpers import copy_run, snakemake

    def build(work):
        copy_run(default_run, work / "run")
        snakemake(work / "run", "--report", "results/report.html")

    return _shared_run(tmp_path_factory, "default_report", build) / "run"


#: The lab run's tool-file datasets (``tools.yaml``; docs/tracks.md): the example tracks as a
#: long CSV (``tracked``) and as a folder of Tracker projects (``trk``), reduced and fitted
#: (--until fit_ex tracks_qa). The other formats give the same tracks as the .trk files
#: (tracks/formats/test_layout.py::test_every_format_imports_the_same_tracks).
TOOL_CAMERAS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}


def _tools_config(work: Path) -> dict:
    from track_files import TOOL_NAMES, write_lab_folder

    example = work / "config" / "examples"
    write_lab_folder(work / "lab" / "trk", example / "tracked_tracks.csv", "trk", TOOL_CAMERAS)
    tracked = yaml.safe_load((example / "tracked.yaml").read_text())["datasets"]["tracked"]["tracks"]
    keep = ("mirror", "m_per_px_err")  # frame rates and pixel scales: from the files
    cameras = {cam: {k: v for k, v in c.items() if k in keep} for cam, c in tracked["cameras"].items()}
    lab = {"points": dict(TOOL_NAMES), "impacts": tracked["impacts"], "cameras": cameras, "rig": tracked["rig"]}
    return {"tracked": {"tracks": tracked}, "trk": {"tracks": {**lab, "dir": "lab/trk"}}}


@pytest.fixture(scope="session")
def lab_run(tmp_path_factory):
    """The other build of the workflow in the suite: what a lab runs beside the default, in one folder.

    - dataset ``small``: 36 rendered impacts (3 ball x bat pairs, camera tracks as the default's);
    - dataset ``maple``: the example measured dataset (config/examples/maple.yaml);
    - scenarios: the paper's with 26 offsets and e_x from ``small``, and ``flyballs``
      (2 exit speeds x 3 launch angles, 11 points);
    - studies of ``small``: calibration (4 replicates in 2 batches), design (2 sizes) and,
      on request, robustness (a grid of 2 points with drawn calibration);
    - ``tools.yaml``: the tool-file datasets (:func:`_tools_config`), run --until fit_ex tracks_qa.

    Built with ``snakemake -c2 all studies studies_on_request``, then the tool files'
    datasets. The package's source is copied too (tests edit it to see what reruns). Tests
    change copies of it (:func:`workflow_helpers.copy_run`), never the run itself.
    """
    from workflow_helpers import SMALL_SYNTHETIC, make_workdir, snakemake, write_config

    def edit(cfg):
        render = {**cfg["datasets"]["synthetic"]["render"], "tilted_fraction": 0.0}
        small = {"synthetic": SMALL_SYNTHETIC, "render": render}
        maple = yaml.safe_load((ROOT / "config" / "examples" / "maple.yaml").read_text())["datasets"]["maple"]
        cfg["datasets"] = {"small": small, "maple": maple}
        paper = cfg["implications"]["scenarios"]["paper"]
        paper["sweep"]["D_in"]["num"] = 26
        paper["e_x_from_dataset"] = "small"
        cfg["implications"]["scenarios"]["flyballs"] = {
            "ball": "baseball",
            "launch": {"exit_speed_mph": [95, 105], "launch_deg": [15, 25, 35], "backspin_rpm": 2200},
            "flight": {"n_points": 11},
        }
        cfg["studies"] = LAB_STUDIES

    def build(work):
        make_workdir(work, copy_package=True)
        write_config(work, edit)
        snakemake(work, "-c2", "all", "studies", "studies_on_request")
        (work / "tools.yaml").write_text(yaml.safe_dump({"datasets": _tools_config(work)}))
        snakemake(work, "-c2", "--configfile", "tools.yaml", "--until", "fit_ex", "tracks_qa")

    return _shared_run(tmp_path_factory, "lab_run", build)


@pytest.fixture(scope="session")
def maple_reference(lab_run):
    """The maple example's files of a clean run (lab_run: maple beside a rendered synthetic dataset)."""
    from workflow_helpers import maple_data_files

    return maple_data_files(lab_run)


@pytest.fixture
def maple_copy(lab_run, maple_reference, tmp_path):
    """A copy of the lab run (timestamps kept) for one fault test to damage, with the clean run's maple files."""
    from workflow_helpers import copy_run, maple_data_files

    wd = copy_run(lab_run, tmp_path / "wd")
    assert maple_data_files(wd) == maple_reference
    return wd, maple_reference


#: The lab run's studies (of dataset ``small``).
LAB_STUDIES = {
    "calibration": {"dataset": "small", "seed": 1, "replicates": 4, "batch_size": 3, "truth_impacts": 40},
    "design": {
        "dataset": "small",
        "seed": 2,
        "replicates": 2,
        "batch_size": 4,
        "truth_impacts": 40,
        "sweep": {"parameter": "impacts_per_bat", "values": [5, 8]},
    },
    "robustness": {
        "dataset": "small",
        "seed": 3,
        "on_request": True,
        "replicates": 2,
        "batch_size": 4,
        "truth_impacts": 30,
        "draw_calibration": True,
        "sweep": {"grid": {"pixel_noise_px": [1.0, 5.0], "impacts_per_bat": [6], "contact_ms": [1.0]}},
    },
}


#: The order of the test modules, as paths relative to tests/ (``make test`` and ``make test-lab``:
#: ``--dist loadscope --no-loadscope-reorder``, a module per pytest-xdist process, in this order, each
#: process taking the next module when it is nearly done), so that both processes stay busy and end
#: together. In ``make test-all`` one process builds the lab run (workflow/test_outputs.py, its first
#: module) while the other builds the default run and runs its tests, then the unit tests (no shared
#: run); the lab run's other tests come last (:data:`LAST`), so that no process waits for the lab run
#: while there is other work, and both share its reruns. ``make test`` (no lab run) starts with the
#: default run's build beside the unit tests; ``make test-lab`` with the lab run's.
FIRST = (
    "workflow/test_outputs.py",
    "workflow/test_crate.py",
    "workflow/test_lab_numbers.py",
    "workflow/test_diagnoses.py",
    "workflow/test_report_browser.py",
)

#: The modules that copy or read the lab run, after every other module: the heaviest first (their
#: Snakemake reruns), the quick ones last so that the two processes end together.
LAST = (
    "workflow/test_faults_runs.py",
    "workflow/test_faults.py",
    "workflow/test_reruns.py",
    "workflow/test_guards.py",
    "workflow/test_byod.py",
    "workflow/test_redteam.py",
    "workflow/test_studies.py",
    "workflow/test_study_runs.py",
    "workflow/test_track_formats.py",
)

#: The folder of the test modules: :data:`FIRST` and :data:`LAST` name them by their path relative to it
#: (basenames repeat: tests/test_ingest.py, tests/stages/test_ingest.py).
TESTS = Path(__file__).resolve().parent


def module_key(path: Path) -> str:
    """A test module's path relative to tests/, with forward slashes (as :data:`FIRST` and :data:`LAST` name it)."""
    return Path(path).resolve().relative_to(TESTS).as_posix()


#: The report in a real browser (marker ``browser``): ``make test-report``'s, on the checkout's own
#: run; ``make test`` leaves it out (CI runs it there), ``make test-all`` and ``pytest`` keep it.
BROWSER = "workflow/test_report_browser.py"


def pytest_collection_modifyitems(config, items):
    """Mark the lab run's tests ``lab``; order the modules: :data:`FIRST`, the rest as collected, :data:`LAST`.

    A test is ``lab`` when it reads or copies :func:`lab_run` (directly or through another
    fixture): ``make test`` leaves those to ``make test-lab``, and CI runs both on the same two
    shared runs (``BALLBAT_TEST_SHARED_RUNS``, ``.ci/run``). The order is the same in every process.
    """
    for item in items:
        if "lab_run" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.lab)
        if module_key(item.path) == BROWSER:
            item.add_marker(pytest.mark.browser)
    rank = {name: i for i, name in enumerate(FIRST)}
    rank.update({name: len(FIRST) + 1 + i for i, name in enumerate(LAST)})
    items.sort(key=lambda item: rank.get(module_key(item.path), len(FIRST)))
