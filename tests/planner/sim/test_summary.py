"""Counting simulated searches and failed trials (``planner.sim.summary``) by their reasons'
kinds, and what ``wobjcal validate --json`` writes of them: the words stay as users read them,
the kind (and a collision's pair) stands beside them, nothing is read back from the words."""

from __future__ import annotations

import numpy as np

from planner.cli.validate import report_json
from planner.reasons import Reason
from planner.sim.report import FailureCount, ValidationReport, report_markdown
from planner.sim.search_events import PARTLY_OFF_FACE, ProbeEvent, SearchFailure
from planner.sim.summary import failure_counts, point_outcomes
from planner.sim.trial import TrialResult

MISSED = Reason("search", "no detection within 50 mm")
HIT = Reason(
    "collision", "unreachable or colliding: at 3.0 mm: link_6 hits clamp", ("link_6", "clamp")
)
LIMIT = Reason("joint_limit", "unreachable or colliding: at 0.0 mm: joint 5 at limit (j5)")


def _trial(failed: SearchFailure | None = None, x: SearchFailure | None = None) -> TrialResult:
    nan6 = np.full(6, np.nan) if failed else np.zeros(6)
    return TrialResult(
        str(failed) if failed else "",
        (),
        (),
        nan6,
        nan6,
        None,
        str(x) if x else "",
        failed,
        x,
    )


def test_point_outcomes_count_failures_by_their_reason() -> None:
    events = [
        ProbeEvent("D", "approach", cause=MISSED),
        ProbeEvent("D", "approach", cause=MISSED),
        ProbeEvent("D", "approach", cause=HIT),
        ProbeEvent("E", "approach", landing=PARTLY_OFF_FACE, off_fraction=0.2),
        ProbeEvent("PX1_3", "approach", cause=LIMIT),
    ]
    (d, e, px) = point_outcomes(["D", "D", "D", "D", "E", "PX1_3"], events)
    assert d.searches == 4 and d.failed == {MISSED: 2, HIT: 1}
    assert e.failed == {} and e.partly_off == 1 and e.off_fraction_max == 0.2
    assert px.point_id == "PX (x-offset run)" and px.failed == {LIMIT: 1}


def test_failure_counts_group_trials_by_search_and_reason() -> None:
    d_missed, d_hit = SearchFailure("D", MISSED), SearchFailure("D", HIT)
    px = SearchFailure("PX1_11", LIMIT)
    trials = [_trial(d_missed), _trial(d_hit), _trial(d_missed), _trial(), _trial(x=px)]
    trials.append(
        TrialResult("procedure: the points define no frame", (), (), np.zeros(6), np.zeros(6))
    )
    counts = failure_counts(trials)
    assert [(f.label, f.run, f.count) for f in counts] == [
        ("D: no detection within 50 mm", "procedure", 2),
        ("D: unreachable or colliding: at 3.0 mm: link_6 hits clamp", "procedure", 1),
        ("procedure: the points define no frame", "procedure", 1),
        (
            "x-offset PX1_11: unreachable or colliding: at 0.0 mm: joint 5 at limit (j5)",
            "x-offset",
            1,
        ),
    ]
    assert [f.failed.cause.kind if f.failed else None for f in counts] == [
        "search",
        "collision",
        None,
        "joint_limit",
    ]
    assert counts[1].failed is not None and counts[1].failed.cause.pair == ("link_6", "clamp")


def _report(**kw: object) -> ValidationReport:
    return ValidationReport(
        n_trials=3,
        n_ok=1,
        rows=(),
        samples_procedure={},
        samples_best_fit={},
        delta_procedure=np.zeros((1, 6)),
        delta_best_fit=np.zeros((1, 6)),
        landings={},
        elapsed_s=0.0,
        workers=1,
        **kw,  # type: ignore[arg-type]
    )


def test_the_json_report_lists_each_failure_with_its_kind_beside_its_words() -> None:
    events = [ProbeEvent("D", "approach", cause=MISSED), ProbeEvent("D", "approach", cause=HIT)]
    trials = [_trial(SearchFailure("D", MISSED)), _trial(SearchFailure("D", HIT))]
    counts = failure_counts(trials)
    report = _report(
        outcomes=point_outcomes(["D", "D", "D"], events),
        failures={f.label: f.count for f in counts},
        failure_counts=counts,
    )
    data = report_json(report)
    (d,) = data["outcomes"]
    assert d["failed"] == {str(MISSED): 1, str(HIT): 1}  # the words, as before
    assert d["failed_reasons"] == [
        {"kind": "search", "text": "no detection within 50 mm", "count": 1},
        {
            "kind": "collision",
            "text": "unreachable or colliding: at 3.0 mm: link_6 hits clamp",
            "pair": ["link_6", "clamp"],
            "count": 1,
        },
    ]
    assert data["failures"] == {f"D: {MISSED}": 1, f"D: {HIT}": 1}
    assert data["failure_reasons"][1] == {
        "label": f"D: {HIT}",
        "run": "procedure",
        "count": 1,
        "search": "D",
        "kind": "collision",
        "text": str(HIT),
        "pair": ["link_6", "clamp"],
    }
    # the markdown's words are those the report always printed
    md = report_markdown(report)
    assert f"| D | 3 | {MISSED}: 1; {HIT}: 1 | 0 | 0 | — |" in md
    assert f"- D: {MISSED}: 1" in md and f"- D: {HIT}: 1" in md


def test_a_procedure_that_got_no_frame_has_no_kind_in_the_json() -> None:
    label = "procedure: the points define no frame"
    report = _report(
        failures={label: 2}, failure_counts=(FailureCount(label, "procedure", None, 2),)
    )
    assert report_json(report)["failure_reasons"] == [
        {
            "label": label,
            "run": "procedure",
            "count": 2,
            "search": None,
            "kind": None,
            "text": label,
        }
    ]


def test_failures_among_the_trials_checked_in_the_cell_are_not_diluted_by_the_others() -> None:
    """helper-55 (D2): 396 of 400 'calibrated' while 4 of the 20 trials checked in the cell had
    failed; the 380 others could not fail on reach or collisions. The report says so, with an
    exact (Clopper-Pearson) interval, scipy's binomtest the reference."""
    from scipy.stats import binomtest

    from planner.sim.report import reach_warning

    report = _report(failures={}, reach_checked=20, reach_failed=4)
    report = ValidationReport(**{**report.__dict__, "n_trials": 400, "n_ok": 396})
    text = reach_warning(report)
    ci = binomtest(4, 20).proportion_ci(0.95, method="exact")
    assert f"AND 4 OF THEM FAILED THERE (20%; 95 % interval {ci.low:.0%} to {ci.high:.0%};" in text
    assert "--reach-trials 400" in text
    assert text in report_markdown(report).splitlines()[1:3]
    data = report_json(report)
    assert (data["reach_checked"], data["reach_failed"], data["reach_warning"]) == (20, 4, text)
    # nothing to say: every trial checked, or none of the checked failed
    for kw in ({"reach_checked": 400, "reach_failed": 4}, {"reach_checked": 20}):
        quiet = ValidationReport(**{**report.__dict__, "reach_failed": 0, **kw})
        assert reach_warning(quiet) == ""
        assert "CHECKED IN THE CELL" not in report_markdown(quiet)


def test_only_failures_the_cell_shows_count_for_the_warning() -> None:
    """A missed search fails checked and unchecked trials alike: it is not what the unchecked
    trials could not show (review of the warning, helper-57)."""
    from planner.sim.summary import _failed_in_cell

    assert _failed_in_cell(_trial(SearchFailure("D", HIT)))
    assert _failed_in_cell(_trial(SearchFailure("D", LIMIT)))
    assert not _failed_in_cell(_trial(SearchFailure("D", MISSED)))
    assert not _failed_in_cell(_trial())
