"""wobjcal planner: the cell, its kinematics and collisions, the simulation, and the plan jobs.

Subpackages, from the bottom up (each imports only the ones before it; a test checks this):
    - :mod:`planner.robot`: the URDF parser, kinematics, reach;
    - :mod:`planner.parts`: built-in work objects (the stator);
    - :mod:`planner.faces`: planar faces and sensor footprints;
    - :mod:`planner.cell`: the PyBullet cell, feasibility of probe poses and search paths;
    - :mod:`planner.program`: the measuring program a controller runs for a plan (its steps,
      safe starts and searches, and its execution against a probe), which every job judges;
    - :mod:`planner.sim`: sensors against the mesh, error models in use, the Monte Carlo;
    - :mod:`planner.export`: robot programs (RAPID, KRL, URScript, FANUC TP);
    - :mod:`planner.cli`: the ``wobjcal`` command.

The plan-level jobs sit side by side at the top, and every face of the product (the command
line, the web UI, scripts) calls them: :func:`planner.check.check_plan`,
:func:`planner.validate.validate_plan`, :func:`planner.calibrate.calibrate_plan`,
:func:`planner.export_plan.export_program`, with :mod:`planner.plan_cell` (a plan's cell and
frames) and :mod:`planner.demo` (the built-in demo). :mod:`planner.builtins` lists the built-in
robots, tools and parts; :mod:`planner.errors` the planner's errors.
"""

from calib._version import __version__

__all__ = ["__version__"]
