"""Settings of the paper's A-H procedure: the one definition the plan, the procedure, the
simulation and the adaptive RAPID program all read.

In a plan file this is ``"procedure": {"method": "hultman2013", ...}`` (``method`` is the tag
of the procedure union, :data:`calib.procedures.ProcedureSettings`).
"""

from __future__ import annotations

import math

import msgspec

from calib.errors import PlanError
from calib.paper.xoffset import SlotGrid
from calib.structs import Strict, check_length, check_positive, check_search_lengths


class XOffsetRun(Strict, frozen=True, kw_only=True):
    """The paper's x-offset run (section 3.2, eq. 13-14) after the frame is fixed.

    Over every second tooth at two slot-hole levels the side face is measured along the WOCS
    x axis in the calibrated frame; eq. 14 interpolates these into the x-offset of every slot
    hole (:func:`calib.paper.xoffset.xoffset_matrix`), which the slot targets then use.

    Attributes:
        grid: the slot holes of the side face the robot works on (WOCS).
        layers: 1-based layers whose level the measurements are taken at (default: the first
            and the last, the paper's "two different slot hole levels").
        teeth: teeth measured over (tooth t lies between slots t and t + 1; default every
            second tooth 1, 3, 5, ...).
        start_offset_m: start of each approach outside the calibrated face, metres.
        overtravel_m: allowed travel past the calibrated face, metres.
    """

    grid: SlotGrid
    layers: tuple[int, ...] | None = None
    teeth: tuple[int, ...] | None = None
    start_offset_m: float = 0.020
    overtravel_m: float = 0.020

    def __post_init__(self) -> None:
        check_positive(self.start_offset_m, "start_offset_m")
        check_positive(self.overtravel_m, "overtravel_m")
        check_search_lengths(self.start_offset_m, self.overtravel_m)
        for field, values, top in (
            ("layers", self.layers, self.grid.n_layers),
            ("teeth", self.teeth, self.grid.n_slots),
        ):
            check_length(values or (), field, top, "values", "one per layer or tooth of the grid")
        for field, values, check in (
            ("layers", self.layers, lambda v: self.grid.check_slot(1, v)),
            ("teeth", self.teeth, self.grid.tooth_y_m),
        ):
            if values is not None and len(set(values)) < 2:
                raise PlanError(f"{field}: needs at least 2 distinct values, got {list(values)}")
            for v in values or ():
                try:
                    check(v)
                except ValueError as exc:
                    raise PlanError(f"{field}: {exc}") from None


class Hultman2013(
    msgspec.Struct,
    tag="hultman2013",
    tag_field="method",
    frozen=True,
    forbid_unknown_fields=True,
    kw_only=True,
):
    """Settings of the paper's A-H procedure (Hultman & Leijon 2013, section 3.2).

    Attributes:
        p3_height_m: height of the constructed point P3 above B (eq. 12), metres (paper: 50 mm).
        beta1_rad: assumed inclination of the stator side from vertical (eq. 12), radians
            (paper: 15 deg; positive when the face's top leans towards base +x, see
            :func:`calib.paper.hultman.p3_estimate`).
        retake_c_d: measure C and D again at the end, as the paper does (``"C2"``, ``"D2"``);
            when False the first C and D are reused for the final origin.
        edge_start_from_measured: start the edge search F at the measured E and H at the
            measured G, shifted ``edge_start_offset_m`` along the estimated WOCS +x (the
            paper's literal wording); when False (default) F and H start where the plan's
            search says (e.g. at E's and G's nominal height). The search still runs up to the
            height where the plan's search ends.
        edge_start_offset_m: the paper's "few millimeters" offset in +x of that start, metres.
        edge_event_offset_m: how far past the true edge, along the search direction, the
            sensor reports it (a sensor characteristic measured once on a reference edge;
            footprint and hysteresis make it a few mm), metres; subtracted from F and H.
            ``None``: not measured; every face (the programs, ``wobjcal calibrate``, check and
            validate) then uses the sensor model's analytic value
            (``planner.program.settings.resolved_settings``); :attr:`edge_offset_m` reads 0.
        xoffset: the x-offset run after the frame is fixed (eq. 13-14), or ``None``.
    """

    p3_height_m: float = 0.050
    beta1_rad: float = math.radians(15.0)
    retake_c_d: bool = True
    edge_start_from_measured: bool = False
    edge_start_offset_m: float = 0.0
    edge_event_offset_m: float | None = None
    xoffset: XOffsetRun | None = None

    def __post_init__(self) -> None:
        beta1 = float(self.beta1_rad)
        if not (math.isfinite(beta1) and abs(beta1) < math.pi / 2):
            raise PlanError(f"beta1_rad: must lie in (-pi/2, pi/2), got {beta1}")
        check_positive(self.p3_height_m, "p3_height_m")
        check_positive(self.edge_start_offset_m, "edge_start_offset_m", allow_zero=True)
        if self.edge_event_offset_m is not None and not math.isfinite(self.edge_event_offset_m):
            raise PlanError(f"edge_event_offset_m: must be finite, got {self.edge_event_offset_m}")

    @property
    def edge_offset_m(self) -> float:
        """The edge-event offset the procedure removes from F and H, m (0 when unset)."""
        return 0.0 if self.edge_event_offset_m is None else float(self.edge_event_offset_m)
