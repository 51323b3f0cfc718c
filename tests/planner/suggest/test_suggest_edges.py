"""Edge searches in ``wobjcal suggest``: a thin box whose sides are too narrow for the
proximity sensor's 18 mm footprint, so only edge searches over its top can fix x, y and the
turn about z."""

from __future__ import annotations

from pathlib import Path

import msgspec
import numpy as np
import pytest
import shapely
import trimesh

from calib.estimators.layout import search_constraint_set
from calib.estimators.observability import analyze_layout
from calib.plan.base import file_sha256
from calib.plan.file import Plan, load_plan
from planner.faces.detection import find_planar_faces
from planner.faces.edges import edge_candidates
from planner.faces.outline import FaceOutlines

ASSETS = Path(__file__).resolve().parents[3] / "assets" / "plans"
#: The box, mm: 200 x 300 x 10 (sides 10 mm: too thin for the 18 mm footprint).
SIZE_MM = (200.0, 300.0, 10.0)


def _box(folder: Path) -> Path:
    box = trimesh.creation.box(extents=SIZE_MM)
    box.apply_translation(np.array(SIZE_MM) / 2)  # wobj origin at a bottom corner
    path = folder / "thin_box.stl"
    box.export(path)
    return path


@pytest.fixture(scope="module")
def box_plan(tmp_path_factory: pytest.TempPathFactory) -> Plan:
    """The plate's cell (IRB 4400, pedestal) with the thin box and the stator plan's proximity
    sensor, as it is (256 rays: the simulation resolves edge events between them,
    :mod:`planner.sim.subray`; with plain rays x and the turn about z simulated 1.59 times the
    prediction)."""
    stl = _box(tmp_path_factory.mktemp("box"))
    plate = load_plan(ASSETS / "plate_holes_best_fit.json", check_files=False)  # mesh replaced
    sensor = load_plan(ASSETS / "stator_section_ah.json").validation.sensor
    assert sensor.n_rays == 256
    wo = msgspec.structs.replace(plate.work_object, mesh=str(stl), sha256=file_sha256(stl))
    v = msgspec.structs.replace(plate.validation, sensor=sensor)
    return msgspec.structs.replace(plate, work_object=wo, validation=v)


def test_edge_candidates_lie_on_the_top_edges_and_point_out(tmp_path: Path) -> None:
    mesh = trimesh.load(_box(tmp_path))
    mesh.apply_scale(1e-3)
    r = 0.009
    faces = find_planar_faces(mesh, min_area_m2=np.pi * r**2, footprint_radius_m=r)
    top = [i for i, f in enumerate(faces.faces) if f.normal[2] > 0.99]
    assert len(top) == 1
    c = edge_candidates(FaceOutlines(faces, r), top, r, start_m=0.03, shift_m=0.005)
    assert len(c) == 12 and c.is_edge.all()  # 4 edges x (1/4, 1/2, 3/4)
    P, D = c.positions_m, c.edge_dirs
    assert D is not None
    assert np.allclose(P[:, 2], 0.010)
    assert np.allclose(np.abs(D).max(axis=1), 1.0) and np.allclose(D[:, 2], 0.0)
    # each lies on the edge its direction points at
    hi = np.array([0.2, 0.3])
    for p, d in zip(P, D, strict=True):
        k = int(np.argmax(np.abs(d[:2])))
        assert p[k] == pytest.approx(hi[k] if d[k] > 0 else 0.0, abs=1e-6)  # the weld
    assert sorted(np.round(P[D[:, 0] > 0.5, 1] * 1e3, 3)) == [75.0, 150.0, 225.0]
    # a start farther in than the box is long leaves none; wider than wide, the y edges only
    assert len(edge_candidates(FaceOutlines(faces, r), top, r, 0.35, 0.005)) == 0
    wide = edge_candidates(FaceOutlines(faces, r), top, r, 0.25, 0.005)
    assert (
        len(wide) == 6
        and wide.edge_dirs is not None
        and np.allclose(wide.edge_dirs[:, 0], 0, atol=1e-6)
    )


@pytest.mark.slow
def test_thin_box_is_fixed_by_edge_searches(box_plan: Plan) -> None:
    """The suggestion fixes all six DOF with edge searches, checks, and its Monte Carlo
    agrees with the prediction within 25 % on every row."""
    from planner.check.job import check_plan
    from planner.suggest import suggest_plan
    from planner.validate.job import validate_plan

    res = suggest_plan(box_plan, ASSETS, max_points=8)
    pts = res.plan.points
    edges = [p for p in pts if p.search.kind == "edge"]
    approaches = [p for p in pts if p.search.kind == "approach"]
    assert len(edges) >= 3 and len(approaches) >= 3
    assert all(p.normal[2] > 0.99 for p in pts)  # every search runs over the top
    assert pts[: len(approaches)] == approaches  # the approaches first: height and tilts
    report = analyze_layout(search_constraint_set([p.to_probe_point() for p in pts]))
    assert report.rating == "ok", report
    assert res.quality is not None and res.quality.rating == "ok"
    check = check_plan(res.plan, ASSETS)
    assert check.feasible, [(p.point_id, p.reason) for p in check.points if not p.feasible]
    sim = validate_plan(res.plan, trials=300, seed=7, workers=1, plan_dir=ASSETS)
    assert sim.failures == {}
    for row in sim.rows:
        if row.level_percent == 95.5:
            assert row.procedure == pytest.approx(row.procedure_predicted, rel=0.25), row.key


def _block(slope_deg: float) -> trimesh.Trimesh:
    """A 200 x 300 x 20 mm block (metres): a 5 x 5 mm chamfer along its top +x edge and its
    -x side sloped by ``slope_deg`` (leaning out, so the rays past the top edge see it)."""
    s = 0.020 * np.tan(np.radians(slope_deg))
    profile = shapely.Polygon(  # (x, z)
        [(-s, 0.0), (0.2, 0.0), (0.2, 0.015), (0.195, 0.020), (0.0, 0.020)]
    )
    mesh = trimesh.creation.extrude_polygon(profile, 0.3)  # along w: (u, v, w) = (x, z, -y)
    mesh.apply_transform(np.array([[1, 0, 0, 0], [0, 0, -1, 0.3], [0, 1, 0, 0], [0, 0, 0, 1.0]]))
    return mesh


@pytest.mark.parametrize(("slope_deg", "kept_minus_x"), [(10.0, False), (2.0, True)])
def test_edges_that_are_not_square_get_no_edge_search(slope_deg: float, kept_minus_x: bool) -> None:
    """The chamfered +x edge never, the -x edge when its side is within 3 degrees of square;
    the square +-y edges (the block's ends) always."""
    mesh = _block(slope_deg)
    assert mesh.is_watertight and mesh.volume > 0
    r = 0.009
    faces = find_planar_faces(mesh, min_area_m2=np.pi * r**2, footprint_radius_m=r)
    top = [i for i, f in enumerate(faces.faces) if f.normal[2] > 0.99]
    assert len(top) == 1
    c = edge_candidates(FaceOutlines(faces, r), top, r, start_m=0.03, shift_m=0.005)
    D = c.edge_dirs
    assert D is not None
    sides = {tuple(np.round(d).astype(int)) for d in D}
    want = {(0, 1, 0), (0, -1, 0)} | ({(-1, 0, 0)} if kept_minus_x else set())
    assert sides == want
    assert np.allclose(c.positions_m[:, 2], 0.020)
    # the chamfer's face ends 5 mm in: without the check the +x edge search was offered there
    ends, across = FaceOutlines(faces, r).rim(top[0])
    assert len(ends) and np.any(np.isclose(across @ [1, 0, 0], np.cos(np.pi / 4), atol=1e-6))
