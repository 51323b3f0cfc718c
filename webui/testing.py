"""Helpers for tests and benchmarks of the UI: a small box plan, free ports, screen projection,
waiting for a condition."""

from __future__ import annotations

import socket
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

from calib.frames import (
    make_transform,
    matrix_from_quat_wxyz,
    matrix_from_rotvec,
    quat_wxyz_from_matrix,
)
from calib.plan.file import (
    CellSpec,
    Plan,
    PlanPoint,
    Pose,
    RobotSpec,
    WorkObjectSpec,
    file_sha256,
    save_plan,
)
from calib.probing import ProbePoint
from calib.procedures import ThreeTwoOne

#: Size of the test box, metres (x, y, z); its top face is z = 0 and it lies in z < 0.
BOX_EXTENTS = (0.6, 0.4, 0.3)
#: Pose of the box's wobj frame in the world: in front of the robot, turned 90 deg about z.
T_WORLD_WOBJ_BOX = make_transform(matrix_from_rotvec([0.0, 0.0, np.pi / 2]), [1.5, 0.2, 0.8])


def box_mesh() -> trimesh.Trimesh:
    """The test box (12 triangles) in its wobj frame."""
    mesh = trimesh.creation.box(extents=BOX_EXTENTS)
    mesh.apply_translation((0.0, 0.0, -BOX_EXTENTS[2] / 2))
    return mesh


def dense_box_mesh(n_triangles: int) -> trimesh.Trimesh:
    """The test box with each face a regular grid, about ``n_triangles`` triangles in all."""
    k = max(1, round(np.sqrt(n_triangles / 12.0)))
    parts = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            s = np.linspace(-0.5, 0.5, k + 1)
            uu, vv = np.meshgrid(s, s, indexing="ij")
            verts = np.zeros((uu.size, 3))
            verts[:, axis] = 0.5 * sign
            verts[:, u], verts[:, v] = uu.ravel(), vv.ravel()
            idx = np.arange(uu.size).reshape(k + 1, k + 1)
            a, b = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel()
            c, d = idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
            faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
            if sign < 0:
                faces = faces[:, ::-1]
            grid = trimesh.Trimesh(verts, faces, process=False)
            parts.append(grid)
    mesh = trimesh.Trimesh(*_stack(parts), process=False)
    mesh.merge_vertices()
    mesh.apply_scale(BOX_EXTENTS)
    mesh.apply_translation((0.0, 0.0, -BOX_EXTENTS[2] / 2))
    return mesh


def _stack(parts: list[trimesh.Trimesh]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Vertices and faces of several meshes as one."""
    offsets = np.cumsum([0] + [len(p.vertices) for p in parts[:-1]])
    verts = np.vstack([p.vertices for p in parts])
    faces = np.vstack([p.faces + k for p, k in zip(parts, offsets, strict=True)])
    return verts, faces


def box_plan(folder: Path, n_triangles: int | None = None, name: str = "box_plan") -> Path:
    """Write a 3-2-1 plan on the test box (mesh in metres) into ``folder``; return its path.

    Args:
        folder: where the plan and its mesh file go.
        n_triangles: make the box of about this many triangles (``None``: 12).
        name: the plan's name and file stem.
    """
    folder.mkdir(parents=True, exist_ok=True)
    mesh_path = folder / f"{name}_box.stl"
    mesh = box_mesh() if n_triangles is None else dense_box_mesh(n_triangles)
    mesh.export(mesh_path)
    hx, hy = BOX_EXTENTS[0] / 2, BOX_EXTENTS[1] / 2
    spots = [
        ("P1", "primary", (-0.2, -0.1, 0.0), (0, 0, 1)),
        ("P2", "primary", (0.2, -0.1, 0.0), (0, 0, 1)),
        ("P3", "primary", (0.0, 0.12, 0.0), (0, 0, 1)),
        ("S1", "secondary", (-0.2, -hy, -0.1), (0, -1, 0)),
        ("S2", "secondary", (0.2, -hy, -0.1), (0, -1, 0)),
        ("T1", "tertiary", (hx, 0.0, -0.1), (1, 0, 0)),
    ]
    points = [
        PlanPoint.from_probe_point(ProbePoint(pid, pos, nrm), role) for pid, role, pos, nrm in spots
    ]
    q = quat_wxyz_from_matrix(T_WORLD_WOBJ_BOX[:3, :3])
    plan = Plan(
        name=name,
        cell=CellSpec(robot=RobotSpec(urdf="builtin:irb4400")),
        work_object=WorkObjectSpec(
            mesh=mesh_path.name,
            units="m",
            sha256=file_sha256(mesh_path),
            T_world_wobj=Pose(
                position_m=tuple(float(v) for v in T_WORLD_WOBJ_BOX[:3, 3]),  # type: ignore[arg-type]
                quat_wxyz=tuple(float(v) for v in q),  # type: ignore[arg-type]
            ),
        ),
        points=points,
        procedure=ThreeTwoOne(),
    )
    return save_plan(plan, folder / f"{name}.json")


def wait_until(pred: Callable[[], object], what: str, timeout_s: float = 120.0) -> None:
    """Poll ``pred`` every 10 ms until it is truthy; ``AssertionError`` naming ``what`` after
    ``timeout_s`` seconds (generous: a loaded machine)."""
    deadline = time.monotonic() + timeout_s
    while not pred():
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.01)


def free_port() -> int:
    """A TCP port on 127.0.0.1 that is free right now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def project_to_screen(
    p_world: ArrayLike,
    position: ArrayLike,
    wxyz: ArrayLike,
    fov_rad: float,
    width_px: int,
    height_px: int,
) -> NDArray[np.float64]:
    """Pixel ``(u, v)`` of a world point in a viser camera (OpenCV axes: x right, y down, z fwd).

    Args:
        p_world: ``(3,)`` the point, world frame.
        position: ``(3,)`` camera position, world frame.
        wxyz: camera orientation ``R_world_camera`` as a (w, x, y, z) quaternion.
        fov_rad: vertical field of view, radians.
        width_px: canvas width, pixels.
        height_px: canvas height, pixels.
    """
    R = matrix_from_quat_wxyz(wxyz)
    pc = R.T @ (np.asarray(p_world, float) - np.asarray(position, float))
    if pc[2] <= 0:
        raise ValueError("the point is behind the camera")
    f = (height_px / 2.0) / np.tan(fov_rad / 2.0)
    return np.array([width_px / 2.0 + f * pc[0] / pc[2], height_px / 2.0 + f * pc[1] / pc[2]])
