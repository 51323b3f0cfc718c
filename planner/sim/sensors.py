"""The sensor registry: which simulated search runs for each sensor model.

A sensor kind is one model struct in :mod:`calib.models` (the plan holds it, tagged by
``kind``; it satisfies :class:`calib.models.sensor.SensorModel`) plus one simulator here: a
class built as ``Simulator(caster, T_base_wobj_true, rng, sensor=..., robot_error=...,
accuracy_field=..., faces=..., tcp_error_m=..., reachability=..., edge_inset_m=...,
edge_tolerance_m=...)`` that is a :data:`calib.probing.Probe` (one commanded search in, a
:class:`calib.probing.ProbeResult` out) and lists what happened in ``events``. Adding a sensor
is a model, a simulator module and one entry in :data:`SENSORS` (and a member of
:data:`calib.models.SensorSettings`), as the touch probe went in::

    SENSORS["touch"] = SensorKind(
        "touch", TouchProbe, "planner.sim.touch:SimulatedTouchProbe", "ball-tip touch probe"
    )

Simulators are imported when first used.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Protocol

from calib.errors import PlanError
from calib.models.proximity import ProximitySensor
from calib.models.sensor import SensorModel
from calib.models.touch import TouchProbe
from calib.probing import ProbeResult, SearchCommand
from calib.registry import lookup, unknown_name
from planner.sim.search_events import ProbeEvent


class SimulatedSensorProbe(Protocol):
    """A simulated search against the true part: a probe that records what happened."""

    events: list[ProbeEvent]

    def __call__(self, command: SearchCommand) -> ProbeResult:
        """Run one commanded search (base frame) and return what the controller records."""
        ...


#: Builds a simulated probe (see the module docstring for its arguments).
SimulatorFactory = Callable[..., SimulatedSensorProbe]


@dataclass(frozen=True)
class SensorKind:
    """One sensor kind.

    Attributes:
        name: its name, equal to the model's ``KIND``.
        model: the model struct (in :mod:`calib.models`).
        simulator: ``"module:attr"`` of its simulator class.
        summary: one line for humans.
        noise_terms: the sensor's noise terms for the sensitivity table: name -> the model's
            fields that turn the term off (:mod:`planner.sim.sensitivity`).
    """

    name: str
    model: type
    simulator: str
    summary: str
    noise_terms: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    def load(self) -> SimulatorFactory:
        """The simulator class (imports its module)."""
        module, _, attr = self.simulator.partition(":")
        factory: SimulatorFactory = getattr(importlib.import_module(module), attr)
        return factory


#: The sensor kinds by name.
SENSORS: dict[str, SensorKind] = {
    "proximity": SensorKind(
        "proximity",
        ProximitySensor,
        "planner.sim.proximity:SimulatedProbe",
        "inductive proximity sensor: ray bundle over the face, exponential damping, hysteresis",
        {"sensor repeatability": {"repeatability_sigma_m": 0.0}},
    ),
    "touch": SensorKind(
        "touch",
        TouchProbe,
        "planner.sim.touch:SimulatedTouchProbe",
        "touch-trigger probe: ball contact on the mesh, radius compensation, pre-travel lobing",
        {
            "probe trigger scatter": {"trigger_repeatability_sigma_m": 0.0},
            "probe pre-travel lobing": {
                "axial_pretravel_m": 0.0,
                "side_pretravel_m": 0.0,
                "lobing_amplitude_m": 0.0,
            },
        },
    ),
}


def sensor_kind(model: SensorModel) -> SensorKind:
    """The registry entry of a sensor model.

    Raises:
        PlanError: no simulator for this kind of sensor (the message lists the known ones).
    """
    name = str(getattr(type(model), "KIND", type(model).__name__))
    kind = lookup(SENSORS, name, "sensor simulator (validation.sensor.kind)", PlanError)
    if not isinstance(model, kind.model):
        raise unknown_name(
            "sensor simulator (validation.sensor.kind)", type(model).__name__, SENSORS, PlanError
        )
    return kind
