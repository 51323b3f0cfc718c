"""The procedure registry: every procedure a plan can name, behind one protocol.

Each registered procedure, run step by step with an ideal probe on a misplaced box, recovers
the true frame; estimated again from the measurements it took, it gives the same frame.
"""

from __future__ import annotations

import re
import typing

import numpy as np
import pytest

from calib.errors import PlanError
from calib.frames import make_transform, matrix_from_rotvec, motion_between
from calib.paper.stator_layout import example_stator_points
from calib.procedures import PROCEDURES, ProcedureSettings, RolePoint, procedure_kind
from calib.procedures.three_two_one import pick_roles
from tests.box_part import BoxProbe

T_NOM = make_transform(None, [1.0, 0.2, 0.5])
T_TRUE = T_NOM @ make_transform(matrix_from_rotvec([0.01, -0.02, 0.015]), [0.004, -0.006, 0.003])


def role_points(method: str) -> list[RolePoint]:
    """The A-H points of the box with the roles of ``method``."""
    pts = [RolePoint(pid, p) for pid, p in example_stator_points().items()]
    if method == "hultman2013":
        return pts
    if method == "three_two_one":
        return [RolePoint(role, rp.point) for role, rps in pick_roles(pts).items() for rp in rps]
    return [RolePoint("fit", rp.point) for rp in pts]


def test_registry_matches_the_plan_union() -> None:
    """One registry entry per member of the plan's ``procedure`` union, and back."""
    tags = {t.__struct_config__.tag: t for t in typing.get_args(ProcedureSettings)}
    assert set(tags) == set(PROCEDURES)
    for method, kind in PROCEDURES.items():
        assert kind.method == method and kind.settings_type is tags[method]
        assert kind.roles and kind.summary
    with pytest.raises(
        PlanError,
        match=r"unknown procedure \(procedure.method\) 'iterative_guess'; known: best_fit, "
        r"hultman2013, iterative, three_two_one$",
    ):
        procedure_kind("iterative_guess")


@pytest.mark.parametrize("method", list(PROCEDURES))
def test_run_recovers_the_true_frame_and_estimate_agrees(method: str) -> None:
    kind = PROCEDURES[method]
    pts = role_points(method)
    settings = kind.settings_type()
    run = kind.run(pts, T_NOM, BoxProbe(T_TRUE), settings)
    assert np.abs(motion_between(T_TRUE, run.T_base_wobj)).max() < 1e-9
    measured: dict[str, list[np.ndarray]] = {}
    for key, p in run.measured_m.items():  # "<id>#2" is a second measurement of <id>
        measured.setdefault(key.split("#")[0], []).append(p)
    again = kind.estimate(pts, {k: np.array(v) for k, v in measured.items()}, T_NOM, settings)
    assert np.abs(motion_between(run.T_base_wobj, again.T_base_wobj)).max() < 1e-9
    assert set(again.used_ids) <= {rp.point.id for rp in pts}


@pytest.mark.parametrize("method", list(PROCEDURES))
def test_role_checks_name_the_problem(method: str) -> None:
    kind = PROCEDURES[method]
    assert kind.role_problem([rp.role for rp in role_points(method)], complete=True) == ""
    assert "points[0].role" in kind.role_problem(["no_such_role"], complete=False)


def test_only_hultman_runs_adaptively_in_programs() -> None:
    adaptive = {m for m, k in PROCEDURES.items() if k.adaptive_layout(role_points(m))}
    assert adaptive == {"hultman2013"}


@pytest.mark.parametrize(
    ("renamed", "message"),
    [
        ({"A": "B", "B": "A"}, "point 'B' (role A): its id is what the procedure calls its search"),
        ({"E": "C2"}, "point 'C2' (role E): its id is what the procedure calls its search of the"),
    ],
)
def test_an_ah_point_id_that_names_another_search_is_refused(
    renamed: dict[str, str], message: str
) -> None:
    """A-H commands its searches by role (and C2, D2 for the retakes), and a program finds the
    point by that name: a point whose id is another point's role, or a retake's name, would
    have its searches measured at the wrong point. Refused with one message naming it."""
    import dataclasses

    pts = [
        RolePoint(rp.role, dataclasses.replace(rp.point, id=renamed.get(rp.role, rp.role)))
        for rp in role_points("hultman2013")
    ]
    with pytest.raises(PlanError, match=re.escape(message)):
        PROCEDURES["hultman2013"].assign(pts)
    assert PROCEDURES["hultman2013"].assign(role_points("hultman2013"))  # ids = roles: fine
