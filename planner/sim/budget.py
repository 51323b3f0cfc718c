"""What one validation run costs, known from the plan before any trial runs (issue 27).

A run keeps every trial's result until its report is made, and the report keeps, per row, two
samples (procedure and best fit) for every trial and report point. So its memory grows with
trials x (searches per trial + report points), and its computing with trials x searches x rays:
:func:`run_size` counts them from the plan alone (no mesh, no cell), and
:func:`check_run_size` refuses a run above :data:`calib.limits.MAX_RESULT_BYTES` or
:data:`calib.limits.MAX_RAY_WORK` before any work, naming the numbers and what would fit.

The costs per unit (measured with ``tracemalloc`` on the A-H and plate plans: 15-19 kB a
trial of 54 searches, 0.7 kB a trial of 10; rounded up):

- :data:`TRIAL_BYTES` a trial's result without its searches;
- :data:`SEARCH_BYTES` per search of a trial (its id, and its event when it landed partly off);
- :data:`SAMPLE_BYTES` per main trial and report point (two samples kept, 8 bytes each), and
  :data:`ROW_BYTES` per main trial and point of the largest row (the transients of the row
  being made: its error vectors come a few points at a time; the spread of each of its two
  samples takes a copy of it, 8 bytes, and both are taken at once on a large report,
  :func:`planner.sim.summary.build_rows`);
- :data:`XOFFSET_BYTES` per main trial and slot hole of an x-offset run (its x error, and the
  error vectors of the x-offset rows).

Beside its results a run holds the part: :data:`FIXED_BYTES` and :data:`TRIANGLE_BYTES` per
triangle of the work object, for all its processes together (the cell it checks in, the
simulation's own part with its faces and ray caster, and each worker's copy; measured with the
proportional set size of the process tree: 317 MB with the 1,136-triangle plate, 849 MB with
196,608 triangles, 2,324 MB with 786,432). The results get what the part leaves of
:data:`calib.limits.MEMORY_BUDGET_BYTES`, at most :data:`calib.limits.MAX_RESULT_BYTES`. A run
inside a process that holds memory already (the UI server, its session's cell and drawings:
``held_bytes``) runs in that process, with its own cell and part: :data:`IN_PROCESS_TRIANGLE_BYTES`
a triangle (measured: a UI server at 922 MiB with a 496,896-triangle part went to 2,200 MiB
validating 4,680 trials).
"""

from __future__ import annotations

from dataclasses import dataclass

from calib.errors import InputError
from calib.limits import MAX_RAY_WORK, MAX_RESULT_BYTES, MEMORY_BUDGET_BYTES, MiB
from calib.plan.file import Plan
from calib.plan.report_spec import RegionSpec

TRIAL_BYTES = 1024
FIXED_BYTES = 320 * MiB
TRIANGLE_BYTES = 2700
IN_PROCESS_TRIANGLE_BYTES = 2200
SEARCH_BYTES = 320
SAMPLE_BYTES = 16
ROW_BYTES = 32
XOFFSET_BYTES = 64
#: The six frame rows (origin x/y/z, three rotations): one sample per trial each.
FRAME_ROWS = 6

__all__ = ["RunSize", "check_run_size", "run_size", "sensitivity_runs"]


@dataclass(frozen=True)
class RunSize:
    """The size of one validation run.

    Attributes:
        trials: main trials.
        protocol_trials: trials of the paper's protocol (positions x repeats; 0 without).
        searches: searches per trial (upper bound: every round of an iterative fit).
        slot_holes: slot holes of the x-offset run (0 without one).
        report_points: report points summed over the rows (a frame row counts one).
        largest_row: report points of the largest row.
        triangles: triangles of the work object (0: not known yet, before it is loaded).
        held_bytes: memory the process running the trials holds already (the UI server);
            0: a command of its own.
        rays: rays per search (the sensor's ``n_rays``).
        runs: how many times the trials run (the sensitivity table: once per noise term).
    """

    trials: int
    protocol_trials: int
    searches: int
    slot_holes: int
    report_points: int
    rays: int
    runs: int = 1
    largest_row: int = 0
    triangles: int = 0
    held_bytes: int = 0

    @property
    def per_trial_bytes(self) -> int:
        """Bytes one main trial keeps until the report: its result and its samples."""
        result = TRIAL_BYTES + SEARCH_BYTES * self.searches + 8 * self.slot_holes
        samples = SAMPLE_BYTES * self.report_points + ROW_BYTES * self.largest_row
        return result + samples + XOFFSET_BYTES * self.slot_holes

    @property
    def result_bytes(self) -> int:
        """Bytes the results of one run hold until its report is made (estimate, from above)."""
        protocol = TRIAL_BYTES + SEARCH_BYTES * self.searches + 8 * self.slot_holes
        return self.trials * self.per_trial_bytes + self.protocol_trials * protocol

    @property
    def room_bytes(self) -> int:
        """What the results may hold: the budget less the part's share, at most
        :data:`calib.limits.MAX_RESULT_BYTES`."""
        if self.held_bytes:
            part = self.held_bytes + IN_PROCESS_TRIANGLE_BYTES * self.triangles
        else:
            part = FIXED_BYTES + TRIANGLE_BYTES * self.triangles
        return max(0, min(MAX_RESULT_BYTES, MEMORY_BUDGET_BYTES - part))

    @property
    def ray_work(self) -> int:
        """Rays cast by all runs: trials x searches x rays (the edge scans' few rays aside)."""
        return self.runs * (self.trials + self.protocol_trials) * self.searches * self.rays


def run_size(
    plan: Plan,
    trials: int | None = None,
    protocol: tuple[int, int] | None = None,
    fmt: str | None = None,
    runs: int = 1,
) -> RunSize:
    """The size of a validation of ``plan`` (see :class:`RunSize`), from the plan alone.

    Args:
        plan: the plan.
        trials: main trials (default ``plan.validation.trials``).
        protocol: ``(positions, repeats)`` of the paper's protocol, or ``None``.
        fmt: the controller whose program is simulated (``None``: the default).
        runs: how many times the trials run (the sensitivity table runs them once per term).
    """
    from calib.paper.xoffset import xoffset_probe_points
    from planner.program.build import measuring_program
    from planner.program.model import SearchStep

    program = measuring_program(plan, fmt)
    searches = sum(isinstance(s, SearchStep) for s in program.steps)
    searches *= int(getattr(plan.procedure, "max_rounds", 1))
    slot_holes = 0
    run = getattr(plan.procedure, "xoffset", None)
    if run is not None:
        searches += sum(len(row) for row in xoffset_probe_points(run.grid, run.layers, run.teeth))
        slot_holes = run.grid.n_slots * run.grid.n_layers
    spec = plan.validation.report
    rows = [1] * (
        FRAME_ROWS + (1 if spec.points_of_interest is None else len(spec.points_of_interest))
    )
    for region in spec.regions if spec.regions is not None else [RegionSpec(name="part")]:
        slots = region.points == "slot_holes" and slot_holes > 0
        rows.append(min(region.max_points, slot_holes) if slots else region.max_points)
    rows += [slot_holes] * (2 if slot_holes else 0)  # the two x-offset rows
    return RunSize(
        trials=plan.validation.trials if trials is None else int(trials),
        protocol_trials=0 if protocol is None else int(protocol[0]) * int(protocol[1]),
        searches=searches,
        slot_holes=slot_holes,
        report_points=sum(rows),
        rays=int(plan.validation.sensor.n_rays),
        runs=runs,
        largest_row=max(rows),
    )


def check_run_size(size: RunSize, what: str = "validation") -> None:
    """Raise :class:`InputError` when ``size`` exceeds the memory or the computing budget,
    naming the numbers, the bound and the most trials that fit."""
    protocol = f" + {size.protocol_trials:,} protocol trials" if size.protocol_trials else ""
    if size.result_bytes > size.room_bytes:
        room = size.room_bytes - size.protocol_trials * (
            TRIAL_BYTES + SEARCH_BYTES * size.searches + 8 * size.slot_holes
        )
        fit = max(0, room // size.per_trial_bytes)
        server = f"the server ({size.held_bytes / MiB:,.0f} MiB) and " if size.held_bytes else ""
        part = (
            f", what {server}a {size.triangles:,}-triangle part "
            f"{'leave' if server else 'leaves'} of the 2 GB"
            if size.room_bytes < MAX_RESULT_BYTES
            else ""
        )
        raise InputError(
            f"{what}: {size.trials:,} trials{protocol} keep about "
            f"{size.result_bytes / MiB:,.0f} MiB of results until the report, at most "
            f"{size.room_bytes / MiB:.0f} MiB{part} (each trial keeps "
            f"~{size.per_trial_bytes / 1024:.1f} kB: {size.searches} searches and "
            f"{size.report_points:,} report points; a run stays under 2 GB with its workers): "
            f"at most {fit:,} trials of this plan fit; use fewer trials, or fewer report "
            "points (validation.report.regions max_points)"
        )
    if size.ray_work > MAX_RAY_WORK:
        per = size.runs * size.searches * size.rays
        fit = max(0, MAX_RAY_WORK // max(per, 1) - size.protocol_trials)
        runs = f" x {size.runs} runs" if size.runs > 1 else ""
        raise InputError(
            f"{what}: {size.trials:,} trials{protocol}{runs} x {size.searches} searches x "
            f"{size.rays:,} rays is {size.ray_work:.3g} ray casts, at most {MAX_RAY_WORK:.0e} "
            f"(hours of computing; more is a run of days): at most {fit:,} trials with "
            f"{size.rays:,} rays; use fewer trials or fewer rays (validation.sensor.n_rays)"
        )


def sensitivity_runs(plan: Plan) -> int:
    """How many times the sensitivity table runs the trials: all terms on, then each noise
    term off in turn (the terms of :func:`planner.sim.sensitivity.noise_terms`)."""
    from planner.sim.sensors import sensor_kind

    v = plan.validation
    robot_terms = ("repeatability_sigma_m", "tcp_sigma_m", "accuracy_amplitude_m")
    robot = sum(bool(getattr(v.robot_error, attr)) for attr in robot_terms)
    return 2 + len(sensor_kind(v.sensor).noise_terms) + robot  # + all on, misplacement off
