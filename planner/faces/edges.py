"""Edge-search candidates along the straight edges of planar faces, for ``wobjcal suggest``.

An edge search (``calib.probing``, kind ``"edge"``) slides the sensor over a face toward one of
its edges until the face ends; it measures only the edge's coordinate across the edge (the
row :func:`calib.estimators.layout.search_constraint_set` gives it). Candidates lie on the
straight segments of a face's outer outline (:meth:`planner.faces.outline.FaceOutlines.face`)
long enough for a few footprints, at a quarter, half and three quarters of each; the search
moves along the segment's outward in-plane normal, which is also the other face's normal at a
square edge (``edge_normal``). A candidate is kept when its whole track, from a start
``start_m`` inside the edge to the edge, keeps the footprint on the face (the face eroded by
the footprint radius, :meth:`~planner.faces.outline.FaceOutlines.free`) even when moved in
the plane by the misplacement (a hole beside the track would end the search early).

The design and the prediction take the edge as square (the face across it along the search
direction), and the sensor's edge-event offset is that of a square edge; a chamfer, a fillet
or a sloped side is seen by the rays past the edge and moves the event by an amount nothing
models. So a segment is used only when the mesh says it is square: the triangles across every
mesh edge along it (:meth:`~planner.faces.outline.FaceOutlines.rim`) must cover it
(:data:`MIN_RIM_COVER`) and have their normals within :data:`SQUARE_TOL_RAD` of the search
direction (:func:`square_edge`).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry.polygon import orient

from planner.faces.candidates import Candidates, FaceTried
from planner.faces.outline import FaceOutlines

FloatArray = NDArray[np.float64]

#: Where along a straight edge the candidates lie (fractions of its length).
FRACTIONS = (0.25, 0.5, 0.75)
#: Straight segments shorter than this many footprint diameters get no candidate.
MIN_EDGE_FOOTPRINTS = 3.0
#: The track's end is checked this far inside the eroded outline's rim, metres.
_INSIDE_M = 1e-4
#: Largest angle between the face across an edge and the search direction (a draft of a few
#: degrees hides the side from the rays past the edge; a 45 degree chamfer does not), radians.
SQUARE_TOL_RAD = float(np.radians(3.0))
#: Least part of a segment's length the mesh edges along it must cover to show what is across.
MIN_RIM_COVER = 0.95
#: A mesh edge lies on a segment when both its ends are this close to it, metres.
_ON_SEGMENT_M = 1e-4


def square_edge(
    ends: FloatArray, across: FloatArray, a: FloatArray, b: FloatArray, out3: FloatArray
) -> bool:
    """Whether the mesh shows a square edge along the segment ``a``-``b`` of a face's outline.

    Args:
        ends: ``(E, 2, 2)`` the face's boundary edges in its basis (metres).
        across: ``(E, 3)`` the unit normal of the triangle across each.
        a, b: ``(2,)`` the segment's ends in the same basis.
        out3: ``(3,)`` the search direction (the segment's outward normal, wobj frame).

    Returns:
        True when the edges along the segment cover :data:`MIN_RIM_COVER` of it and every
        triangle across is within :data:`SQUARE_TOL_RAD` of ``out3``.
    """
    seg = b - a
    length = float(np.linalg.norm(seg))
    along = seg / length
    normal2 = np.array([-along[1], along[0]])
    rel = ends - a  # (E, 2, 2)
    off = np.abs(rel @ normal2)  # (E, 2)
    t = rel @ along  # (E, 2)
    on = (off.max(axis=1) <= _ON_SEGMENT_M) & (t.min(axis=1) >= -_ON_SEGMENT_M)
    on &= t.max(axis=1) <= length + _ON_SEGMENT_M
    if not on.any():
        return False
    cover = float(np.sum(np.abs(t[on, 1] - t[on, 0])))
    if cover < MIN_RIM_COVER * length:
        return False
    return bool(np.all(across[on] @ out3 >= np.cos(SQUARE_TOL_RAD)))


def edge_candidates(
    outlines: FaceOutlines,
    face_ids: Sequence[int],
    footprint_radius_m: float,
    start_m: float,
    shift_m: float,
) -> Candidates:
    """Edge searches toward the straight outer edges of ``face_ids`` (wobj frame, metres).

    Args:
        outlines: the part's face outlines with the sensor footprint.
        face_ids: the faces the searches slide over.
        footprint_radius_m: the sensor footprint's radius, metres.
        start_m: how far inside the edge each search starts, metres.
        shift_m: how far the track may lie off its nominal in the face's plane when the part
            lies misplaced (the whole misplacement: the approaches measured before an edge
            search fix its height and tilts only), metres.
    """
    P: list[FloatArray] = []
    N: list[FloatArray] = []
    F: list[int] = []
    D: list[FloatArray] = []
    min_len = MIN_EDGE_FOOTPRINTS * 2 * footprint_radius_m
    for fid in face_ids:
        B = outlines.basis(fid)
        n = outlines.normal(fid)
        h = outlines.height_m(fid)
        free = outlines.free(fid)
        rim_ends, rim_across = outlines.rim(fid)
        shape = outlines.face(fid).simplify(1e-6)
        polys = list(shape.geoms) if hasattr(shape, "geoms") else [shape]
        for poly in polys:
            ring = np.asarray(orient(poly, 1.0).exterior.coords, dtype=np.float64)
            for a, b in itertools.pairwise(ring):
                seg = b - a
                length = float(np.linalg.norm(seg))
                if length < min_len:
                    continue
                out = np.array([seg[1], -seg[0]]) / length  # outward: exterior is CCW
                along = seg / length
                if not square_edge(rim_ends, rim_across, a, b, B @ out):
                    continue
                for t in FRACTIONS:
                    c = a + t * seg
                    # the track from its start (moved back by the shift) to a footprint radius
                    # inside the edge, moved sideways by the shift either way
                    far = c - (start_m + shift_m) * out
                    near = c - (footprint_radius_m + _INSIDE_M) * out
                    track = shapely.Polygon(
                        [
                            far - shift_m * along,
                            near - shift_m * along,
                            near + shift_m * along,
                            far + shift_m * along,
                        ]
                    )
                    if not free.contains(track):
                        continue
                    P.append(B @ c + h * n)
                    N.append(n)
                    F.append(int(fid))
                    D.append(B @ out)
    tried: tuple[FaceTried, ...] = ()
    if not P:
        z = np.zeros((0, 3))
        return Candidates(z, z, np.zeros(0, np.int64), tried, z)
    return Candidates(np.array(P), np.array(N), np.array(F, np.int64), tried, np.array(D))
