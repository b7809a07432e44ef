"""Joint-space fitting of an articulated body (docs/interface.md "Version 2"):
recover its coordinates x from observed vertex positions, as inverse
kinematics or camera-to-robot calibration do.

The residual is r(x) = p(x) - p_observed over the chosen vertices, 3 N
values [m]; its Jacobian is the node's dp/dx (3 x dof per vertex, columns in
x order), so SciPy's ``least_squares`` gets exact derivatives in one
round trip per evaluation. Joint limits from ``get_bodies`` are the bounds
(+-inf where the URDF gives none).
"""
import numpy as np
from scipy.optimize import least_squares


class _Evaluations(object):
    """positions and J at the last x asked for, so that least_squares' fun and
    jac at the same x cost one get_vertex_jacobians call."""

    def __init__(self, client, body, vertices):
        self.client, self.body, self.vertices = client, body, vertices
        self.x, self.positions, self.jacobian = None, None, None
        self.calls = 0

    def at(self, x):
        if self.x is None or not np.array_equal(x, self.x):
            self.positions, self.jacobian = self.client.vertex_jacobians(self.body, q=x, vertices=self.vertices)
            self.x = np.array(x, dtype=float)
            self.calls += 1
        return self.positions, self.jacobian


def joint_bounds(client, body):
    """(lower, upper) of x for ``body``: -inf/+inf for a floating root's six
    coordinates, then the joint limits [rad or m]."""
    bodies = client.bodies()
    i = bodies.names.index(body)
    joints = bodies.joints[i]
    free = int(bodies.dofs[i]) - len(joints)
    lower = np.concatenate([np.full(free, -np.inf), [j.lower for j in joints]])
    upper = np.concatenate([np.full(free, np.inf), [j.upper for j in joints]])
    return lower, upper


def fit_joints(client, body, observed, x0, vertices=None, bounds=None):
    """x minimising |p(x) - observed|^2 from ``x0`` within ``bounds``
    ((lower, upper), default: the body's joint limits). ``observed`` is (N, 3)
    [m] for ``vertices`` (None = all). Returns (x, result, round trips)."""
    lower, upper = bounds if bounds is not None else joint_bounds(client, body)
    x0 = np.clip(np.asarray(x0, dtype=float), lower, upper)
    observed = np.asarray(observed, dtype=float)
    evaluations = _Evaluations(client, body, vertices)

    def residual(x):
        return (evaluations.at(x)[0] - observed).ravel()

    def jacobian(x):
        J = evaluations.at(x)[1]
        return J.reshape(-1, J.shape[-1])

    result = least_squares(residual, x0, jac=jacobian, bounds=(lower, upper), method='trf',
                           xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200)
    return result.x, result, evaluations.calls
