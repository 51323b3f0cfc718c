"""``hultman2013``: the paper's A-H procedure (Hultman & Leijon 2013, section 3.2).

Every role ``A`` ... ``H`` is used exactly once. The equations are in :mod:`calib.paper`; this
module adapts them to the :class:`calib.procedures.base.ProcedureKind` protocol.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import replace
from functools import lru_cache
from types import MappingProxyType
from typing import Literal

import numpy as np

from calib.errors import PlanError
from calib.paper.settings import Hultman2013
from calib.paper.stator_layout import STATOR_POINT_IDS, StatorLayout, check_stator_points
from calib.paper.stator_procedure import probe_from_measurements, run_stator_procedure
from calib.paper.table1 import PAPER_TABLE1
from calib.probing import Probe, ProbePoint
from calib.procedures.base import (
    FloatArray,
    LayoutDesign,
    Measured,
    ProcedureRun,
    RolePoint,
    Steering,
    unknown_role_problem,
)

ROLES = STATOR_POINT_IDS


def points_by_role(points: Sequence[RolePoint]) -> dict[str, ProbePoint]:
    """``{role: point}`` of an A-H layout (each point keeps its plan id).

    Raises:
        PlanError: a role of A-H is missing or used twice, or a point's id is a name the
            procedure gives another point's search (its role, or a retake ``C2``, ``D2``).
    """
    problem = HULTMAN2013.role_problem([rp.role for rp in points], complete=True)
    if problem:
        raise PlanError(f"hultman2013: {problem}")
    taken = {rp.role: (rp.role, f"role {rp.role}") for rp in points}
    taken |= {"C2": ("C", "the retake of C"), "D2": ("D", "the retake of D")}
    for rp in points:
        role, what = taken.get(rp.point.id, (rp.role, ""))
        if role != rp.role:  # (C's id C2 is harmless: both of its names find it)
            raise PlanError(
                f"hultman2013: point {rp.point.id!r} (role {rp.role}): its id is what the "
                f"procedure calls its search of {what}; give it another id (e.g. its role)"
            )
    return {rp.role: rp.point for rp in points}


class Hultman2013Procedure:
    """The A-H procedure as a :class:`~calib.procedures.base.ProcedureKind`."""

    method = "hultman2013"
    settings_type: type = Hultman2013
    roles: tuple[str, ...] = ROLES
    role_limits: Mapping[str, int | None] = MappingProxyType(dict.fromkeys(ROLES, 1))
    label = "A-H"
    summary = "the paper's A-H procedure: 3 points fix the plane, searches fix the origin"
    #: no suggested layout: A-H's points follow the stator's geometry (paper, section 3.2)
    design: LayoutDesign | None = None
    #: adaptive by its own steps (:meth:`adaptive_layout`), not the progressive update
    steering: Steering | None = None
    #: the paper's Table 1, beside a validation of a built-in stator
    published: Mapping[tuple[str, float], float] | None = PAPER_TABLE1
    #: F and H stand on the side face and find its top edge (eq. 10-12)
    edge_rows: Literal["both", "edge"] = "both"

    def role_problem(self, roles: Sequence[str], complete: bool) -> str:
        """See :meth:`ProcedureKind.role_problem`."""
        problem = unknown_role_problem(self.method, roles, ROLES)
        if problem:
            return problem
        counts = Counter(roles)
        if complete:
            bad = [r for r in ROLES if counts[r] != 1]
            if bad:
                return f"points: hultman2013 needs each role A-H exactly once; wrong count of {bad}"
            return ""
        twice = sorted(r for r in ROLES if counts[r] > 1)
        if twice:
            return f"points: hultman2013 uses each role once; used more than once: {twice}"
        return ""

    def assign(self, points: Sequence[RolePoint]) -> list[RolePoint]:
        """The points unchanged: the A-H roles cannot be guessed from geometry.

        Raises:
            PlanError: the points do not hold each role A-H once.
        """
        points_by_role(points)
        return list(points)

    def _keyed(self, points: Sequence[RolePoint]) -> tuple[StatorLayout, dict[str, str]]:
        by_role = points_by_role(points)
        ids = {role: p.id for role, p in by_role.items()}
        try:
            return _layout(tuple(by_role.items())), ids
        except TypeError:  # a point holding a list is not hashable: validate it uncached
            return check_stator_points(by_role), ids

    def run(
        self,
        points: Sequence[RolePoint],
        T_base_wobj_nominal: FloatArray,
        probe: Probe,
        settings: object,
    ) -> ProcedureRun:
        """Run A-H step by step (:func:`calib.paper.stator_procedure.run_stator_procedure`)."""
        layout, ids = self._keyed(points)
        return _plan_keyed(
            run_stator_procedure(layout, T_base_wobj_nominal, probe, _settings(settings)), ids
        )

    def estimate(
        self,
        points: Sequence[RolePoint],
        measured: Measured,
        T_base_wobj_nominal: FloatArray,
        settings: object,
    ) -> ProcedureRun:
        """Replay A-H on recorded points: the retakes of C and D (their second measurement,
        else the first) feed ``C2`` and ``D2``.

        Raises:
            ProbeFailedError: the replay needs a point that was not measured.
        """
        layout, ids = self._keyed(points)
        table: dict[str, FloatArray] = {}
        for role, pid in ids.items():
            if pid in measured:
                seq = np.asarray(measured[pid], dtype=float).reshape(-1, 3)
                table[role] = seq[0]
                if role in ("C", "D"):
                    table[f"{role}2"] = seq[1] if len(seq) > 1 else seq[0]
            else:
                measured[pid]  # raises naming the point (and why it failed on the robot)
        res = run_stator_procedure(
            layout, T_base_wobj_nominal, probe_from_measurements(table), _settings(settings)
        )
        return _plan_keyed(res, ids)

    def adaptive_layout(self, points: Sequence[RolePoint]) -> StatorLayout | None:
        """The A-H layout (programs run A-H adaptively); ``None`` when a role is missing."""
        if self.role_problem([rp.role for rp in points], complete=True):
            return None
        return check_stator_points(points_by_role(points))


@lru_cache(maxsize=16)
def _layout(by_role: tuple[tuple[str, ProbePoint], ...]) -> StatorLayout:
    """The validated A-H layout of ``by_role``, cached: the linearisation of one plan runs the
    procedure on the same points once per search and sign (:mod:`calib.procedures.linearize`),
    and validating them is about a tenth of a run. Keyed by value (frozen points), so a moved
    point is a new key."""
    return check_stator_points(dict(by_role))


def _settings(settings: object) -> Hultman2013:
    if settings is None:
        return Hultman2013()
    if not isinstance(settings, Hultman2013):
        raise PlanError(f"hultman2013 needs Hultman2013 settings, got {type(settings).__name__}")
    return settings


def _plan_keyed(run: ProcedureRun, ids: dict[str, str]) -> ProcedureRun:
    """``run`` of :func:`run_stator_procedure` with its measurements keyed as a plan's
    (``"C2"`` -> ``"<id>#2"``); the commands keep the keys they were sent under."""
    return replace(run, measured_m={_key(k, ids): v for k, v in run.measured_m.items()})


def _key(key: str, ids: dict[str, str]) -> str:
    """Measurement key of the procedure (``"C"``, ``"C2"``) -> plan key (``id``, ``id#2``)."""
    return f"{ids[key[0]]}#2" if key.endswith("2") else ids[key]


HULTMAN2013 = Hultman2013Procedure()
