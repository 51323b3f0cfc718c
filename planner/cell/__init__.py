"""The kinematic cell: robot, tool, work object and fixtures in one PyBullet DIRECT client.

Owns:
    - :mod:`planner.cell.scene`: :class:`CellScene` (bodies, joint state, frames, the clearance
      query, ``saved_state()``, ``close()``/``with``); :mod:`planner.cell.cell`: :class:`Cell`,
      the scene with its queries as methods;
    - bodies: :mod:`~planner.cell.bodies`, :mod:`~planner.cell.robot_body`,
      :mod:`~planner.cell.tool` (tool and TCP frames), :mod:`~planner.cell.workobject` (meshes,
      units, repair), :mod:`~planner.cell.fixtures`, :mod:`~planner.cell.pybullet_client`;
    - collisions: :mod:`~planner.cell.acl` (allowed-collision list, sampled once, cached),
      :mod:`~planner.cell.collision` and :mod:`~planner.cell.clearance` (the clearance query
      and its result, the default margins);
    - queries: :mod:`~planner.cell.feasibility` (probe poses, ``check_probes``),
      :mod:`~planner.cell.probe_clearance` (its staged collision checks),
      :mod:`~planner.cell.search_paths` (``check_search``), :mod:`~planner.cell.reachability_map`.

One client per cell, ``physicsClientId`` on every call, no global state; not thread-safe (the UI
serializes access through one worker). ``docs/cell.md`` has the details.
"""
