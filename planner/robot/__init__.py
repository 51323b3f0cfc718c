"""The robot: its URDF (one parser), its kinematics and its reach.

Owns:
    - :mod:`planner.robot.urdf` (+ ``urdf_model``, ``urdf_meshes``): the one URDF parser, built
      on yourdfpy, into a frozen, validated :class:`~planner.robot.urdf_model.URDFModel`
      (links with inertials, joints, shapes; fixed-tree poses, mass and centre of mass);
    - :mod:`planner.robot.kinematics`: :class:`KinematicChain` (vectorized FK, Jacobian),
      analytic OPW IK, numeric IK, :func:`make_ik_solver`, ABB confdata;
    - :mod:`planner.robot.reach`: the arm's reach and why a pose has no IK solution.

No simulator: everything here is numpy; the PyBullet bodies are built in :mod:`planner.cell`.
``docs/kinematics.md`` has the details.
"""
