"""Predicted accuracy of any procedure: linearise its run around the ideal measurements.

A procedure turns a sequence of searches into a frame, each search commanded in the estimate so far
(the A-H procedure's F is commanded in the plane measured through D and E, so F's recorded x *is* a
function of D's and E's noise). To first order every noise source moves one search's event along its
direction by a small travel ``eps_j``, and the frame error is ``delta = G eps`` with ``G = d delta /
d eps`` (6 x S). :func:`linearize` finds ``G`` by running the procedure itself against the ideal
probe (:class:`calib.plane_probe.PlaneProbe`: the nominal faces of the part at the true pose, every
event moved by its ``eps_j``) with central differences, so the step-by-step dependencies are in
``G`` exactly as they are in the procedure, and nothing is derived by hand per procedure. With the
covariance ``C`` of ``eps`` (:func:`event_covariance`: the sensor's own noise, the robot's
repeatability, a TCP calibration error common to all searches) the predicted covariance of the frame
is ``G C G^T`` (:meth:`Linearization.covariance`).

For the best fit this reproduces the estimator's own covariance
(:meth:`calib.estimators.best_fit.BestFitResult.predicted_error` with the same noise); for the
A-H procedure and 3-2-1 it is their linearisation. Not in the prediction: anything that depends
on where the misplaced part puts a search (holes and edges under the footprint, the stator's
bulge), the sensor's response to tilted faces, the robot's smooth absolute-accuracy field.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.frames import check_transform
from calib.models.sensor import SearchNoise, tool_rotation
from calib.plane_probe import PlaneProbe
from calib.probing import Probe, SearchCommand

FloatArray = NDArray[np.float64]

#: A run of a procedure against a probe: named output vectors (e.g. the frame errors).
RunFunction = Callable[[Probe], Mapping[str, FloatArray]]


@dataclass(frozen=True)
class Linearization:
    """First-order map from event travels to the outputs of a run.

    Attributes:
        commands: the ``S`` searches of the unperturbed run, in order (base frame).
        jacobians: per output name, ``(n, S)`` the derivative of the output with respect to
            each search's event travel (output units per metre).
    """

    commands: tuple[SearchCommand, ...]
    jacobians: dict[str, FloatArray]

    def covariance(self, name: str, event_cov: FloatArray) -> FloatArray:
        """``(n, n)`` predicted covariance of output ``name`` for event covariance ``(S, S)``."""
        G = self.jacobians[name]
        cov = G @ np.asarray(event_cov, dtype=np.float64) @ G.T
        return 0.5 * (cov + cov.T)


def linearize(
    run: RunFunction,
    T_base_wobj_true: FloatArray,
    edge_offset_m: float = 0.0,
    step_m: float = 1e-6,
    edge_axis_gain: float = 0.0,
) -> Linearization:
    """Linearise ``run`` around the ideal measurements on the part at ``T_base_wobj_true``.

    Args:
        run: runs the procedure with the given probe and returns named output vectors (e.g.
            ``motion_between(T_true, T_calibrated)``).
        T_base_wobj_true: ``(4, 4)`` the part's pose the ideal measurements are taken on.
        edge_offset_m: the sensor's edge-event offset (the procedure removes it again).
        step_m: central-difference step of the event travels, metres.
        edge_axis_gain: the sensor's axis gain of edge searches (see
            :class:`calib.plane_probe.PlaneProbe`).

    Raises:
        InputError: the ideal run fails, or a perturbed run takes a different number of
            searches (the procedure is not smooth there).
    """
    T = check_transform(T_base_wobj_true, "T_base_wobj_true")
    ideal = PlaneProbe(T, edge_offset_m, edge_axis_gain)
    base = {k: np.asarray(v, dtype=np.float64).ravel() for k, v in run(ideal).items()}
    n = len(ideal.commands)
    jac = {k: np.zeros((v.size, n)) for k, v in base.items()}
    for j in range(n):
        out = []
        for sign in (1.0, -1.0):
            probe = PlaneProbe(T, edge_offset_m, edge_axis_gain, {j: sign * step_m})
            res = run(probe)
            if len(probe.commands) != n:
                raise InputError(
                    f"linearisation: moving search {j} ({ideal.commands[j].point_id}) by "
                    f"{step_m:g} m changed the number of searches ({n} -> {len(probe.commands)})"
                )
            out.append(res)
        for k in base:
            plus = np.asarray(out[0][k], dtype=np.float64).ravel()
            minus = np.asarray(out[1][k], dtype=np.float64).ravel()
            jac[k][:, j] = (plus - minus) / (2.0 * step_m)
    return Linearization(tuple(ideal.commands), jac)


def event_covariance(
    commands: Sequence[SearchCommand],
    noise: Sequence[SearchNoise],
    robot_sigma_m: float,
    tcp_sigma_m: float = 0.0,
) -> FloatArray:
    """``(S, S)`` covariance of the event travels of ``commands``.

    With the robot offset ``o`` of a search's TCP, its event travel moves by
    ``b . o`` with ``b = -m / (d . m) + k a`` (``m`` the normal of the face that stops it, ``d``
    the search direction, ``a`` the sensor axis, ``k`` the sensor's axis gain), plus the
    sensor's own noise. The repeatability gives every search its own isotropic ``o``
    (``robot_sigma_m`` per axis); a TCP calibration error is one vector in the sensor's tool
    frame (:func:`calib.models.sensor.tool_rotation`, ``tcp_sigma_m`` per axis) shared by all
    searches, so it correlates them.

    Args:
        commands: the searches, base frame.
        noise: each search's sensor noise (:meth:`SensorModel.search_noise`).
        robot_sigma_m: robot repeatability, 1-sigma per axis, metres.
        tcp_sigma_m: TCP calibration error, 1-sigma per axis, metres.
    """
    if len(noise) != len(commands):
        raise InputError(f"need one noise per search ({len(commands)}), got {len(noise)}")
    n = len(commands)
    var = np.zeros(n)
    C_tcp = np.zeros((n, 3))
    for j, (cmd, nz) in enumerate(zip(commands, noise, strict=True)):
        d = np.asarray(cmd.direction, dtype=np.float64)
        a = np.asarray(cmd.sensor_axis, dtype=np.float64)
        m = -d if cmd.stop_normal is None else np.asarray(cmd.stop_normal, dtype=np.float64)
        b = -m / float(d @ m) + nz.axis_gain * a
        var[j] = nz.sensor_sigma_m**2 + robot_sigma_m**2 * float(b @ b)
        C_tcp[j] = tool_rotation(a).T @ b
    cov = np.diag(var)
    if tcp_sigma_m:
        cov += tcp_sigma_m**2 * (C_tcp @ C_tcp.T)
    return cov
