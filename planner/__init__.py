"""wobjcal planner: the cell, its kinematics and collisions, the simulation, and the plan jobs.

Subpackages, from the bottom up (each imports only the ones before it; a test checks this):
    - :mod:`planner.robot`: the URDF parser, kinematics, reach;
    - :mod:`planner.parts`: built-in work objects (the stator);
    - :mod:`planner.faces`: planar faces and sensor footprints;
    - :mod:`planner.cad`: STEP and IGES parts;
    - :mod:`planner.cell`: the PyBullet cell, feasibility of probe poses and search paths;
    - :mod:`planner.program`: the measuring program a controller runs for a plan (its steps,
      safe starts and searches, and its execution against a probe), which every job judges;
    - :mod:`planner.sim`: sensors against the mesh, error models in use, the Monte Carlo;
    - :mod:`planner.export`: robot programs (RAPID, KRL, URScript, FANUC TP);
    - :mod:`planner.results`: what the controllers write back, read into measurements;
    - :mod:`planner.plan_cell`: a plan's cell and frames (the one place the part is loaded).

The jobs, one package each, which every face of the product (the command line, the web UI,
scripts) calls: :mod:`planner.check` (the verdict on the program the robot will run, so every
other job runs it and it sits below them), then side by side, importing none of each other,
:mod:`planner.validate`, :mod:`planner.suggest`, :mod:`planner.calibrate`,
:mod:`planner.export_plan`, :mod:`planner.sweep` and :mod:`planner.demo` (the built-in demo);
:mod:`planner.cli` is the ``wobjcal`` command over them all. :mod:`planner.builtins` lists the
built-in robots, tools and parts; :mod:`planner.errors` the planner's errors;
:mod:`planner.reasons` why a pose, a search or a move fails, with its kind; :mod:`planner.memo`
the in-process memo of what is computed from a robot's or a part's content.
"""

from calib._version import __version__

__all__ = ["__version__"]
