"""Running one whole command in a source tree: ours or a reference commit's worktree.

Shared by the benches that compare this code with a reference commit in the same run
(``bench.bench_map_vs_reference``, ``bench.bench_suggest_vs_reference``). Each command runs
with the working directory and ``PYTHONPATH`` set to its tree, so neither side picks up the
other's code (an editable install points at the main tree; :func:`planner_file` records where
``planner`` really comes from), and with a cache directory of its own
(``WOBJCAL_CACHE_DIR``: the distance fields, allowed-collision lists and, under it, the numba
kernels; ``NUMBA_CACHE_DIR`` is removed so that it cannot win over it). numba keeps one
version of the kernels per cache directory and deletes the others, so two trees sharing one
would compile at every turn.

The commands run in a session of their own: a background compile helper a command starts
(``planner.cell.kernels.kernel_cache.start_background``) is waited for (and, past a bound, ended by
its process group) before the next command, so that it does not load the machine under the
next measurement. The load average is read before and after every command.

Same interpreter for both trees: a second virtual environment cannot be built offline here,
so "its own venv" is the same Python and packages with the tree's code first on the path.
"""

from __future__ import annotations

import contextlib
import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent


def tree_env(tree: Path, cache_dir: Path) -> dict[str, str]:
    """The environment of a command run in ``tree`` with ``cache_dir`` as its cache."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    env["WOBJCAL_CACHE_DIR"] = str(cache_dir)
    env.pop("NUMBA_CACHE_DIR", None)
    return env


def planner_file(tree: Path) -> str:
    """Where ``import planner`` resolves in ``tree``'s environment; refused unless in it."""
    env = tree_env(tree, Path("/nonexistent-cache"))
    out = subprocess.run(
        [sys.executable, "-P", "-c", "import planner; print(planner.__file__)"],
        cwd=tree,
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    where = out.stdout.strip()
    if not where.startswith(str(tree.resolve())):
        raise SystemExit(f"{tree} imports planner from {where}")
    return where


def head_commit(tree: Path) -> str:
    """The commit checked out in ``tree`` (short hash), and ``+dirty`` with local changes."""
    rev = subprocess.run(
        ["git", "-C", str(tree), "rev-parse", "--short", "HEAD"], capture_output=True, text=True
    ).stdout.strip()
    dirty = subprocess.run(
        ["git", "-C", str(tree), "status", "--porcelain", "--untracked-files=no"],
        capture_output=True,
        text=True,
    ).stdout.strip()
    return rev + ("+dirty" if dirty else "")


def run_header(ours: Path, reference: Path, name: str) -> dict[str, Any]:
    """What a result file says of the two trees it compared (commits, where ``planner`` came
    from, the interpreter, the CPUs)."""
    return {
        "reference": name,
        "reference_commit": head_commit(reference),
        "ours_commit": head_commit(ours),
        "planner_imported_from": {
            "ours": planner_file(ours),
            "reference": planner_file(reference),
        },
        "interpreter": "the same Python for both trees, PYTHONPATH isolation (no second venv)",
        "cpu_count": os.cpu_count(),
    }


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def adopt_orphans() -> bool:
    """Make this process the reaper of its descendants' orphans (Linux
    ``PR_SET_CHILD_SUBREAPER``); False where that is not possible.

    A validation's workers come from a fork server that outlives the command by a moment and
    is then nobody's child: its CPU, and its workers', would be missing from
    ``RUSAGE_CHILDREN``. Adopted, it is waited for by :func:`reap_orphans` and counted."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return bool(libc.prctl(36, 1, 0, 0, 0) == 0)  # PR_SET_CHILD_SUBREAPER = 36
    except (OSError, AttributeError):
        return False


def reap_orphans(timeout_s: float = 60.0) -> None:
    """Wait (up to ``timeout_s``) for every child of this process, the adopted orphans of a
    command that has ended included, so that their CPU counts in ``RUSAGE_CHILDREN``. Call it
    only when no command of this process is running."""
    deadline = time.perf_counter() + timeout_s
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            if time.perf_counter() > deadline:
                return
            time.sleep(0.05)


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def run_in_tree(
    tree: Path, argv: list[str], cache_dir: Path, helper_wait_s: float = 180.0
) -> dict[str, Any]:
    """Run ``argv`` (``sys.executable`` is put first) in ``tree``: wall and CPU seconds of the
    command, the load before and after, exit code, stdout and the last line of stderr; then
    wait up to ``helper_wait_s`` for what it left running in its session (a background
    compile), and end that process group past it."""
    load0 = os.getloadavg()[0]
    cpu0, t0 = _children_cpu_s(), time.perf_counter()
    proc = subprocess.Popen(
        [sys.executable, *argv],
        cwd=tree,
        env=tree_env(tree, cache_dir),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    stdout, stderr = proc.communicate()
    wall = time.perf_counter() - t0
    reap_orphans()
    cpu = _children_cpu_s() - cpu0
    load1 = os.getloadavg()[0]
    t1 = time.perf_counter()
    ended = False
    while _group_alive(proc.pid):
        if time.perf_counter() - t1 > helper_wait_s:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGTERM)
            ended = True
            time.sleep(1.0)
            break
        time.sleep(0.2)
    return {
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "load_1min_before": round(load0, 2),
        "load_1min_after": round(load1, 2),
        "exit_code": proc.returncode,
        "helper_after_s": round(time.perf_counter() - t1, 2),
        "helper_ended": ended,
        "stdout": stdout,
        "stderr_last": (stderr.strip().splitlines() or [""])[-1][:400],
    }
