"""The feasibility of one probe point as the UI shows it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

Status = Literal["feasible", "marginal", "infeasible", "pending"]


@dataclass(frozen=True)
class PointCheck:
    """Result of checking one probe point and its search path in the cell.

    Attributes:
        point_id: id of the point.
        status: ``feasible``, ``marginal`` (reachable with little clearance or near a limit),
            ``infeasible``; ``pending`` while being computed.
        reason: why the point is marginal or infeasible (empty when feasible).
        q: ``(n,)`` joint values at the probe pose, radians, or ``None`` when unreachable.
        q_path: ``(M, n)`` joint values along the search path, radians, or ``None``.
        clearance_m: smallest distance to an obstacle at the probe pose, metres (``nan``: unknown).
        elapsed_s: time the check took, seconds.
    """

    point_id: str
    status: Status
    reason: str = ""
    q: NDArray[np.float64] | None = None
    q_path: NDArray[np.float64] | None = None
    clearance_m: float = float("nan")
    elapsed_s: float = 0.0

    @property
    def text(self) -> str:
        """One line for the panel, e.g. ``"C: infeasible - joint 5 at limit"``."""
        tail = f" - {self.reason}" if self.reason else ""
        clear = (
            f" (clearance {self.clearance_m * 1000:.0f} mm)"
            if np.isfinite(self.clearance_m) and self.status != "infeasible"
            else ""
        )
        return f"{self.point_id}: {self.status}{clear}{tail}"
