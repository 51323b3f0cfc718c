"""Procedure settings of a plan (``"procedure": {"method": ...}``) and the point roles each needs.

``method`` is the tag of a msgspec tagged union:

- ``hultman2013``: the paper's A-H procedure for the stator section (section 3.2). Every role
  ``A`` ... ``H`` is used exactly once.
- ``three_two_one``: general 3-2-1 alignment: exactly 3 ``primary`` points on one face, 2
  ``secondary`` on a second, 1 ``tertiary`` on a third.
- ``best_fit``: least-squares point-to-plane fit of all ``fit`` points (at least 3; together
  they must constrain all 6 degrees of freedom: an edge point constrains two faces).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence

import msgspec

HULTMAN_ROLES = ("A", "B", "C", "D", "E", "F", "G", "H")
THREE_TWO_ONE_ROLES = {"primary": 3, "secondary": 2, "tertiary": 1}
BEST_FIT_ROLE = "fit"
BEST_FIT_MIN_POINTS = 3


class Hultman2013(
    msgspec.Struct,
    tag="hultman2013",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """Settings of the paper's A-H procedure.

    Attributes:
        p3_height_m: height of the constructed point P3 above B (eq. 12), metres (paper: 50 mm).
        beta1_rad: assumed inclination of the stator side (eq. 12), radians (paper: 15 deg).
        retake_c_d: measure C and D again at the end, as the paper does.
        edge_start_from_measured: start the edge searches F and H at the measured E and G
            (the paper's literal wording) instead of where the plan's search starts.
        edge_start_offset_m: offset of that start along the estimated WOCS +x, metres.
        edge_event_offset_m: how far past the true edge the sensor reports it (measured once
            on a reference edge), metres, removed from F and H; ``None``: the sensor model's
            value in ``validate``, 0 in ``calibrate``.
    """

    p3_height_m: float = 0.050
    beta1_rad: float = math.radians(15.0)
    retake_c_d: bool = True
    edge_start_from_measured: bool = False
    edge_start_offset_m: float = 0.0
    edge_event_offset_m: float | None = None


class ThreeTwoOne(
    msgspec.Struct,
    tag="three_two_one",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """3-2-1 alignment: primary, secondary and tertiary faces (no settings)."""


class BestFit(
    msgspec.Struct,
    tag="best_fit",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """Least-squares point-to-plane fit.

    Attributes:
        max_iterations: largest number of Gauss-Newton iterations.
        tol: stop when the step is smaller than this (metres, and radians times the layout
            size).
    """

    max_iterations: int = 30
    tol: float = 1e-13


Procedure = Hultman2013 | ThreeTwoOne | BestFit
METHODS = ("hultman2013", "three_two_one", "best_fit")


def method_of(procedure: Procedure) -> str:
    """The ``method`` tag of a procedure struct."""
    return str(type(procedure).__struct_config__.tag)


def check_roles(procedure: Procedure, roles: Sequence[str], complete: bool = True) -> str:
    """Return an error message (``""`` when fine) about the point roles for ``procedure``.

    Args:
        procedure: the procedure settings.
        roles: the role of each point, in plan order.
        complete: also require the numbers of points the procedure needs (a plan being edited
            may be incomplete; running the procedure needs a complete one).
    """
    method = method_of(procedure)
    if method == "hultman2013":
        allowed: tuple[str, ...] = HULTMAN_ROLES
    elif method == "three_two_one":
        allowed = tuple(THREE_TWO_ONE_ROLES)
    else:
        allowed = (BEST_FIT_ROLE,)
    for i, role in enumerate(roles):
        if role not in allowed:
            return f"points[{i}].role: must be one of {list(allowed)} for {method}, got {role!r}"
    counts = Counter(roles)
    if not complete:
        if method == "hultman2013":
            twice = sorted(r for r in HULTMAN_ROLES if counts[r] > 1)
            if twice:
                return f"points: hultman2013 uses each role once; used more than once: {twice}"
        return ""
    if method == "hultman2013":
        bad = [r for r in HULTMAN_ROLES if counts[r] != 1]
        if bad:
            return f"points: hultman2013 needs each role A-H exactly once; wrong count of {bad}"
    elif method == "three_two_one":
        for role, need in THREE_TWO_ONE_ROLES.items():
            if counts[role] != need:
                return f"points: three_two_one needs {need} {role!r} points, got {counts[role]}"
    elif counts[BEST_FIT_ROLE] < BEST_FIT_MIN_POINTS:
        return f"points: best_fit needs at least {BEST_FIT_MIN_POINTS} points, got {len(roles)}"
    return ""
