"""How large a number a user may set: the one table of the bounds that keep wobjcal's memory in
budget (issue 27, "never exhaust the machine").

Every count or size a plan, a command-line option, a mesh, a URDF or an upload sets is bounded
here, so that no command and no UI server goes above :data:`MEMORY_BUDGET_BYTES` whatever the
input. A number above its bound is refused *before any work*, with a message naming the field,
the value, the bound and why (``docs/cli.md``, "Limits"). A bound is far above what a real cell
needs (the value a real user sets is in the comment) and far below what exhausts the machine
(the cost per unit measured on the 2-core test machine is in the comment as well).

The costs behind the numbers (``python3 -m planner ...`` under ``/usr/bin/time -v``, and the
proportional set size of a command's processes):

- ``check`` holds about 0.15 MB per plan point (poses, candidates, moves) and its layout checks
  compare points pairwise (a 10,000-point plan asked for a 2.2 GiB ``(10000, 10000, 3)`` array);
- a work-object mesh costs about 1.4 kB per triangle while the cell is built (repair ~0.8 kB,
  the PyBullet concave shape ~0.45 kB, the ray caster ~0.3 kB), and ``validate`` about 2.6 kB
  (its cell, the simulation's own copy with its faces and ray caster, each worker's copy):
  786,432 triangles took ``check`` to 1.4 GB and ``validate`` to 2.3 GB;
- a simulated search casts ``n_rays`` rays once and ``n_scan_rays`` rays per 2.5 mm step of an
  edge scan, about 0.3 kB a ray while they are cast;
- ``validate`` keeps every trial's result (about 1 kB, plus 0.3 kB a search) and, per report
  row, two samples per trial and report point (8 bytes each) until the report is made.
"""

from __future__ import annotations

from typing import Final

MiB: Final = 1024 * 1024

#: What no command and no UI server may exceed, whatever the input, bytes (the figures of the
#: largest inputs accepted are in ``docs/cli.md``).
MEMORY_BUDGET_BYTES: Final = 2 * 1024 * MiB

# ---- plans -------------------------------------------------------------------------------
#: Most points in a plan: a calibration uses 6 (3-2-1) to 8 (A-H) to a few dozen (best fit);
#: ``check`` holds ~0.15 MB a point and compares points pairwise (10,000 points: 6.8 GB).
MAX_PLAN_POINTS: Final = 500
#: Most vias on the way to one point (a real path needs 1 to 3; each is checked in the cell).
MAX_VIAS_PER_POINT: Final = 64
#: Longest search start offset and longest overtravel, each, m: a robot's reach is 1-3 m and a
#: search a few centimetres; an edge scan casts its rays every 2.5 mm of it.
MAX_SEARCH_LENGTH_M: Final = 1.0
#: Most fixtures in a cell (a table, clamps, a pallet: a handful), each a body in the cell.
MAX_FIXTURES: Final = 64

# ---- sensors (every kind) ------------------------------------------------------------------
#: Most rays over a sensor face (proximity ``n_rays``) or a touch probe's ball (touch
#: ``n_rays``): the defaults are 256 and 121; 65,536 rays take ~20 MB a cast (a touch probe
#: with 10^9 rays took 10.9 GB and was killed).
MAX_RAYS: Final = 65_536
#: Most rays of the proximity sensor's coarse edge scan (``n_scan_rays``, default 19): they are
#: cast at every 2.5 mm step of an edge search at once (65,536 of them: 1 GB for two trials).
MAX_SCAN_RAYS: Final = 1_024

# ---- validation --------------------------------------------------------------------------
#: Most trials of the paper's protocol (``--protocol PxR``: P x R, the paper's is 20 x 20),
#: the same bound as ``validation.trials``.
MAX_PROTOCOL_TRIALS: Final = 100_000
#: Most bytes the results of one validation may hold until its report is made: every trial's
#: outcome, and per report row and trial the samples of both fits (see
#: :class:`planner.sim.budget.RunSize`); with the process itself (~0.3 GB) and its two workers
#: (~0.3 GB each) a run stays within :data:`MEMORY_BUDGET_BYTES`. A large part takes its share
#: first: the results get what it leaves.
MAX_RESULT_BYTES: Final = 768 * MiB
#: Most ray casts of one validation: trials x searches per trial x rays per search. The
#: default A-H plan (400 trials, 54 searches, 256 rays) is 5.5 million; 2 x 10^9 is one to
#: three hours of computing (100,000 trials of it), more is a run of days.
MAX_RAY_WORK: Final = 2_000_000_000
#: Most confidence levels of a report (the paper gives 3).
MAX_REPORT_LEVELS: Final = 10
#: Most points of interest, and most regions, of a report (each is a row of every report).
MAX_REPORT_ROWS: Final = 100
#: Most surface points of one report region (``max_points``, default 2,000).
MAX_REGION_POINTS: Final = 20_000
#: Most slots along y, and most layers along z, of the A-H x-offset grid (a stator section has
#: a few dozen slots and ~10 layers).
MAX_XOFFSET_SLOTS: Final = 1_000
MAX_XOFFSET_LAYERS: Final = 100
#: Most Gauss-Newton iterations of the best fit (it converges in fewer than 10).
MAX_FIT_ITERATIONS: Final = 1_000
#: Most rounds of the iterative best fit (each runs every search again; it settles in 2 or 3).
MAX_ROUNDS: Final = 20

# ---- placement sweeps (``wobjcal sweep``) ---------------------------------------------------
#: Most placements of one sweep (``--samples``): each is a whole ``check`` (about 1 s for the
#: plate, 3 s for the stator on one core) and a CSV row of ~150 bytes; 100,000 stator
#: placements are about 40 core-hours, a night on a small cluster.
MAX_SWEEP_SAMPLES: Final = 100_000
#: Most worker processes of the local cluster (``--workers``): each holds its own cell
#: (~0.3-0.5 GB, ``docs/sweep.md``); a larger cluster is a running scheduler (``--scheduler``).
MAX_SWEEP_WORKERS: Final = 64
#: Memory limit of each worker process of the local cluster, bytes: a worker holds ~0.45-0.5 GB
#: after its first stator placement and grows ~45 MB a placement (each check's PyBullet client
#: keeps the part's mesh arrays; measured, ``docs/sweep.md``); its nanny restarts it at 95 % of
#: this, so 2 workers and the command itself (~0.2 GB) stay within the budget.
SWEEP_WORKER_MEMORY_BYTES: Final = 896 * MiB
#: Smallest and largest ``--memory-limit`` of a local sweep worker, MiB: below 512 a stator
#: worker would restart after every placement; 64 GiB is more than a worker ever needs.
MIN_SWEEP_WORKER_MIB: Final = 512
MAX_SWEEP_WORKER_MIB: Final = 65_536
#: Largest offset of a swept pose from the plan's, mm (``--base-x`` ...), and largest yaw, deg.
MAX_SWEEP_OFFSET_MM: Final = 10_000.0
MAX_SWEEP_YAW_DEG: Final = 180.0

# ---- cycle time (plausibility, not memory: a typo such as ms given as s is refused) --------
#: Longest settle time per search stop and longest I/O time per recorded point, s: a robot
#: settles in 0.1-0.5 s and writes a measurement in milliseconds; a minute is a typo.
MAX_SETTLE_S: Final = 60.0
MAX_IO_S: Final = 60.0
#: Largest joint acceleration of the cycle-time model, rad/s^2 (m/s^2 for a sliding joint):
#: industrial arms reach 5-50; 1,000 is far above any and still finite arithmetic.
MAX_JOINT_ACCELERATION_RAD_S2: Final = 1000.0

# ---- meshes and URDFs --------------------------------------------------------------------
#: Most triangles of one mesh (work object or fixture), and of all the cell's meshes together:
#: ``validate`` holds ~2.6 kB a triangle, so 500,000 take 1.6 GB of the 2 GB and leave the rest
#: to its results (a machined part's CAD export has 10^3-10^5; decimate a scan).
MAX_MESH_TRIANGLES: Final = 500_000
MAX_CELL_TRIANGLES: Final = 500_000
#: Most links (and most joints) of a URDF, refused before they are parsed (a 16 MiB URDF can
#: hold 500,000): an arm has 7 to 10 links, with a track, a positioner and a tool changer a few
#: dozen. Up to this many the file is read (~5 kB a link) and the robot is then refused by
#: PyBullet's own bound, 128 links in one body
#: (:data:`planner.cell.scene.bodies.PYBULLET_MAX_LINKS`).
MAX_URDF_LINKS: Final = 10_000
#: Most bytes of the mesh files a URDF refers to (all distinct files together): PyBullet and the
#: drawings load every one (a vendor arm's meshes are 5-40 MB).
MAX_URDF_MESH_BYTES: Final = 128 * MiB
#: Largest CAD file (STEP, IGES) read: OpenCASCADE holds its whole model and the triangulation
#: in memory, ~12 times the file over a ~0.3 GB base (measured: box_sides.STEP copied 4 and 16
#: times, 6.3 MB and 26 MB, read in 462 MB and 613 MB); 64 MiB stays near 1.1 GB, and a machined
#: part's STEP is a few MB.
MAX_CAD_FILE_BYTES: Final = 64 * MiB

# ---- the UI server -------------------------------------------------------------------------
#: Largest upload, bytes (viser holds an upload in memory until it is complete).
MAX_UPLOAD_BYTES: Final = 50 * MiB
#: Most uploads one tab may have under way at once (the UI takes them one by one).
MAX_UPLOADS_PER_CLIENT: Final = 2
#: Most bytes of the uploads under way from all tabs together (24 unfinished uploads from one
#: tab took the server from 697 to 1,552 MB).
MAX_UPLOADS_IN_FLIGHT_BYTES: Final = 128 * MiB
#: An unfinished upload that sends nothing for this long is dropped, s.
UPLOAD_IDLE_TIMEOUT_S: Final = 120.0
#: Most bytes a robot zip may unpack to (the meshes of a vendor arm are 5-40 MB; it is then read
#: as a URDF, :data:`MAX_URDF_MESH_BYTES`), and most files in it.
MAX_ZIP_UNPACKED_BYTES: Final = MAX_URDF_MESH_BYTES
MAX_ZIP_MEMBERS: Final = 2_000
#: Most bytes a zip's files may unpack to per byte of the zip: a mesh compresses 3-10 times;
#: a 513 KB zip that unpacks to 450 MiB (900 times) is a zip bomb.
MAX_ZIP_RATIO: Final = 100
#: Most bytes of uploads kept on disk (``~/.cache/wobjcal/uploads``): beyond it the oldest
#: that no session and no autosave uses are removed.
MAX_UPLOADS_KEPT_BYTES: Final = 1024 * MiB


__all__ = [
    "MAX_CAD_FILE_BYTES",
    "MAX_CELL_TRIANGLES",
    "MAX_FIT_ITERATIONS",
    "MAX_FIXTURES",
    "MAX_IO_S",
    "MAX_JOINT_ACCELERATION_RAD_S2",
    "MAX_MESH_TRIANGLES",
    "MAX_PLAN_POINTS",
    "MAX_PROTOCOL_TRIALS",
    "MAX_RAYS",
    "MAX_RAY_WORK",
    "MAX_REGION_POINTS",
    "MAX_REPORT_LEVELS",
    "MAX_REPORT_ROWS",
    "MAX_RESULT_BYTES",
    "MAX_ROUNDS",
    "MAX_SCAN_RAYS",
    "MAX_SEARCH_LENGTH_M",
    "MAX_SETTLE_S",
    "MAX_SWEEP_OFFSET_MM",
    "MAX_SWEEP_SAMPLES",
    "MAX_SWEEP_WORKERS",
    "MAX_SWEEP_WORKER_MIB",
    "MAX_SWEEP_YAW_DEG",
    "MAX_UPLOADS_IN_FLIGHT_BYTES",
    "MAX_UPLOADS_KEPT_BYTES",
    "MAX_UPLOADS_PER_CLIENT",
    "MAX_UPLOAD_BYTES",
    "MAX_URDF_LINKS",
    "MAX_URDF_MESH_BYTES",
    "MAX_VIAS_PER_POINT",
    "MAX_XOFFSET_LAYERS",
    "MAX_XOFFSET_SLOTS",
    "MAX_ZIP_MEMBERS",
    "MAX_ZIP_RATIO",
    "MAX_ZIP_UNPACKED_BYTES",
    "MEMORY_BUDGET_BYTES",
    "MIN_SWEEP_WORKER_MIB",
    "SWEEP_WORKER_MEMORY_BYTES",
    "UPLOAD_IDLE_TIMEOUT_S",
    "MiB",
]
