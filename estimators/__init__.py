"""Estimation: the plug-in interface and causal replay, the shared estimation building blocks,
and the built-in estimators.

Modules
-------
base          the ``Estimator`` contract (SPEC section 6) and ``InitialState``
registry      finding estimator classes: built-ins, entry points, ``module:Class``
replay        causal replay of a dataset into one estimator; the solution file (SPEC section 7)
strapdown     NED quaternion INS mechanisation
kalman        KF prediction, Joseph-form update, closed/open-loop error states
sigma_points  symmetric and spherical-simplex sigma points, the unscented transform
gauss_markov  first-order Gauss-Markov and Van Loan discretisation
nav_error     the [dr, dv, psi] navigation error convention
constraints   non-holonomic and height pseudo-measurements
baselines     ``gnss_only`` and ``dead_reckoning``
"""
