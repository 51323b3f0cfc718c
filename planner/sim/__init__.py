"""Simulated calibrations: sensors against the true mesh, robot errors, the Monte Carlo.

Owns:
    - :mod:`planner.sim.sensors`: the sensor registry (:data:`SENSORS`: model -> simulator);
    - :mod:`planner.sim.probe`: :class:`SimulatedProbe`, the proximity sensor's searches
      against the misplaced part (closed-form approach, scanned and refined edge search);
    - :mod:`planner.sim.raycast`: batched first-hit ray casting (Embree);
    - :mod:`planner.sim.search_events`: what happened in a search (landings, reachability);
    - :mod:`planner.sim.trial`: one trial (:class:`TrialRunner`), the simulation setup;
    - :mod:`planner.sim.montecarlo`: :func:`validate`, many seeded trials on up to 2 processes;
    - :mod:`planner.sim.report` and :mod:`planner.sim.plots`: the Table-1 report and its PNGs.

The physical models themselves (sensor, robot error, misplacement) are in :mod:`calib.models`;
a cell, when a trial vets its searches in one, is passed in explicitly. The plan-level entry
point is :func:`planner.validate.validate_plan`. ``docs/simulation.md`` has the models.
"""
