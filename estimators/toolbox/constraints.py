"""Pseudo-measurements of land-vehicle motion constraints, with their Jacobians with respect
to the navigation error state of ``estimators.toolbox.nav_error`` ([dr, dv, psi], estimate minus
truth).

* Non-holonomic constraint: a wheeled vehicle does not slide sideways or leave the road, so the
  body-frame velocity v^b = C_n^b v^n has zero lateral (y) and vertical (z) components (Chan et
  al., "non-holonomic constraint" measurement; Tan et al. 2008 velocity constraint). With
  C(estimate) = (I + [psi x]) C(true), v^b(estimate) ~ v^b + C_n^b dv + C_n^b [v^n x] psi, so
  H = rows y, z of [0, C_n^b, C_n^b [v^n x]].
* Height constraint: the height is known (a flat road, a map), h(estimate) = h - dr_d, so
  H = [0, 0, -1, 0 ...] (Tan et al. 2008).

Each function returns dz = h(estimate) - z, ready for ``kalman.ErrorState.update``, and H over
``n_states`` columns with the navigation block in the first nine.

Public functions
----------------
nonholonomic, height.
"""

from __future__ import annotations

import numpy as np

from simulator.earth import quat_to_dcm, skew


def nonholonomic(q: np.ndarray, v_ned: np.ndarray, n_states: int = 9
                 ) -> tuple[np.ndarray, np.ndarray]:
    """Zero lateral and vertical body velocity.

    Parameters
    ----------
    q : (4,) estimated body-to-NED quaternion; v_ned : (3,) estimated NED velocity, m/s.
    n_states : int
        Length of the error state (>= 9).

    Returns
    -------
    dz : (2,) estimated lateral and vertical body velocity (the constraint says 0), m/s;
    h : (2, n_states) Jacobian with respect to [dr, dv, psi, ...].
    """
    c_nb = quat_to_dcm(q).T
    v_b = c_nb @ v_ned
    h = np.zeros((2, n_states))
    h[:, 3:6] = c_nb[1:3]
    h[:, 6:9] = (c_nb @ skew(v_ned))[1:3]
    return v_b[1:3], h


def height(h_estimate: float, h_reference: float, n_states: int = 9
           ) -> tuple[np.ndarray, np.ndarray]:
    """Known height.

    Parameters
    ----------
    h_estimate : estimated ellipsoidal height, m; h_reference : the known height, m.

    Returns
    -------
    dz : (1,) h_estimate - h_reference, m; h : (1, n_states) Jacobian, -1 on dr_d.
    """
    h = np.zeros((1, n_states))
    h[0, 2] = -1.0
    return np.array([h_estimate - h_reference]), h
