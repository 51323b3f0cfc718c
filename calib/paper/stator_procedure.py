"""The paper's A-H calibration procedure for the UU WEC stator section (section 3.2).

The procedure never moves anything. It builds each search with
:meth:`calib.probing.SearchCommand.from_point` in the WOCS estimated so far, asks the
``probe`` callback for the result, and updates the estimate with the equations of
:mod:`calib.paper.hultman`, in the paper's order:

1. A, B measured in the preliminary WOCS; alpha1 and P3 (eq. 11-12); rotation from A, B, P3
   (eq. 1-9).
2. B as P4 adjusts the x origin (eq. 10).
3. C (short side) as P5 adjusts the y origin.
4. D, E over a tooth; rotation from ``V1 = B - A`` and ``V2 = D - E`` (eq. 2-9), which turns
   the WOCS about its y and z axes onto the side face.
5. E adjusts the x origin (the paper writes "P5_W", but says it fixes the x origin: E is used
   as P4, the x point of eq. 10).
6. F (edge search up the side face), G, then H (edge search started from G); final rotation
   from H = P1, F = P2, D = P3 with V2 inverted (eq. 1-9).
7. H as P6 adjusts the z origin.
8. C retaken (``"C2"``) as P5 adjusts y; 9. D retaken (``"D2"``) as P4 adjusts x.

Errors: a failed probe raises :class:`calib.errors.ProbeFailedError` with the measurement's
key (``"A"``... ``"H"``, ``"C2"``, ``"D2"``) and the probe's reason; bad layouts raise
:class:`calib.errors.InputError` subclasses before any probe is called. Probes return
the sensor-TCP position the robot records at the event. For the edge searches F and H that is
on the side face: by then the WOCS yz-plane is the plane measured through A, B, D, E and the
search runs in it. When an edge search is started ``edge_start_offset_m`` outside the face
(:class:`calib.paper.settings.Hultman2013`), F and H are moved back by that offset before use;
a point left off
the face by ``d`` would tilt the final WOCS by about ``d / |F - D|``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_vector3
from calib.errors import DegenerateGeometryError, ProbeFailedError, ShapeError
from calib.frames import check_transform
from calib.paper.hultman import (  # the unchecked kernels: inputs are checked here, once
    _rotation_from_points,
    _rotation_from_vectors,
    _shift_origin,
    p3_estimate,
)
from calib.paper.settings import Hultman2013
from calib.paper.stator_layout import (
    STATOR_POINT_IDS,
    StatorLayout,
    check_stator_points,
    example_stator_points,
    relabel_point,
)
from calib.probing import Probe, ProbePoint, ProbeResult, SearchCommand
from calib.procedure_run import EstimateUpdate, ProbeStep, ProcedureRun

__all__ = [
    "STATOR_POINT_IDS",
    "StatorLayout",
    "check_stator_points",
    "example_stator_points",
    "probe_from_measurements",
    "run_stator_procedure",
]

FloatArray = NDArray[np.float64]


def probe_from_measurements(measured_m: Mapping[str, ArrayLike]) -> Probe:
    """A probe that replays measured points (base frame, metres) by measurement key.

    Use it to compute the calibration from points measured on a real robot: the keys are the
    measurement keys of the procedure (``"A"`` ... ``"H"``, ``"C2"``, ``"D2"``).
    """
    table = {k: check_vector3(v, f"measured_m[{k!r}]") for k, v in measured_m.items()}

    def probe(command: SearchCommand) -> ProbeResult:
        point = table.get(command.point_id)
        if point is None:
            return ProbeResult(None, f"no measurement for {command.point_id!r}")
        return ProbeResult(point.copy(), travel_m=float("nan"))

    return probe


class _Run:
    """State of one run: the estimate, the measurements and the steps so far."""

    def __init__(self, layout: StatorLayout, T: FloatArray, probe: Probe) -> None:
        self.layout = layout
        self.T = T
        self.probe = probe
        self.measured: dict[str, FloatArray] = {}
        self.commands: dict[str, SearchCommand] = {}
        self.probes: list[ProbeStep] = []
        self.updates: list[EstimateUpdate] = []

    def measure(
        self, point_id: str, key: str | None = None, start_m: FloatArray | None = None
    ) -> FloatArray:
        """Probe ``point_id`` in the current estimate; ``start_m`` replaces the start (base)."""
        key = point_id if key is None else key
        point = relabel_point(self.layout.points[point_id], key)
        command = SearchCommand.from_point(point, self.T)
        if start_m is not None:  # run up to where the plan's search ends, along its direction
            end = command.start_m + command.length_m * command.direction
            length = float(command.direction @ (end - start_m))
            if length <= 0.0:
                raise ProbeFailedError(key, "the measured start lies past the end of the search")
            command = replace(command, start_m=start_m, length_m=length)
        self.commands[key] = command
        result = self.probe(command)
        if not isinstance(result, ProbeResult):
            raise ShapeError(
                f"probe must return a ProbeResult, got {type(result).__name__} for point {key}"
            )
        if result.point_m is None:
            raise ProbeFailedError(key, result.reason or "the probe gave no reason")
        p = check_vector3(result.point_m, f"probe result for point {key}")
        self.measured[key] = p
        own_id = self.layout.points[point_id].id  # the point's own (plan) id
        self.probes.append(ProbeStep(own_id, int(key != point_id), command, p))
        return p

    def step(self, T: FloatArray, name: str, ids: tuple[str, ...], equations: str) -> None:
        self.T = T
        self.updates.append(EstimateUpdate(T, name, ids, equations))

    def origin(self, axis: int, key: str, name: str, point: FloatArray | None = None) -> None:
        face = self.layout.face_coords_wobj[axis]
        p = self.measured[key] if point is None else point
        T = _shift_origin(self.T, axis, p, face)
        self.step(T, name, (key,), "eq. 10")

    def rotate(self, R: FloatArray, name: str, ids: tuple[str, ...], equations: str) -> None:
        T = self.T.copy()
        T[:3, :3] = R
        self.step(T, name, ids, equations)


def run_stator_procedure(
    points: Mapping[str, ProbePoint] | Sequence[ProbePoint] | StatorLayout,
    T_base_wobj_prelim: ArrayLike,
    probe: Probe | Callable[[SearchCommand], ProbeResult],
    settings: Hultman2013 | None = None,
) -> ProcedureRun:
    """Run the paper's A-H procedure (section 3.2) with ``probe`` and return the calibrated WOCS.

    Args:
        points: the nominal probe points A-H (wobj frame), or a layout from
            :func:`check_stator_points` (validated once; pass it when running many times).
        T_base_wobj_prelim: ``(4, 4)`` the preliminary ``T_base_wobj`` the first searches are
            commanded in.
        probe: runs one search and returns its result.
        settings: the A-H settings (beta1, P3 height, retakes, edge starts and offset); the
            paper's values by default.

    Returns:
        The final frame, the points' own ids in A-H order (``used_ids``), every measurement
        by measurement key (``"A"`` ... ``"H"``, the retakes ``"C2"``, ``"D2"``: ``measured_m``
        and the commands), the estimate after every step and the constructed ``"P3"`` (eq. 12).

    Raises:
        ProbeFailedError: a probe returned no point (``point_id`` is the measurement key).
        InputError: bad layout, frame or settings; a probe result that is not a finite
            ``(3,)`` point; measured points that define no frame (DegenerateGeometryError).
    """
    layout = check_stator_points(points)
    cfg = Hultman2013() if settings is None else settings
    T0 = check_transform(T_base_wobj_prelim, "T_base_wobj_prelim")
    if T0.shape != (4, 4):
        raise ShapeError(f"T_base_wobj_prelim must be (4, 4), got {T0.shape}")
    run = _Run(layout, T0, probe)

    a, b = run.measure("A"), run.measure("B")
    p3 = p3_estimate(a, b, cfg.beta1_rad, cfg.p3_height_m)
    R1 = _rotation_from_points(a, b, p3, False, ("A", "B", "P3"))
    run.rotate(R1, "preliminary rotation from A, B, P3", ("A", "B"), "eq. 1-9, 11-12")
    run.origin(0, "B", "x origin from B (P4)")

    run.measure("C")
    run.origin(1, "C", "y origin from C (P5)")

    d, e = run.measure("D"), run.measure("E")
    R2 = _rotation_from_vectors(b - a, d - e, ("V1 = B - A", "V2 = D - E"))
    run.rotate(R2, "rotation about y and z from A, B, D, E", ("A", "B", "D", "E"), "eq. 2-9")
    run.origin(0, "E", "x origin from E (P4; the paper's 'P5_W')")

    # F: edge search up the tooth over D and E; G, then H: edge search up from G (eq. 1-9)
    from_measured = cfg.edge_start_from_measured
    x_now, off = run.T[:3, 0].copy(), cfg.edge_start_offset_m
    f = run.measure("F", start_m=e + off * x_now if from_measured else None)
    g = run.measure("G")
    h = run.measure("H", start_m=g + off * x_now if from_measured else None)
    if from_measured:  # the TCP ran `off` outside the face: back onto it
        f, h = f - off * x_now, h - off * x_now
    if cfg.edge_offset_m:  # the sensor reports the edge this far past it
        f = f - cfg.edge_offset_m * run.commands["F"].direction
        h = h - cfg.edge_offset_m * run.commands["H"].direction
    R3 = _rotation_from_points(h, f, d, True, ("H", "F", "D"))
    run.rotate(R3, "final rotation from H, F, D (V2 inverted)", ("H", "F", "D"), "eq. 1-9")
    run.origin(2, "H", "z origin from H (P6)", point=h)

    c_key, d_key = ("C2", "D2") if cfg.retake_c_d else ("C", "D")
    if cfg.retake_c_d:
        run.measure("C", "C2")
    run.origin(1, c_key, f"y origin from {c_key} (P5)")
    if cfg.retake_c_d:
        run.measure("D", "D2")
    run.origin(0, d_key, f"x origin from {d_key} (P4)")

    if not np.all(np.isfinite(run.T)):  # cannot happen after the checks above; never silent
        raise DegenerateGeometryError("the A-H procedure produced a non-finite frame")
    return ProcedureRun(
        T_base_wobj=run.T,
        used_ids=tuple(layout.points[r].id for r in STATOR_POINT_IDS),
        measured_m=run.measured,
        probes=tuple(run.probes),
        updates=tuple(run.updates),
        constructed_m={"P3": p3},
    )
