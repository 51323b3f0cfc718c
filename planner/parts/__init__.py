"""Built-in work objects: the paper's stator section, as geometry, mesh and demo placement.

Owns:
    - :mod:`planner.parts.stator`: :class:`StatorGeometry` (dimensions, slot holes, teeth, the
      bolt bulge; the paper's Fig. 2 and 8a);
    - :mod:`planner.parts.stator_mesh`: :func:`build_stator_mesh` and the factories of the
      built-in parts ``builtin:stator_section`` and ``builtin:stator_prototype``;
    - :mod:`planner.parts.stator_demo`: the demo placement (the part inclined before the robot)
      and the A-H points of section 3.2.

Built-in parts are listed in :data:`planner.builtins.BUILTIN_PARTS` and loaded lazily; a new
part is a module with a mesh factory plus one entry there.
"""
