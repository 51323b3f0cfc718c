"""Robot kinematics: URDF chains, forward kinematics, analytic OPW and numeric inverse kinematics.

Entry points: :class:`planner.robot.kinematics.chain.KinematicChain` and
:func:`planner.robot.kinematics.solver.make_ik_solver`; see ``docs/kinematics.md``.
"""
