"""Whether each search of a program can reach its face or edge wherever the part may lie.

The program starts every approach at its safe start (:mod:`planner.program.safety`: outside
the largest shift of the face plus the sensing distance), so an approach can no longer start
too close; it ends where the plan's search ends, ``overtravel_m`` past the nominal face, which
must be at least the face's largest shift (the part misplaced away). An edge search starts
``start_offset_m`` before the nominal edge and ends ``overtravel_m`` past it: the start must be
at least the shift before it (else it may start past a moved edge) and the end at least the
shift plus the sensor's edge-event offset past it.

:func:`search_problems` names every problem of every point at once; ``wobjcal check`` (so
export too) and the validation's preflight both call it, so they refuse the same plans.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from calib.probing import ProbePoint
from planner.program.safety import SafetySpec
from planner.reasons import Reason


def search_problems(
    points: Sequence[ProbePoint], safety: SafetySpec, edge_offset_m: float = 0.0
) -> dict[str, Reason]:
    """``{point id: why}`` for the points whose search cannot reach its face or edge under
    ``safety``'s misplacement (every problem of a point, joined with ``"; "``), and the fix: a
    ``search`` reason each.

    Args:
        points: the plan's points (wobj frame).
        safety: the misplacement bound and pivot the program's safe starts are sized for.
        edge_offset_m: how far past an edge the sensor reports it, m.
    """
    out: dict[str, Reason] = {}
    whole = (
        f" (misplaced up to {safety.max_translation_m * 1e3:.1f} mm and "
        f"{math.degrees(safety.max_angle_rad):.2f} deg)"
    )
    for p in points:
        shift = safety.surface_shift_bound_m(p.position_m, p.id)
        bound = (
            whole
            if shift >= safety.surface_shift_bound_m(p.position_m)
            else " in the frame the adaptive program estimates from the points before it "
            '(search_sizing "steered")'
        )
        s = p.search
        why = []
        if s.kind == "approach":
            if s.overtravel_m < shift:
                why.append(
                    f"the search ends {s.overtravel_m * 1e3:.1f} mm past the nominal face, but "
                    f"the part may lie up to {shift * 1e3:.1f} mm farther{bound}: overtravel at "
                    f"least {shift * 1e3:.1f} mm, or a smaller misplacement bound"
                )
        else:
            if s.start_offset_m < shift:
                why.append(
                    f"the edge search starts {s.start_offset_m * 1e3:.1f} mm before the nominal "
                    f"edge, but the edge may lie up to {shift * 1e3:.1f} mm closer: start at "
                    f"least {shift * 1e3:.1f} mm before it"
                )
            need = shift + edge_offset_m
            if s.overtravel_m < need:
                why.append(
                    f"the edge search ends {s.overtravel_m * 1e3:.1f} mm past the nominal edge, "
                    f"but the edge may lie up to {shift * 1e3:.1f} mm farther and the sensor "
                    f"reports it {edge_offset_m * 1e3:.1f} mm past it: overtravel at least "
                    f"{need * 1e3:.1f} mm"
                )
        if why:
            out[p.id] = Reason("search", "; ".join(why))
    return out
