"""Joint moves in the cell: limits and collisions along a move, via paths, vias that clear a move.

Built on :mod:`planner.cell.scene` only: a move is checked pose by pose with the scene's
clearance query. ``wobjcal check`` (the moves through each point's vias, ``--add-vias``) and
the UI's Teach tab call it.

Modules:

- :mod:`~planner.cell.moves.joint_moves`: joint moves in the cell: limits and collisions along a
  move, linear in joint space;
- :mod:`~planner.cell.moves.via_search`: via points that clear a joint move between two probe
  points: retract, swing, approach.
"""

from planner.cell.moves.joint_moves import MoveCheck, ViaPath, check_joint_move, check_via_path
from planner.cell.moves.via_search import suggest_vias

__all__ = ["MoveCheck", "ViaPath", "check_joint_move", "check_via_path", "suggest_vias"]
