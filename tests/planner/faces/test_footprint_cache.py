"""Detection's footprint test kept on disk (:mod:`planner.faces.footprint_cache`): a later
detection reads the answer instead of casting its rays, gets the same faces, and an unusable
or foreign entry costs time, never an answer."""

from __future__ import annotations

from collections import OrderedDict
from pathlib import Path

import numpy as np
import pytest
import trimesh

from planner.cell import disk_cache
from planner.faces import detection, footprint, footprint_cache


def _plate_with_slot() -> trimesh.Trimesh:
    """A 0.2 x 0.1 x 0.01 m plate with a 6 mm wide slot wall: faces that hold a footprint
    and faces too narrow for it."""
    plate = trimesh.creation.box((0.2, 0.1, 0.01))
    rib = trimesh.creation.box((0.1, 0.006, 0.02))
    rib.apply_translation([0.0, 0.0, 0.015])
    return trimesh.util.concatenate([plate, rib])


def _faces_signature(f: detection.PlanarFaces) -> tuple[object, ...]:
    return (
        f.face_id.tobytes(),
        tuple(
            (tuple(np.asarray(s.normal).tolist()), s.area_m2, s.holds_footprint) for s in f.faces
        ),
        f.region_holds.tobytes(),
    )


@pytest.fixture
def fresh(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> Path:
    """An empty disk cache and an empty in-process detection cache."""
    monkeypatch.setenv("WOBJCAL_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(detection, "_cache", OrderedDict())
    return tmp_path


def test_a_second_detection_reads_the_answer_from_disk(
    fresh: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mesh = _plate_with_slot()
    plain = detection._detect(mesh, "part", **_tols())
    first = detection.find_planar_faces(mesh, footprint_radius_m=0.009, cache=disk_cache)
    assert _faces_signature(first) == _faces_signature(plain)
    assert not first.region_holds.all()  # the narrow faces were tested and refused
    stored = list((fresh / footprint_cache.CACHE_KIND).glob("*.npz"))
    assert len(stored) == 1

    def no_rays(*args: object, **kwargs: object) -> None:
        raise AssertionError("the footprint test ran again")

    monkeypatch.setattr(detection, "_cache", OrderedDict())
    monkeypatch.setattr(footprint, "holds_footprint", no_rays)
    again = detection.find_planar_faces(mesh, footprint_radius_m=0.009, cache=disk_cache)
    assert _faces_signature(again) == _faces_signature(plain)


def test_another_radius_or_an_unusable_entry_is_computed_again(fresh: Path) -> None:
    mesh = _plate_with_slot()
    detection.find_planar_faces(mesh, footprint_radius_m=0.009, cache=disk_cache)
    detection.find_planar_faces(mesh, footprint_radius_m=0.002, cache=disk_cache)
    files = sorted((fresh / footprint_cache.CACHE_KIND).glob("*.npz"))
    assert len(files) == 2  # the radius is in the key
    for f in files:  # a foreign answer (wrong size) under each key
        key = f.stem
        disk_cache.save_arrays(
            footprint_cache.CACHE_KIND, key, footprint_cache.CACHE_VERSION, {"holds": np.ones(1)}
        )
    detection._cache.clear()
    got = detection.find_planar_faces(mesh, footprint_radius_m=0.009, cache=disk_cache)
    want = detection._detect(mesh, "part", **_tols())
    assert _faces_signature(got) == _faces_signature(want)


def _tols() -> dict[str, float]:
    return {
        "min_area_m2": detection.MIN_AREA_M2,
        "angle_tol_rad": detection.ANGLE_TOL_RAD,
        "flatness_tol_m": detection.FLATNESS_TOL_M,
        "max_deviation_m": detection.MAX_DEVIATION_M,
        "footprint_radius_m": 0.009,
    }


def test_check_and_validate_keep_the_faces_of_the_plan_on_disk(
    fresh: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The plan's face check before a validation (``preflight``), the trials' setup and
    ``wobjcal check``'s point check keep detection's answer on disk: the next command reads it
    (they computed it again in every command)."""
    from calib.plan.file import load_plan
    from planner.check.simulatable import check_simulatable, preflight, work_object_mesh
    from planner.check.simulation_setup import simulation_setup

    path = Path(__file__).resolve().parents[3] / "assets" / "plans" / "stator_section_ah.json"
    plan = load_plan(path)
    models = check_simulatable(plan)
    mesh = work_object_mesh(plan, path.parent, models)
    preflight(plan, models, mesh)
    assert len(list((fresh / footprint_cache.CACHE_KIND).glob("*.npz"))) == 1

    def no_rays(*args: object, **kwargs: object) -> None:
        raise AssertionError("the footprint test ran again")

    monkeypatch.setattr(detection, "_cache", OrderedDict())  # a new command
    monkeypatch.setattr(footprint, "holds_footprint", no_rays)
    preflight(plan, models, mesh)
    monkeypatch.setattr(detection, "_cache", OrderedDict())
    assert simulation_setup(plan, models, mesh).faces is not None
    monkeypatch.setattr(detection, "_cache", OrderedDict())
    from planner.check.job import check_plan

    assert all(c.face_cause is None for c in check_plan(plan, path.parent).points)
