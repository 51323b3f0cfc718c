"""The accuracy of a plan predicted from the procedure's linearisation, with the same noise.

:func:`predict` executes the plan's measuring program (the one the trials execute; and the
best fit fed as it is fed, and the x-offset run) against the ideal part at the nominal pose through
:func:`calib.procedures.linearize.linearize`, and combines the resulting Jacobians with the
event covariance of every search (:func:`calib.procedures.linearize.event_covariance`: the
sensor's own noise from :meth:`SensorModel.search_noise`, the robot's repeatability, the TCP
error). The report puts the resulting intervals beside the simulated ones.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError, WobjcalError
from calib.frames import motion_between, small_motion
from calib.plane_probe import PlaneProbe
from calib.probing import Probe
from calib.procedures.comparison import FedFit
from calib.procedures.linearize import event_covariance, linearize
from planner.program.execute import execute
from planner.sim.setup import SimulationSetup
from planner.sim.xoffset import run_xoffset

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Prediction:
    """Predicted covariances of a plan's calibration.

    Attributes:
        cov_procedure: ``(6, 6)`` covariance of the procedure's frame error (m, rad).
        cov_best_fit: ``(6, 6)`` that of the best fit fed as the procedure is fed.
        xoffset_sigma_m: pooled 1-sigma of the slot targets' x error with the x-offset
            matrix, metres (NaN without an x-offset run).
        n_searches: searches of one calibration (with the x-offset run).
    """

    cov_procedure: FloatArray = field(repr=False)
    cov_best_fit: FloatArray = field(repr=False)
    xoffset_sigma_m: float = float("nan")
    n_searches: int = 0


def predict(setup: SimulationSetup, step_m: float = 1e-6, best_fit: bool = True) -> Prediction:
    """Linearise the plan's calibration and propagate the noise figures of ``setup``.

    Args:
        setup: the plan's points, procedure, nominal pose and noise figures.
        step_m: central-difference step of the event travels, metres.
        best_fit: also linearise the best fit fed as the procedure is fed (the report's
            comparison column); without it ``cov_best_fit`` is all NaN and every run of the
            procedure is about a sixth cheaper (the live layout quality needs only the
            procedure's covariance).

    Raises:
        InputError: the ideal calibration fails (the plan cannot calibrate even without
            noise), or the procedure is not smooth around it.
    """
    fed = FedFit([rp.point for rp in setup.points], setup.edge_offset_m)
    T_nom = setup.T_base_wobj_nominal
    xs = setup.xoffset.with_holes(setup.xoffset.targets_wobj) if setup.xoffset else None

    def run(probe: Probe, T_true: FloatArray = T_nom) -> dict[str, FloatArray]:
        res = execute(setup.program, T_nom, probe)
        out = {"procedure": motion_between(T_true, res.T_base_wobj)}
        if best_fit:
            out["best_fit"] = motion_between(T_true, fed(res).T_base_wobj)
        if xs is not None:
            out["xoffset"] = run_xoffset(xs, probe, res.T_base_wobj, T_true)[:, 0]
        return out

    gain = (
        setup.sensor.search_noise("edge", setup.edge_inset_m).axis_gain
        if setup.sensor.runs_edge_searches
        else 0.0
    )
    lin = linearize(run, T_nom, setup.edge_offset_m, step_m, gain)
    noise = [setup.sensor.search_noise(c.kind, setup.edge_inset_m) for c in lin.commands]
    C = event_covariance(
        lin.commands, noise, setup.robot_error.repeatability_sigma_m, setup.robot_error.tcp_sigma_m
    )
    placed = misplacement_covariances(run, setup, gain)
    x_sigma = float("nan")
    if xs is not None:
        var = np.diag(lin.covariance("xoffset", C) + placed["xoffset"])
        x_sigma = float(np.sqrt(max(float(np.mean(var)), 0.0)))
    return Prediction(
        cov_procedure=lin.covariance("procedure", C) + placed["procedure"],
        cov_best_fit=(
            lin.covariance("best_fit", C) + placed["best_fit"]
            if best_fit
            else np.full((6, 6), np.nan)
        ),
        xoffset_sigma_m=x_sigma,
        n_searches=len(lin.commands),
    )


def predict_report(setup: SimulationSetup) -> Prediction:
    """:func:`predict` of a validation report's rows, on a worker process or in this one.

    Its failure is one :class:`InputError` that says it is the prediction's and that a worker
    process can send back (a :class:`calib.errors.ProbeFailedError` raised there would come
    back as a broken pool: its arguments do not pickle).

    Raises:
        InputError: the prediction failed (the plan cannot calibrate even on the ideal part,
            or its procedure is not smooth there); the message says why.
    """
    try:
        return predict(setup)
    except WobjcalError as exc:
        raise InputError(
            f"the prediction (the plan's procedure linearised on the ideal part) failed: {exc}"
        ) from exc


def misplacement_covariances(
    run: Callable[[Probe, FloatArray], dict[str, FloatArray]],
    setup: SimulationSetup,
    edge_axis_gain: float,
    step: float = 1e-5,
) -> dict[str, FloatArray]:
    """Per output of ``run``, the covariance the part's misplacement adds to first order.

    The program is exact on the ideal part wherever it lies, except where a search commanded in
    an estimate meets the true part otherwise than the estimate says: an edge search whose track
    runs closer to or farther from the tilted face it slides over than commanded (its event moves
    by the sensor's axis gain), or a nominal program's searches that cross a face off their
    nominal spots. Central differences of ``run`` against the ideal part moved by each of the six
    small motions (``step``, m and rad), with the misplacement's motion covariance
    (:meth:`calib.models.Misplacement.motion_covariance`).
    """
    T_nom = setup.T_base_wobj_nominal
    S = setup.misplacement.motion_covariance(setup.pivot_wobj_m)
    cols: dict[str, list[FloatArray]] = {}
    for i in range(6):
        outs = []
        for sign in (1.0, -1.0):
            d = np.zeros(6)
            d[i] = sign * step
            T_true = T_nom @ small_motion(d)
            outs.append(run(PlaneProbe(T_true, setup.edge_offset_m, edge_axis_gain), T_true))
        for k in outs[0]:
            plus = np.asarray(outs[0][k], dtype=np.float64).ravel()
            minus = np.asarray(outs[1][k], dtype=np.float64).ravel()
            cols.setdefault(k, []).append((plus - minus) / (2.0 * step))
    out = {}
    for k, c in cols.items():
        J = np.stack(c, axis=1)
        cov = J @ S @ J.T
        out[k] = 0.5 * (cov + cov.T)
    return out
