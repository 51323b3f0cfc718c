"""Fine jogging in the Teach tab: a typed value per joint and steps of 0.1, 1 or 10 degrees.

The coarse sliders (:mod:`webui.teach_panel`) move a joint over its whole range in a few
hundred pixels (a 24 px drag moved J1 by 42 deg); here each joint has a number field (deg,
applied as it changes, within the URDF's limits) and a joint is stepped with **−** / **+** by
the chosen **Step (deg)** (the fields' own arrows and the keyboard's up/down keys step by it
too). A typed value outside the joint's limits is refused with the limits named (the robot
stays); a step that would cross a limit stops at it and says so, and a step from the limit
outwards is refused.

The pure helpers (:func:`typed_value_deg`, :func:`stepped_value_deg`) hold the rules; the
widget class :class:`FineJog` turns events into calls of the teach panel's ``jog``.
"""

from __future__ import annotations

import contextlib
import logging
import threading
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from webui.markdown_text import plain

if TYPE_CHECKING:
    from planner.robot.kinematics.chain import KinematicChain
    from webui.context import AppContext
    from webui.panel import Guard

logger = logging.getLogger(__name__)

#: The step sizes offered, deg (as the dropdown shows them).
STEPS_DEG: tuple[str, ...] = ("0.1", "1", "10")
#: The step chosen at first, deg.
DEFAULT_STEP_DEG = "1"
#: The button group's labels: one step down, one step up.
MINUS, PLUS = "− step", "+ step"
#: A continuous joint (no finite URDF limit) is jogged within this, deg.
CONTINUOUS_DEG = 360.0
#: Decimals the joint fields show (0.01 deg).
FIELD_DECIMALS = 2
#: Values within this of a limit count as at it, deg.
AT_LIMIT_DEG = 1e-6


def limits_deg(chain: KinematicChain) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(lower, upper)`` ``(n,)`` joint limits in degrees (±:data:`CONTINUOUS_DEG` for a
    continuous joint)."""
    lo = np.where(np.isfinite(chain.lower), np.degrees(chain.lower), -CONTINUOUS_DEG)
    hi = np.where(np.isfinite(chain.upper), np.degrees(chain.upper), CONTINUOUS_DEG)
    return (  # to 0.001 deg, rounded inwards: a value at a shown limit is within the URDF's
        np.asarray(np.ceil(lo * 1000.0 - 1e-9) / 1000.0, dtype=np.float64),
        np.asarray(np.floor(hi * 1000.0 + 1e-9) / 1000.0, dtype=np.float64),
    )


def typed_value_deg(name: str, value_deg: float, lo_deg: float, hi_deg: float) -> float:
    """A typed joint value, checked against the joint's limits (all deg).

    Raises:
        InputError: not a finite number, or outside ``[lo_deg, hi_deg]``, e.g. ``J1: 200.0 deg
            is outside its limits (-165.0 to 165.0 deg); the robot stays``.
    """
    v = float(value_deg)
    if not np.isfinite(v):
        raise InputError(f"{name}: type a number of degrees")
    if v < lo_deg - AT_LIMIT_DEG or v > hi_deg + AT_LIMIT_DEG:
        raise InputError(
            f"{name}: {v:.1f} deg is outside its limits ({lo_deg:.1f} to {hi_deg:.1f} deg); "
            "the robot stays"
        )
    return float(np.clip(v, lo_deg, hi_deg))


def stepped_value_deg(
    name: str, value_deg: float, step_deg: float, lo_deg: float, hi_deg: float
) -> tuple[float, str]:
    """One step of ``step_deg`` (signed) from ``value_deg`` within ``[lo_deg, hi_deg]`` (deg).

    Returns:
        The new value and ``""``, or the limit and a note when the step would cross it (``J3
        stopped at its upper limit (70.0 deg)``).

    Raises:
        InputError: the joint already stands at the limit the step goes towards.
    """
    if step_deg == 0.0 or not np.isfinite(step_deg):
        raise InputError(f"{name}: the step must be a non-zero number of degrees")
    side, limit = ("upper", hi_deg) if step_deg > 0 else ("lower", lo_deg)
    if abs(value_deg - limit) <= AT_LIMIT_DEG or (value_deg - limit) * step_deg > 0:
        raise InputError(f"{name} is at its {side} limit ({limit:.1f} deg); the robot stays")
    target = value_deg + step_deg
    if (target - limit) * step_deg > 0:
        return limit, f"{name} stopped at its {side} limit ({limit:.1f} deg)"
    return target, ""


class FineJog:
    """The "Fine jog" folder of the Teach tab (shared by all tabs).

    Args:
        app: the app (its GUI).
        guard: the Teach panel's :meth:`webui.panel.Panel.guard` (a refusal told to the tab
            that acted).
        jog: the teach panel's jog: put the robot at ``q`` (rad), check and show it.
        current: the jogged joint values now, rad.
    """

    def __init__(
        self,
        app: AppContext,
        guard: Guard,
        jog: Callable[[NDArray[np.float64]], Any],
        current: Callable[[], NDArray[np.float64]],
    ) -> None:
        self._app = app
        self._panel_guard = guard
        self._jog = jog
        self._current = current
        self._sync = threading.local()
        self.fields: list[Any] = []
        self.lo = np.zeros(0)
        self.hi = np.zeros(0)
        gui = app.server.gui
        self.folder = gui.add_folder("Fine jog (deg)")
        with self.folder:
            self.step = gui.add_dropdown(
                "Step (deg)", STEPS_DEG, initial_value=DEFAULT_STEP_DEG,
                hint="what − / + and the fields' arrows add to the joint",
            )  # fmt: skip
            self.joint = gui.add_dropdown("Joint", ("J1",), hint="the joint − / + steps")
            self.buttons = gui.add_button_group("Step joint", (MINUS, PLUS))
            #: why the last step stopped short or a value was refused (``""``: it was not)
            self.note_md = gui.add_markdown("")
        self.step.on_update(lambda _ev: self._set_field_steps())
        self.buttons.on_click(self._on_button)

    @contextlib.contextmanager
    def _programmatic(self) -> Iterator[None]:
        self._sync.on = True
        try:
            yield
        finally:
            self._sync.on = False

    def _try(self, event: Any, fn: Callable[..., Any], *args: Any) -> Any:
        """The Teach panel's rule, and more: a refusal is also shown beside the fields (a typed
        value out of range stays explained there), and its notification closes by itself."""
        return self._panel_guard(event, fn, *args, title="Not moved", refusal_is_error=False,
                                 on_refusal=self._note)  # fmt: skip

    def _note(self, text: str) -> None:
        content = "" if not text else f"<span style='color:orange'>{plain(text)}</span>"
        if self.note_md.content != content:
            self.note_md.content = content

    @property
    def step_deg(self) -> float:
        """The chosen step, deg."""
        return float(self.step.value)

    def build(self, chain: KinematicChain | None, q0: NDArray[np.float64]) -> None:
        """One number field per joint of ``chain`` at ``q0`` (rad), within its limits."""
        for f in self.fields:
            f.remove()
        self.fields = []
        if chain is None:
            self.lo, self.hi = np.zeros(0), np.zeros(0)
            return
        self.lo, self.hi = limits_deg(chain)
        gui = self._app.server.gui
        names = tuple(f"J{i + 1}" for i in range(chain.n_joints))
        with self._programmatic():
            if tuple(self.joint.options) != names:
                self.joint.options = names
        with self.folder:
            for i, name in enumerate(chain.joint_names):
                v = float(np.clip(np.degrees(q0[i]), self.lo[i], self.hi[i]))
                field = gui.add_number(
                    f"J{i + 1} (deg)", round(v, FIELD_DECIMALS), min=float(self.lo[i]),
                    max=float(self.hi[i]), step=self.step_deg,
                    hint=f"{name}: type a value ({self.lo[i]:.1f} to {self.hi[i]:.1f} deg)",
                )  # fmt: skip
                field.precision = FIELD_DECIMALS
                field.on_update(lambda ev, i=i: self._on_field(ev, i))
                self.fields.append(field)

    def show(self, q: NDArray[np.float64]) -> None:
        """Put the fields at ``q`` (rad) without jogging."""
        with self._programmatic():
            for f, v in zip(self.fields, np.degrees(q), strict=False):
                value = round(float(v), FIELD_DECIMALS)
                if abs(float(f.value) - value) > 1e-9:
                    f.value = value

    def _set_field_steps(self) -> None:
        for f in self.fields:
            f.step = self.step_deg

    def _on_field(self, event: Any, i: int) -> None:
        if getattr(self._sync, "on", False):
            return
        value = float(self.fields[i].value)
        if self._try(event, self.set_joint, i, value) is None:
            self.show(self._current())  # refused: the field shows where the joint is

    def _on_button(self, event: Any) -> None:
        i = list(self.joint.options).index(str(self.joint.value))
        sign = -1.0 if str(event.target.value) == MINUS else 1.0
        self._try(event, self.step_joint, i, sign * self.step_deg)

    def set_joint(self, index: int, value_deg: float) -> Any:
        """Jog joint ``index`` (0-based) to ``value_deg`` (deg), the others unchanged.

        Raises:
            InputError: no robot, or the value is outside the joint's limits.
        """
        q = self._q_checked(index)
        name = f"J{index + 1}"
        v = typed_value_deg(name, value_deg, float(self.lo[index]), float(self.hi[index]))
        q[index] = np.radians(v)
        status = self._jog(q)
        self._note("")
        return status

    def step_joint(self, index: int, step_deg: float) -> Any:
        """Step joint ``index`` (0-based) by ``step_deg`` (deg, signed), stopping at its limit
        (and saying so).

        Raises:
            InputError: no robot, or the joint already stands at that limit.
        """
        q = self._q_checked(index)
        name = f"J{index + 1}"
        v, note = stepped_value_deg(
            name, float(np.degrees(q[index])), step_deg, float(self.lo[index]),
            float(self.hi[index]),
        )  # fmt: skip
        q[index] = np.radians(v)
        status = self._jog(q)
        self._note(note)
        return status

    def _q_checked(self, index: int) -> NDArray[np.float64]:
        q = np.array(self._current(), dtype=np.float64)
        if len(q) == 0 or len(self.fields) != len(q):
            raise InputError("load a plan with a robot first")
        if not 0 <= index < len(q):
            raise InputError(f"the robot has joints J1 to J{len(q)}, not J{index + 1}")
        return q
