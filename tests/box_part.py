"""An ideal analytic stator box and a noise-free probe over it (procedure and export tests).

The box is the stator-like part in its true WOCS: x in [-0.25, 0], y in [-1.2, 0],
z in [-0.40, 0] (side face x = 0, short side y = 0, top z = 0).
"""

from __future__ import annotations

import numpy as np

from calib.frames import invert_transform, transform_directions, transform_points
from calib.probing import ProbeResult, SearchCommand

BOX_LO = np.array([-0.25, -1.2, -0.40])
BOX_HI = np.zeros(3)


def slab(start: np.ndarray, direction: np.ndarray, lo: np.ndarray, hi: np.ndarray):
    """Entry parameter and entry axis of the line ``start + t d`` into the box, or None."""
    t_in, t_out, axis_in = -np.inf, np.inf, -1
    for k in range(3):
        if abs(direction[k]) < 1e-15:
            if not lo[k] <= start[k] <= hi[k]:
                return None
            continue
        t1, t2 = (lo[k] - start[k]) / direction[k], (hi[k] - start[k]) / direction[k]
        near, far = min(t1, t2), max(t1, t2)
        if near > t_in:
            t_in, axis_in = near, k
        t_out = min(t_out, far)
    if t_in > t_out or t_out < 0:
        return None
    return t_in, axis_in


def distance_to_box(p_wobj: np.ndarray) -> float:
    """Distance of a point (true wobj frame, m) from the box; negative inside."""
    d_out = np.maximum(BOX_LO - p_wobj, p_wobj - BOX_HI)
    outside = np.linalg.norm(np.maximum(d_out, 0.0))
    return float(outside) if outside > 0 else float(d_out.max())


class BoxProbe:
    """Ideal noise-free sensor on a box posed at ``T_base_true``.

    Approach: the first point where the commanded line enters the box. Edge: the foot of the
    sensor axis on the face it looks at moves with the TCP; the event is where that foot
    leaves the face (reaches an edge). Both return the commanded TCP at the event, as a robot
    controller records it.
    """

    def __init__(self, T_base_true: np.ndarray, offset_wobj=(0.0, 0.0, 0.0), fail=()) -> None:
        self.T_true_base = invert_transform(T_base_true)
        self.T_base_true = T_base_true
        self.lo = BOX_LO + np.asarray(offset_wobj)
        self.hi = BOX_HI + np.asarray(offset_wobj)
        self.fail = set(fail)
        self.calls: list[str] = []

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        self.calls.append(cmd.point_id)
        if cmd.point_id in self.fail:
            return ProbeResult(None, "sensor already detecting at start")
        s = transform_points(self.T_true_base, cmd.start_m)
        d = transform_directions(self.T_true_base, cmd.direction)
        if cmd.kind == "approach":
            if np.all(s >= self.lo) and np.all(s <= self.hi):
                return ProbeResult(None, "sensor already detecting at start")
            hit = slab(s, d, self.lo, self.hi)
            if hit is None or hit[0] > cmd.length_m:
                return ProbeResult(None, f"no detection within {cmd.length_m * 1e3:.0f} mm")
            q, t = s + hit[0] * d, hit[0]
        else:
            a = transform_directions(self.T_true_base, cmd.sensor_axis)
            look = slab(s - 0.05 * a, a, self.lo, self.hi)
            if look is None:
                return ProbeResult(None, "no face under the sensor at start")
            k = look[1]
            face = (s - 0.05 * a)[k] + look[0] * a[k]
            q0 = s + (face - s[k]) / a[k] * a
            w = d - d[k] / a[k] * a
            ts = [
                ((self.hi[m] if w[m] > 0 else self.lo[m]) - q0[m]) / w[m]
                for m in range(3)
                if m != k and abs(w[m]) > 1e-15
            ]
            t = min(ts)
            if t > cmd.length_m:
                return ProbeResult(None, "the face did not end within the search")
            q = s + t * d
        return ProbeResult(transform_points(self.T_base_true, q), travel_m=float(t))
