"""Red team, issue 34 (part A): no lost files, no memory blow-ups, tool files rerun by content, one line.

:data:`RED_TEAM` lists each case of issue 34's "Why" that part A answers, with its expected outcome
and the tests that hold it; each test fails on the code before issue 34 (67926bf) and passes now.
The command line runs as ``python -m ballbat.cli`` in a child process; cases that once allocated
tens of GiB run under a memory limit (:func:`ballbat`'s ``mem_gib``), so that the old code fails
with a MemoryError instead of taking the machine down.
"""

from __future__ import annotations

import errno
import os
import re
import shutil
import stat
import subprocess
import sys
import zipfile
from pathlib import Path

import forked
import numpy as np
import pytest
import xarray as xr
import yaml
from helpers import assert_cases_have_tests
from track_files import TOOL_NAMES, kva_text, read_long_csv, trk_text, write_lab_folder, write_trz

from ballbat import cli
from ballbat.config_checks import validate_config
from ballbat.pipeline.checked import DamagedFileError
from ballbat.pipeline.config import ConfigError
from ballbat.pipeline.ncio import read_dataset, write_dataset
from ballbat.pipeline.provenance import sha256_file
from ballbat.pipeline.runlog import logged
from ballbat.tracks import formats
from ballbat.tracks.formats import FormatError
from ballbat.tracks.formats.tracker import read_trz

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "config" / "examples"
CAMS = {"swing": {"fps": 3000.0, "m_per_px": 0.00074}, "spin": {"fps": 1000.0, "m_per_px": 0.00125}}
POINTS = "--points=ball=ball,bat_tip=tip,dot_a=A,dot_b=B"
RIG = {"pivot_to_tip_in": 34.0, "pivot_to_impact_in": 28.0}
MIRRORS = {"swing": {"mirror": False, "m_per_px_err": 0.005}, "spin": {"mirror": True}}

#: case -> (expected outcome, tests)
RED_TEAM = {
    "`import-tracks trk/ -o trk/W01_swing.trk` (an input), or a file named as input": (
        "exit 2, one line: an input of this command; the file is unchanged",
        ["test_output_refused"],
    ),
    "`-o /dev/null`, `-o /dev/full` (a device; as root it was replaced by a CSV)": (
        "exit 2, one line: a device, not a regular file",
        ["test_output_refused"],
    ),
    "`-o /tmp` (a folder: IsADirectoryError)": ("exit 2, one line: a folder", ["test_output_refused"]),
    "`-o /nonexistent/dir/x.csv` created folders from /": (
        "exit 2, one line naming the folder; nothing created; --parents creates it",
        ["test_output_refused", "test_parents_and_stdout"],
    ),
    "`-o -` wrote a file named '-'": ("the CSV on standard output, no file", ["test_parents_and_stdout"]),
    "`-o` a lab's own file": (
        "exit 2, one line; the file is unchanged; ballbat's own earlier output is replaced",
        ["test_output_refused", "test_parents_and_stdout"],
    ),
    "a full disk while import-tracks writes": (
        "exit 1, one line: disk full, naming the file; the earlier file is unchanged",
        ["test_cli_disk_full_keeps_the_old_file"],
    ),
    "a new command that writes a file without the writer": (
        "every subcommand with an output option is one of the commands tested here",
        ["test_every_writing_command_is_tested"],
    ),
    "W05_swing.trk replaced by edited content with an older timestamp": (
        "import_tracks reruns (the sha256 of every tool file is a parameter)",
        ["test_tool_file_content_reruns_the_import"],
    ),
    "a .trk mark at frame 999999999 (89 GiB allocated)": (
        "exit 1 naming file, track and frame, within 3 GiB of memory",
        ["test_hostile_tool_file"],
    ),
    "a .trz member of 6 GB (MemoryError), or compressed 1000 times": (
        "refused before reading, naming the member, its size and the limit",
        ["test_hostile_tool_file", "test_trz_member_limits"],
    ),
    "an encrypted .trz member (traceback)": ("exit 1, one problem line naming the member", ["test_hostile_tool_file"]),
    "a 1e6-point .kva track (148 s, 3.5 GB)": (
        "refused before reading: larger than the tool-file limit",
        ["test_hostile_tool_file"],
    ),
    "a lab CSV with 1e6 rest frames in one impact's track (every impact padded: 9.7 GB)": (
        "exit 1 naming the impact, the frames it spans and the limit, before the arrays are sized",
        ["test_long_rest_in_a_lab_csv"],
    ),
    "thousands of impacts and one track 10x longer than the rest (every impact padded to it; past 2 GiB refused)": (
        "accepted and reduced in blocks of impacts, padding at most as much again as the tracks "
        "(memory: bench/bench_track_blocks.py)",
        ["test_one_long_track_among_many"],
    ),
    "a YAML alias bomb in a config (the schema check hangs)": (
        "a one-line config error, at once",
        ["test_yaml_alias_bomb"],
    ),
    "a measured dataset with a render block (InputFunctionException KeyError: 'synthetic')": (
        "a config error naming datasets.NAME.render",
        ["test_render_block_of_a_measured_dataset"],
    ),
    "--pattern '{impact_id}_{camera}.{ext}{impact_id}' (regex error)": (
        "exit 1, one problem line: a field given twice",
        ["test_hostile_tool_file"],
    ),
    "`check --config` given a binary file (UnicodeDecodeError)": (
        "exit 2, one line: not UTF-8 text",
        ["test_check_config_binary"],
    ),
    "a user's NetCDF at an intermediate path (KeyError downstream)": (
        "the job reading it fails naming it (no provenance record), and leaves it",
        ["test_users_netcdf_at_a_results_path"],
    ),
    "a full disk while a NetCDF is written ('NetCDF: HDF error')": (
        "OSError 'disk full' naming the file; the earlier file is unchanged",
        ["test_netcdf_disk_full"],
    ),
}


def test_every_case_has_its_tests():
    assert_cases_have_tests(RED_TEAM, globals())


def ballbat(*args, cwd: Path = ROOT, mem_gib: float | None = None) -> subprocess.CompletedProcess:
    """Run the command line in a process of its own (forked: :mod:`forked`), under a memory limit of ``mem_gib``."""
    return forked.ballbat(*args, cwd=cwd, timeout=300, mem_gib=mem_gib)


def one_line(out: subprocess.CompletedProcess, status: int, text: str) -> None:
    """The run ended with ``status`` and one line on standard error holding ``text``, no traceback."""
    assert out.returncode == status, out.stdout + out.stderr
    assert "Traceback" not in out.stderr and len(out.stderr.strip().splitlines()) == 1, out.stderr
    assert text in out.stderr, out.stderr


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    """A folder of Tracker projects, one per impact and camera (the example's tracks)."""
    return write_lab_folder(tmp_path_factory.mktemp("lab") / "trk", EXAMPLE / "tracked_tracks.csv", "trk", CAMS)


@pytest.fixture
def lab(tmp_path, template):
    return Path(shutil.copytree(template, tmp_path / "trk"))


# --- 1. the writer ------------------------------------------------------------------------------


def _device(work: Path, name: str, minor: int) -> Path:
    """A memory device of the test's own (char 1:minor, as /dev/null and /dev/full) when run as root.

    Run as root, the code before issue 34 replaced the device node it was given by a CSV file: the
    test never gives it the system's. Without root, /dev/NAME itself (which cannot be replaced).
    """
    if os.geteuid() != 0:
        return Path("/dev") / name
    path = work / name
    os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
    return path


def _fifo(work: Path) -> Path:
    os.mkfifo(work / "pipe")
    return work / "pipe"


#: (case, -o target given the work folder w, text of the one line); the target must be unchanged.
REFUSED = [
    ("a file of the input folder", lambda w: w / "trk" / "W01_swing.trk", "is inside the input folder"),
    ("a file named as input", lambda w: w / "W01_swing.trk", "is an input of this command"),
    ("/dev/null", lambda w: _device(w, "null", 3), "is a device"),
    ("/dev/full", lambda w: _device(w, "full", 7), "is a device"),
    ("a named pipe", lambda w: _fifo(w), "not a regular file (a pipe or socket"),
    ("a folder", lambda w: w / "out", "is a folder"),
    ("a missing folder", lambda w: w / "nonexistent" / "dir" / "x.csv", "does not exist (give --parents"),
    ("a lab's own file", lambda w: w / "mine.csv", "exists and was not written by ballbat"),
]


@pytest.mark.slow  # about 3 s a row: the command reads 24 Tracker files
@pytest.mark.parametrize(("case", "target", "text"), REFUSED, ids=[r[0] for r in REFUSED])
def test_output_refused(tmp_path, lab, case, target, text):
    shutil.copy(lab / "W01_swing.trk", tmp_path / "W01_swing.trk")
    (tmp_path / "out").mkdir()
    (tmp_path / "mine.csv").write_text("impact_id,camera,point,frame,x_px,y_px\nW01,swing,ball,1,2.0,3.0\n")
    path = target(tmp_path)
    before = sha256_file(path) if path.is_file() else None
    inputs = [tmp_path / "W01_swing.trk"] if case == "a file named as input" else [lab]
    out = ballbat("import-tracks", *inputs, POINTS, "-o", path)
    one_line(out, 2, text)
    assert f"{path}:" in out.stderr
    if before is not None:
        assert sha256_file(path) == before
    if case.startswith("/dev/"):
        assert path.is_char_device()
    assert not (tmp_path / "nonexistent").exists()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == []


@pytest.mark.slow  # about 10 s: the command reads 24 Tracker files, four times
def test_parents_and_stdout(tmp_path, lab):
    """``--parents`` creates the folder; ``-o -`` writes to standard output; ballbat's own file is replaced."""
    deep = tmp_path / "a" / "b" / "tracks.csv"
    out = ballbat("import-tracks", lab, POINTS, "-o", deep, "--parents")
    assert out.returncode == 0, out.stderr
    want = read_long_csv(deep)
    assert len(want) == 24
    again = ballbat("import-tracks", lab, POINTS, "-o", deep)  # ballbat wrote it: replaced
    assert again.returncode == 0, again.stderr
    out = ballbat("import-tracks", lab, POINTS, "-o", "-", cwd=tmp_path)
    assert out.returncode == 0 and not (tmp_path / "-").exists(), out.stderr
    assert out.stdout == deep.read_text()
    assert yaml.safe_load(out.stderr)["written"] == "standard output"


@pytest.mark.slow  # about 3 s: the command reads 24 Tracker files
def test_cli_disk_full_keeps_the_old_file(tmp_path, lab, monkeypatch, capsys):
    out = tmp_path / "tracks.csv"
    assert cli.main(["import-tracks", str(lab), POINTS, "-o", str(out)]) == 0
    before = sha256_file(out)
    (lab / "W01_swing.trk").write_text(trk_text(_shifted(lab), 3000.0, 0.00074))

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    capsys.readouterr()
    assert cli.main(["import-tracks", str(lab), POINTS, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{out}: disk full" in err and len(err.strip().splitlines()) == 1, err
    assert sha256_file(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tracks.csv", "trk"]  # no temporary left


def test_every_writing_command_is_tested():
    """Every subcommand with an output option writes through ballbat.writer and is tested (import-tracks above,
    track-video in test_track_video_writes_through_the_writer).
    """
    parser = cli.parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    writing = {
        name
        for name, p in sub.choices.items()
        if any(a.dest in ("output", "out") or "-o" in a.option_strings for a in p._actions)
    }
    assert writing == {"import-tracks", "track-video"}, f"test the writer of {sorted(writing - {'import-tracks'})} here"
    source = "".join(p.read_text() for p in sorted(Path(cli.__file__).parent.glob("*.py")))  # every command
    for direct in (
        r"(?<![\w.])open\(",
        r"\.write_text\(",
        r"\.write_bytes\(",
        r"atomic_write_text\(",
        r"atomic_target\(",
    ):
        assert not re.search(direct, source), (
            f"a command of ballbat.cli writes with {direct}: use ballbat.writer.write_output"
        )


# --- 2. tool files rerun by content -------------------------------------------------------------


def _shifted(folder: Path) -> dict:
    """The tracks of W01's swing file, the ball 3 px to the right (an edit a lab might make)."""
    rows = read_long_csv(EXAMPLE / "tracked_tracks.csv")[("W01", "swing")]
    order = [TOOL_NAMES[p] for p in ("ball", "bat_tip")]
    out = {n: rows[n] for n in order}
    fr, x, y = out["ball"]
    out["ball"] = (fr, x + 3.0, y)
    return out


@pytest.mark.slow  # about 40 s: two runs of snakemake's import_tracks and two summaries
def test_tool_file_content_reruns_the_import(tmp_path):
    from workflow_helpers import make_workdir, planned_jobs, snakemake, write_config

    work = make_workdir(tmp_path)
    write_lab_folder(work / "lab" / "trk", EXAMPLE / "tracked_tracks.csv", "trk", CAMS)
    block = {"dir": "lab/trk", "points": dict(TOOL_NAMES), "impacts": str(EXAMPLE / "tracked_impacts.csv")}

    def edit(cfg):
        cfg["datasets"] = {"lab": {"tracks": {**block, "cameras": MIRRORS, "rig": RIG}}}
        cfg.pop("studies", None)

    write_config(work, edit)
    target = "results/lab/imported_tracks.nc"
    snakemake(work, "-c1", target)
    assert planned_jobs(work, target) == {}
    trk = work / "lab" / "trk" / "W01_swing.trk"
    trk.write_text(trk_text(_shifted(trk.parent), 3000.0, 0.00074, video="W01_swing.mp4"))
    os.utime(trk, (978307200, 978307200))  # touch -d 2001-01-01: older than every output
    assert planned_jobs(work, target) == {"import_tracks": 1}
    snakemake(work, "-c1", target)
    got = xr.open_dataset(work / target)
    sel = (got["impact_id"].values.astype(str) == "W01") & (got["point"].values.astype(str) == "ball")
    sel &= got["camera"].values.astype(str) == "swing"
    want = read_long_csv(EXAMPLE / "tracked_tracks.csv")[("W01", "swing")]["ball"]
    np.testing.assert_allclose(np.sort(got["x_px"].values[sel]), np.sort(want[1] + 3.0))


# --- 3. size limits and 4. one line ---------------------------------------------------------------


def _far_mark(lab: Path) -> str:
    rows = read_long_csv(EXAMPLE / "tracked_tracks.csv")[("W05", "swing")]
    tracks = {n: rows[n] for n in ("ball", "tip")}
    fr, x, y = tracks["ball"]
    tracks["ball"] = (np.r_[fr, 999999999], np.r_[x, x[-1]], np.r_[y, y[-1]])
    (lab / "W05_swing.trk").write_text(trk_text(tracks, 3000.0, 0.00074))
    return "W05_swing.trk: track 'ball': frame 999999999 of impact 'W05' in the swing camera is"


def _encrypted(lab: Path) -> str:
    """W05's swing project in a .trz whose member says it is encrypted (zip flag bit 0)."""
    src = lab / "W05_swing.trk"
    path = lab / "W05_swing.trz"
    write_trz(path, src.read_text(), "W05_swing.trk")
    src.unlink()
    data = bytearray(path.read_bytes())
    for sig, at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        i = data.find(sig)
        while i >= 0:
            data[i + at] |= 0x01
            i = data.find(sig, i + 4)
    path.write_bytes(bytes(data))
    return "W05_swing.trz:W05_swing.trk: the member is encrypted"


def _big_kva(lab: Path) -> str:
    """W05's swing file as a .kva whose ball holds 1e6 points (some 57 MiB)."""
    (lab / "W05_swing.trk").unlink()
    fr = np.arange(1_000_000)
    tracks = {"ball": (fr, 500 + 1e-4 * fr, 400 + 0 * fr), "tip": (fr[:50], fr[:50] + 0.0, fr[:50] + 0.0)}
    path = lab / "W05_swing.kva"
    path.write_text(kva_text(tracks, 3000.0, 0.00074))
    size = path.stat().st_size / 2**20
    return f"W05_swing.kva: {size:.0f} MiB, more than the {formats.MAX_FILE_BYTES // 2**20} MiB a tool file may hold"


def _bomb_trz(lab: Path) -> str:
    """W05's swing project as a .trz whose member unpacks to 40 MiB (from some 40 kB)."""
    (lab / "W05_swing.trk").unlink()
    with zipfile.ZipFile(lab / "W05_swing.trz", "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("W05_swing.trk", b"<object>" + b" " * (40 * 2**20) + b"</object>")
    return "W05_swing.trz:W05_swing.trk: 40 MiB, more than the 32 MiB"


#: (case, how the lab's folder is changed (returns the text of the problem line), extra arguments)
HOSTILE = [
    ("a .trk mark at frame 999999999", _far_mark, ()),
    ("an encrypted .trz member", _encrypted, ()),
    ("a 1e6-point .kva track", _big_kva, ()),
    ("a .trz member unpacking to 40 MiB", _bomb_trz, ()),
    (
        "a pattern with a field twice",
        lambda lab: "has {impact_id} 2 times",
        ("--pattern", "{impact_id}_{camera}.{ext}{impact_id}"),
    ),
]


@pytest.mark.slow  # about 5 s a row: import-tracks and check read 24 files (under 3 GiB of memory)
@pytest.mark.parametrize(("case", "change", "extra"), HOSTILE, ids=[r[0] for r in HOSTILE])
def test_hostile_tool_file(tmp_path, lab, case, change, extra):
    """import-tracks and ``check --kind tracks --config`` name the problem in one line, exit 1, no traceback."""
    text = change(lab)
    out = ballbat("import-tracks", lab, POINTS, "-o", tmp_path / "t.csv", *extra, mem_gib=3)
    assert out.returncode == 1 and "Traceback" not in out.stderr, out.stderr[-3000:]
    assert text in out.stderr and not (tmp_path / "t.csv").exists(), out.stderr[-3000:]
    if extra:
        return
    block = {"dir": str(lab), "points": dict(TOOL_NAMES), "impacts": str(EXAMPLE / "tracked_impacts.csv")}
    cfg = tmp_path / "lab.yaml"
    cfg.write_text(yaml.safe_dump({"datasets": {"lab": {"tracks": {**block, "cameras": MIRRORS, "rig": RIG}}}}))
    out = ballbat("check", "--kind", "tracks", "--config", cfg, mem_gib=3)
    assert out.returncode == 1 and "Traceback" not in out.stderr, out.stderr[-3000:]
    assert text in out.stdout, out.stdout[-3000:]


def test_trz_member_limits(tmp_path):
    """A member compressed far more than Tracker's XML is refused before it is read, as one of 32 MiB or more."""
    path = tmp_path / "W01_swing.trz"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("W01_swing.trk", b"<object>" + b"\0" * (8 * 2**20) + b"</object>")
    with pytest.raises(FormatError, match=r"W01_swing.trk: compressed \d+ times, more than the 200"):
        read_trz(path)


@pytest.mark.slow  # about 5 s: the check reads 33 000 rows
def test_long_rest_in_a_lab_csv(tmp_path):
    """One impact tracked through 30000 frames at rest: named, with the limit, before every impact is padded to it."""
    lines = (EXAMPLE / "tracked_tracks.csv").read_text().splitlines()
    rows = [ln.split(",") for ln in lines[1:]]
    ball = [r for r in rows if r[:3] == ["W03", "swing", "ball"]]
    last = max(int(r[3]) for r in ball)
    rest = [f"W03,swing,ball,{last + k},{ball[-1][4]},{ball[-1][5]}" for k in range(1, 30_001)]
    path = tmp_path / "tracks.csv"
    path.write_text("\n".join([*lines, *rest]) + "\n")
    out = ballbat("check", path, "--kind", "tracks", "--impacts", EXAMPLE / "tracked_impacts.csv", mem_gib=3)
    assert out.returncode == 1 and "Traceback" not in out.stderr, out.stderr
    assert f"{path}: impact 'W03' spans" in out.stdout and "more than the 20000 one impact's track may span" in (
        out.stdout
    ), out.stdout


def test_one_long_track_among_many(tmp_path, monkeypatch):
    """30 impacts, one track 10x longer, a block budget lowered to a fifth of one block: reduced in blocks, the
    padding bounded by the tracks' own size, the same flags as one block (a dataset of thousands, scaled down).
    """
    from helpers import BALLS, BATS, one_long_track

    from ballbat.stages import reduce
    from ballbat.tracks import data
    from ballbat.tracks.io import load_tracks
    from ballbat.tracks.reduce import ReduceOptions

    s = one_long_track(tmp_path / "tracks.nc", factor=10)
    one = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)

    def nbytes(tr):
        return sum(a.nbytes for b in tr.blocks for ct in b.cameras.values() for a in (*ct.x.values(), *ct.y.values()))

    tracked = sum(int(np.isfinite(ct.x[p]).sum()) * 16 for ct in one.cameras.values() for p in ct.x)
    monkeypatch.setattr(data, "BLOCK_BYTES", nbytes(one) // 5)
    blocks = load_tracks(tmp_path / "tracks.nc", balls=BALLS, bats=BATS)
    assert nbytes(one) > 4 * tracked and nbytes(blocks) < 2 * tracked
    settings = reduce.ReduceSettings(
        {"swing": s.swing.camera, "spin": s.spin.camera},
        s.rig,
        ReduceOptions.schema_defaults(),
        "tracks",
        True,
        True,
        True,
    )
    a, b = (reduce.run(settings, tr, BALLS, BATS) for tr in (one, blocks))
    assert b.sizes["impact"] == 30 and np.isfinite(b["v_bat"].values).sum() >= 25
    np.testing.assert_array_equal(b["ingest_flag"].values, a["ingest_flag"].values)


def test_yaml_alias_bomb(tmp_path, raw):
    """Nine aliases of nine, eleven deep (3e10 values): a config error at once (run apart, 60 s at most)."""
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 12)]
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("\n".join(lines) + "\n")
    code = (
        "import sys, yaml; from ballbat.config_checks import ConfigError, validate_config\n"
        "cfg = yaml.safe_load(open(sys.argv[2])); cfg['datasets']['synthetic']['extra'] = yaml.safe_load("
        "open(sys.argv[1]))\n"
        "schema = yaml.safe_load(open('workflow/schemas/config.schema.yaml'))\n"
        "try:\n    validate_config(cfg, schema, 'bomb.yaml')\nexcept ConfigError as e:\n    print(e)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code, bomb, ROOT / "config" / "config.yaml"],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=ROOT,
    )
    assert "once its YAML aliases (*name) are expanded, more than 100000" in out.stdout, out.stdout + out.stderr
    assert len(out.stdout.strip().splitlines()) == 2  # "bomb.yaml is not valid:" and the one problem


def test_render_block_of_a_measured_dataset(raw, schema):
    import copy

    cfg = copy.deepcopy(raw)
    render = copy.deepcopy(raw["datasets"]["synthetic"]["render"])
    cfg["datasets"]["maple"] = {"impacts": "config/examples/maple_impacts.csv", "render": render}
    with pytest.raises(ConfigError, match=r"datasets\.maple\.render: only a synthetic dataset renders camera tracks"):
        validate_config(cfg, schema, available=2**40)


def test_check_config_binary(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_bytes(bytes(range(256)) * 8)
    one_line(ballbat("check", "--kind", "tracks", "--config", path), 2, f"{path}: not UTF-8 text")


def test_users_netcdf_at_a_results_path(tmp_path, monkeypatch):
    """A NetCDF of the user's where normalize.nc belongs: the job reading it names it, leaves it, says why."""
    monkeypatch.chdir(tmp_path)
    user = Path("results") / "maple" / "normalize.nc"
    user.parent.mkdir(parents=True)
    xr.Dataset({"v_bat": ("impact", np.arange(5.0))}).to_netcdf(user, engine="netcdf4")
    before = sha256_file(user)
    with pytest.raises(DamagedFileError, match=r"normalize\.nc: lacks the workflow's provenance record.*left alone"):
        with logged("log/reconstruct.log", "reconstruct"):
            read_dataset(user)
    assert sha256_file(user) == before


def test_netcdf_disk_full(tmp_path, monkeypatch):
    """A full disk: netCDF says "NetCDF: HDF error" when it fills; the error says disk full and names the file."""
    ds = xr.Dataset({"x": ("n", np.arange(10.0), {"units": "m", "long_name": "a length"})})
    path = write_dataset(ds, tmp_path / "x.nc", title="t", rule="r", inputs={}, config={})
    before = sha256_file(path)

    def hdf_error(self, *args, **kwargs):
        raise RuntimeError("NetCDF: HDF error")

    class Full:
        f_bavail, f_frsize = 0, 4096

    monkeypatch.setattr(xr.Dataset, "to_netcdf", hdf_error)
    monkeypatch.setattr(os, "statvfs", lambda p: Full())
    said = rf"disk full: {re.escape(str(path))} could not be written \(RuntimeError: NetCDF: HDF error\)"
    with pytest.raises(OSError, match=said):
        write_dataset(ds, path, title="t", rule="r", inputs={}, config={})
    assert sha256_file(path) == before and sorted(p.name for p in tmp_path.iterdir()) == ["x.nc"]
