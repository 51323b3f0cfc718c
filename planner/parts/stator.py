"""The UU WEC stator section as a parametric work object (Hultman & Leijon 2013, Fig. 2, 8a).

The section is a stack of electrical-steel sheets lying in the wobj yz-plane and stacked along
wobj x, so the side face (the face with slot holes, towards the robot) is the outermost sheet and
the slot holes run through the stack along x. In the wobj frame of ``docs/ARCHITECTURE.md``:
origin at the top corner of the side face at the short side, ``+x`` out of the side face, ``+y``
towards the short side (the short side is ``y = 0``), ``+z`` up (the top side is ``z = 0``); the
part fills ``-depth <= x <= 0``, ``-length <= y <= 0``, ``-height <= z <= 0`` minus the holes.

Slot holes lie in ``n_layers`` layers (rows, wobj z) and slots (columns, wobj y); the metal between
two slots is a tooth, the solid band below the lowest layer is the yoke. Tightening bolts in slots
3, 15 and 31 bulge the side face in wobj x (Fig. 8a); the bulge is applied to the mesh and to the
ground-truth slot-hole centres. Every default dimension is justified in ``docs/simulation.md``.

The mesh is built by construction (no boolean): the side face is a grid of cells, each either solid
or holding one hole, sampled with the same points on shared cell edges, so the mesh is watertight
and the side face has vertices every few millimetres for the bulge displacement.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from calib.arguments import check_positive
from calib.errors import ShapeError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Distance from the WOCS origin to the slot hole furthest away from it, wobj frame (paper Fig. 8a).
EPSILON_M: tuple[float, float, float] = (0.0, -1.000, -0.100)


@dataclass(frozen=True)
class StatorGeometry:
    """Dimensions of a stator section, metres (justified in ``docs/simulation.md``).

    Attributes:
        length_m: section length along wobj -y (paper: full section 2 m, prototype 0.5 m).
        height_m: side-face height along wobj -z, slot region plus yoke.
        depth_m: stack thickness along wobj -x (about 500 sheets of 0.5 mm).
        n_layers: slot-hole layers (rows) from the top side down.
        layer_pitch_m: vertical distance between layer centres.
        first_layer_depth_m: depth of the top layer's centres below the top side.
        slot_pitch_m: distance between slot (column) centres along y; tooth centres lie halfway.
        first_slot_offset_m: distance of slot 1's centre from the short side.
        hole_diameter_m: slot-hole diameter.
        hole_segments: polygon segments per hole (multiple of 4); the polygon keeps the circle area.
        bolt_slots: 1-based slot numbers holding tightening bolts (paper Fig. 8a: 3, 15, 31).
        bolt_bulge_m: largest outward (+x) bulge of the side face at a bolt slot.
        bulge_sigma_y_m: Gaussian width of a bulge along y.
        bulge_sigma_z_m: Gaussian width of a bulge along z, centred on the slot region.
        reach_length_m: length of side face one robot works on (paper: about 1 m of 2 m).
    """

    length_m: float = 2.000
    height_m: float = 0.200
    depth_m: float = 0.250
    n_layers: int = 6
    layer_pitch_m: float = 0.015
    first_layer_depth_m: float = 0.025
    slot_pitch_m: float = 0.024
    first_slot_offset_m: float = 0.016
    hole_diameter_m: float = 0.010
    hole_segments: int = 12
    bolt_slots: tuple[int, ...] = (3, 15, 31)
    bolt_bulge_m: float = 0.0003
    bulge_sigma_y_m: float = 0.030
    bulge_sigma_z_m: float = 0.060
    reach_length_m: float = 1.000

    def __post_init__(self) -> None:
        # a tuple, whatever sequence was given: the geometry is a key (its mesh is kept by it)
        object.__setattr__(self, "bolt_slots", tuple(int(k) for k in self.bolt_slots))
        for name in (
            "length_m",
            "height_m",
            "depth_m",
            "layer_pitch_m",
            "first_layer_depth_m",
            "slot_pitch_m",
            "first_slot_offset_m",
            "hole_diameter_m",
            "bulge_sigma_y_m",
            "bulge_sigma_z_m",
            "reach_length_m",
        ):
            check_positive(getattr(self, name), f"geometry.{name}")
        check_positive(self.bolt_bulge_m, "geometry.bolt_bulge_m", allow_zero=True)
        if self.n_layers < 0:
            raise ShapeError(f"geometry.n_layers must be >= 0, got {self.n_layers}")
        if self.hole_segments < 8 or self.hole_segments % 4:
            raise ShapeError(
                f"geometry.hole_segments must be a multiple of 4 and >= 8, got {self.hole_segments}"
            )
        if self.hole_diameter_m >= min(self.slot_pitch_m, self.layer_pitch_m):
            raise ShapeError(
                "geometry.hole_diameter_m must be smaller than slot_pitch_m and layer_pitch_m"
            )
        if self.first_slot_offset_m < self.slot_pitch_m / 2:
            raise ShapeError("geometry.first_slot_offset_m must be >= slot_pitch_m / 2")
        if self.first_layer_depth_m < self.layer_pitch_m / 2:
            raise ShapeError("geometry.first_layer_depth_m must be >= layer_pitch_m / 2")
        if self.slot_region_bottom_m <= -self.height_m:
            raise ShapeError("geometry.height_m leaves no yoke below the slot holes")

    @classmethod
    def full_section(cls) -> StatorGeometry:
        """A full-length (2 m) UU WEC stator section."""
        return cls()

    @classmethod
    def prototype(cls) -> StatorGeometry:
        """The paper's 0.5 m prototype section."""
        return cls(length_m=0.500)

    @property
    def epsilon_m(self) -> FloatArray:
        """``(3,)`` the paper's epsilon, the slot hole furthest from the origin, wobj, m."""
        return np.array(EPSILON_M)

    @property
    def n_slots(self) -> int:
        """Number of slots (columns) whose cells fit the length with a margin at the far end."""
        usable = self.length_m - self.first_slot_offset_m - self.slot_pitch_m / 2
        return max(0, math.floor(usable / self.slot_pitch_m + 1e-9) + 1) if usable >= 0 else 0

    @property
    def slot_y_m(self) -> FloatArray:
        """``(n_slots,)`` slot-centre y (wobj, m); index j is slot number j + 1."""
        return -(
            self.first_slot_offset_m + self.slot_pitch_m * np.arange(self.n_slots, dtype=float)
        )

    @property
    def layer_z_m(self) -> FloatArray:
        """``(n_layers,)`` layer-centre z (wobj, m), top layer first."""
        return -(
            self.first_layer_depth_m + self.layer_pitch_m * np.arange(self.n_layers, dtype=float)
        )

    @property
    def tooth_y_m(self) -> FloatArray:
        """``(n_slots - 1,)`` tooth-centre y (wobj, m): tooth t lies between slots t+1, t+2."""
        return self.slot_y_m[:-1] - self.slot_pitch_m / 2

    @property
    def web_z_m(self) -> FloatArray:
        """``(n_layers - 1,)`` z of the solid webs halfway between two layers (wobj, m)."""
        return self.layer_z_m[:-1] - self.layer_pitch_m / 2

    @property
    def slot_region_bottom_m(self) -> float:
        """z of the bottom of the slot-hole cells (top of the yoke), wobj, m."""
        if self.n_layers == 0:
            return -self.first_layer_depth_m
        return float(self.layer_z_m[-1]) - self.layer_pitch_m / 2

    def side_face_offset_m(self, y: ArrayLike, z: ArrayLike) -> FloatArray:
        """Outward bulge of the side face along wobj +x at ``(y, z)`` (broadcast), metres."""
        y_arr, z_arr = np.asarray(y, float), np.asarray(z, float)
        if self.bolt_bulge_m == 0.0 or self.n_layers == 0:
            return np.zeros(np.broadcast_shapes(y_arr.shape, z_arr.shape))
        z_c = 0.5 * (float(self.layer_z_m[0]) + float(self.layer_z_m[-1]))
        g_z = np.exp(-0.5 * ((z_arr - z_c) / self.bulge_sigma_z_m) ** 2)
        g_y = np.zeros_like(y_arr)
        for slot in self.bolt_slots:
            if 1 <= slot <= self.n_slots:
                y_b = float(self.slot_y_m[slot - 1])
                g_y = g_y + np.exp(-0.5 * ((y_arr - y_b) / self.bulge_sigma_y_m) ** 2)
        return self.bolt_bulge_m * np.minimum(g_y, 1.0) * g_z

    def slot_centres_m(self, reach_only: bool = True) -> FloatArray:
        """Ground-truth slot-hole centres on the (bulged) side face, ``(M, 3)``, wobj, metres.

        Args:
            reach_only: only the holes within ``reach_length_m`` of the short side (the paper's
                "500 slot holes" one robot works on); otherwise every hole.
        """
        yy, zz = np.meshgrid(self.slot_y_m, self.layer_z_m, indexing="xy")
        y, z = yy.ravel(), zz.ravel()
        if reach_only:
            keep = y >= -self.reach_length_m - 1e-9
            y, z = y[keep], z[keep]
        return np.column_stack([self.side_face_offset_m(y, z), y, z])

    def hole_near(self, y: ArrayLike, z: ArrayLike) -> NDArray[np.bool_]:
        """True where side-face point(s) ``(y, z)`` lie inside a slot hole (round, exact)."""
        y_arr, z_arr = np.broadcast_arrays(np.asarray(y, float), np.asarray(z, float))
        if self.n_slots == 0 or self.n_layers == 0:
            return np.zeros(y_arr.shape, bool)
        j = np.clip(
            np.rint((-y_arr - self.first_slot_offset_m) / self.slot_pitch_m), 0, self.n_slots - 1
        )
        k = np.clip(
            np.rint((-z_arr - self.first_layer_depth_m) / self.layer_pitch_m), 0, self.n_layers - 1
        )
        dy = y_arr + self.first_slot_offset_m + j * self.slot_pitch_m
        dz = z_arr + self.first_layer_depth_m + k * self.layer_pitch_m
        return np.hypot(dy, dz) < self.hole_diameter_m / 2
