"""Acceptance of issue 20 (one measuring program) on a part nobody here made: an L-bracket.

The plans are what a user makes (:mod:`tests.bracket_part`): the shipped plate plan as the
template, the bracket's STL in metres, an 18 mm proximity sensor, a 20 mm / 3 deg misplacement
bound, hand-placed points (3-2-1: 3 on the base's top, 2 on the upright, 1 on an end face;
best fit: 3 + 3 + 3), the vias ``wobjcal check --add-vias`` adds. For the RAPID program
(adaptive: frame updated between searches) and the FANUC TP one (every search in the
nominal frame), what the issue promises:

- check rates the plan feasible for the program, or names the point and what to change;
- the validation of that program agrees with its prediction within 1.25x on every row at
  95.5 %, and a plan check calls feasible fails in at most a few calibrations;
- suggest gives a layout that validates within 1.25x of its prediction, or refuses saying
  what stops it.

What does not hold today is marked ``xfail(strict=True)`` with the gap named: the nominal
FANUC programs cannot measure the 20 mm end strips under a 20 mm bound (check says so,
rightly). The hand-placed top points lie 25 mm in front of the upright: check names them (the
sensor runs into the upright when the part lies towards them), as the validation's failures
show. 200 trials, the plan's own seed: a half-width scatters by about 10 %.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import msgspec
import pytest

from calib.plan.file import Plan
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import BestFit
from tests.bracket_part import SENSOR, bracket_mesh, bracket_plans

#: The report level the rows are compared at, percent.
LEVEL = 95.5
#: Simulated and predicted half-widths agree within this factor, either way.
AGREE = 1.25
TRIALS = 200
#: The plans' own seed (the template's).
SEED = 20131023
#: A plan check calls feasible fails in at most this share of simulated calibrations (check's
#: landing limit is 1 %; 2 % leaves room for the scatter of 200 trials).
FAIL_SHARE = 0.02
#: Suggest's target at the points of interest, m.
TARGET_M = 0.3e-3
#: How each controller's program is named: RAPID steers best fit and 3-2-1, FANUC TP does not.
PROGRAM = {"rapid": "RAPID, adaptive", "fanuc": "TP, nominal"}

TP_NOMINAL = (
    "FANUC TP runs every search in the nominal frame (the TP writer computes no frame update): the "
    "end-face searches land off the 20 mm end strips in ~30 % of calibrations under the 20 mm "
    "bound; check refuses them (landing), rightly, and nothing in the plan can fix it short of "
    "a smaller bound"
)


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("bracket")


@pytest.fixture(scope="module")
def plans(folder: Path) -> dict[str, Plan]:
    return bracket_plans(folder)


class _Runs:
    """Each job run once per module (check, validate, suggest are seconds each)."""

    def __init__(self, folder: Path, plans: dict[str, Plan]) -> None:
        self.folder, self.plans = folder, plans
        self._cache: dict[tuple[str, ...], Any] = {}

    def _once(self, key: tuple[str, ...], make: Any) -> Any:
        if key not in self._cache:
            self._cache[key] = make()
        return self._cache[key]

    def check(self, procedure: str, fmt: str) -> Any:
        from planner.check.job import check_plan

        plan = self.plans[procedure]
        return self._once(("check", procedure, fmt), lambda: check_plan(plan, self.folder, fmt=fmt))

    def validate(self, procedure: str, fmt: str) -> Any:
        return self._once(
            ("validate", procedure, fmt), lambda: self.validate_plan(self.plans[procedure], fmt)
        )

    def validate_plan(self, plan: Plan, fmt: str) -> Any:
        from planner.validate.job import validate_plan

        return validate_plan(
            plan, trials=TRIALS, seed=SEED, workers=1, plan_dir=self.folder, fmt=fmt
        )

    def suggest(self, procedure: str, fmt: str) -> Any:
        """The suggestion for the bracket (the best-fit plan's cell and models), or the
        :class:`planner.suggest.SuggestError` it raised."""
        from planner.suggest import SuggestError, suggest_plan

        def make() -> Any:
            try:
                return suggest_plan(
                    self.plans["best_fit"],
                    self.folder,
                    target_m=TARGET_M,
                    max_points=10,
                    procedure=procedure,
                    fmt=fmt,
                )
            except SuggestError as exc:
                return exc

        return self._once(("suggest", procedure, fmt), make)


@pytest.fixture(scope="module")
def runs(folder: Path, plans: dict[str, Plan]) -> _Runs:
    return _Runs(folder, plans)


def _ratios(report: Any) -> dict[str, float]:
    """Simulated / predicted half-width per row at :data:`LEVEL`."""
    return {
        r.key: r.procedure / r.procedure_predicted
        for r in report.rows
        if abs(r.level_percent - LEVEL) < 1e-9
    }


def _disagree(report: Any) -> dict[str, float]:
    return {k: round(v, 2) for k, v in _ratios(report).items() if not 1 / AGREE <= v <= AGREE}


def _failed_share(report: Any) -> float:
    return (report.n_trials - report.n_ok) / report.n_trials


def _cases(xfail_nominal: str | None) -> list[Any]:
    """``(procedure, fmt)`` for both procedures and programs; the nominal (FANUC) ones marked
    xfail with ``xfail_nominal`` as the reason when given."""
    out = []
    for procedure in ("three_two_one", "best_fit"):
        for fmt in ("rapid", "fanuc"):
            marks = []
            if fmt == "fanuc" and xfail_nominal is not None:
                marks = [pytest.mark.xfail(strict=True, reason=xfail_nominal)]
            out.append(pytest.param(procedure, fmt, marks=marks, id=f"{procedure}-{fmt}"))
    return out


# --------------------------------------------------------------------------- the part
@pytest.mark.slow
def test_the_bracket_is_a_closed_l_of_the_stated_size(plans: dict[str, Plan]) -> None:
    mesh = bracket_mesh()
    assert mesh.is_watertight and mesh.is_volume
    assert mesh.bounds.ravel().tolist() == pytest.approx([0, 0, 0, 0.2, 0.1, 0.165], abs=1e-9)
    plan = plans["three_two_one"]
    assert plan.work_object.units == "m" and plan.work_object.sha256
    assert plan.validation.sensor.KIND == "proximity"
    assert plan.validation.sensor.face_diameter_m == pytest.approx(0.018)
    assert plan.validation.misplacement.max_translation_m == pytest.approx(0.020)
    assert [p.role for p in plan.points].count("primary") == 3
    assert len(plans["best_fit"].points) == 9


def test_the_planar_face_check_refuses_15_mm_end_strips_for_an_18_mm_sensor() -> None:
    """With 15 mm walls no 18 mm disk fits on an end face (17.6 mm in the L's corner): the
    refusal is right, and says why, however the STL is triangulated."""
    from planner.faces.checks import plan_face_reasons

    point = ProbePoint("T1", (0.0, 0.0925, 0.1), (-1.0, 0.0, 0.0), SearchSpec("approach"))
    for mesh in (bracket_mesh(0.015), bracket_mesh(0.015).subdivide_to_size(0.02)):
        (why,) = plan_face_reasons(
            mesh, [point], name="bracket", footprint_radius_m=SENSOR.footprint_radius_m
        )
        assert why is not None and why.kind == "footprint"
        assert "too narrow for the 18 mm sensor" in why.text


def test_a_20_mm_end_strip_holds_the_18_mm_sensor_however_the_stl_is_meshed() -> None:
    from planner.faces.checks import plan_face_reasons

    point = ProbePoint("T1", (0.0, 0.09, 0.1), (-1.0, 0.0, 0.0), SearchSpec("approach"))
    fine = bracket_mesh().subdivide_to_size(0.02)
    assert plan_face_reasons(fine, [point], footprint_radius_m=SENSOR.footprint_radius_m) == [None]
    coarse = bracket_mesh()  # the fewest triangles: what a CAD export without a chord limit gives
    assert plan_face_reasons(coarse, [point], footprint_radius_m=SENSOR.footprint_radius_m) == [
        None
    ]


# --------------------------------------------------------------------------- check
def _trouble(report: Any) -> set[str]:
    """The points whose searches failed or landed off their face in the validation."""
    bad = {o.point_id.split("@")[0] for o in report.outcomes if o.failed or o.landed_off}
    return {k.split("@")[0].split(":")[0] for k in report.failures} | bad


@pytest.mark.slow
@pytest.mark.parametrize(("procedure", "fmt"), _cases(None))
def test_check_and_the_validation_give_one_verdict(runs: _Runs, procedure: str, fmt: str) -> None:
    """Check rates the plan feasible for the program and its validation then agrees with the
    prediction and rarely fails; or check names the points, and those are the points whose
    searches fail or land off their face in the validation of the same program."""
    check = runs.check(procedure, fmt)
    report = runs.validate(procedure, fmt)
    assert check.quality is not None and check.quality.program.startswith(PROGRAM[fmt])
    assert report.program.startswith(check.quality.program)
    if check.feasible:
        assert _disagree(report) == {}, f"{report.program}: {_ratios(report)}"
        assert _failed_share(report) <= FAIL_SHARE, report.failures
        return
    named = {p.point_id for p in check.points if not p.feasible}
    assert named <= _trouble(report), (named, report.failures, report.landings)
    for p in check.points:
        if not p.feasible:
            assert "in the" not in p.search_reason or "%" in p.search_reason
            assert any(w in p.search_reason for w in ("move the point", "misplacement bound"))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("procedure", "points"), [("three_two_one", {"T1"}), ("best_fit", {"E1", "E2", "E3"})]
)
def test_check_refuses_the_nominal_program_naming_the_point_and_what_to_change(
    runs: _Runs, procedure: str, points: set[str]
) -> None:
    check = runs.check(procedure, "fanuc")
    bad = {p.point_id: p.reason for p in check.points if not p.feasible}
    assert points <= set(bad), bad
    for pid in points:
        why = bad[pid]
        assert "TP, nominal" in why and "lands off its face" in why, why
        assert "adaptive program" in why and "misplacement bound" in why, why


@pytest.mark.slow
@pytest.mark.parametrize(
    ("procedure", "points"), [("three_two_one", {"P1", "P2"}), ("best_fit", {"T1", "T2"})]
)
def test_check_sees_the_sensor_run_into_the_upright(
    runs: _Runs, procedure: str, points: set[str]
) -> None:
    """The top points 25 mm in front of the 145 mm upright: with the part up to 20 mm towards
    them the sensor's face starts inside the upright or meets it on the way down. The ray
    bundle of the landing risk sees it, names them, and they are the validation's failures."""
    check = runs.check(procedure, "rapid")
    bad = {p.point_id: p.search_reason for p in check.points if not p.feasible}
    assert set(bad) == points, bad
    assert all("another surface" in why for why in bad.values()), bad
    failed = {k.split(":")[0] for k in runs.validate(procedure, "rapid").failures}
    assert failed <= points and failed, failed


# --------------------------------------------------------------------------- validate
@pytest.mark.slow
@pytest.mark.parametrize(
    ("procedure", "fmt"),
    _cases(
        TP_NOMINAL + ": origin_x simulated 11-15x its prediction (the prediction leaves out "
        "where a misplaced part puts a search), and the rows it drives with it"
    ),
)
def test_validation_agrees_with_the_prediction_on_every_row(
    runs: _Runs, procedure: str, fmt: str
) -> None:
    report = runs.validate(procedure, fmt)
    assert report.program.startswith(runs.check(procedure, fmt).quality.program)
    assert _disagree(report) == {}, f"{report.program}: {_ratios(report)}"


# --------------------------------------------------------------------------- suggest
@pytest.mark.slow
@pytest.mark.parametrize(("procedure", "fmt"), _cases(None))
def test_suggest_gives_a_layout_that_validates_or_says_what_stops_it(
    runs: _Runs, procedure: str, fmt: str
) -> None:
    from planner.suggest import SuggestError

    res = runs.suggest(procedure, fmt)
    if isinstance(res, SuggestError):
        msg = str(res)
        assert "misplacement, 20.0 mm and 3.00 deg" in msg, msg
        assert "normal -x" in msg and "footprint off the face" in msg, msg  # the end faces
        if fmt == "fanuc":
            assert "nominal frame" in msg, msg
            if procedure == "three_two_one":  # RAPID's adaptive 3-2-1 has one (the test above)
                assert "An adaptive program has a layout at this bound: --format rapid" in msg, msg
        # and what would make a layout exist: the bound at which one does, or that none does
        assert (
            "the footprints fit a layout at a misplacement bound of" in msg
            or "no layout exists" in msg
        )
        return
    from planner.check.job import check_plan

    check = check_plan(res.plan, runs.folder, fmt=fmt)
    assert check.feasible, [(p.point_id, p.reason) for p in check.points if not p.feasible]
    report = runs.validate_plan(res.plan, fmt)
    assert _disagree(report) == {}, f"{report.program}: {_ratios(report)}"
    assert _failed_share(report) <= FAIL_SHARE, report.failures
    if not res.met:  # the best it can do, and what would do better
        assert "not reached" in res.message and "misplacement" in res.message, res.message


@pytest.mark.slow
def test_suggest_finds_a_best_fit_for_the_adaptive_program(runs: _Runs) -> None:
    """A best-fit layout exists (the 3-2-1 suggestion's points run as a best fit), so suggest
    gives one. Its designs chosen for information alone hold no point that can be measured
    first under the whole 20 mm / 3 deg (each lies near an edge of its face): it grows a
    design in measuring order instead of banning those points and their faces' candidates
    (``test_suggest_gives_a_layout_that_validates_or_says_what_stops_it`` checks and validates
    it)."""
    from planner.check.job import check_plan

    three = runs.suggest("three_two_one", "rapid")
    as_fit = msgspec.structs.replace(
        three.plan,
        procedure=BestFit(),
        points=[msgspec.structs.replace(p, role="fit") for p in three.plan.points],
    )
    assert check_plan(as_fit, runs.folder, fmt="rapid").feasible  # a best-fit layout exists
    res = runs.suggest("best_fit", "rapid")
    assert not isinstance(res, Exception), str(res)
