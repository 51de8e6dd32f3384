"""Commands of the suite run as processes forked from a server that has their libraries loaded.

The suite runs Snakemake about a hundred times and the ``ballbat`` command about a hundred
times more; as fresh interpreters each paid 1-2.5 s of CPU importing Snakemake, xarray, scipy
and the rest before doing anything. Here each run is a child of a fork server (one per test
process) that imported those once (:mod:`snakemake_preload`): a real process of its own, with its
own working folder, environment, streams and exit status, as a subprocess would have.

Nothing of ballbat is loaded in the server: each child imports it afresh (from ``workdir/src``
when a run has its own copy of the package). The installed entry points themselves are tested
as subprocesses (cli/test_app.py::test_entry_point_is_installed, test_release.py).

A Snakemake run's jobs are Python scripts that Snakemake starts as ``{sys.executable} SCRIPT``:
fresh interpreters again, each paying about a second of imports. In a forked run
``sys.executable`` is a small launcher (:func:`_job_launcher`) that hands the script, its working
folder, environment, memory limit and standard streams to a job server forked from the same
preloaded server (:func:`_serve_jobs`); the server forks a child that runs the script as
``__main__`` and reports its exit status back, which the launcher exits with. The job is still a
process of its own, run by Snakemake's own code from Snakemake's own script file; only the
interpreter's start is shared. ``BALLBAT_TEST_FRESH_JOBS=1`` turns this off for a run, and the
suite's runs through ``make run`` and ``make test-slurm`` use fresh interpreters throughout.

Set ``BALLBAT_TEST_COST_LOG`` to a file to get one JSON line per run: the test, the command,
its wall time and its CPU time with its children's (the jobs of a Snakemake run).
"""

from __future__ import annotations

import atexit
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: The module the fork server imports once, before it forks each run.
PRELOAD = ["snakemake_preload"]
_CONTEXT = None


def _context():
    global _CONTEXT
    if _CONTEXT is None:
        import multiprocessing
        from multiprocessing import forkserver

        _CONTEXT = multiprocessing.get_context("forkserver")
        _CONTEXT.set_forkserver_preload(PRELOAD)
        # The server starts with this folder on its path, so that it finds the preload module
        # (Python 3.11's fork server ignores the parent's sys.path, and skips a preload it
        # cannot import without a word); the runs it forks set their own environment.
        saved = os.environ.get("PYTHONPATH")
        os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(Path(__file__).parent), saved) if p)
        try:
            forkserver.ensure_running()
        finally:
            if saved is None:
                del os.environ["PYTHONPATH"]
            else:
                os.environ["PYTHONPATH"] = saved
    return _CONTEXT


def _child(kind: str, workdir: str, args: list[str], env: dict, out: str, err: str, mem_bytes: int | None) -> None:
    """The child: ``snakemake ARGS`` or ``ballbat ARGS`` in ``workdir`` with ``env``, its output in two files."""
    if PRELOAD[0] not in sys.modules:  # the server skips a preload it cannot import, silently
        raise RuntimeError(f"the fork server did not preload {PRELOAD[0]}: see forked._context")
    os.chdir(workdir)
    os.environ.clear()
    os.environ.update(env)
    sys.path[:0] = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    for fd, path in ((1, out), (2, err)):
        handle = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(handle, fd)
        os.close(handle)
    sys.stdout = open(1, "w", closefd=False)  # the child's own streams, left open for its exit
    sys.stderr = open(2, "w", closefd=False)
    if mem_bytes:
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
    start = time.perf_counter()
    try:
        if kind == "snakemake":
            launcher = env.get("BALLBAT_TEST_JOB_LAUNCHER")
            if launcher and env.get("BALLBAT_TEST_FRESH_JOBS") != "1":
                sys.executable = launcher  # Snakemake starts its Python jobs as {sys.executable} SCRIPT
            sys.argv = ["snakemake", *args]
            from snakemake.cli import main

            main()
        else:
            sys.argv = ["ballbat", *args]
            from ballbat.cli import main

            sys.exit(main(args))
    finally:
        _log_cost(kind, args, time.perf_counter() - start)


#: Length prefix of a job request (bytes, little-endian) sent to the job server.
_LEN = 8
_JOBS: tuple[str, str] | None = None  # (socket path, launcher path) of this test process's job server


def _job_server() -> tuple[str, str]:
    """The job server of this test process (started on first use): its socket and its launcher."""
    global _JOBS
    if _JOBS is None:
        folder = tempfile.mkdtemp(prefix="ballbat-jobs-")
        atexit.register(shutil.rmtree, folder, True)
        sock, launcher = os.path.join(folder, "jobs.sock"), _write_launcher(folder)
        server = _context().Process(target=_serve_jobs, args=(sock,), daemon=True)
        server.start()
        deadline = time.monotonic() + 30
        while not os.path.exists(sock):
            if not server.is_alive() or time.monotonic() > deadline:
                raise RuntimeError("the job server of tests/forked.py did not start")
            time.sleep(0.01)
        _JOBS = (sock, launcher)
    return _JOBS


def _write_launcher(folder: str) -> str:
    """Write the launcher into ``folder``, or where it can run if ``folder`` is on a noexec mount.

    The fallback is tests/.forked/PID (git ignores it), on the checkout's own file system, where
    the virtual environment's programs run.
    """
    for where in (folder, str(Path(__file__).resolve().parent / ".forked" / str(os.getpid()))):
        os.makedirs(where, exist_ok=True)
        launcher = os.path.join(where, "python")
        with open(launcher, "w") as fh:
            fh.write(_job_launcher(sys.executable))
        os.chmod(launcher, 0o755)
        try:
            if subprocess.run([launcher, "-c", "pass"], timeout=60).returncode == 0:
                if where != folder:
                    atexit.register(shutil.rmtree, where, True)
                return launcher
        except OSError:  # PermissionError: mounted noexec
            pass
    raise RuntimeError(f"tests/forked.py: the job launcher runs neither in {folder} nor in tests/.forked")


def _job_launcher(python: str) -> str:
    """The launcher's source: ``python SCRIPT.py`` as a request to the job server, any other call exec'd."""
    return f"""#!{python} -IS
# Written by tests/forked.py: runs ``python SCRIPT.py`` in a child of the test suite's job server.
import json, os, resource, socket, sys

args = sys.argv[1:]
addr = os.environ.get("BALLBAT_TEST_JOB_SERVER")
if not addr or len(args) != 1 or not args[0].endswith(".py"):
    os.execv({python!r}, [{python!r}, *args])
for fd in (0, 1, 2):  # a closed standard stream is /dev/null, as it can't be passed on
    try:
        os.fstat(fd)
    except OSError:
        os.open(os.devnull, os.O_RDWR)
body = json.dumps(
    {{"argv": args, "cwd": os.getcwd(), "env": dict(os.environ), "as": resource.getrlimit(resource.RLIMIT_AS)}}
).encode()
conn = socket.socket(socket.AF_UNIX)
conn.connect(addr)
socket.send_fds(conn, [len(body).to_bytes({_LEN}, "little") + body], [0, 1, 2])
reply = conn.recv(16)
if not reply:
    sys.stderr.write("tests/forked.py: the job's process ended without an exit status\\n")
    sys.exit(1)
sys.exit(int(reply))
"""


def _serve_jobs(path: str) -> None:
    """Accept job requests on the socket ``path``; fork a child for each (:func:`_run_job`)."""
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # the children are reaped by the kernel
    server = socket.socket(socket.AF_UNIX)
    server.bind(path + ".tmp")
    server.listen(64)
    os.rename(path + ".tmp", path)  # the socket appears only once it listens
    while True:
        conn, _ = server.accept()
        if os.fork() == 0:
            server.close()
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            _run_job(conn)
        conn.close()


def _run_job(conn: socket.socket) -> None:
    """In a job's child: take the request, become the job, run its script as ``__main__``, report, exit."""
    import json
    import resource
    import runpy
    import traceback

    data, fds, _, _ = socket.recv_fds(conn, 1 << 20, 3)
    size, body = int.from_bytes(data[:_LEN], "little"), data[_LEN:]
    while len(body) < size:
        body += conn.recv(1 << 20)
    job = json.loads(body)
    for target, fd in enumerate(fds):
        os.dup2(fd, target)
        os.close(fd)
    os.chdir(job["cwd"])
    os.environ.clear()
    os.environ.update(job["env"])
    resource.setrlimit(resource.RLIMIT_AS, tuple(job["as"]))
    # a fresh interpreter is no daemon: the job may start processes of its own (a clip import's pool)
    import multiprocessing

    multiprocessing.current_process()._config["daemon"] = False
    script = job["argv"][0]
    sys.argv = list(job["argv"])
    extra = [p for p in job["env"].get("PYTHONPATH", "").split(os.pathsep) if p]
    sys.path[:0] = [os.path.dirname(os.path.abspath(script)), *extra]  # as a fresh interpreter's path
    sys.stdin = open(0, closefd=False)
    sys.stdout = open(1, "w", closefd=False)
    sys.stderr = open(2, "w", closefd=False)
    start, code = time.perf_counter(), 1
    try:
        runpy.run_path(script, run_name="__main__")
        code = 0
    except SystemExit as stop:
        if stop.code is None or isinstance(stop.code, int):
            code = stop.code or 0
        else:
            print(stop.code, file=sys.stderr)
    except BaseException:  # as an interpreter would: the traceback, then status 1
        traceback.print_exc()
    finally:
        import atexit

        try:
            atexit._run_exitfuncs()
        except BaseException:
            traceback.print_exc()
        _log_cost("job", job["argv"], time.perf_counter() - start)
        sys.stdout.flush()
        sys.stderr.flush()
        conn.sendall(str(code).encode())
        os._exit(code)


def _log_cost(kind: str, args: list[str], wall: float) -> None:
    """Append the run's wall and CPU time (its own and its children's) to $BALLBAT_TEST_COST_LOG, when set."""
    path = os.environ.get("BALLBAT_TEST_COST_LOG")
    if not path:
        return
    import json
    import resource

    cpu = sum(
        r.ru_utime + r.ru_stime
        for r in (resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN))
    )
    test = os.environ.get("PYTEST_CURRENT_TEST", "")
    with open(path, "a") as fh:
        row = {"test": test, "kind": kind, "args": args, "wall": round(wall, 2), "cpu": round(cpu, 2)}
        fh.write(json.dumps(row) + "\n")


def run(
    kind: str,
    workdir: Path | str,
    args: list[str],
    env: dict | None = None,
    timeout: float = 600,
    mem_gib: float | None = None,
) -> subprocess.CompletedProcess:
    """Run ``kind`` (``snakemake`` or ``ballbat``) with ``args`` in ``workdir`` as a forked child.

    ``env`` is the child's whole environment (default: this process's); ``mem_gib`` caps its
    address space. The exit status, standard output and standard error come back as those of a
    subprocess; a child still running after ``timeout`` seconds is killed (``TimeoutExpired``).
    """
    env = dict(os.environ) if env is None else env
    if kind == "snakemake":
        env = dict(env)
        env["BALLBAT_TEST_JOB_SERVER"], env["BALLBAT_TEST_JOB_LAUNCHER"] = _job_server()
    mem = int(mem_gib * 2**30) if mem_gib else None
    argv = [str(a) for a in args]
    with tempfile.TemporaryDirectory() as tmp:
        out, err = os.path.join(tmp, "stdout"), os.path.join(tmp, "stderr")
        child = _context().Process(target=_child, args=(kind, str(workdir), argv, env, out, err, mem))
        child.start()
        child.join(timeout)
        if child.exitcode is None:
            child.kill()
            child.join()
            raise subprocess.TimeoutExpired([kind, *argv], timeout)
        with open(out) as fh_out, open(err) as fh_err:
            return subprocess.CompletedProcess([kind, *argv], child.exitcode, fh_out.read(), fh_err.read())


def ballbat(*args, cwd: Path | str, timeout: float = 300, mem_gib: float | None = None) -> subprocess.CompletedProcess:
    """Run the ``ballbat`` command line (:func:`ballbat.cli.main`) as a forked child in ``cwd``."""
    return run("ballbat", cwd, list(args), timeout=timeout, mem_gib=mem_gib)
