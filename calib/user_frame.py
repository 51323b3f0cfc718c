"""A user frame from three taught points, as a robot controller's 3-point user frame, and the
re-expression of probe points in a new frame.

Three points ``origin``, ``on_x`` (a point on +x) and ``in_xy`` (a point in the xy-plane on
the +y side) give the frame ``x = (on_x - origin) / |on_x - origin|``,
``z = x × (in_xy - origin)`` normalised, ``y = z × x``, origin at ``origin``: ABB's
"3-point" user frame and KUKA's "3-point" base measurement work this way.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.errors import InputError
from calib.frames import make_transform, transform_directions, transform_points
from calib.probing import ProbePoint

FloatArray = NDArray[np.float64]

#: Two taught points closer than this are the same point, m.
MIN_SEPARATION_M = 1e-3
#: The third point must lie at least this far off the x axis, m (not collinear).
MIN_OFF_AXIS_M = 1e-3

__all__ = ["MIN_OFF_AXIS_M", "MIN_SEPARATION_M", "probe_point_in", "three_point_frame"]


def _vec3(value: ArrayLike, name: str) -> FloatArray:
    v = np.asarray(value, dtype=np.float64)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InputError(f"{name}: must be 3 finite coordinates, got {np.asarray(value).tolist()}")
    return v


def three_point_frame(origin: ArrayLike, on_x: ArrayLike, in_xy: ArrayLike) -> FloatArray:
    """``(4, 4)`` the frame taught by three points, in the frame the points are given in.

    Args:
        origin: ``(3,)`` the new frame's origin, m.
        on_x: ``(3,)`` a point on the new +x axis, m.
        in_xy: ``(3,)`` a point in the new xy-plane on its +y side, m.

    Returns:
        ``T_ref_frame``: the new frame in the points' frame ``ref``.

    Raises:
        InputError: two points coincide (closer than :data:`MIN_SEPARATION_M`), or the three
            are collinear (the third within :data:`MIN_OFF_AXIS_M` of the x axis); the message
            names the points and the distance.
    """
    o, px, pxy = _vec3(origin, "origin"), _vec3(on_x, "+x point"), _vec3(in_xy, "xy-plane point")
    names = (("origin", o), ("+x point", px), ("xy-plane point", pxy))
    for i in range(3):
        for j in range(i + 1, 3):
            d = float(np.linalg.norm(names[i][1] - names[j][1]))
            if d < MIN_SEPARATION_M:
                raise InputError(
                    f"the {names[i][0]} and the {names[j][0]} coincide ({d * 1000:.3f} mm "
                    f"apart, at least {MIN_SEPARATION_M * 1000:g} mm needed): pick them apart"
                )
    x = (px - o) / np.linalg.norm(px - o)
    z = np.cross(x, pxy - o)
    off_axis = float(np.linalg.norm(z))  # distance of the third point from the x axis
    if off_axis < MIN_OFF_AXIS_M:
        raise InputError(
            f"the three points are collinear: the xy-plane point is {off_axis * 1000:.3f} mm "
            f"from the line origin -> +x (at least {MIN_OFF_AXIS_M * 1000:g} mm needed): pick "
            "it off that line, on the +y side"
        )
    z /= off_axis
    y = np.cross(z, x)
    return make_transform(np.column_stack([x, y, z]), o)


def probe_point_in(T_new_old: ArrayLike, point: ProbePoint) -> ProbePoint:
    """``point`` (position, normal, edge direction and edge normal) re-expressed in another
    frame: ``p_new = T_new_old @ p_old``; the same physical point."""
    T = np.asarray(T_new_old, dtype=np.float64)

    def pos(v: ArrayLike) -> tuple[float, float, float]:
        p = transform_points(T, v)
        return (float(p[0]), float(p[1]), float(p[2]))

    def direction(v: ArrayLike) -> tuple[float, float, float]:
        d = transform_directions(T, v)
        d = d / np.linalg.norm(d)
        return (float(d[0]), float(d[1]), float(d[2]))

    search = point.search
    if search.edge_direction is not None:
        search = dataclasses.replace(search, edge_direction=direction(search.edge_direction))
    edge_normal = None if point.edge_normal is None else direction(point.edge_normal)
    return dataclasses.replace(
        point,
        position_m=pos(point.position_m),
        normal=direction(point.normal),
        search=search,
        edge_normal=edge_normal,
    )
