"""The paper's Table 1: the A-H procedure's published confidence half-widths on the stator.

Hultman & Leijon (2013), Table 1: the half-widths of the calibrated frame's errors over repeated
calibrations of the prototype section, in display units (mm for the origin and the points, deg
for the rotations), by the report's row key and the confidence level. The A-H procedure's
registry entry (:attr:`calib.procedures.hultman2013.Hultman2013Procedure.published`) carries it,
and the validation report of a built-in stator shows it beside the simulated rows.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

#: The paper's Table 1 half-widths, display units, keyed by (row key, level in percent).
PAPER_TABLE1: Mapping[tuple[str, float], float] = MappingProxyType(
    {
        ("origin_x", 95.5): 0.10,
        ("origin_y", 95.5): 0.08,
        ("origin_z", 95.5): 0.16,
        ("rot_x", 95.5): 0.0002,
        ("rot_y", 95.5): 0.0018,
        ("rot_z", 95.5): 0.0003,
        ("rot_x", 99.99): 0.0004,
        ("rot_y", 99.99): 0.0035,
        ("rot_z", 99.99): 0.0006,
        ("yz_origin", 95.5): 0.18,
        ("yz_origin", 99.0): 0.23,
        ("yz_origin", 99.9): 0.30,
        ("yz_epsilon", 95.5): 0.40,
        ("yz_epsilon", 99.0): 0.51,
        ("yz_epsilon", 99.9): 0.66,
        ("yz_slots", 95.5): 0.28,
        ("yz_slots", 99.99): 0.55,
        ("yz_slots", 99.999): 0.62,
        ("yz_slots", 99.9999): 0.69,
    }
)
