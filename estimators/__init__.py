"""Estimation: the plug-in interface, the filter toolbox and the built-in estimators.

The causal replay that feeds an estimator is the harness, not an estimator: it lives in
``simulator.replay``. Estimators depend only on the core (``simulator.earth``,
``simulator.columns``, ``simulator.errors``) and on the replay's message contract described
in ``estimators.base``.

Modules and packages
--------------------
base          the ``Estimator`` contract (SPEC section 6) and ``InitialState``
registry      finding estimator classes: built-ins, entry points, ``module:Class``
toolbox/      shared filter blocks (Kalman updates, sigma points, strapdown, error models, aids)
builtin/      the baselines and the estimators of the seed papers
"""
