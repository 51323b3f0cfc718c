"""A vetted trial asks a hook that vets many paths at once after the trial, in one call, and runs
the trial again search by search only when a path is refused: the same result as the hook asked
search by search, whether it refuses an A-H search, an x-offset search or none."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from calib.errors import NonFiniteError
from calib.plan.file import load_plan
from calib.probing import SearchCommand
from planner.check.simulatable import check_simulatable, work_object_mesh
from planner.check.simulation_setup import simulation_setup
from planner.reasons import Reason
from planner.sim.trial import TrialResult, TrialRunner

PLAN = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"


@pytest.fixture(scope="module")
def runner() -> TrialRunner:
    plan = load_plan(PLAN)
    models = check_simulatable(plan)
    mesh = work_object_mesh(plan, PLAN.parent, models)
    return TrialRunner(simulation_setup(plan, models, mesh), mesh)


class _Hook:
    """Refuses the searches of one id; counts how it is asked."""

    def __init__(self, refuse: str) -> None:
        self.refuse = refuse
        self.single = 0
        self.batches: list[int] = []

    def _why(self, cmd: SearchCommand) -> Reason | None:
        if cmd.point_id != self.refuse:
            return None
        return Reason("collision", "link_5 hits clamp", pair=("link_5", "clamp"))

    def __call__(self, cmd: SearchCommand) -> Reason | None:
        self.single += 1
        return self._why(cmd)


class _ManyHook(_Hook):
    def many(self, cmds: list[SearchCommand]) -> list[Reason | None]:
        self.batches.append(len(cmds))
        return [self._why(c) for c in cmds]


def _same(a: TrialResult, b: TrialResult) -> None:
    assert (a.failure, a.searched, a.events) == (b.failure, b.searched, b.events)
    assert (a.xoffset_failure, a.failed_search, a.xoffset_failed_search) == (
        b.xoffset_failure,
        b.failed_search,
        b.xoffset_failed_search,
    )
    assert np.array_equal(a.delta_procedure, b.delta_procedure, equal_nan=True)
    assert np.array_equal(a.delta_best_fit, b.delta_best_fit, equal_nan=True)
    assert a.xoffset_x_m is not None and b.xoffset_x_m is not None
    assert np.array_equal(a.xoffset_x_m, b.xoffset_x_m, equal_nan=True)


@pytest.mark.parametrize("refuse", ["none", "F", "PX1_3"])
def test_a_hook_of_many_paths_gives_the_trial_of_a_hook_asked_one_by_one(
    runner: TrialRunner, refuse: str
) -> None:
    seed = np.random.SeedSequence(11)
    one, many = _Hook(refuse), _ManyHook(refuse)
    expected = runner.run_trial(seed, one)
    got = runner.run_trial(seed, many)
    _same(got, expected)
    assert many.batches[0] >= 12  # the trial's paths, at once
    if refuse == "none":
        assert expected.failure == expected.xoffset_failure == ""
        assert many.single == 0 and len(many.batches) == 1  # no search asked again
        assert many.batches[0] == one.single  # every path the trial ran
    else:
        # run again with the hook, to stop where refused (the x-offset run's approaches
        # asked at once there too)
        assert many.single > 0 and len(many.batches) == (2 if refuse.startswith("PX") else 1)
        failed = expected.failed_search or expected.xoffset_failed_search
        assert failed is not None and failed.search == refuse
        assert failed.cause.kind == "collision"


class _RaisingManyHook(_ManyHook):
    """Asked about many paths at once it raises; asked one by one it refuses ``refuse``."""

    def many(self, cmds: list[SearchCommand]) -> list[Reason | None]:
        self.batches.append(len(cmds))
        raise NonFiniteError("a path's pose is not finite")


def test_a_hook_that_raises_when_asked_for_many_gives_the_trial_asked_one_by_one(
    runner: TrialRunner,
) -> None:
    """What ``many`` raises does not escape the trial: it runs again search by search, as the
    hook asked one by one gives it (here the refusal of F)."""
    seed = np.random.SeedSequence(11)
    expected = runner.run_trial(seed, _Hook("F"))
    hook = _RaisingManyHook("F")
    _same(runner.run_trial(seed, hook), expected)
    assert hook.batches and hook.single > 0
    assert expected.failed_search is not None and expected.failed_search.search == "F"
