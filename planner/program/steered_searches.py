"""Searches sized for an adaptive program: later searches start nearer and run shorter.

An adaptive best-fit or 3-2-1 program commands each search after its first update in the frame
estimated from the points measured before it (:mod:`planner.program.steering`). That estimate
has already taken out most of the part's misplacement, so the face such a search runs to lies
much nearer its nominal height than the whole misplacement allows: to first order it is off by
``g_t @ t + g_w @ w`` (:func:`calib.estimators.steering.normal_shift_maps`, the part of the
misplacement ``(t, w)`` the earlier points leave), at most ``a |g_t| + b |g_w|`` for a
misplacement within ``|t| <= a``, ``|w| <= b``.

A plan with ``search_sizing: "steered"`` sizes those searches (their safe start and the end the
check holds them to) for :func:`steered_bounds`:

    bound = SAFETY * (a |g_t| + b |g_w|) + NOISE_SIGMAS * sigma + second order + FLOOR_M

- ``sigma``: the errors of the earlier searches through the estimate, and the search's own
  (sensor and robot repeatability, the TCP's calibration, the robot's absolute accuracy taken
  as noise);
- the second order of the misplacement the linear model leaves out: the face's tilt times how
  far the search lands from its nominal spot, ``b (a + b r)``, and the rotation's own,
  ``b^2 r / 2``, with ``r`` the point's distance from the misplacement's pivot.

A point measured before the first update keeps the whole misplacement's bound, and no bound is
ever larger than that one (:meth:`planner.program.safety.SafetySpec.surface_shift_bound_m`).
The bound is a first-order model with margins, not a proof: ``wobjcal validate`` runs the same
program against simulated parts misplaced anywhere within the tolerance, searches included, and
is the judge.

Only a program that commands the search in the estimate may run it; a program that runs every
search in the nominal frame (FANUC TP, an edge search in the layout, a plan without the roles
the update needs) refuses the plan, naming this field (:func:`planner.program.build.
build_program`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from calib.errors import InputError
from calib.estimators.steering import normal_noise_var, normal_shift_bound, normal_shift_maps
from calib.plan.file import Plan
from calib.probing import ProbePoint
from calib.procedures import procedure_kind
from planner.program.safety import SafetySpec
from planner.program.steering import STEERED_METHODS, layout_pivot_scale, update_groups

#: Factor on the first-order shift the estimate leaves (the linear model's error).
SAFETY = 1.5
#: Sigmas of the shift the searches' errors leave (the earlier ones' and the search's own).
NOISE_SIGMAS = 4.0
#: Added to every bound, metres: what neither the model nor its second order covers.
FLOOR_M = 0.25e-3


def steered_bounds(
    ordered: Sequence[ProbePoint],
    method: str,
    max_translation_m: float,
    max_angle_rad: float,
    pivot_m: Sequence[float],
    var_m2: float,
) -> dict[str, float]:
    """``{point id: bound}``, metres: for each search the program of ``method`` commands in an
    estimate, the largest shift of its face along its normal in that estimate (module
    docstring); the points measured before the first update are left out.

    Args:
        ordered: the approach points in the order the program measures them, wobj frame.
        method: ``"best_fit"`` or ``"three_two_one"`` (which updates the program makes,
            :func:`planner.program.steering.update_groups`).
        max_translation_m: the misplacement's largest translation, m.
        max_angle_rad: its largest rotation, rad.
        pivot_m: ``(3,)`` the misplacement's pivot, wobj frame, m.
        var_m2: the variance of one search's error, m^2.
    """
    ids = [p.id for p in ordered]
    groups = update_groups(method, ids)
    if not groups:
        return {}
    c, scale = layout_pivot_scale(list(ordered))
    P = np.array([p.position_m for p in ordered], dtype=np.float64)
    N = np.array([p.normal for p in ordered], dtype=np.float64)
    m = np.asarray(pivot_m, dtype=np.float64).reshape(3)
    a, b = float(max_translation_m), float(max_angle_rad)
    out: dict[str, float] = {}
    for k, p in enumerate(ordered):
        done = max((len(g) for g in groups if len(g) <= k), default=0)
        if done == 0:
            continue  # commanded in the nominal frame: the whole misplacement
        X, Nx = P[:done], N[:done]
        g_t, g_w = normal_shift_maps(P[k], N[k], X, Nx, c, scale, m)
        first = normal_shift_bound(g_t, g_w, a, b)
        var = normal_noise_var(P[k], N[k], X, Nx, c, scale, np.full(done, var_m2)) + var_m2
        r = float(np.linalg.norm(P[k] - m))
        second = b * (a + b * r) + 0.5 * b * b * r
        out[p.id] = SAFETY * first + NOISE_SIGMAS * math.sqrt(var) + second + FLOOR_M
    return out


def search_variance_m2(plan: Plan) -> float:
    """The variance of one approach search's error in ``plan``'s models, m^2: the sensor's, the
    robot's repeatability, the TCP calibration and the absolute accuracy field (per axis)."""
    v = plan.validation
    sensor = v.sensor.search_noise("approach", 0.003).sensor_sigma_m
    r = v.robot_error
    return float(
        sensor**2 + r.repeatability_sigma_m**2 + r.tcp_sigma_m**2 + r.accuracy_amplitude_m**2
    )


def steered_safety(plan: Plan, whole: SafetySpec) -> SafetySpec:
    """``whole`` (the misplacement's safety of ``plan``) with the steered bounds of the program
    ``plan``'s procedure runs adaptively (module docstring); ``steered`` set and no bound when
    its procedure or layout cannot be steered (the programs then refuse the plan)."""
    steered = dataclasses.replace(whole, steered=True)
    kind = procedure_kind(plan.procedure)
    if kind.method not in STEERED_METHODS or any(p.search.kind != "approach" for p in plan.points):
        return steered
    try:
        ordered = [rp.point for rp in kind.assign(plan.role_points())]
        bounds = steered_bounds(
            ordered,
            kind.method,
            whole.max_translation_m,
            whole.max_angle_rad,
            whole.pivot_wobj_m,
            search_variance_m2(plan),
        )
    except InputError:  # no adaptive program (a role missing, a degenerate layout): the
        return steered  # programs refuse the plan, naming search_sizing
    by_id = {p.id: p for p in plan.points}
    nearer = {  # only the searches the bound really shortens start nearer
        pid: b
        for pid, b in bounds.items()
        if b < whole.surface_shift_bound_m(by_id[pid].position_m)
    }
    return dataclasses.replace(
        steered, steered_bounds_m=tuple((pid, nearer[pid]) for pid in sorted(nearer))
    )
