"""``wobjcal validate``: Monte Carlo validation of a plan, reported like Table 1 of the paper."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from calib.atomic_io import write_text_atomic
from calib.plan import Plan, PlanError
from calib.plan_procedures import Hultman2013
from planner.cli_common import read_plan, stderr, stdout
from planner.plan_io import hultman_points, nominal_T_base_wobj, require

#: Built-in work objects validation can simulate, and the StatorGeometry constructor of each.
SIMULATED_PARTS = {
    "builtin:stator_section": "full_section",
    "builtin:stator_prototype": "prototype",
}


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``validate`` to the subparsers ``sub``."""
    p = add(
        sub,
        "validate",
        "simulate the calibration many times and report confidence intervals (Table 1)",
        "Simulate the whole calibration TRIALS times with the plan's sensor model, robot\n"
        "error model and part misplacement, and print the confidence intervals of the frame\n"
        "and slot-position errors beside the paper's Table 1, plus which points failed how\n"
        "often. Runs the A-H procedure (hultman2013) on a built-in stator work object.\n\n"
        "exit codes: 0 every trial calibrated, 1 some trials failed (listed), 2 bad input",
        "wobjcal validate assets/plans/stator_section_ah.json --trials 400 --seed 1\n"
        "wobjcal validate plan.json --json report.json --plots plots/",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument("--trials", type=int, help="number of trials (default: the plan's)")
    p.add_argument("--seed", type=int, help="random seed (default: the plan's)")
    p.add_argument("--workers", type=int, help="worker processes (default: up to 2)")
    p.add_argument("--json", metavar="FILE", help="also write the report as JSON to FILE")
    p.add_argument("--plots", metavar="DIR", help="also write PNG plots to DIR")
    p.set_defaults(handler=cmd_validate)


def _models(plan: Plan) -> dict[str, Any]:
    sensor_mod = require("planner.sensor", "validate")
    err_mod = require("planner.error_models", "validate")
    v = plan.validation
    s, r, m = v.sensor, v.robot_error, v.misplacement
    return {
        "sensor": sensor_mod.ProximitySensor(
            face_diameter_m=s.face_diameter_m,
            sensing_distance_m=s.sensing_distance_m,
            decay_length_m=s.decay_length_m,
            hysteresis_fraction=s.hysteresis_fraction,
            repeatability_sigma_m=s.repeatability_sigma_m,
            n_rays=s.n_rays,
            n_scan_rays=s.n_scan_rays,
        ),
        "robot_error": err_mod.RobotErrorModel(
            repeatability_sigma_m=r.repeatability_sigma_m,
            accuracy_amplitude_m=r.accuracy_amplitude_m,
            accuracy_wavelength_m=r.accuracy_wavelength_m,
            accuracy_terms=r.accuracy_terms,
        ),
        "misplacement": err_mod.Misplacement(m.max_translation_m, m.max_angle_rad),
    }


def report_json(report: Any) -> dict[str, Any]:
    """The JSON of a ``ValidationReport``: rows (display units), failures, landings."""

    def num(x: float) -> float | None:
        return float(x) if math.isfinite(x) else None

    return {
        "n_trials": report.n_trials,
        "n_ok": report.n_ok,
        "elapsed_s": report.elapsed_s,
        "rows": [
            {
                "key": r.key,
                "label": r.label,
                "unit": r.unit,
                "level_percent": r.level_percent,
                "procedure": num(r.procedure),
                "procedure_bias": num(r.procedure_bias),
                "best_fit": num(r.best_fit),
                "best_fit_bias": num(r.best_fit_bias),
                "paper": num(r.paper),
            }
            for r in report.rows
        ],
        "failures": report.failures,
        "landings": report.landings,
    }


def cmd_validate(args: argparse.Namespace) -> int:
    """Run the validation with a progress bar and print the report."""
    plan, _ = read_plan(args.plan)
    if plan.work_object.mesh not in SIMULATED_PARTS:
        raise PlanError(
            f"work_object.mesh: validate simulates only {sorted(SIMULATED_PARTS)} for now, "
            f"got {plan.work_object.mesh!r}"
        )
    plots = require("planner.plots", "validate --plots") if args.plots else None
    mc = require("planner.montecarlo", "validate")
    edge_inset_m = mc.DEFAULT_EDGE_INSET_M  # edge searches run this far inside the face
    stator = require("planner.stator", "validate")
    sp = require("calib.stator_procedure", "validate")
    geometry = getattr(stator.StatorGeometry, SIMULATED_PARTS[plan.work_object.mesh])()
    trials = plan.validation.trials if args.trials is None else args.trials
    seed = plan.validation.seed if args.seed is None else args.seed
    settings = plan.procedure
    if not isinstance(settings, Hultman2013):
        raise PlanError(
            f"procedure.method: validate simulates only hultman2013, got {plan.method!r}"
        )
    models = _models(plan)
    edge_offset = settings.edge_event_offset_m
    if edge_offset is None:  # the sensor model's straight-edge offset, as montecarlo's default
        edge_offset = models["sensor"].edge_event_offset_m(edge_inset_m)
    stator_settings = sp.StatorSettings(
        beta1_rad=settings.beta1_rad,
        p3_height_m=settings.p3_height_m,
        retake_c_d=settings.retake_c_d,
        edge_start_from_measured=settings.edge_start_from_measured,
        edge_start_offset_m=settings.edge_start_offset_m,
        edge_event_offset_m=edge_offset,
    )
    with Progress(
        TextColumn("validating"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=stderr(),
        transient=True,
    ) as bar:
        task = bar.add_task("trials", total=trials)
        report = mc.validate(
            hultman_points(plan),
            geometry,
            nominal_T_base_wobj(plan),
            trials,
            np.random.default_rng(seed),
            workers=args.workers,
            progress=lambda done, total: bar.update(task, completed=done, total=total),
            settings=stator_settings,
            edge_inset_m=edge_inset_m,
            **models,
        )
    stdout().print(report.to_markdown(), markup=False)
    if args.json:
        data = report_json(report) | {"plan": args.plan, "seed": seed}
        write_text_atomic(args.json, json.dumps(data, indent=2, sort_keys=True) + "\n")
    if plots is not None:
        out_dir = Path(args.plots)
        out_dir.mkdir(parents=True, exist_ok=True)
        written = plots.save_validation_plots(report, out_dir)
        stderr().print(f"plots: {', '.join(str(p) for p in written)}")
    return 0 if report.n_ok == report.n_trials else 1
