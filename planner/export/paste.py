"""The lines to paste into a controller to use a calibrated work object.

``wobjcal calibrate`` prints, for every export format (:data:`planner.export.FORMATS`) or the one
asked for, the calibrated frame ``T_base_wobj`` written in that controller's own syntax, in the
frame its programs use (the controller's world frame taken to be the robot base, as every
writer takes it). Each writer module has a function ``(T_base_wobj) -> PasteLines`` next to
its writer, named by its format's entry (:attr:`planner.export.ExportFormat.paste`), so the
lines use the same literals as the programs: RAPID ``wobjdata``, KRL ``BASE_DATA``, a URScript
pose, FANUC TP position-register and user-frame instructions.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class PasteLines:
    """A calibrated frame in one controller's syntax.

    Attributes:
        where: where the lines go and which frame the values are in, for the heading, e.g.
            ``"world frame = robot base"``.
        lines: the lines, each a complete statement or declaration of the language (mm and
            degrees, or metres and radians where the language works in them).
    """

    where: str
    lines: tuple[str, ...]
