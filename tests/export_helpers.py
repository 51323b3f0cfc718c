"""Helpers shared by the exporter tests: what a plan says the programs must contain."""

from __future__ import annotations

import numpy as np

from calib.plan.file import Plan


def expected_ends_wobj(plan: Plan) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Start and end TCP positions (m, wobj frame) computed from the plan's fields."""
    out = {}
    for p in plan.points:
        pos, n, s = np.array(p.position_m), np.array(p.normal), p.search
        if s.kind == "approach":
            out[p.id] = (pos + s.start_offset_m * n, pos - s.overtravel_m * n)
        else:
            d = np.array(s.edge_direction)
            out[p.id] = (pos - s.start_offset_m * d, pos + s.overtravel_m * d)
    return out
