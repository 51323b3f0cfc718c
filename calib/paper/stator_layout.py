"""The nominal A-H layout of the paper's stator procedure (section 3.2, Fig. 8a): validation
against what the equations assume, and an example layout.

Stator WOCS (see ``docs/ARCHITECTURE.md``): origin at the top corner of the side face at the
short side, ``+x`` out of the side face, ``+y`` along the section towards the short side,
``+z`` up; the part lies in ``x < 0, y < 0, z < 0``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from calib.errors import DegenerateGeometryError, ShapeError
from calib.probing import ProbePoint, SearchSpec
from calib.tolerances import FACE_MAX_DEVIATION_M, ROLE_NORMAL_TOL_RAD, same_direction

STATOR_POINT_IDS = ("A", "B", "C", "D", "E", "F", "G", "H")
#: Smallest separation of points that must lie in an order (metres): A before B, E below D...
LAYOUT_TOL = 1e-6
#: Points that must share a coordinate (lie on one face, or on one line along an axis) may
#: differ by this much, metres: the planar-face tolerance (:mod:`calib.tolerances`).
SHARE_TOL_M = FACE_MAX_DEVIATION_M

_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class StatorLayout:
    """A validated A-H layout (build it once with :func:`check_stator_points`, reuse it).

    Attributes:
        points: the nominal probe points ``"A"`` ... ``"H"``, wobj frame.
        face_coords_wobj: ``(3,)`` x of the side face, y of the short side, z of the top side
            in the nominal WOCS, metres (all 0 for the paper's WOCS at the corner).
    """

    points: Mapping[str, ProbePoint]
    face_coords_wobj: tuple[float, float, float]


def _same(a: Sequence[float] | None, b: Sequence[float]) -> bool:
    """``a`` is the unit direction ``b`` within :data:`calib.tolerances.ROLE_NORMAL_TOL_RAD`
    (a normal clicked on a mesh triangle is the face normal only to float precision)."""
    if a is None:
        return False
    v = np.asarray(a, dtype=np.float64)
    n = float(np.linalg.norm(v))
    return n > 0 and same_direction(float(v @ np.asarray(b, dtype=np.float64)) / n)


def _angle_deg(a: Sequence[float], b: Sequence[float]) -> float:
    v, w = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    c = float(v @ w) / max(float(np.linalg.norm(v) * np.linalg.norm(w)), 1e-300)
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def relabel_point(point: ProbePoint, new_id: str) -> ProbePoint:
    """``point`` under the id ``new_id`` (its role, or a retake key such as ``"C2"``)."""
    if point.id == new_id:
        return point
    return ProbePoint(new_id, point.position_m, point.normal, point.search, point.edge_normal)


def check_stator_points(
    points: Mapping[str, ProbePoint] | Sequence[ProbePoint] | StatorLayout,
) -> StatorLayout:
    """Validate the nominal A-H layout against what the paper's equations assume.

    A, B, D, E, G are approach points on the side face (normal +x); F and H are edge searches
    up (+z) that face to the top side; C is an approach point on the short side (normal +y).
    All side-face points share one x, F and H one z; A and B share z with A at smaller y;
    E lies below D, D below F, and H at smaller y than F. Extra points are ignored.

    Tolerances fit real meshes (:mod:`calib.tolerances`): a normal or direction within
    :data:`~calib.tolerances.ROLE_NORMAL_TOL_RAD` (0.5 deg) of its axis, shared coordinates
    within :data:`SHARE_TOL_M` (the planar-face tolerance, 0.5 mm). The face coordinates
    of the layout are the means over the points that share them.

    A mapping is keyed by role (``"A"`` ... ``"H"``); a point whose own id differs (a plan id
    such as ``"yoke_left"``) is re-labelled with its role, so search commands, measurements
    and :class:`ProbeFailedError` all use the role names (and ``"C2"``, ``"D2"``).

    Raises:
        ShapeError: a point is missing or of the wrong kind.
        DegenerateGeometryError: the layout breaks one of the conditions above.
    """
    if isinstance(points, StatorLayout):
        return points
    by_id = dict(points) if isinstance(points, Mapping) else {p.id: p for p in points}
    missing = [i for i in STATOR_POINT_IDS if i not in by_id]
    if missing:
        raise ShapeError(f"stator points are missing {', '.join(missing)} (need A-H)")
    pts = {i: relabel_point(by_id[i], i) for i in STATOR_POINT_IDS}
    for pid in STATOR_POINT_IDS:
        p = pts[pid]
        want_edge = pid in ("F", "H")
        if (p.search.kind == "edge") != want_edge:
            kind = "an edge search" if want_edge else "an approach search"
            raise ShapeError(f"point {pid} must be {kind}, got {p.search.kind!r}")
        want_normal = _Y if pid == "C" else _X
        if not _same(p.normal, want_normal):
            got = ", ".join(f"{v:.4g}" for v in p.normal)
            raise DegenerateGeometryError(
                f"point {pid} must have normal {want_normal} (wobj frame) within "
                f"{np.degrees(ROLE_NORMAL_TOL_RAD):.2g} deg, got ({got}), "
                f"{_angle_deg(p.normal, want_normal):.3g} deg off"
            )
        if want_edge and not (
            _same(p.search.edge_direction, _Z) and _same(p.edge_normal or (0, 0, 0), _Z)
        ):
            raise DegenerateGeometryError(
                f"point {pid} must search up the side face: edge_direction and edge_normal "
                f"(0, 0, 1), got {p.search.edge_direction} and {p.edge_normal}"
            )
    pos = {i: np.asarray(p.position_m, dtype=np.float64) for i, p in pts.items()}
    side_x = [float(pos[i][0]) for i in "ABDEFGH"]
    x_face, y_face = float(np.mean(side_x)), float(pos["C"][1])
    z_top = 0.5 * float(pos["F"][2] + pos["H"][2])
    mm = f"within {SHARE_TOL_M * 1e3:g} mm"
    conditions = [
        (
            float(np.ptp(side_x)) <= SHARE_TOL_M,
            f"A, B, D-H share x {mm} (they differ by {np.ptp(side_x) * 1e3:.3f} mm)",
        ),
        (
            abs(pos["H"][2] - pos["F"][2]) <= SHARE_TOL_M,
            f"F and H share z {mm} (the top edge; they differ by "
            f"{abs(pos['H'][2] - pos['F'][2]) * 1e3:.3f} mm)",
        ),
        (
            abs(pos["A"][2] - pos["B"][2]) <= SHARE_TOL_M,
            f"A and B share z {mm} (A -> B along +y; they differ by "
            f"{abs(pos['A'][2] - pos['B'][2]) * 1e3:.3f} mm)",
        ),
        (pos["B"][1] > pos["A"][1] + LAYOUT_TOL, "A lies at smaller y than B"),
        (pos["D"][2] > pos["E"][2] + LAYOUT_TOL, "E lies below D (D - E along +z)"),
        (pos["F"][2] > pos["D"][2] + LAYOUT_TOL, "D lies below the edge point F"),
        (pos["F"][1] > pos["H"][1] + LAYOUT_TOL, "H lies at smaller y than F"),
    ]
    for ok, what in conditions:
        if not ok:
            raise DegenerateGeometryError(f"stator layout: the A-H procedure needs that {what}")
    return StatorLayout(pts, (x_face, y_face, z_top))


def example_stator_points(
    *,
    yoke_z_m: float = -0.25,
    a_y_m: float = -0.90,
    b_y_m: float = -0.30,
    c_x_m: float = -0.04,
    c_z_m: float = -0.15,
    tooth_y_m: float = -0.10,
    d_z_m: float = -0.04,
    e_z_m: float = -0.15,
    h_y_m: float = -0.50,
    g_z_m: float = -0.10,
    approach: SearchSpec | None = None,
    edge_overtravel_m: float = 0.050,
) -> dict[str, ProbePoint]:
    """A nominal A-H layout in the paper's stator WOCS (origin at the top corner of the side
    face at the short side), after Fig. 8a; all positions wobj frame, metres.

    A and B lie on the yoke at ``yoke_z_m``; C on the short side (``y = 0``); D and E over the
    tooth at ``tooth_y_m``; F is the edge search up that tooth, starting at E's height (the
    paper starts it "from point E"); G lies at ``h_y_m`` and H is the edge search up from G.

    Args:
        approach: search of the approach points; default 80 mm start, 80 mm overtravel, which
            covers the paper's misplacement (20 mm and 3 deg over a 1 m section).
        edge_overtravel_m: how far past the nominal top edge F and H may search, metres.
    """
    spec = approach or SearchSpec(kind="approach", start_offset_m=0.080, overtravel_m=0.080)

    def side(pid: str, y: float, z: float) -> ProbePoint:
        return ProbePoint(pid, (0.0, y, z), _X, spec)

    def edge(pid: str, y: float, start_z: float) -> ProbePoint:
        search = SearchSpec("edge", -start_z, edge_overtravel_m, _Z)
        return ProbePoint(pid, (0.0, y, 0.0), _X, search, edge_normal=_Z)

    return {
        "A": side("A", a_y_m, yoke_z_m),
        "B": side("B", b_y_m, yoke_z_m),
        "C": ProbePoint("C", (c_x_m, 0.0, c_z_m), _Y, spec),
        "D": side("D", tooth_y_m, d_z_m),
        "E": side("E", tooth_y_m, e_z_m),
        "F": edge("F", tooth_y_m, e_z_m),
        "G": side("G", h_y_m, g_z_m),
        "H": edge("H", h_y_m, g_z_m),
    }
