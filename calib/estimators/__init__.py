"""General frame estimators: any faces, any number of points, with their uncertainty.

Owns:
    - :mod:`calib.estimators.layout`: point-to-plane constraint sets and their Jacobians;
    - :mod:`calib.estimators.three_two_one`: closed-form 3-2-1 alignment on any three
      non-parallel faces (:func:`three_two_one`, :class:`ThreeTwoOneLayout`);
    - :mod:`calib.estimators.best_fit`: least-squares point-to-plane fit with the 6x6
      covariance and the predicted error at any point (:func:`best_fit`);
    - :mod:`calib.estimators.observability`: does a layout fix all 6 degrees of freedom, and
      if not, which motion is free, in words (:func:`analyze_layout`);
    - :mod:`calib.estimators.runners`: step-by-step 3-2-1 and best fit driven by a probe.

Pure numpy/scipy. ``docs/estimators.md`` has the mathematics; the procedures that use them are
registered in :mod:`calib.procedures`.
"""
