"""The x-offset matrix (Hultman & Leijon 2013, eq. 13-14) and the slot-hole target function.

After the WOCS is calibrated, the bulge of the stator side (the tightening bolts push it out
along WOCS x) is measured at every second tooth on two slot-hole levels. Eq. 14 estimates the
x-offset of every slot hole from these measurements by linear interpolation (extrapolation at
the ends) in y and z; the results form the ``m x n`` matrix ``MX_W`` of eq. 13 (rows: slot-hole
layers, columns: slots). The target function then returns a robot target at any slot hole:
rotation aligned with the WOCS, position offset in y and z by the slot geometry and in x by
``MX_W`` plus a standoff.

Slot and layer *numbers* are 1-based as in the paper ("slots number 3, 15 and 31"); array
indices into ``MX_W`` are 0-based (``MX_W[layer - 1, slot - 1]``).
"""

from __future__ import annotations

import math
import numbers

import msgspec
import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_shape
from calib.errors import DegenerateGeometryError, ShapeError
from calib.frames import check_transform, make_transform
from calib.limits import MAX_XOFFSET_LAYERS, MAX_XOFFSET_SLOTS
from calib.probing import ProbePoint, SearchSpec

FloatArray = NDArray[np.float64]

#: Measurement pairs closer than this in y or z (metres) cannot give a slope.
MIN_SPACING_M = 1e-9


def _count(value: object, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or int(value) < 1:
        raise ShapeError(f"{name} must be an integer >= 1, got {value!r}")
    return int(value)


def _finite(value: object, name: str) -> float:
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ShapeError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise ShapeError(f"{name} must be finite, got {x}")
    return x


class SlotGrid(msgspec.Struct, frozen=True, forbid_unknown_fields=True):
    """Where the slot holes lie on the stator side face (the WOCS plane ``x = 0``).

    A plan holds it in its x-offset run (``procedure.xoffset.grid``).

    Slot ``j`` (1-based) of layer ``i`` (1-based) has its centre at
    ``(0, first_slot_y_m + (j - 1) * slot_step_y_m, first_layer_z_m + (i - 1) * layer_step_z_m)``
    in the nominal WOCS, before the x-offset.

    Attributes:
        n_slots: number of slots along y (the ``n`` columns of ``MX_W``).
        n_layers: number of slot-hole layers along z (the ``m`` rows of ``MX_W``).
        first_slot_y_m: y of slot 1, wobj frame, metres (e.g. ``-0.020``).
        first_layer_z_m: z of layer 1, wobj frame, metres (e.g. ``-0.030``).
        slot_step_y_m: signed y step from slot ``j`` to ``j + 1``, metres (negative when slot 1
            is the one nearest the short side at ``y = 0``); non-zero when ``n_slots > 1``.
        layer_step_z_m: signed z step from layer ``i`` to ``i + 1``, metres (negative when
            layer 1 is the top layer); non-zero when ``n_layers > 1``.
    """

    n_slots: int
    n_layers: int
    first_slot_y_m: float
    first_layer_z_m: float
    slot_step_y_m: float
    layer_step_z_m: float

    def __post_init__(self) -> None:
        _count(self.n_slots, "grid.n_slots")
        _count(self.n_layers, "grid.n_layers")
        for name, value, top in (
            ("n_slots", self.n_slots, MAX_XOFFSET_SLOTS),
            ("n_layers", self.n_layers, MAX_XOFFSET_LAYERS),
        ):
            if value > top:
                raise ShapeError(
                    f"{name}: {value:,}, at most {top:,} (a stator section has a few dozen "
                    "slots and about ten layers; every trial of validate keeps an x-offset per "
                    "slot hole)"
                )
        for name in ("first_slot_y_m", "first_layer_z_m", "slot_step_y_m", "layer_step_z_m"):
            _finite(getattr(self, name), f"grid.{name}")
        if self.n_slots > 1 and abs(self.slot_step_y_m) < MIN_SPACING_M:
            raise ShapeError("grid.slot_step_y_m must be non-zero when n_slots > 1")
        if self.n_layers > 1 and abs(self.layer_step_z_m) < MIN_SPACING_M:
            raise ShapeError("grid.layer_step_z_m must be non-zero when n_layers > 1")

    @property
    def slot_y_m(self) -> FloatArray:
        """``(n_slots,)`` y of each slot, wobj frame, metres."""
        return self.first_slot_y_m + np.arange(self.n_slots, dtype=np.float64) * self.slot_step_y_m

    @property
    def layer_z_m(self) -> FloatArray:
        """``(n_layers,)`` z of each layer, wobj frame, metres."""
        steps = np.arange(self.n_layers, dtype=np.float64)
        return self.first_layer_z_m + steps * self.layer_step_z_m

    def tooth_y_m(self, tooth: int) -> float:
        """y of tooth ``tooth``, the one between slots ``tooth`` and ``tooth + 1``, metres.

        Tooth 0 lies before slot 1 and tooth ``n_slots`` after the last slot.
        """
        if isinstance(tooth, bool) or not isinstance(tooth, numbers.Integral):
            raise ShapeError(f"tooth must be an integer, got {tooth!r}")
        if not 0 <= tooth <= self.n_slots:
            raise ShapeError(f"tooth must lie in 0..{self.n_slots}, got {tooth}")
        return self.first_slot_y_m + (int(tooth) - 0.5) * self.slot_step_y_m

    def check_slot(self, slot: int, layer: int) -> tuple[int, int]:
        """Return 0-based ``(layer_index, slot_index)`` or raise naming the bad number."""
        for name, value, top in (("slot", slot, self.n_slots), ("layer", layer, self.n_layers)):
            if isinstance(value, bool) or not isinstance(value, numbers.Integral):
                raise ShapeError(f"{name} must be an integer, got {value!r}")
            if not 1 <= value <= top:
                raise ShapeError(f"{name} must lie in 1..{top}, got {value}")
        return int(layer) - 1, int(slot) - 1


def slot_positions_wobj(grid: SlotGrid, xoffset: ArrayLike | None = None) -> FloatArray:
    """Centres of all slot holes, ``(n_layers, n_slots, 3)``, wobj frame, metres.

    Args:
        grid: the slot geometry.
        xoffset: ``(n_layers, n_slots)`` x-offset matrix ``MX_W`` (metres); zeros if ``None``.
    """
    m, n = grid.n_layers, grid.n_slots
    out = np.zeros((m, n, 3))
    if xoffset is not None:
        out[..., 0] = check_shape(xoffset, (m, n), "xoffset")
    out[..., 1] = grid.slot_y_m[None, :]
    out[..., 2] = grid.layer_z_m[:, None]
    return out


def xoffset_probe_points(
    grid: SlotGrid,
    layers: tuple[int, ...] | None = None,
    teeth: tuple[int, ...] | None = None,
    search: SearchSpec | None = None,
) -> tuple[tuple[ProbePoint, ...], ...]:
    """Nominal x-offset measurements ``PX``: over teeth, at slot-hole levels (paper section 3.2).

    Args:
        grid: the slot geometry.
        layers: 1-based layers whose z the measurements are taken at; default the first and
            the last layer (the paper's two levels).
        teeth: teeth to measure over (see :meth:`SlotGrid.tooth_y_m`); default every second
            tooth, ``1, 3, 5, ...`` (between slots 1-2, 3-4, ...).
        search: the approach search of each point; default :class:`SearchSpec()`.

    Returns:
        ``K x L`` nested tuples of approach points (ids ``"PX<layer>_<tooth>"``, normal +x).
    """
    layer_nums = (1, grid.n_layers) if layers is None else tuple(layers)
    tooth_nums = tuple(range(1, grid.n_slots, 2)) if teeth is None else tuple(teeth)
    if len(set(layer_nums)) < 2 or len(set(tooth_nums)) < 2:
        raise ShapeError(
            "x-offset measurements need at least 2 distinct layers and 2 distinct teeth, got "
            f"layers={layer_nums}, teeth={tooth_nums}"
        )
    spec = SearchSpec() if search is None else search
    z_all = grid.layer_z_m
    rows = []
    for layer in layer_nums:
        grid.check_slot(1, layer)
        z = float(z_all[layer - 1])
        rows.append(
            tuple(
                ProbePoint(
                    id=f"PX{layer}_{tooth}",
                    position_m=(0.0, grid.tooth_y_m(tooth), z),
                    normal=(1.0, 0.0, 0.0),
                    search=spec,
                )
                for tooth in tooth_nums
            )
        )
    return tuple(rows)


def _bracket(values: FloatArray, queries: FloatArray, what: str) -> NDArray[np.intp]:
    """Index ``l`` in ``0..len-2`` with ``queries`` in ``[values[l], values[l+1]]`` (clamped)."""
    steps = np.diff(values)
    if not (np.all(steps > MIN_SPACING_M) or np.all(steps < -MIN_SPACING_M)):
        raise DegenerateGeometryError(
            f"{what} must be strictly increasing or decreasing, got {np.round(values, 6)}"
        )
    sign = 1.0 if steps[0] > 0 else -1.0
    idx = np.searchsorted(sign * values, sign * queries, side="right") - 1
    return np.clip(idx, 0, len(values) - 2)


def xoffset_matrix(px_wobj: ArrayLike, grid: SlotGrid) -> FloatArray:
    """Eq. 13-14: the x-offset matrix ``MX_W``, ``(n_layers, n_slots)``, metres.

    ``px_wobj[k, l]`` is the measurement at level ``k`` (z) over tooth ``l`` (y), in the
    calibrated WOCS. For slot hole ``(i, j)`` at ``(y, z)``, ``l`` is the pair of teeth that
    brackets ``y`` on level ``k`` and ``k`` the pair of levels that brackets ``z`` (the end
    pairs when outside: extrapolation), and
    ``MX = PX[k,l].x + (y - PX[k,l].y) s_y + (z - PX[k,l].z) s_z``, the plane through
    ``PX[k,l]``, ``PX[k,l+1]``, ``PX[k+1,l]``. On a y-z grid the slopes are exactly eq. 14's
    ``s_y = (PX[k,l+1].x - PX[k,l].x) / (PX[k,l+1].y - PX[k,l].y)`` and
    ``s_z = (PX[k+1,l].x - PX[k,l].x) / (PX[k+1,l].z - PX[k,l].z)``; eq. 14 as printed omits
    the term ``PX[k,l].x`` and the reference ``PX[k,l].y, .z`` (we take them as implied, since
    without them the estimate is zero at the origin whatever was measured). Solving the plane
    through the three measured points keeps the estimate exact for an affine x-offset field
    even when the measured points are off the nominal grid.

    Args:
        px_wobj: ``(K, L, 3)`` measured points, wobj frame, metres; ``K >= 2`` levels with
            monotonic z, ``L >= 2`` teeth with monotonic y on every level.
        grid: the slot geometry.

    Raises:
        ShapeError, NonFiniteError: wrong shape or NaN/inf.
        DegenerateGeometryError: levels or teeth not strictly monotonic, or three
            measurements that span no plane.
    """
    px = check_shape(px_wobj, (None, None, 3), "px_wobj")
    K, L = px.shape[:2]
    if K < 2 or L < 2:
        raise ShapeError(f"px_wobj needs at least 2 levels and 2 teeth, got shape {px.shape}")
    y_hole, z_hole = grid.slot_y_m, grid.layer_z_m
    k_of_layer = _bracket(px[:, 0, 2], z_hole, "px_wobj levels (z of px_wobj[:, 0])")
    out = np.empty((grid.n_layers, grid.n_slots))
    for i, k in enumerate(k_of_layer):
        l_idx = _bracket(px[k, :, 1], y_hole, f"px_wobj teeth (y of px_wobj[{k}, :])")
        p0, p1, p2 = px[k, l_idx], px[k, l_idx + 1], px[k + 1, l_idx]
        d1, d2 = p1 - p0, p2 - p0
        det = d1[:, 1] * d2[:, 2] - d1[:, 2] * d2[:, 1]
        bad = np.abs(det) < MIN_SPACING_M**2
        if np.any(bad):
            l_bad = int(l_idx[np.argmax(bad)])
            raise DegenerateGeometryError(
                f"px_wobj[{k}, {l_bad}], [{k}, {l_bad + 1}] and [{k + 1}, {l_bad}] are collinear "
                "in the y-z plane, so they give no x-offset slope"
            )
        s_y = (d1[:, 0] * d2[:, 2] - d1[:, 2] * d2[:, 0]) / det
        s_z = (d1[:, 1] * d2[:, 0] - d1[:, 0] * d2[:, 1]) / det
        out[i] = p0[:, 0] + (y_hole - p0[:, 1]) * s_y + (z_hole[i] - p0[:, 2]) * s_z
    return out


def slot_target(
    T_base_wobj: ArrayLike,
    grid: SlotGrid,
    slot: int,
    layer: int,
    *,
    standoff_m: float = 0.0,
    rotation_rad: float = 0.0,
    xoffset: ArrayLike | None = None,
) -> FloatArray:
    """The robot target at a slot hole, ``T_base_target`` (4x4), paper section 3.2.

    The target's rotation is the WOCS rotation, turned by ``rotation_rad`` about the WOCS x
    axis (the slot-hole axis, along which the tool points into the hole). Its position is the
    slot hole's geometric offset in y and z from the WOCS origin, the hole's x-offset from
    ``MX_W``, plus ``standoff_m`` along WOCS +x (out of the side face, towards the robot).

    Args:
        T_base_wobj: ``(4, 4)`` the calibrated work-object frame.
        grid: the slot geometry.
        slot: 1-based slot number.
        layer: 1-based slot-hole layer number.
        standoff_m: distance from the hole along WOCS +x, metres (may be negative).
        rotation_rad: rotation about the WOCS x axis, radians.
        xoffset: ``(n_layers, n_slots)`` x-offset matrix from :func:`xoffset_matrix`, metres;
            ``None`` uses zero.

    Returns:
        ``(4, 4)`` ``T_base_target``.

    Raises:
        InputError: bad frame, slot or layer out of range, non-finite numbers, wrong shapes.
    """
    T = check_transform(T_base_wobj, "T_base_wobj")
    if T.shape != (4, 4):
        raise ShapeError(f"T_base_wobj must be (4, 4), got {T.shape}")
    i, j = grid.check_slot(slot, layer)
    standoff = _finite(standoff_m, "standoff_m")
    angle = _finite(rotation_rad, "rotation_rad")
    x = 0.0
    if xoffset is not None:
        x = float(check_shape(xoffset, (grid.n_layers, grid.n_slots), "xoffset")[i, j])
    p_wobj = (x + standoff, float(grid.slot_y_m[j]), float(grid.layer_z_m[i]))
    c, s = math.cos(angle), math.sin(angle)
    R_wobj_target = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    return T @ make_transform(R_wobj_target, p_wobj)
