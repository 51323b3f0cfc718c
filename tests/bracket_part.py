"""A machined L-bracket nobody here designed for, and the plans a user would make on it.

The part (metres, its own frame = the WOCS): a base plate ``x in [0, 0.2]``, ``y in [0, 0.1]``,
``z in [0, t]`` with two through-holes (11 mm, for M10 screws), and an upright ``t`` thick
along the ``y = 0.1`` edge, ``0.165`` tall: 200 x 100 x 165 mm overall. Faces: the base's top
(``z = t``, +z), the upright's inner face (``y = 0.1 - t``, -y), its outer face (+y), its top
(``z = 0.165``), the front of the base (``y = 0``) and the two L-shaped end faces (``x = 0``:
-x, ``x = 0.2``: +x), a ``t`` wide strip round the L.

The default wall is 20 mm: with 15 mm walls no 18 mm sensor footprint fits anywhere on an end
face (the largest disk in the L's corner is 17.6 mm), so no approach could measure x (``wobjcal
check``: "on a flat face of 3750.0 mm^2 too narrow for the 18 mm sensor").

Built without booleans (no mesh engine is a dependency): the base (outline with holes,
extruded in z) and the upright (hand-written quads, split where they meet the base) are joined
by dropping the faces they share, then checked watertight.

The plans copy the shipped ``assets/plans/plate_holes_best_fit.json`` (the cell: IRB 4400,
cable feeder, a 100 x 200 mm pedestal) as a user would, with the bracket in metres on the
pedestal (upright away from the robot, its inner face towards it), an 18 mm proximity sensor
and a 20 mm / 3 deg misplacement bound, and hand-placed points: a 3-2-1 (3 on the base's top,
2 on the upright's inner face, 1 on an end face) and a 9-point best fit (3 + 3 + 3 over the
three face directions), each well inside its face.

The part floats 10 mm over the pedestal, as the template's plate does: resting on it, the top
searches' overtravel (at least ~25 mm, which the 20 mm bound asks for, as the misplacement is
symmetric) runs the sensor into the pedestal below the 20 mm base, and check refuses P1-P3
("sensor_body is too near pedestal (clearance 4.0 mm)").
"""

from __future__ import annotations

import math
from pathlib import Path

import msgspec
import numpy as np
import shapely.geometry as sg
import trimesh

from calib.models import Misplacement, ProximitySensor
from calib.plan.file import Plan, PlanPoint, Pose, Search, file_sha256, load_plan, save_plan
from calib.procedures import BestFit, ThreeTwoOne

REPO = Path(__file__).resolve().parents[1]
TEMPLATE = REPO / "assets" / "plans" / "plate_holes_best_fit.json"

LENGTH_M, DEPTH_M, HEIGHT_M = 0.200, 0.100, 0.165
WALL_M = 0.020
#: Through-holes in the base: centres (x, y) and diameter, m.
HOLES_M = ((0.050, 0.030), (0.150, 0.030))
HOLE_DIAMETER_M = 0.011

#: Where the user puts the bracket: where the template puts its plate, over the template's
#: pedestal (a 100 x 200 mm box, top at z = 0.74 m, centred at x = 1.4016 m) and 10 mm above
#: it as the template's plate is, turned -90 deg about z so the part's x runs along -y (world)
#: and the upright stands on the far side with its inner face towards the robot.
T_WORLD_WOBJ = Pose(
    position_m=(1.3516, 0.1, 0.75),
    quat_wxyz=(math.cos(-math.pi / 4), 0.0, 0.0, math.sin(-math.pi / 4)),
)
SENSOR = ProximitySensor(face_diameter_m=0.018)
MISPLACEMENT = Misplacement(max_translation_m=0.020, max_angle_rad=math.radians(3.0))
#: Searches: start 40 mm out, run 30 mm past the face (the misplacement moves a face up to
#: ~27 mm along its normal at these levers; the template's 15 mm were for a 3 mm bound).
SEARCH = Search(kind="approach", start_offset_m=0.040, overtravel_m=0.030, speed_m_s=0.01)
#: Longest triangle edge of the STL written, m: the triangles of a CAD export with a chord
#: setting, not the fewest (see :func:`write_bracket`).
MAX_EDGE_M = 0.020

UP, INNER, END0, END1 = (0.0, 0.0, 1.0), (0.0, -1.0, 0.0), (-1.0, 0.0, 0.0), (1.0, 0.0, 0.0)


def bracket_mesh(wall_m: float = WALL_M, holes: bool = True) -> trimesh.Trimesh:
    """The bracket (module docstring), metres, watertight."""
    t, L, D, H = wall_m, LENGTH_M, DEPTH_M, HEIGHT_M
    yi = D - t  # the upright's inner face
    outline = sg.Polygon(
        [(0, 0), (L, 0), (L, yi), (0, yi)],
        holes=[
            list(sg.Point(c).buffer(HOLE_DIAMETER_M / 2, quad_segs=16).exterior.coords)[::-1]
            for c in (HOLES_M if holes else ())
        ],
    )
    base = trimesh.creation.extrude_polygon(outline, t)
    # the base's face against the upright (y = yi, normal +y) is inside the part: drop it
    inside = (np.abs(base.triangles_center[:, 1] - yi) < 1e-9) & (base.face_normals[:, 1] > 0.5)
    base.update_faces(~inside)
    base.remove_unreferenced_vertices()
    # the upright x in [0, L], y in [yi, D], z in [0, H], as quads (outward, counter-clockwise),
    # its inner face split at z = t where the base's top meets it (the part below is inside)
    v = {
        (i, j, k): (x, y, z)
        for i, x in enumerate((0.0, L))
        for j, y in enumerate((yi, D))
        for k, z in enumerate((0.0, t, H))
    }
    keys = list(v)
    idx = {key: n for n, key in enumerate(keys)}
    quads = [
        [(0, 0, 1), (1, 0, 1), (1, 0, 2), (0, 0, 2)],  # inner face above the base (-y)
        [(0, 1, 0), (0, 1, 2), (1, 1, 2), (1, 1, 0)],  # outer face (+y)
        [(0, 0, 2), (1, 0, 2), (1, 1, 2), (0, 1, 2)],  # top (+z)
        [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)],  # bottom (-z)
    ]
    faces = [[idx[q[0]], idx[q[1]], idx[q[2]]] for q in quads]
    faces += [[idx[q[0]], idx[q[2]], idx[q[3]]] for q in quads]
    for i, sign in ((0, -1), (1, 1)):  # the end faces: pentagons (y, z) with (yi, t) on an edge
        ring = [(i, 0, 0), (i, 0, 1), (i, 0, 2), (i, 1, 2), (i, 1, 0)]
        if sign > 0:
            ring = ring[::-1]
        # fan from the outer bottom corner: no triangle degenerates on the split edge
        apex = ring.index((i, 1, 0))
        ring = ring[apex:] + ring[:apex]
        faces += [[idx[ring[0]], idx[ring[m]], idx[ring[m + 1]]] for m in range(1, 4)]
    upright = trimesh.Trimesh(np.array([v[key] for key in keys]), np.array(faces), process=False)
    mesh = trimesh.util.concatenate([base, upright])
    mesh.merge_vertices(digits_vertex=9)
    mesh.fix_normals()
    if not (mesh.is_watertight and mesh.is_volume):
        raise RuntimeError("the bracket mesh is not a closed volume")
    return mesh


def write_bracket(
    folder: Path,
    wall_m: float = WALL_M,
    name: str = "bracket.stl",
    max_edge_m: float | None = MAX_EDGE_M,
) -> Path:
    """Write the bracket (metres) as a binary STL into ``folder``; the file's path.

    ``max_edge_m`` subdivides the triangles to at most that edge length (``None``: the fewest
    triangles, as built). The planar-face check admits the 20 mm end strips only when one of
    its sampled triangle centroids lies near a strip's centre line: the fewest triangles (long
    fan triangles) have none, 20 mm triangles do (see ``test_bracket_programs``).
    """
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    mesh = bracket_mesh(wall_m)
    if max_edge_m is not None:
        mesh = mesh.subdivide_to_size(max_edge_m)
    mesh.export(path)
    return path


def _points(spots: list[tuple[str, str, tuple[float, float, float], tuple]]) -> list[PlanPoint]:
    """Plan points from ``(id, role, position mm, normal)``."""
    return [
        PlanPoint(
            id=pid,
            role=role,
            position_m=tuple(c * 1e-3 for c in xyz),  # type: ignore[arg-type]
            normal=normal,
            search=SEARCH,
        )
        for pid, role, xyz, normal in spots
    ]


def three_two_one_points(wall_m: float = WALL_M) -> list[PlanPoint]:
    """3 on the base's top, 2 on the upright's inner face, 1 on the -x end of the upright."""
    t, yi = wall_m * 1e3, (DEPTH_M - wall_m) * 1e3
    mid = (DEPTH_M * 1e3 + yi) / 2  # the middle of the upright's end strip
    return _points(
        [
            ("P1", "primary", (30, 55, t), UP),
            ("P2", "primary", (170, 55, t), UP),
            ("P3", "primary", (100, 25, t), UP),
            ("S1", "secondary", (30, yi, 110), INNER),
            ("S2", "secondary", (170, yi, 110), INNER),
            ("T1", "tertiary", (0, mid, 100), END0),
        ]
    )


def best_fit_points(wall_m: float = WALL_M) -> list[PlanPoint]:
    """3 on the top, 3 on the upright's inner face, 3 on the end faces (top first)."""
    t, yi = wall_m * 1e3, (DEPTH_M - wall_m) * 1e3
    mid = (DEPTH_M * 1e3 + yi) / 2
    return _points(
        [
            ("T1", "fit", (30, 55, t), UP),
            ("T2", "fit", (170, 55, t), UP),
            ("T3", "fit", (100, 25, t), UP),
            ("U1", "fit", (30, yi, 120), INNER),
            ("U2", "fit", (170, yi, 120), INNER),
            ("U3", "fit", (100, yi, 60), INNER),
            ("E1", "fit", (0, mid, 110), END0),
            ("E2", "fit", (200, mid, 110), END1),
            ("E3", "fit", (200, mid, 50), END1),
        ]
    )


def bracket_plans(
    folder: Path,
    wall_m: float = WALL_M,
    max_edge_m: float | None = MAX_EDGE_M,
    vias: bool = True,
) -> dict[str, Plan]:
    """The 3-2-1 and best-fit plans on the bracket, written with its mesh into ``folder``.

    Made as a user makes them: the shipped plate plan loaded as the template (without its
    plate mesh, which ``../shared/reference`` holds: it is replaced), its work object, sensor,
    misplacement, points and procedure replaced (``msgspec.structs.replace``);
    with ``vias``, the via points ``wobjcal check --add-vias`` adds where a joint move between
    points collides (:func:`planner.check.vias.plan_with_vias`: the check names those moves and
    says to); saved beside the mesh and loaded back (digest checked).

    Returns:
        ``{"three_two_one": plan, "best_fit": plan}``; the files are
        ``folder/bracket_321.json`` and ``folder/bracket_best_fit.json``.
    """
    rep = msgspec.structs.replace
    mesh = write_bracket(folder, wall_m, max_edge_m=max_edge_m)
    template = load_plan(TEMPLATE, check_files=False)  # its plate mesh is replaced
    work_object = rep(
        template.work_object,
        mesh=mesh.name,
        units="m",
        sha256=file_sha256(mesh),
        T_world_wobj=T_WORLD_WOBJ,
    )
    validation = rep(template.validation, sensor=SENSOR, misplacement=MISPLACEMENT)
    common = {"work_object": work_object, "validation": validation}
    plans = {
        "three_two_one": rep(
            template,
            name="bracket_321",
            description="3-2-1 on the L-bracket with the 18 mm proximity sensor",
            points=three_two_one_points(wall_m),
            procedure=ThreeTwoOne(),
            **common,
        ),
        "best_fit": rep(
            template,
            name="bracket_best_fit",
            description="9-point best fit on the L-bracket with the 18 mm proximity sensor",
            points=best_fit_points(wall_m),
            procedure=BestFit(),
            **common,
        ),
    }
    out = {}
    for key, plan in plans.items():
        if vias:
            plan = with_vias(plan, folder)
        path = save_plan(plan, folder / f"{plan.name}.json")
        out[key] = load_plan(path)
    return out


def with_vias(plan: Plan, folder: Path) -> Plan:
    """``plan`` with the vias ``wobjcal check --add-vias`` adds (its cell opened from
    ``folder``)."""
    from planner.check.vias import plan_with_vias
    from planner.plan_cell import open_cell

    with open_cell(plan, folder) as cell:
        return plan_with_vias(plan, cell)[0]
