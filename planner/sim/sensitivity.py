"""The sensitivity table: which noise term dominates each row (each term turned off in turn).

The same trials (same seed, so the same misplacements and draws wherever a term is on) are
run with everything on, then with one term off at a time: the sensor's own noise terms (from
the sensor registry, :attr:`planner.sim.sensors.SensorKind.noise_terms`), the robot's
repeatability, its TCP error and accuracy field when they are on, and the part's misplacement.
A row's dominant term is the one whose removal narrows its interval most.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import msgspec
import numpy as np
import trimesh

from calib.models import Misplacement
from planner.sim.montecarlo import simulate
from planner.sim.report import ValidationReport
from planner.sim.rows import RowSpec
from planner.sim.sensors import sensor_kind
from planner.sim.setup import SimulationSetup

#: A row shrinking by less than this share with a term off has no dominant term.
MIN_SHARE = 0.05


def noise_terms(setup: SimulationSetup) -> dict[str, SimulationSetup]:
    """The setups with one noise term off each, by the term's name."""
    out: dict[str, SimulationSetup] = {}
    for name, fields in sensor_kind(setup.sensor).noise_terms.items():
        out[f"{name} off"] = dataclasses.replace(
            setup, sensor=msgspec.structs.replace(setup.sensor, **fields)
        )
    robot = setup.robot_error
    for name, attr in (
        ("robot repeatability", "repeatability_sigma_m"),
        ("TCP error", "tcp_sigma_m"),
        ("robot accuracy field", "accuracy_amplitude_m"),
    ):
        if getattr(robot, attr):
            off = msgspec.structs.replace(robot, **{attr: 0.0})
            out[f"{name} off"] = dataclasses.replace(setup, robot_error=off)
    out["misplacement off"] = dataclasses.replace(
        setup, misplacement=Misplacement(max_translation_m=0.0, max_angle_rad=0.0)
    )
    return out


@dataclass(frozen=True)
class SensitivityTable:
    """Half-widths of the procedure's rows with every term on and with each term off.

    Attributes:
        terms: the column names, ``"all on"`` first.
        rows: ``(key, label, unit, level_percent, half-widths per term)`` of each row at its
            first level, display units.
        dominant: per row key, the term whose removal narrows it most (``""``: none by more
            than :data:`MIN_SHARE`).
        n_trials: trials per column.
    """

    terms: tuple[str, ...]
    rows: tuple[tuple[str, str, str, float, tuple[float, ...]], ...]
    dominant: dict[str, str] = field(default_factory=dict)
    n_trials: int = 0

    def to_markdown(self) -> str:
        """The table, one row per quantity, the dominant term last."""
        head = ["Quantity", "Conf. [%]", *self.terms, "dominant"]
        lines = [
            f"Sensitivity ({self.n_trials} trials per column, same seed): half-widths with "
            "every term on and with one term off.",
            "",
            "| " + " | ".join(head) + " |",
            "|" + "---|" * len(head),
        ]
        for key, label, unit, level, values in self.rows:
            d = 4 if unit == "deg" else 3
            cells = [f"± {v:.{d}f}" if math.isfinite(v) else "—" for v in values]
            lines.append(
                f"| {label} [{unit}] | {level:g} | "
                + " | ".join(cells)
                + f" | {self.dominant.get(key, '') or '—'} |"
            )
        return "\n".join(lines) + "\n"


def sensitivity(
    setup: SimulationSetup,
    mesh: trimesh.Trimesh,
    rows: list[RowSpec],
    n_trials: int,
    seed: int,
    *,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> SensitivityTable:
    """Run the rows with every term on and with each term off in turn (``n_trials`` each)."""
    cases = {"all on": setup, **noise_terms(setup)}
    reports: dict[str, ValidationReport] = {}
    for k, (name, case) in enumerate(cases.items()):

        def step(done: int, total: int, k: int = k) -> None:
            if progress is not None:
                progress(k * n_trials + done, len(cases) * n_trials)

        reports[name] = simulate(
            case, mesh, rows, n_trials, np.random.default_rng(seed), workers=workers, progress=step
        )
    first: dict[str, tuple[str, str, float]] = {}
    for r in reports["all on"].rows:
        first.setdefault(r.key, (r.label, r.unit, r.level_percent))
    table = []
    dominant: dict[str, str] = {}
    for key, (label, unit, level) in first.items():
        values = tuple(reports[name].row(key, level).procedure for name in cases)
        table.append((key, label, unit, level, values))
        base = values[0]
        drops = {name: base - v for name, v in zip(cases, values, strict=True) if name != "all on"}
        best = max(drops, key=lambda n: drops[n]) if drops else ""
        dominant[key] = best.removesuffix(" off") if best and drops[best] > MIN_SHARE * base else ""
    return SensitivityTable(tuple(cases), tuple(table), dominant, n_trials)
