"""A validation's workers come from a fork server, never from a fork of a process that has cast
rays (:mod:`planner.sim.pool`).

Embree runs on TBB threads that stay alive after a ray batch. A validation in a pytest worker
that had cast rays before forked its workers while one of those threads held TBB's lock, and
both workers waited for it for ever at their first ray batch (the suite hung at 97 %). The hang
needs a fork at the wrong instant, so no test makes it happen at will: these check that no
plain fork is made, and that a process that has cast rays gets its trials back.
"""

from __future__ import annotations

import multiprocessing as mp
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from planner.sim.pool import start_method

REPO = Path(__file__).resolve().parents[3]


def _run(script: str) -> subprocess.CompletedProcess[str]:
    """Run a Python ``script`` in a fresh process at the repository's root; it must exit 0
    within 180 s (a timeout stands for a hang)."""
    out = subprocess.run(
        [sys.executable, "-c", script],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=180,
        check=False,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    return out


def test_workers_never_fork_this_process() -> None:
    expected = "forkserver" if "forkserver" in mp.get_all_start_methods() else None
    assert start_method() == expected
    assert start_method() != "fork"


@pytest.mark.slow
def test_a_process_that_cast_rays_gets_its_trials_back() -> None:
    """Rays in this process first (Embree's threads start), then a validation on two workers;
    a timeout stands for the hang."""
    script = textwrap.dedent(
        """
        import numpy as np
        from bench.box_plans import POINT_SENSOR, box_mesh, box_plans
        from planner.sim.raycast import MeshRayCaster
        from planner.validate.job import validate_plan

        if __name__ == "__main__":
            mesh = box_mesh()
            caster = MeshRayCaster(mesh)
            rng = np.random.default_rng(0)
            for _ in range(20):  # Embree's TBB threads busy until just before the pool opens
                o = rng.uniform(-2.0, 2.0, (20000, 3))
                caster.first_hits(o, -o / np.linalg.norm(o, axis=1, keepdims=True))
            plan = box_plans(POINT_SENSOR)["three_two_one"]
            report = validate_plan(plan, trials=120, seed=3, mesh=mesh, workers=2)
            print(report.n_ok)
        """
    )
    out = _run(script)
    assert out.stdout.split()[-1] == "120"


def test_a_worker_finds_the_ray_kernel_loaded() -> None:
    """The fork server loads numba and the float64 ray-cast kernel once (for the types a cast
    passes: no second compile at the first cast), not every worker at its first cast."""
    if start_method() != "forkserver":
        pytest.skip("no fork server on this platform")
    script = textwrap.dedent(
        """
        from planner.sim.pool import open_pool, prepare_pool
        from tests.planner.sim.worker_probe import kernel_state, nothing

        if __name__ == "__main__":
            prepare_pool()
            with open_pool(1, nothing, ()) as pool:
                print(pool.submit(kernel_state).result(timeout=120))
        """
    )
    out = _run(script)
    assert out.stdout.split()[-2:] == ["True", "1"]
