"""The stator-section mesh: :func:`build_stator_mesh` and the built-in parts' factories.

The side face (wobj ``x = 0``) is tiled by a rectangular grid of cells: solid cells and cells with
one round slot hole in the middle. Every cell edge is sampled with the same ``k + 1`` points, so
neighbouring cells share vertices exactly. The back face (``x = -depth``) repeats the side-face
triangulation, and quad strips join the two along the outer boundary and through every hole:
the result is watertight by construction, with outward normals.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray

from planner.parts.stator import StatorGeometry

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class FaceGrid:
    """The side-face cell grid, wobj frame, metres.

    Attributes:
        ys: ``(ny + 1,)`` cell boundaries along y, descending from 0 to ``-length``.
        zs: ``(nz + 1,)`` cell boundaries along z, descending from 0 to ``-height``.
        holes: ``(H, 4)`` rows ``(iy, iz, y_centre, z_centre)`` of the cells that hold a hole.
        hole_radius_m: radius of the hole polygon (area equal to the round hole's).
        k: samples per cell edge (segments); a hole polygon has ``4 k`` vertices.
    """

    ys: FloatArray
    zs: FloatArray
    holes: FloatArray
    hole_radius_m: float
    k: int


def _split(a: float, b: float, max_step: float) -> list[float]:
    """Boundaries from ``a`` down to ``b`` (excluding ``a``) in equal steps of at most max_step."""
    if a - b <= 1e-12:
        return []
    n = max(1, math.ceil((a - b) / max_step - 1e-9))
    return [a + (b - a) * i / n for i in range(1, n + 1)]


def side_face_grid(geom: StatorGeometry) -> FaceGrid:
    """The cell grid of ``geom``'s side face."""
    p, lp = geom.slot_pitch_m, geom.layer_pitch_m
    slot_y, layer_z = geom.slot_y_m, geom.layer_z_m
    ys = [0.0]
    if len(slot_y):
        ys += _split(0.0, float(slot_y[0]) + p / 2, p)
        ys += [float(y) - p / 2 for y in slot_y]
    ys += _split(ys[-1], -geom.length_m, p)
    zs = [0.0]
    if len(layer_z):
        zs += _split(0.0, float(layer_z[0]) + lp / 2, lp)
        zs += [float(z) - lp / 2 for z in layer_z]
    zs += _split(zs[-1], -geom.height_m, lp)
    holes = []
    if len(slot_y) and len(layer_z):
        first_iy = next(i for i in range(len(ys) - 1) if ys[i + 1] <= float(slot_y[0]))
        first_iz = next(i for i in range(len(zs) - 1) if zs[i + 1] <= float(layer_z[0]))
        for jj, y in enumerate(slot_y):
            for kk, z in enumerate(layer_z):
                holes.append((first_iy + jj, first_iz + kk, float(y), float(z)))
    n = geom.hole_segments
    r = geom.hole_diameter_m / 2 * math.sqrt(2 * math.pi / (n * math.sin(2 * math.pi / n)))
    return FaceGrid(
        ys=np.asarray(ys),
        zs=np.asarray(zs),
        holes=np.asarray(holes, float).reshape(-1, 4),
        hole_radius_m=r,
        k=n // 4,
    )


def _cell_loop(ylin: FloatArray, zlin: FloatArray) -> FloatArray:
    """``(4k, 2)`` boundary of a cell, counter-clockwise in (y, z), from its (y_lo, z_lo) corner."""
    y_up, z_up = ylin[::-1], zlin[::-1]  # ascending
    bottom = np.column_stack([y_up[:-1], np.full(len(y_up) - 1, z_up[0])])
    right = np.column_stack([np.full(len(z_up) - 1, y_up[-1]), z_up[:-1]])
    top = np.column_stack([ylin[:-1], np.full(len(ylin) - 1, z_up[-1])])
    left = np.column_stack([np.full(len(zlin) - 1, y_up[0]), zlin[:-1]])
    return np.vstack([bottom, right, top, left])


def _zipper(outer: FloatArray, inner: FloatArray, centre: FloatArray) -> FloatArray:
    """Triangles ``(T, 3, 2)`` filling the ring between two star-shaped loops around ``centre``."""
    a_o = np.mod(np.arctan2(*(outer - centre).T[::-1]), 2 * np.pi)
    a_i = np.mod(np.arctan2(*(inner - centre).T[::-1]), 2 * np.pi)
    ref = a_o.min()
    oo, ii = np.argsort(np.mod(a_o - ref, 2 * np.pi)), np.argsort(np.mod(a_i - ref, 2 * np.pi))
    outer, inner = outer[oo], inner[ii]
    u_o = np.append(np.mod(a_o[oo] - ref, 2 * np.pi), 2 * np.pi)
    u_i_s = np.mod(a_i[ii] - ref, 2 * np.pi)
    u_i = np.append(u_i_s, u_i_s[0] + 2 * np.pi)
    no, ni = len(outer), len(inner)
    tris, i, j = [], 0, 0
    while i < no or j < ni:
        if i < no and (j == ni or u_o[i + 1] <= u_i[j + 1]):
            tris.append((outer[i], outer[(i + 1) % no], inner[j % ni]))
            i += 1
        else:
            tris.append((outer[i % no], inner[(j + 1) % ni], inner[j % ni]))
            j += 1
    return np.asarray(tris)


def _grid_tris(ylin: FloatArray, zlin: FloatArray) -> FloatArray:
    """Triangles ``(2 k^2, 3, 2)`` of a solid cell sampled on its ``(k + 1)^2`` grid."""
    yy, zz = np.meshgrid(ylin, zlin, indexing="ij")
    pts = np.stack([yy, zz], axis=-1)
    a, b, c, d = pts[:-1, :-1], pts[1:, :-1], pts[1:, 1:], pts[:-1, 1:]
    t1 = np.stack([a, b, c], axis=-2).reshape(-1, 3, 2)
    t2 = np.stack([a, c, d], axis=-2).reshape(-1, 3, 2)
    return np.concatenate([t1, t2])


def _ccw(tris: FloatArray) -> FloatArray:
    """Reorder triangles ``(T, 3, 2)`` so each is counter-clockwise in (y, z)."""
    e1, e2 = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    cw = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    out = tris.copy()
    out[cw] = tris[cw][:, [0, 2, 1]]
    return out


def triangulate_section(grid: FaceGrid, depth_m: float) -> tuple[FloatArray, IntArray]:
    """Vertices ``(V, 3)`` and faces ``(F, 3)`` of the section, outward-wound, wobj, metres."""
    k = grid.k
    ylins = [np.linspace(grid.ys[i], grid.ys[i + 1], k + 1) for i in range(len(grid.ys) - 1)]
    zlins = [np.linspace(grid.zs[i], grid.zs[i + 1], k + 1) for i in range(len(grid.zs) - 1)]
    hole_at = {(int(h[0]), int(h[1])): h[2:] for h in grid.holes}
    n = 4 * k
    ang = 2 * np.pi * (np.arange(n) + 0.5) / n
    unit = np.column_stack([np.cos(ang), np.sin(ang)]) * grid.hole_radius_m
    tris, rings = [], []
    for iy, ylin in enumerate(ylins):
        for iz, zlin in enumerate(zlins):
            centre = hole_at.get((iy, iz))
            if centre is None:
                tris.append(_grid_tris(ylin, zlin))
            else:
                ring = centre + unit
                rings.append(ring)
                tris.append(_zipper(_cell_loop(ylin, zlin), ring, centre))
    front_tris = _ccw(np.concatenate(tris))
    outer = _cell_loop(
        np.concatenate([y[:-1] for y in ylins] + [ylins[-1][-1:]]),
        np.concatenate([z[:-1] for z in zlins] + [zlins[-1][-1:]]),
    )
    ring_pts = np.concatenate(rings) if rings else np.zeros((0, 2))
    all_pts = np.concatenate([front_tris.reshape(-1, 2), outer, ring_pts])
    uniq, inv = np.unique(all_pts, axis=0, return_inverse=True)
    inv = inv.ravel()
    nf = len(front_tris) * 3
    front = inv[:nf].reshape(-1, 3)
    outer_idx = inv[nf : nf + len(outer)]
    ring_idx = inv[nf + len(outer) :].reshape(-1, n)
    nv = len(uniq)
    faces = [front, front[:, ::-1] + nv]
    # outer walls: outward = to the right of the counter-clockwise loop
    a, b = outer_idx, np.roll(outer_idx, -1)
    faces += [np.column_stack([b, a, a + nv]), np.column_stack([b, a + nv, b + nv])]
    # hole walls: outward = into the hole, to the left of the counter-clockwise ring
    if len(ring_idx):
        a, b = ring_idx.ravel(), np.roll(ring_idx, -1, axis=1).ravel()
        faces += [np.column_stack([a, b, b + nv]), np.column_stack([a, b + nv, a + nv])]
    vertices = np.zeros((2 * nv, 3))
    vertices[:nv, 1:], vertices[nv:, 1:] = uniq, uniq
    vertices[nv:, 0] = -depth_m
    return vertices, np.concatenate(faces).astype(np.int64)


def build_stator_mesh(geom: StatorGeometry, deformed: bool = True) -> trimesh.Trimesh:
    """Watertight triangle mesh of the section in the wobj frame, metres.

    Args:
        geom: the dimensions.
        deformed: apply the tightening-bolt bulge to the side face.

    Returns:
        A new mesh each call (the caller may change it); its side face lies at
        ``x = side_face_offset_m(y, z)`` (``x = 0`` undeformed). The triangulation is kept per
        geometry (a few of them in this process): ``wobjcal validate`` builds the part for the
        trials and again for its cell.
    """
    key = (geom, deformed)
    with _built_lock:
        kept = _built.get(key)
    if kept is None:
        grid = side_face_grid(geom)
        vertices, faces = triangulate_section(grid, geom.depth_m)
        if deformed:
            front = vertices[:, 0] == 0.0
            vertices[front, 0] = geom.side_face_offset_m(vertices[front, 1], vertices[front, 2])
        mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=True, validate=False)
        kept = (np.array(mesh.vertices), np.array(mesh.faces))
        with _built_lock:
            _built[key] = kept
            while len(_built) > _BUILT_SIZE:
                _built.pop(next(iter(_built)))
    return trimesh.Trimesh(vertices=kept[0].copy(), faces=kept[1].copy(), process=False)


#: The processed vertices and faces of stator meshes built, by (geometry, deformed); the oldest
#: built is dropped first.
_built: dict[tuple[StatorGeometry, bool], tuple[NDArray[np.float64], NDArray[np.int64]]] = {}
_built_lock = threading.Lock()
_BUILT_SIZE = 4


def full_section_mesh() -> trimesh.Trimesh:
    """``builtin:stator_section``: the full-size section (:meth:`StatorGeometry.full_section`)."""
    return build_stator_mesh(StatorGeometry.full_section())


def prototype_mesh() -> trimesh.Trimesh:
    """``builtin:stator_prototype``: the 0.5 m prototype (:meth:`StatorGeometry.prototype`)."""
    return build_stator_mesh(StatorGeometry.prototype())
