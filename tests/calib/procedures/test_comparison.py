"""The best fit fed as the procedure is fed (calib.procedures.comparison)."""

from __future__ import annotations

import numpy as np
import pytest

from calib.estimators.layout import constraint_set, search_constraint_set
from calib.frames import make_transform, matrix_from_rotvec, motion_between, transform_points
from calib.paper.stator_layout import example_stator_points
from calib.plane_probe import PlaneProbe
from calib.probing import SearchCommand
from calib.procedures import BEST_FIT, HULTMAN2013, ITERATIVE, RolePoint
from calib.procedures.base import ProcedureRun
from calib.procedures.comparison import FedFit, last_measurements
from tests.box_part import BoxProbe

T_NOM = make_transform(None, [1.0, 0.2, 0.5])
T_TRUE = T_NOM @ make_transform(matrix_from_rotvec([0.01, -0.02, 0.015]), [0.004, -0.006, 0.003])
AH = example_stator_points()


def test_retakes_replace_the_first_measurements() -> None:
    run = ProcedureRun(
        np.eye(4), ("C",), {"C": np.zeros(3), "C#2": np.ones(3), "D": np.full(3, 2.0)}
    )
    last = last_measurements(run, ["C", "D", "E"])
    assert set(last) == {"C", "D"} and np.all(last["C"] == 1.0) and np.all(last["D"] == 2.0)


def test_an_edge_search_counts_by_its_edge_coordinate_only() -> None:
    pts = list(AH.values())
    both, edge_only = constraint_set(pts), search_constraint_set(pts)
    assert both.n_constraints == 10 and edge_only.n_constraints == 8
    f = [i for i, pid in enumerate(edge_only.constraint_ids) if pid == "F"]
    np.testing.assert_allclose(edge_only.normals[f], [[0.0, 0.0, 1.0]])


def test_fed_fit_of_the_a_h_run_finds_the_part() -> None:
    """On an ideal box the fit of A-H's own measurements (retakes last, F and H by z only)
    finds the true frame, and moving F's recorded point across the face changes nothing."""
    pts = [RolePoint(r, p) for r, p in AH.items()]
    run = HULTMAN2013.run(pts, T_NOM, BoxProbe(T_TRUE), None)
    fed = FedFit(list(AH.values()))
    assert np.abs(motion_between(T_TRUE, fed(run).T_base_wobj)).max() < 1e-9
    moved = dict(run.measured_m)
    moved["F"] = moved["F"] + T_TRUE[:3, 0] * 0.003  # 3 mm off the side face: unmeasured
    again = fed(ProcedureRun(run.T_base_wobj, run.used_ids, moved))
    assert np.abs(motion_between(T_TRUE, again.T_base_wobj)).max() < 1e-9
    # ... while C's first measurement moved changes nothing either: C2 is used
    moved = dict(run.measured_m)
    moved["C"] = moved["C"] + T_TRUE[:3, 1] * 0.002
    again = fed(ProcedureRun(run.T_base_wobj, run.used_ids, moved))
    assert np.abs(motion_between(T_TRUE, again.T_base_wobj)).max() < 1e-9


def test_edge_offset_is_removed_along_the_search() -> None:
    pts = [RolePoint(r, p) for r, p in AH.items()]
    run = HULTMAN2013.run(pts, T_NOM, BoxProbe(T_TRUE), None)
    shifted = dict(run.measured_m)
    for k in ("F", "H"):
        shifted[k] = shifted[k] + 0.006 * T_TRUE[:3, 2]  # reported 6 mm past the edge
    fit = FedFit(list(AH.values()), edge_offset_m=0.006)
    res = fit(ProcedureRun(run.T_base_wobj, run.used_ids, shifted))
    assert np.abs(motion_between(T_TRUE, res.T_base_wobj)).max() < 1e-9


@pytest.mark.parametrize("kind", [BEST_FIT, ITERATIVE])
def test_a_frame_estimated_from_recorded_points_keeps_them_as_measured(kind: object) -> None:
    """A nominal program's frame comes from ``estimate`` on its recorded points. The run keeps
    them as measured, the sensor's edge offset still in the edge searches' events, so the fit
    fed as the procedure removes the offset once: the fit of a best fit is the best fit itself
    (``estimate`` once returned the points corrected, the offset came off twice, and the
    validation's comparison column showed a 7 mm / 1.3 deg bias on a plate with edge searches).
    """
    offset = 0.006
    pts = list(AH.values())
    probe = PlaneProbe(T_TRUE, edge_offset_m=offset)
    measured = {
        p.id: np.asarray(probe(SearchCommand.from_point(p, T_NOM)).point_m)[None] for p in pts
    }
    settings = kind.settings_type(edge_event_offset_m=offset)  # type: ignore[attr-defined]
    run = kind.estimate(  # type: ignore[attr-defined]
        [RolePoint("fit", p) for p in pts], measured, T_NOM, settings
    )
    assert all(np.array_equal(run.measured_m[p.id], measured[p.id][0]) for p in pts)
    assert np.abs(motion_between(T_TRUE, run.T_base_wobj)).max() < 1e-9
    fed = FedFit(pts, edge_offset_m=offset)(run)
    # the fed fit takes the offset along the final estimate's axes, the procedure along the
    # nominal ones it commanded in: second order, 6 mm x (1 - cos 0.02 rad) = 1.2 um
    assert np.abs(motion_between(run.T_base_wobj, fed.T_base_wobj)).max() < 5e-6


def test_a_layout_fixed_only_by_track_heights_is_refused_saying_why() -> None:
    """A, B, C with F and H: five degrees of freedom once F's and H's heights over the side
    face (their commanded tracks) do not count; the refusal names the free turn and says why
    the edge searches do not fix it."""
    from calib.errors import UnobservableError
    from calib.procedures import BestFit

    pts = [p for k, p in AH.items() if k in "ABCFH"]
    measured = {p.id: transform_points(T_NOM, p.position_m)[None] for p in pts}
    with pytest.raises(UnobservableError, match="rotation about") as err:
        BEST_FIT.estimate([RolePoint("fit", p) for p in pts], measured, T_NOM, BestFit())
    assert "an edge search counts by its edge coordinate only" in str(err.value)
