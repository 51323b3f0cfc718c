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
    - the broad phase of the clearance query, for batches of candidates:
      :mod:`~planner.cell.broad_phase` (with :mod:`~planner.cell.broad_arrays`,
      :mod:`~planner.cell.broad_parts`), its compiled kernels (:mod:`~planner.cell.broad_kernels`,
      :mod:`~planner.cell.mesh_kernels`, :mod:`~planner.cell.field_kernels`,
      :mod:`~planner.cell.gjk_kernels`, :mod:`~planner.cell.bound_kernels`; cached where
      :mod:`~planner.cell.kernel_cache` says, typed helpers compiled on first use by
      :mod:`~planner.cell.lazy_kernel`), :mod:`~planner.cell.sphere_tree`,
      :mod:`~planner.cell.link_geometry`, :mod:`~planner.cell.distance_field` (cached on disk by
      :mod:`~planner.cell.disk_cache`);
    - queries: :mod:`~planner.cell.feasibility` (probe poses, ``check_probes``) with
      :mod:`~planner.cell.probe_candidates`, :mod:`~planner.cell.probe_rule`,
      :mod:`~planner.cell.probe_choice`, :mod:`~planner.cell.probe_flags`,
      :mod:`~planner.cell.probe_parts`,
      :mod:`~planner.cell.slack_bounds` (bounds that spare Bullet queries) and
      :mod:`~planner.cell.probe_clearance` (Bullet for the parts the broad phase leaves open),
      :mod:`~planner.cell.path_clearance` (the verdict of a sampled path, broad phase first),
      :mod:`~planner.cell.search_paths` (``check_search``),
      :mod:`~planner.cell.reachability_map`.

One client per cell, ``physicsClientId`` on every call, no global state; not thread-safe (the UI
serializes access through one worker). ``docs/cell.md`` has the details.
"""
