"""Candidate probe points on the planar faces of a part, for ``wobjcal suggest``.

Per planar face (:func:`planner.faces.detection.find_planar_faces` with the sensor's
footprint): area-weighted samples on its triangles (fixed seed), kept where the footprint
*grown by a shift margin* (``shift_m``; ``wobjcal suggest`` passes a floor and checks
each chosen point's real shift in its measuring order) lies wholly on the face
(:func:`planner.faces.checks.check_probe_faces`: not over a hole or an edge even when the part
lies misplaced), then thinned by farthest-point sampling so the candidates spread over the
face, its extremes included. Every face tried is reported with what stopped its samples.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planner.faces.checks import check_probe_faces
from planner.faces.detection import PlanarFaces

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Seed of the samples (the same candidates on every run).
CANDIDATE_SEED = 13


@dataclass(frozen=True)
class FaceTried:
    """What became of one planar face's samples.

    Attributes:
        face_id: the planar face.
        normal: ``(3,)`` its outward normal, wobj frame.
        area_m2: its area, m^2.
        sampled: samples drawn on it.
        kept: samples whose grown footprint lies on it (before thinning).
        footprint_reason: why the others failed (the first reason met), ``""`` if none did.
    """

    face_id: int
    normal: FloatArray = field(repr=False)
    area_m2: float
    sampled: int
    kept: int
    footprint_reason: str

    @property
    def name(self) -> str:
        """E.g. ``"face 2 (normal +z, 0.500 m^2)"``."""
        n = self.normal
        k = int(np.argmax(np.abs(n)))
        axis = f"{'+' if n[k] > 0 else '-'}{'xyz'[k]}" if abs(n[k]) > 0.99 else _vec(n)
        return f"face {self.face_id} (normal {axis}, {self.area_m2:.4f} m^2)"


def _vec(n: FloatArray) -> str:
    return "(" + ", ".join(f"{c:.2f}" for c in n) + ")"


@dataclass(frozen=True)
class Candidates:
    """Candidate approach searches on planar faces.

    Attributes:
        positions_m: ``(C, 3)`` points on the faces, wobj frame, metres.
        normals: ``(C, 3)`` their faces' unit outward normals, wobj frame.
        face: ``(C,)`` the planar face of each.
        faces: every planar face tried, with what stopped its samples.
        edge_dirs: ``(C, 3)`` for an edge search, its unit direction of motion over the face
            toward the edge (also the outward normal of the square edge's other face, whose
            end it finds), zeros for an approach search; ``None``: approaches only.
    """

    positions_m: FloatArray = field(repr=False)
    normals: FloatArray = field(repr=False)
    face: IntArray = field(repr=False)
    faces: tuple[FaceTried, ...]
    edge_dirs: FloatArray | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return len(self.positions_m)

    def subset(self, keep: NDArray[np.bool_] | IntArray) -> Candidates:
        """The candidates ``keep`` (a mask or indices), with the same faces tried."""
        e = None if self.edge_dirs is None else self.edge_dirs[keep]
        return Candidates(
            self.positions_m[keep], self.normals[keep], self.face[keep], self.faces, e
        )

    @property
    def is_edge(self) -> NDArray[np.bool_]:
        """``(C,)`` which candidates are edge searches."""
        if self.edge_dirs is None:
            return np.zeros(len(self), dtype=bool)
        return np.any(self.edge_dirs != 0.0, axis=1)

    def joined(self, other: Candidates) -> Candidates:
        """These candidates followed by ``other``'s (the faces tried are these)."""

        def dirs(c: Candidates) -> FloatArray:
            return np.zeros((len(c), 3)) if c.edge_dirs is None else c.edge_dirs

        return Candidates(
            np.concatenate([self.positions_m, other.positions_m]),
            np.concatenate([self.normals, other.normals]),
            np.concatenate([self.face, other.face]),
            self.faces,
            np.concatenate([dirs(self), dirs(other)]),
        )


def face_candidates(
    faces: PlanarFaces,
    footprint_radius_m: float,
    per_face: int,
    shift_m: Callable[[FloatArray], FloatArray] | None = None,
    face_ids: list[int] | None = None,
) -> Candidates:
    """Spread candidates on planar faces whose grown footprint stays on the face.

    Args:
        faces: the part's planar faces (wobj frame, metres).
        footprint_radius_m: the sensor's footprint radius, metres.
        per_face: at most this many candidates per face.
        shift_m: ``(N, 3) -> (N,)`` how far a point may move within its face when the part
            lies misplaced, metres (grows the footprint); ``None``: no shift.
        face_ids: the faces to sample (default all).
    """
    rng = np.random.default_rng(CANDIDATE_SEED)
    mesh = faces.mesh
    tri = np.asarray(mesh.triangles, dtype=np.float64)
    area = np.asarray(mesh.area_faces, dtype=np.float64)
    P_all, N_all, F_all, tried = [], [], [], []
    for fid in range(len(faces.faces)) if face_ids is None else face_ids:
        stats = faces.faces[fid]
        on = np.flatnonzero(faces.face_id == fid)
        n_raw = 6 * per_face
        pick = on[rng.choice(len(on), size=n_raw, p=area[on] / area[on].sum())]
        uv = rng.uniform(size=(n_raw, 2))
        flip = uv.sum(axis=1) > 1.0
        uv[flip] = 1.0 - uv[flip]
        t = tri[pick]
        P = t[:, 0] + uv[:, :1] * (t[:, 1] - t[:, 0]) + uv[:, 1:] * (t[:, 2] - t[:, 0])
        normal = np.asarray(stats.normal, dtype=np.float64)
        N = np.repeat(normal[None], n_raw, axis=0)
        grow = np.zeros(n_raw) if shift_m is None else np.asarray(shift_m(P), dtype=np.float64)
        # the footprint and rings out to the grown radius (every footprint radius of ring
        # samples, so a hole between the rim samples of a large ring is not missed); one
        # batched check per distinct radius (rounded up to 1 mm)
        grown = footprint_radius_m + np.ceil(grow * 1e3) * 1e-3
        ok = np.ones(n_raw, dtype=bool)
        reason = ""
        step = max(footprint_radius_m, 1e-3)
        for r in np.unique(grown):
            sel = np.flatnonzero(grown == r)
            for ring in np.unique(np.minimum(footprint_radius_m + step * np.arange(64), r)):
                sel = sel[ok[sel]]
                if len(sel) == 0:
                    break
                checks = check_probe_faces(faces, P[sel], N[sel], footprint_radius_m=float(ring))
                for i, c in zip(sel, checks, strict=True):
                    good = c.ok and c.face_id == fid
                    ok[i] = good
                    if not good and not reason:
                        reason = c.reason or "lands on another face"
        kept = np.flatnonzero(ok)
        tried.append(FaceTried(fid, normal, stats.area_m2, n_raw, len(kept), reason))
        if len(kept) == 0:
            continue
        spread = kept[_farthest_points(P[kept], per_face)]
        P_all.append(P[spread])
        N_all.append(N[spread])
        F_all.append(np.full(len(spread), fid, dtype=np.int64))
    if not P_all:
        return Candidates(np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int64), tuple(tried))
    return Candidates(
        np.concatenate(P_all), np.concatenate(N_all), np.concatenate(F_all), tuple(tried)
    )


def _farthest_points(P: FloatArray, k: int) -> IntArray:
    """Indices of ``k`` points of ``P`` spread by farthest-point sampling (the first is the
    farthest from the centroid, so the extremes come early)."""
    if len(P) <= k:
        return np.arange(len(P))
    d = np.linalg.norm(P - P.mean(axis=0), axis=1)
    out = [int(np.argmax(d))]
    dist = np.linalg.norm(P - P[out[0]], axis=1)
    while len(out) < k:
        j = int(np.argmax(dist))
        out.append(j)
        dist = np.minimum(dist, np.linalg.norm(P - P[j], axis=1))
    return np.asarray(out, dtype=np.int64)
