"""The paper's method: Hultman & Leijon (2013), equations (1)-(14) and the A-H procedure.

Owns:
    - :mod:`calib.paper.hultman`: eq. 1-12 (orientation from three points, origin shifts, the
      constructed point P3);
    - :mod:`calib.paper.xoffset`: eq. 13-14, the x-offset matrix and the slot-hole target;
    - :mod:`calib.paper.settings`: :class:`~calib.paper.settings.Hultman2013`, the one
      definition of the A-H settings (plan, procedure, simulation, RAPID program);
    - :mod:`calib.paper.stator_layout`: the A-H layout checks (:func:`check_stator_points`);
    - :mod:`calib.paper.stator_procedure`: :func:`run_stator_procedure`, section 3.2 step by
      step, driven by a probe callback.

How the text maps to the code, with its ambiguities: ``docs/paper_method.md``. The procedure
is registered for plans in :mod:`calib.procedures.hultman2013`.
"""
