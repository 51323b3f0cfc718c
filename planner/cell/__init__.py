"""The kinematic cell: robot, tool, work object and fixtures in one PyBullet DIRECT client.

By concept, in layers; a module imports only its own layer and those before it in this list
(``tests/test_import_graph.py`` checks it):

- :mod:`~planner.cell.disk_cache`: the per-user cache of derived arrays (distance fields,
  allowed-collision lists, CAD triangulations), below everything;
- :mod:`~planner.cell.kernels`: the broad phase's numba kernels, their on-disk cache and the
  warm-up (``python -m planner.cell.kernels.warmup``);
- :mod:`~planner.cell.scene`: :class:`~planner.cell.scene.CellScene` and its bodies (robot,
  tool, work object, fixtures), the allowed-collision list, the clearance query, rays;
- :mod:`~planner.cell.broad`: the broad phase of the clearance query for batches (sphere trees,
  distance fields, slack bounds, the verdict of a sampled path);
- :mod:`~planner.cell.probe`: probe poses (candidates, the choice among them, feasibility,
  statuses for the heat map), search paths and the reachability map;
- :mod:`~planner.cell.moves`: joint moves, via paths and vias for a move that collides;
- :mod:`~planner.cell.cell`: :class:`~planner.cell.cell.Cell`, the scene with its queries as
  methods: what the jobs, the CLI and the UI open.

Each subpackage's ``__init__`` lists its public names (``__all__``); code outside a subpackage
imports them from the subpackage, never from its modules (``planner.cell.kernels``, whose
names are modules, aside).

One client per cell, ``physicsClientId`` on every call, no global state; not thread-safe (the UI
serializes access through one worker). ``docs/cell.md`` has the details.
"""

__all__ = ["broad", "cell", "disk_cache", "kernels", "moves", "probe", "scene"]
