"""Probe poses in the cell: is a point reachable and clear, with which pose, and its search path?

Owns the candidates of a batch of points (IK over the sensor's rotations, limits,
singularity), the rule that picks one and the choice that applies it broad phase first
(flags, open parts, exact clearance with Bullet), the feasibility entry point
(:func:`check_probes`), the statuses the heat map shows, the search paths
(:func:`check_search`) and the surface reachability map. Built on :mod:`planner.cell.scene`,
:mod:`planner.cell.broad` and :mod:`planner.cell.kernels`; :class:`planner.cell.cell.Cell`
forwards to it.

Modules:

- :mod:`~planner.cell.probe.feasibility`: probe-pose feasibility, batch-first: N surface points in,
  N answers (with reasons) out;
- :mod:`~planner.cell.probe.probe_candidates`: the candidate poses of a batch of probe points: IK,
  limits, singularity, order. Vectorized;
- :mod:`~planner.cell.probe.probe_choice`: deciding probe points from their candidates: broad phase
  first, Bullet only where needed;
- :mod:`~planner.cell.probe.probe_clearance`: exact clearance of probe candidates, part by part, for
  the parts the broad phase left open;
- :mod:`~planner.cell.probe.probe_flags`: what the broad phase and the slack bounds know of one
  probe point's candidates;
- :mod:`~planner.cell.probe.probe_parts`: a probe candidate's open clearance parts with Bullet,
  cheapest first;
- :mod:`~planner.cell.probe.probe_rule`: the rule that picks a probe point's pose from its
  candidates, given their clearances;
- :mod:`~planner.cell.probe.probe_status`: statuses of probe points without their exact poses: the
  reachability heat map's question;
- :mod:`~planner.cell.probe.reachability`: surface reachability map: area-weighted samples on the
  work object, feasibility per sample;
- :mod:`~planner.cell.probe.search_paths`: search-path feasibility: can the robot run a whole
  approach or edge search?;
- :mod:`~planner.cell.probe.search_paths_many`: many search paths at once, each run with its
  program's pose: the vetting of simulated searches.
"""

from planner.cell.probe.feasibility import ProbeFeasibility, check_probes
from planner.cell.probe.probe_status import ProbeStatuses, probe_statuses
from planner.cell.probe.reachability import ReachabilityMap, reachability_map, sample_surface
from planner.cell.probe.search_paths import PathFeasibility, check_search
from planner.cell.probe.search_paths_many import PosedSearch, check_searches

__all__ = [
    "PathFeasibility",
    "PosedSearch",
    "ProbeFeasibility",
    "ProbeStatuses",
    "ReachabilityMap",
    "check_probes",
    "check_search",
    "check_searches",
    "probe_statuses",
    "reachability_map",
    "sample_surface",
]
