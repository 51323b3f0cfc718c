"""Planar faces of a work-object mesh, and whether a probe point's sensor footprint lies on one.

Owns:
    - :mod:`planner.faces.detection`: :func:`find_planar_faces` (cached per mesh),
      :class:`PlanarFaces`, :class:`NoPlanarFaceError` (saying why the largest region fails);
    - :mod:`planner.faces.regions`: flat regions and their least-squares planes;
    - :mod:`planner.faces.footprint`: the sensor's round footprint and its ray tests;
    - :mod:`planner.faces.checks`: per-point checks (:func:`check_probe_faces`,
      :func:`check_plan_faces`, :func:`plan_face_reasons`) with the plan's sensor footprint.

trimesh and numpy only. ``docs/planar_faces.md`` has the tolerances and why.
"""
