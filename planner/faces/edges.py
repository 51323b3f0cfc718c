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
