"""Commands of the suite run as processes forked from a server that has their libraries loaded.

The suite runs Snakemake about a hundred times and the ``ballbat`` command about a hundred
times more; as fresh interpreters each paid 1-2.5 s of CPU importing Snakemake, xarray, scipy
and the rest before doing anything. Here each run is a child of a fork server (one per test
process) that imported those once (:mod:`snakemake_preload`): a real process of its own, with its
own working folder, environment, streams and exit status, as a subprocess would have.

Nothing of ballbat is loaded in the server: each child imports it afresh (from ``workdir/src``
when a run has its own copy of the package). The installed entry points themselves are tested
as subprocesses (test_cli.test_entry_point_is_installed, test_release).

Set ``BALLBAT_TEST_COST_LOG`` to a file to get one JSON line per run: the test, the command,
its wall time and its CPU time with its children's (the jobs of a Snakemake run).
"""

from __future__ import annotations

import os
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
            sys.argv = ["snakemake", *args]
            from snakemake.cli import main

            main()
        else:
            sys.argv = ["ballbat", *args]
            from ballbat.cli import main

            sys.exit(main(args))
    finally:
        _log_cost(kind, args, time.perf_counter() - start)


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
