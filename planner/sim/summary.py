"""From trial results to the report's rows and per-point outcomes.

:func:`build_rows` turns each estimator's frame errors (and predicted covariance) into the
report's :class:`~planner.sim.report.IntervalRow` s (:mod:`planner.sim.rows` has what each row
measures); :func:`point_outcomes` counts every search by its id, with the reason of a failure
and the landing of an approach (the x-offset run's searches pooled under one id);
:func:`failure_counts` counts the failed trials by the search and the reason they stopped at.
Both group by the :class:`planner.reasons.Reason` itself (kind, words, pair), never by
reading its words.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from collections.abc import Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from calib.stats import normal_half_widths
from planner.reasons import Reason
from planner.sim.predict import Prediction
from planner.sim.report import FailureCount, IntervalRow, PointOutcome, ValidationReport
from planner.sim.report_points import XOFFSET_KEYS
from planner.sim.rows import SCALE, RowSpec, predicted_sigma, samples_and_bias, z_values
from planner.sim.search_events import (
    LANDED_OFF_FACE,
    PARTLY_OFF_FACE,
    ProbeEvent,
    search_group,
)
from planner.sim.setup import SimulationSetup
from planner.sim.trial import TrialResult

FloatArray = NDArray[np.float64]

#: What the linear prediction leaves out (a note of every report).
PREDICTION_NOTE = (
    "predicted: the procedure linearised around the ideal part at the nominal pose, with the "
    "sensor, robot-repeatability and TCP noise above; it leaves out what depends on where the "
    "misplaced part puts a search (holes and edges under the footprint, the stator's bulge), "
    "the sensor's response to tilted faces, the ray bundle's residual error of edge events, and "
    "the robot's accuracy field"
)


def point_outcomes(searched: list[str], events: list[ProbeEvent]) -> tuple[PointOutcome, ...]:
    """Per-point outcomes from every search's id (in order) and the notable events (the
    x-offset run's searches pooled, :func:`search_group`)."""
    searched = [search_group(s) for s in searched]
    events = [dataclasses.replace(e, point_id=search_group(e.point_id)) for e in events]
    order = list(dict.fromkeys(searched))
    count: dict[str, int] = {}
    for pid in searched:
        count[pid] = count.get(pid, 0) + 1
    out = []
    for pid in order:
        mine = [e for e in events if e.point_id == pid]
        failed: dict[Reason, int] = {}
        for e in mine:
            if e.cause is not None:
                failed[e.cause] = failed.get(e.cause, 0) + 1
        partly = [e.off_fraction for e in mine if e.landing == PARTLY_OFF_FACE]
        out.append(
            PointOutcome(
                point_id=pid,
                searches=count[pid],
                failed=failed,
                landed_off=sum(1 for e in mine if e.landing == LANDED_OFF_FACE),
                partly_off=len(partly),
                off_fraction_mean=float(np.mean(partly)) if partly else 0.0,
                off_fraction_max=float(np.max(partly)) if partly else 0.0,
            )
        )
    return tuple(out)


def failure_counts(results: list[TrialResult]) -> tuple[FailureCount, ...]:
    """The failed trials of ``results`` grouped by the search and reason (kind, words, pair)
    their calibration or x-offset run stopped at (or by the words of a procedure that got no
    frame), ordered by label."""
    count: Counter[FailureCount] = Counter()
    for r in results:
        if r.failure:
            count[FailureCount(r.failure, "procedure", r.failed_search, 0)] += 1
        if r.xoffset_failure:
            label = f"x-offset {r.xoffset_failure}"
            count[FailureCount(label, "x-offset", r.xoffset_failed_search, 0)] += 1
    rows = [dataclasses.replace(f, count=n) for f, n in count.items()]
    return tuple(
        sorted(rows, key=lambda f: (f.label, "" if f.failed is None else f.failed.cause.kind))
    )


def _half_widths(samples: FloatArray, levels: tuple[float, ...]) -> list[float]:
    """The normal half-widths (SI) of a row's samples at ``levels`` (percent); NaN when there
    are fewer than two or one is not finite."""
    if len(samples) < 2 or not np.all(np.isfinite(samples)):
        return [float("nan")] * len(levels)
    return normal_half_widths(samples, [lv / 100.0 for lv in levels])


@dataclass(frozen=True)
class RowInputs:
    """What one estimator contributes to a row.

    Attributes:
        delta: ``(n, 6)`` frame errors of the trials that calibrated (m, rad).
        cov: ``(6, 6)`` predicted covariance of the frame error.
        point_errors: per row key, ``(n, M, 3)`` point errors that are not those of ``delta``
            (e.g. x-offset corrected targets), with their predicted sigma (SI), or absent.
        protocol_delta: ``(n', 6)`` frame errors under the paper's protocol, centred on each
            position's mean, or None.
    """

    delta: FloatArray
    cov: FloatArray
    point_errors: Mapping[str, tuple[FloatArray, float]] = field(default_factory=dict)
    protocol_delta: FloatArray | None = None


#: Samples (trials, the protocol's included, x points, both estimators, all rows) above which
#: :func:`build_rows` computes the rows on two threads: numpy's loops over a row's millions of
#: samples release the GIL. At most two shares are made at once, each no larger than the
#: largest row's: their transients together stay within ``planner.sim.budget.ROW_BYTES``.
PARALLEL_SAMPLES = 2_000_000

#: What one estimator gives a row: its samples, half-widths, predicted half-widths, bias and
#: the protocol's half-widths (SI).
_RowPart = tuple[FloatArray, list[float], list[float], float, list[float]]


def _row_part(spec: RowSpec, inp: RowInputs) -> _RowPart:
    """One estimator's share of a row (see :func:`build_rows`)."""
    levels = spec.levels_percent
    nan = float("nan")
    extra = inp.point_errors.get(spec.key)
    if len(inp.delta) >= 2:
        s, bias = samples_and_bias(spec, inp.delta, None if extra is None else extra[0])
    else:
        s, bias = np.zeros(0), nan
    sigma = extra[1] if extra is not None else predicted_sigma(spec, inp.cov)
    proto = [nan] * len(levels)
    if inp.protocol_delta is not None and extra is None and len(inp.protocol_delta) >= 2:
        proto = _half_widths(samples_and_bias(spec, inp.protocol_delta)[0], levels)
    return s, _half_widths(s, levels), list(z_values(levels) * sigma), bias, proto


def _row_size(spec: RowSpec, inp: RowInputs) -> int:
    """Samples of one estimator's share of a row (its trials times its points)."""
    extra = inp.point_errors.get(spec.key)
    if extra is not None:
        return int(np.prod(extra[0].shape[:2]))
    points = 1 if spec.points_wobj is None else len(spec.points_wobj)
    protocol = 0 if inp.protocol_delta is None else len(inp.protocol_delta)
    return (len(inp.delta) + protocol) * points


def build_rows(
    specs: list[RowSpec],
    procedure: RowInputs,
    best_fit: RowInputs,
    paper: Mapping[tuple[str, float], float] | None = None,
) -> tuple[tuple[IntervalRow, ...], dict[str, FloatArray], dict[str, FloatArray]]:
    """The report's rows and the samples of each (procedure, best fit).

    Each (row, estimator) share is computed alone (:func:`_row_part`); above
    :data:`PARALLEL_SAMPLES` samples in all they are computed on two threads, the same numbers
    in the same order either way.
    """
    tasks = [(spec, inp) for spec in specs for inp in (procedure, best_fit)]
    if sum(_row_size(spec, inp) for spec, inp in tasks) > PARALLEL_SAMPLES:
        with ThreadPoolExecutor(max_workers=2) as pool:
            parts = list(pool.map(lambda task: _row_part(*task), tasks))
    else:
        parts = [_row_part(spec, inp) for spec, inp in tasks]
    rows: list[IntervalRow] = []
    samples: list[dict[str, FloatArray]] = [{}, {}]
    for n, spec in enumerate(specs):
        scale = SCALE[spec.unit]
        proc, fit = parts[2 * n], parts[2 * n + 1]
        samples[0][spec.key], samples[1][spec.key] = proc[0], fit[0]
        (_, hp, pp, bp, qp), (_, hf, pf, bf, qf) = proc, fit
        for i, level in enumerate(spec.levels_percent):
            rows.append(
                IntervalRow(
                    key=spec.key,
                    label=spec.label,
                    unit=spec.unit,
                    level_percent=level,
                    procedure=hp[i] * scale,
                    procedure_predicted=pp[i] * scale,
                    procedure_bias=bp * scale,
                    best_fit=hf[i] * scale,
                    best_fit_predicted=pf[i] * scale,
                    best_fit_bias=bf * scale,
                    paper=(paper or {}).get((spec.key, level), float("nan")),
                    procedure_protocol=qp[i] * scale,
                    best_fit_protocol=qf[i] * scale,
                )
            )
    return tuple(rows), samples[0], samples[1]


#: The kinds of a failure only the cell shows (reach, limits, collisions, moves): a trial not
#: checked in the cell cannot fail so (:data:`planner.reasons.KINDS`).
CELL_KINDS = frozenset({"reach", "joint_limit", "singularity", "collision", "move"})


def _failed_in_cell(result: TrialResult) -> bool:
    """The trial stopped at a search for a reason only the cell's check shows."""
    f = result.failed_search
    return f is not None and f.cause.kind in CELL_KINDS


def build_report(
    setup: SimulationSetup,
    results: list[TrialResult],
    proto: list[TrialResult],
    protocol: tuple[int, int] | None,
    rows: list[RowSpec],
    prediction: Prediction,
    paper: Mapping[tuple[str, float], float] | None,
    elapsed: float,
    n_workers: int,
    n_reach: int,
) -> ValidationReport:
    """The report of a run: rows of the main trials (and of the protocol's, centred on each
    position's mean), outcomes and failures of all, the prediction beside them."""
    dp = np.array([r.delta_procedure for r in results]).reshape(-1, 6)
    df = np.array([r.delta_best_fit for r in results]).reshape(-1, 6)
    ok = np.all(np.isfinite(dp), axis=1) & np.all(np.isfinite(df), axis=1)
    extra_p: dict[str, tuple[FloatArray, float]] = {}
    extra_f: dict[str, tuple[FloatArray, float]] = {}
    if setup.xoffset is not None:
        x = np.array([r.xoffset_x_m for r in results], dtype=np.float64)[ok]
        x = x[np.all(np.isfinite(x), axis=1)]  # a failed x-offset run is listed as a failure
        e = np.zeros((*x.shape, 3))
        e[..., 0] = x
        extra_p[XOFFSET_KEYS[1]] = (e, prediction.xoffset_sigma_m)
        extra_f[XOFFSET_KEYS[1]] = (np.full_like(e, np.nan), float("nan"))
    centred = [None, None]
    if proto and protocol is not None:
        for k, attr in enumerate(("delta_procedure", "delta_best_fit")):
            d = np.array([getattr(r, attr) for r in proto]).reshape(protocol[0], protocol[1], 6)
            good = np.all(np.isfinite(d), axis=2)
            mean = np.array(
                [
                    d[i][good[i]].mean(axis=0) if good[i].any() else np.zeros(6)
                    for i in range(len(d))
                ]
            )
            centred[k] = (d - mean[:, None, :])[good]
    table, sp, sf = build_rows(
        rows,
        RowInputs(dp[ok], prediction.cov_procedure, extra_p, centred[0]),
        RowInputs(df[ok], prediction.cov_best_fit, extra_f, centred[1]),
        paper,
    )
    all_results = results + proto
    counted = failure_counts(all_results)
    failures: Counter[str] = Counter()
    for f in counted:
        failures[f.label] += f.count
    landings = Counter(item for r in all_results for item in r.landings)
    outcomes = point_outcomes(
        [pid for r in all_results for pid in r.searched],
        [e for r in all_results for e in r.events],
    )
    return ValidationReport(
        n_trials=len(results),
        n_ok=int(ok.sum()),
        rows=table,
        samples_procedure=sp,
        samples_best_fit=sf,
        delta_procedure=dp[ok],
        delta_best_fit=df[ok],
        failures=dict(failures),
        failure_counts=counted,
        landings=dict(landings),
        elapsed_s=elapsed,
        workers=n_workers,
        reach_checked=n_reach,
        reach_failed=sum(_failed_in_cell(r) for r in results[:n_reach]),
        method=setup.method,
        program=setup.program.describe()[0],
        program_steps=tuple(setup.program.describe()[1:]),
        sensor=str(type(setup.sensor).KIND),
        outcomes=outcomes,
        predicted_cov_procedure=prediction.cov_procedure,
        predicted_cov_best_fit=prediction.cov_best_fit,
        noise=setup.noise_figures,
        protocol="" if protocol is None else f"{protocol[0]} positions x {protocol[1]} repeats",
        notes=(PREDICTION_NOTE,),
    )
