"""The filter toolbox: building blocks shared by every built-in estimator, each written once.

Modules
-------
kalman        KF prediction, Joseph-form update, closed/open-loop error states
sigma_points  symmetric and spherical-simplex sigma points, the unscented transform
ukf           the sigma-point filter driver (manifold hooks, augmented or additive noise)
strapdown     NED quaternion INS mechanisation
gauss_markov  first-order Gauss-Markov and Van Loan discretisation
nav_error     the [dr, dv, psi] navigation error convention
constraints   non-holonomic and height pseudo-measurements
ambiguity     integer ambiguity resolution: LAMBDA (decorrelation and search), ratio test,
              bootstrapped success rate, partial fixing
"""
