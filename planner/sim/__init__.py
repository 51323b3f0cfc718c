"""Simulated calibrations of any plan: sensors against the true mesh, robot errors, the Monte
Carlo, the prediction beside it, and the report.

Owns:
    - :mod:`planner.sim.sensors`: the sensor registry (:data:`SENSORS`: model -> simulator);
    - :mod:`planner.sim.sensor_base`: :class:`SimulatedSensor`, what every simulated sensor
      shares (robot offset, refusals, reachability vetting, landings, events, runs in turn);
    - :mod:`planner.sim.proximity`: :class:`SimulatedProbe`, the proximity sensor's searches
      against the misplaced part (closed-form approach, scanned and refined edge search);
    - :mod:`planner.sim.touch`: the touch probe's searches (the sweeping ball's exact contact);
    - :mod:`planner.sim.raycast`: batched first-hit ray casting (Embree), with triangle ids,
      and its float64 step compiled (:mod:`planner.sim.hit_kernel`);
    - :mod:`planner.sim.search_events`: what happened in a search (reasons, landings over the
      whole footprint against the planar faces, reachability hooks);
    - :mod:`planner.sim.setup`: :class:`SimulationSetup`, what every trial of a plan shares;
    - :mod:`planner.sim.trial`: one trial (:class:`TrialRunner`) of any procedure;
    - :mod:`planner.sim.xoffset`: the paper's x-offset run and its slot-target errors;
    - :mod:`planner.sim.montecarlo`: :func:`simulate` (any plan) and
      :func:`simulate_stator_ah` (A-H on a stator), many seeded trials on up to 2 processes;
      :mod:`planner.sim.simulation_run` (a run started on the workers, finished later) and
      :mod:`planner.sim.trial_pool` (the worker processes), :mod:`planner.sim.pool` (started
      from a fork server) and :mod:`planner.sim.worker_preload` (what the server loads once);
    - :mod:`planner.sim.predict`: the intervals predicted from the procedure's linearisation;
    - :mod:`planner.sim.rows`, :mod:`planner.sim.report_points`, :mod:`planner.sim.summary`,
      :mod:`planner.sim.report`: what each row measures, the rows of a plan, the report built
      from the trials, and the report with its Markdown;
    - :mod:`planner.sim.sensitivity`: each noise term off in turn;
    - :mod:`planner.sim.error_map` and :mod:`planner.sim.plots`: the error over the part and
      the PNGs.

The physical models themselves (sensors, robot error, misplacement) are in :mod:`calib.models`;
a cell, when a trial vets its searches in one, is passed in explicitly. The plan-level entry
point is :func:`planner.validate.job.validate_plan`. ``docs/simulation.md`` has the models.
"""
