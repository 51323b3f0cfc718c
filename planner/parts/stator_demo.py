"""The built-in demo: a stator section inclined on a table before an IRB 4400, and the A-H plan.

The Python objects here are the single source of the demo; ``assets/plans/stator_section_ah.json``
is serialised from them.

Placement (robot base frame, metres): the side face leans back by ``beta1 = 15 deg`` (its top is
farther from the robot than its bottom, so the face looks towards the robot and slightly up, the
paper's assumed inclination, eq. 12), the section runs along base ``-y`` (wobj ``+y`` = base
``-y``), and its WOCS origin (top corner at the short side) lies at ``(1.20, -0.50, 1.00)``, so
the first metre of the side face (the part one robot winds) spans base ``y`` from -0.5 to +0.5,
centred in front of the robot, 1.2 m away and 1 m up. Closer or lower placements put joint 3 of
the built-in IRB 4400 at its limit for the yoke points (checked with ``Cell.check_probes``).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from calib.errors import ShapeError
from calib.frames import make_transform
from calib.paper.settings import XOffsetRun
from calib.paper.xoffset import SlotGrid
from calib.plan.report_spec import PointOfInterest, RegionSpec, ReportSpec
from calib.probing import ProbePoint, SearchSpec
from planner.parts.stator import StatorGeometry

FloatArray = NDArray[np.float64]

#: Inclination of the side face in the robot base frame (paper eq. 12: beta1 = 15 deg), rad.
BETA1_RAD = math.radians(15.0)
#: Where the WOCS origin lies in the robot base frame, m.
ORIGIN_BASE_M = (1.20, -0.50, 1.00)

_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def nominal_T_base_wobj(
    beta1_rad: float = BETA1_RAD, origin_m: tuple[float, float, float] = ORIGIN_BASE_M
) -> FloatArray:
    """``(4, 4)`` nominal pose of the stator WOCS in the robot base frame.

    Columns: wobj x = ``(-cos b, 0, sin b)`` (towards the robot, tilted up), wobj y =
    ``(0, -1, 0)``, wobj z = ``(sin b, 0, cos b)`` (up, leaning away from the robot).
    """
    c, s = math.cos(beta1_rad), math.sin(beta1_rad)
    R = np.array([[-c, 0.0, s], [0.0, -1.0, 0.0], [s, 0.0, c]])
    return make_transform(R, np.asarray(origin_m, float))


def stator_ah_points(
    geom: StatorGeometry | None = None,
    approach: SearchSpec | None = None,
    edge_overtravel_m: float = 0.050,
) -> dict[str, ProbePoint]:
    """The paper's A-H points (Fig. 8a) on ``geom``, wobj frame, placed to avoid slot holes.

    - A, B: approach on the yoke, mid-height of the yoke; A 600 mm, B 100 mm from the short side.
    - C: approach on the short side, 30 mm behind the side face, at the yoke's height.
    - D, E: approach over tooth 4 (between slots 4 and 5, 100 mm from the short side), each
      centred on the solid web between two layers (D below layer 1, E below layer 5), where
      the 18 mm face covers only metal.
    - F: edge search up the same tooth from E's height to the top edge.
    - G: approach over tooth 21 (about 0.5 m from the short side) at E's height; H: edge
      search up from G.

    Args:
        geom: the stator (default full section).
        approach: search of the approach points (default: start 50 mm out, 60 mm overtravel:
            covers 20 mm and 3 deg of misplacement about the middle of the probed region).
        edge_overtravel_m: how far past the nominal top edge F and H may search, m.
    """
    g = geom or StatorGeometry.full_section()
    spec = approach or SearchSpec("approach", start_offset_m=0.050, overtravel_m=0.060)
    yoke_z = 0.5 * (g.slot_region_bottom_m - g.height_m)
    teeth, webs = g.tooth_y_m, g.web_z_m
    if len(teeth) < 21 or len(webs) < 5:
        raise ShapeError("stator_ah_points needs at least 22 slots and 6 layers")
    y_def, y_ghi = float(teeth[3]), float(teeth[20])
    z_d, z_e = float(webs[0]), float(webs[4])

    def side(pid: str, y: float, z: float) -> ProbePoint:
        return ProbePoint(pid, (0.0, y, z), _X, spec)

    def edge(pid: str, y: float, start_z: float) -> ProbePoint:
        return ProbePoint(
            pid, (0.0, y, 0.0), _X, SearchSpec("edge", -start_z, edge_overtravel_m, _Z), _Z
        )

    return {
        "A": side("A", -0.600, yoke_z),
        "B": side("B", -0.100, yoke_z),
        "C": ProbePoint("C", (-0.030, 0.0, yoke_z), _Y, spec),
        "D": side("D", y_def, z_d),
        "E": side("E", y_def, z_e),
        "F": edge("F", y_def, z_e),
        "G": side("G", y_ghi, z_e),
        "H": edge("H", y_ghi, z_e),
    }


def demo_table(
    geom: StatorGeometry, T_base_wobj: FloatArray | None = None
) -> tuple[tuple[float, float, float], FloatArray]:
    """Size ``(3,)`` (m) and pose ``(4, 4)`` (base = world) of the demo table box.

    The table top lies 50 mm below the lowest corner of the inclined section (its wedge support
    is not modelled); it is 0.6 m deep and the section's length plus 0.2 m long.
    """
    T = nominal_T_base_wobj() if T_base_wobj is None else np.asarray(T_base_wobj, float)
    g = geom
    corners = np.array(
        [
            [x, y, z, 1.0]
            for x in (0.0, -g.depth_m)
            for y in (0.0, -g.length_m)
            for z in (0.0, -g.height_m)
        ]
    )
    world = corners @ T.T
    top_z = float(world[:, 2].min()) - 0.05
    size = (0.6, g.length_m + 0.2, 0.05)
    centre = (float(world[:, 0].min()) + 0.3, float(world[:, 1].mean()), top_z - 0.025)
    return size, make_transform(None, centre)


#: The paper's Table 1 rows: origin and epsilon in the yz-plane, the stator side (slot holes
#: within the robot's metre), at the paper's confidence levels.
STATOR_REPORT = ReportSpec(
    levels_percent=(95.5, 99.99),
    points_of_interest=[
        PointOfInterest(
            name="origin",
            position_m=(0.0, 0.0, 0.0),
            components="yz",
            label="WOCS yz-plane origin",
            levels_percent=(95.5, 99.0, 99.9),
        ),
        PointOfInterest(
            name="epsilon",
            position_m=(0.0, -1.0, -0.1),
            components="yz",
            label="WOCS yz-plane at epsilon",
            levels_percent=(95.5, 99.0, 99.9),
        ),
    ],
    regions=[
        RegionSpec(
            name="slots",
            points="slot_holes",
            components="yz",
            label="WOCS yz-plane stator side",
            levels_percent=(95.5, 99.99, 99.999, 99.9999),
        )
    ],
)


def stator_xoffset(geom: StatorGeometry) -> XOffsetRun:
    """The paper's x-offset run over the slot holes within the robot's reach of ``geom``:
    every second tooth at the first and the last slot-hole layer (section 3.2)."""
    slots = geom.slot_y_m
    n_slots = int(sum(slots >= -geom.reach_length_m - 1e-9))
    return XOffsetRun(
        grid=SlotGrid(
            n_slots=n_slots,
            n_layers=geom.n_layers,
            first_slot_y_m=float(slots[0]),
            first_layer_z_m=float(geom.layer_z_m[0]),
            slot_step_y_m=-geom.slot_pitch_m,
            layer_step_z_m=-geom.layer_pitch_m,
        )
    )
