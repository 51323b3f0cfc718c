"""What a procedure run gives back: the one result type of every procedure, step runner and
program execution.

A run (the paper's A-H procedure, a 3-2-1 or best fit driven by a probe, a procedure's
``estimate`` from recorded measurements, a measuring program executed against any probe) ends
in one :class:`ProcedureRun`: the frame, the points it came from and every measurement by key;
a run driven by a probe also keeps each search as commanded and measured (:class:`ProbeStep`),
each update of the estimate (:class:`EstimateUpdate`) and its last fit.

Measurement keys: ``"<id>"`` for a point's first measurement, ``"<id>#<k>"`` for its k-th
(:func:`measured_by_key`). The paper's A-H procedure
(:func:`calib.paper.stator_procedure.run_stator_procedure`) keys by its own measurement keys,
``"A"`` ... ``"H"`` and the retakes ``"C2"``, ``"D2"`` (the keys its robot programs use);
:class:`calib.procedures.hultman2013.Hultman2013Procedure` turns them into plan keys.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.probing import SearchCommand

if TYPE_CHECKING:
    from calib.estimators.best_fit import BestFitResult
    from calib.estimators.three_two_one import ThreeTwoOneResult

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ProbeStep:
    """One search of a run: as commanded, and what it measured.

    Attributes:
        point_id: id of the probe point searched for.
        round: the pass over the layout it belongs to (0-based; a retake of a point is its
            next pass).
        command: the search as commanded, built from the estimate at that moment, base frame
            (its ``point_id`` is the key the procedure sent it under, e.g. ``"C2"``).
        measured_m: ``(3,)`` the measured point, robot base frame, metres.
    """

    point_id: str
    round: int
    command: SearchCommand
    measured_m: FloatArray


@dataclass(frozen=True)
class EstimateUpdate:
    """One update of the estimate of the work-object frame during a run.

    Attributes:
        T_base_wobj: ``(4, 4)`` the estimate after the update, base frame, metres.
        name: what the update does, e.g. ``"x origin from B (P4)"``, ``"best fit"``.
        point_ids: the measurement keys it used, e.g. ``("A", "B")``.
        equations: the paper's equations applied (A-H), e.g. ``"eq. 10"``; ``""`` otherwise.
    """

    T_base_wobj: FloatArray
    name: str = ""
    point_ids: tuple[str, ...] = ()
    equations: str = ""


@dataclass(frozen=True)
class ProcedureRun:
    """The frame a procedure computed, from which points, and how.

    Attributes:
        T_base_wobj: ``(4, 4)`` the calibrated work object in the robot base frame, metres.
        used_ids: the point ids the frame was computed from, in procedure order.
        measured_m: ``{key: (3,)}`` every measurement the procedure took or used, as
            measured (an edge search's event with the sensor's edge offset still in it: the
            procedure removes it when it fits), base frame, metres, by measurement key (see the
            module docstring).
        probes: every search in the order run (empty for a frame estimated from recorded
            measurements).
        updates: the estimate after each update, in order (the last is ``T_base_wobj``; the
            start estimate is not one); empty when not recorded.
        fit: the run's last fit (its residuals and, for a best fit, covariance); ``None`` for
            a procedure that fits no such model (A-H) or a run that did not keep it.
        constructed_m: ``{name: (3,)}`` points the procedure constructed rather than measured,
            base frame, metres (A-H: ``"P3"`` of eq. 12).
    """

    T_base_wobj: FloatArray
    used_ids: tuple[str, ...]
    measured_m: Mapping[str, FloatArray] = field(default_factory=dict)
    probes: tuple[ProbeStep, ...] = ()
    updates: tuple[EstimateUpdate, ...] = ()
    fit: ThreeTwoOneResult | BestFitResult | None = None
    constructed_m: Mapping[str, FloatArray] = field(default_factory=dict)

    @property
    def n_probes(self) -> int:
        """Number of searches run."""
        return len(self.probes)

    @property
    def estimates(self) -> FloatArray:
        """``(K, 4, 4)`` the estimate after each update, in order, base frame, metres."""
        return np.array([u.T_base_wobj for u in self.updates]).reshape(-1, 4, 4)

    @property
    def commands(self) -> dict[str, SearchCommand]:
        """``{key: command}`` each search as commanded, by the key it was sent under."""
        return {s.command.point_id: s.command for s in self.probes}

    @property
    def measured_base(self) -> FloatArray:
        """``(N, 3)`` the last measurement of each of :attr:`used_ids` among the searches run,
        in that order, base frame, metres."""
        last = {s.point_id: s.measured_m for s in self.probes}
        return np.array([last[i] for i in self.used_ids]).reshape(-1, 3)


def measured_by_key(probes: Iterable[ProbeStep]) -> dict[str, FloatArray]:
    """``{key: (3,)}`` the measurements of ``probes`` in order: ``"<id>"`` for a point's first,
    ``"<id>#<k>"`` for its k-th (base frame, metres)."""
    count: dict[str, int] = {}
    out: dict[str, FloatArray] = {}
    for s in probes:
        k = count[s.point_id] = count.get(s.point_id, 0) + 1
        out[s.point_id if k == 1 else f"{s.point_id}#{k}"] = s.measured_m
    return out
