"""``wobjcal suggest --objective time`` and ``--front``: the order of least move time (exact
against brute force, valid for landing), the front's Pareto marks, and on the demo stator the
fastest plan written is the one check, export and the front's table all time the same."""

from __future__ import annotations

import csv
import itertools
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from calib.plan.file import load_plan
from planner.cli.main import main
from planner.suggest.front import FrontRow, _mark_pareto, fastest
from planner.suggest.time_order import EXACT_MAX, path_cost, shortest_order, valid

ASSETS = Path(__file__).resolve().parents[3] / "assets" / "plans"
STATOR = ASSETS / "stator_section_ah.json"


def _prerequisites(rng: np.random.Generator, n: int) -> list[frozenset[int]]:
    """A landing rule like the footprints': point ``i`` fits once all of ``need[i]`` came
    before it (a monotone, set-based predicate), drawn along a random order so one exists."""
    perm = [int(i) for i in rng.permutation(n)]
    need = [frozenset[int]() for _ in range(n)]
    for k, i in enumerate(perm):
        m = min(k, int(rng.integers(0, 3)))
        need[i] = (
            frozenset(int(j) for j in rng.choice(perm[:k], size=m, replace=False))
            if m
            else frozenset()
        )
    return need


def _brute(cost: np.ndarray, fits: Callable[[int, frozenset[int]], bool]) -> float | None:
    best = None
    for p in itertools.permutations(range(len(cost))):
        if valid(p, fits):
            c = path_cost(p, cost)
            best = c if best is None or c < best else best
    return best


@pytest.mark.parametrize("seed", range(6))
def test_exact_order_is_the_least_cost_valid_permutation(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 7
    cost = rng.uniform(0.5, 20.0, (n, n))
    need = _prerequisites(rng, n)

    def fits(i: int, earlier: frozenset[int]) -> bool:
        return need[i] <= earlier

    order = shortest_order(cost, fits)
    expected = _brute(cost, fits)
    assert expected is not None
    assert order is not None and sorted(order) == list(range(n))
    assert valid(order, fits)
    assert path_cost(order, cost) == pytest.approx(expected, abs=1e-12)


def test_no_valid_order_is_none() -> None:
    cost = np.ones((3, 3))
    assert shortest_order(cost, lambda i, e: i != 0 and len(e) > 5) is None


def test_large_layouts_keep_landing_and_do_no_worse_than_the_landing_order() -> None:
    rng = np.random.default_rng(11)
    n = EXACT_MAX + 3
    pts = rng.uniform(0, 1, (n, 2))
    cost = np.linalg.norm(pts[:, None] - pts[None], axis=2)
    # 0 first, then anything: a rule the greedy start respects
    need = [frozenset() if i == 0 else frozenset({0}) for i in range(n)]

    def fits(i: int, earlier: frozenset[int]) -> bool:
        return need[i] <= earlier

    landing = tuple(range(n))
    order = shortest_order(cost, fits, fallback=landing)
    assert order is not None and valid(order, fits) and order[0] == 0
    assert path_cost(order, cost) < path_cost(landing, cost)


def test_bad_cost_matrix_is_refused() -> None:
    with pytest.raises(ValueError, match="finite non-negative"):
        shortest_order(np.array([[0.0, -1.0], [1.0, 0.0]]), lambda i, e: True)
    with pytest.raises(ValueError, match="finite non-negative"):
        shortest_order(np.zeros((2, 3)), lambda i, e: True)


def _row(points: int, err: float, t: float, problems: tuple[str, ...] = ()) -> FrontRow:
    return FrontRow(points, "landing", err, t, "ok", problems, err <= 0.2e-3, None, None, None)  # type: ignore[arg-type]


def test_pareto_marks_and_the_fastest_row() -> None:
    rows = [
        _row(6, 0.25e-3, 40.0),  # fastest, misses the target
        _row(7, 0.15e-3, 60.0),  # on the front, meets it
        _row(7, 0.15e-3, 70.0),  # dominated by the one before
        _row(8, 0.10e-3, 90.0),  # on the front
        _row(8, 0.05e-3, 30.0, ("S1: collides",)),  # best in both but check refuses it
    ]
    marked = _mark_pareto(rows)
    assert [r.pareto for r in marked] == [True, True, False, True, False]
    best = fastest(marked)
    assert best is not None and (best.points, best.cycle_s) == (7, 60.0)
    assert fastest([_row(6, 0.3e-3, 10.0)]) is None


@pytest.fixture(scope="module")
def fastest_stator(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, Path]:
    out = tmp_path_factory.mktemp("time")
    argv = ["suggest", str(STATOR), "--target", "0.3", "--objective", "time"]
    argv += ["--max-points", "6", "--front", str(out / "front.png"), "-o", str(out / "fast.json")]
    return main(argv), out


@pytest.mark.slow
def test_the_fastest_plan_is_the_program_check_and_export_time(
    fastest_stator: tuple[int, Path],
) -> None:
    from planner.check.job import check_plan

    code, out = fastest_stator
    assert code == 0
    with (out / "front.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert [(r["points"], r["order"], r["searches"]) for r in rows] == [
        ("6", "landing", "whole"),
        ("6", "time", "whole"),
        ("6", "time", "steered"),  # RAPID runs a best fit adaptively: its searches steered
    ]
    landing, timed, steered = rows
    assert timed["written"] == "yes" and timed["check"] == "passes"
    assert steered["check"] == "passes" and steered["written"] == "no"
    assert float(steered["error_mm"]) == pytest.approx(float(timed["error_mm"]), rel=1e-6)
    # the same points, so the same error; their order alone saves time on the stator
    assert float(timed["error_mm"]) == pytest.approx(float(landing["error_mm"]), rel=1e-6)
    assert float(timed["cycle_time_s"]) < 0.9 * float(landing["cycle_time_s"])
    assert (out / "front.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # a fresh check of the file written times and predicts what the front's row says
    plan = load_plan(out / "fast.json")
    check = check_plan(plan, out)
    assert check.feasible and check.cycle is not None and check.quality is not None
    assert check.cycle.total_s == pytest.approx(float(timed["cycle_time_s"]), abs=1e-3)
    worst = check.quality.worst_poi_m(95.5) * 1e3
    assert worst == pytest.approx(float(timed["error_mm"]), abs=1e-6)
    assert worst <= 0.3
    # and the exported program's header says the same cycle time
    assert (
        main(["export", str(out / "fast.json"), "--format", "rapid", "-o", str(out / "p.mod")]) == 0
    )
    header = (out / "p.mod").read_text()
    m = re.search(r"Estimated cycle time (\d+) s", header)
    assert m is not None and int(m.group(1)) == round(float(timed["cycle_time_s"]))


@pytest.mark.parametrize(
    ("extra", "says"),
    [
        (["--objective", "time"], "needs the target"),
        (["--objective", "time", "--target", "0.3", "--add", "1"], "--add fixes the points"),
        (
            ["--front", "f.png", "--procedure", "three_two_one"],
            "--procedure three_two_one fixes the points",
        ),
    ],
)
def test_objective_refusals(
    extra: list[str], says: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["suggest", str(STATOR), *extra, "-o", str(tmp_path / "o.json")])
    err = capsys.readouterr().err
    assert code == 2
    assert says in err and "Traceback" not in err
    assert not (tmp_path / "o.json").exists()


def test_front_file_type_is_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["suggest", str(STATOR), "--front", "f.txt", "-o", str(tmp_path / "o.json")]) == 2
    assert "a plot file ending in .png, .svg, .pdf" in capsys.readouterr().err


@pytest.mark.slow
def test_rows_are_finite_numbers_or_empty(fastest_stator: tuple[int, Path]) -> None:
    _, out = fastest_stator
    with (out / "front.csv").open() as f:
        for r in csv.DictReader(f):
            for key in ("error_mm", "cycle_time_s"):
                assert r[key] == "" or math.isfinite(float(r[key]))


def test_the_written_plan_is_marked_or_added() -> None:
    """``--front`` with ``--objective accuracy``: the row of the plan written (same points in
    the same order) is marked; a written plan no row has (a redesign) is added, marked."""
    import msgspec

    from planner.suggest.front import with_written

    plan = load_plan(STATOR)
    fewer = msgspec.structs.replace(plan, points=plan.points[:-1])

    def row(p: object, err: float, t: float) -> FrontRow:
        return FrontRow(6, "landing", err, t, "ok", (), True, p, None, None)  # type: ignore[arg-type]

    rows = [row(fewer, 0.2e-3, 50.0), row(plan, 0.1e-3, 60.0)]
    marked = with_written(rows, row(plan, 0.1e-3, 60.0))
    assert [r.written for r in marked] == [False, True] and len(marked) == 2
    other = msgspec.structs.replace(plan, points=list(reversed(plan.points)))
    added = with_written(rows, row(other, 0.05e-3, 55.0))
    assert [r.written for r in added] == [False, False, True]
    assert [r.pareto for r in added] == [True, False, True], "the front redone with it"
