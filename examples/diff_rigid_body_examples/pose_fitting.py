"""Pose fitting: recover a body's q from observed vertex positions.

Residuals r_v(q) = p_v(q) - target_v over the body's vertices, cost
L(q) = 1/2 mean_v |r_v|^2. Two solvers, both evaluated by rigid_body_server
with q passed in each request (the node's state is never changed):

* :func:`fit_gauss_newton`: Gauss-Newton steps dq = -J^+ r with J = dp/dq from
  ``get_vertex_jacobians`` (solved by least squares, not normal equations),
  with Levenberg-Marquardt damping only when a step fails to lower L.
* :func:`fit_lbfgs`: L-BFGS on L with dL/dq from ``backprop`` (a
  vector-Jacobian product: J is never formed) and an Armijo backtracking line
  search. Positions come from ``get_vertex_jacobians``.
* :func:`fit_least_squares`: scipy.optimize.least_squares (trust region
  reflective) with the residuals' Jacobian J from ``get_vertex_jacobians`` as
  ``jac`` (one call per evaluation: its J is reused when SciPy asks for it).

The small rotation helpers below only build test poses and measure errors:
R(q) = Rz(psi) Ry(theta) Rx(phi), as in the node.
"""
import collections
import time

import numpy as np
import scipy.optimize

__all__ = ['FitResult', 'fit_gauss_newton', 'fit_lbfgs', 'fit_least_squares', 'rpy_to_matrix', 'matrix_to_rpy', 'perturbed_pose',
           'pose_error', 'make_problem']

#: q (6,), iterations, evaluations (service calls), cost L [m^2], residual_rms
#: [m], wall_time [s], converged (bool: stopped by a tolerance at a stationary
#: point, |dL/dq| <= STATIONARY |dL/dq at q0|), reason (str), history (costs
#: per iteration).
FitResult = collections.namedtuple(
    'FitResult', 'q iterations evaluations cost residual_rms wall_time converged reason history')

STATIONARY = 1e-8  # |dL/dq|_inf at the end, relative to its value at the start


def rpy_to_matrix(rpy):
    """R = Rz(psi) Ry(theta) Rx(phi)."""
    phi, theta, psi = rpy
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    return np.array([[cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf],
                     [sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf],
                     [-st, ct * sf, ct * cf]])


def matrix_to_rpy(R):
    """(phi, theta, psi) with theta in [-pi/2, pi/2] (away from gimbal lock)."""
    return np.array([np.arctan2(R[2, 1], R[2, 2]), np.arcsin(np.clip(-R[2, 0], -1.0, 1.0)),
                     np.arctan2(R[1, 0], R[0, 0])])


def axis_angle_matrix(axis, angle):
    """Rotation by ``angle`` [rad] about ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K.dot(K)


def perturbed_pose(q, angle, distance, rng):
    """A pose ``angle`` [rad] (about a random axis) and ``distance`` [m] (in a
    random direction) away from ``q``."""
    axis = rng.normal(size=3)
    direction = rng.normal(size=3)
    R = rpy_to_matrix(q[:3]).dot(axis_angle_matrix(axis, angle))
    return np.concatenate([matrix_to_rpy(R), np.asarray(q[3:]) + distance * direction / np.linalg.norm(direction)])


def pose_error(q, q_reference):
    """(rotation angle [rad], translation distance [m]) between two poses."""
    R = rpy_to_matrix(q[:3]).T.dot(rpy_to_matrix(q_reference[:3]))
    # atan2(sin, cos) of the angle: accurate near 0, unlike arccos of the trace.
    sine = 0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    angle = np.arctan2(sine, 0.5 * (np.trace(R) - 1.0))
    return angle, float(np.linalg.norm(np.asarray(q[3:]) - np.asarray(q_reference[3:])))


def make_problem(client, body, q_hidden, noise=0.0, angle=np.radians(30.0), distance=0.2, seed=0):
    """A fitting problem: ``body``'s vertex positions at ``q_hidden`` plus
    Gaussian noise of ``noise`` [m] per coordinate, and a start pose ``angle``
    [rad] and ``distance`` [m] away. Returns (target (N, 3), q_start (6,))."""
    rng = np.random.default_rng(seed)
    positions = client.positions(body, q_hidden)
    target = positions + noise * rng.normal(size=positions.shape)
    return target, perturbed_pose(np.asarray(q_hidden, dtype=float), angle, distance, rng)


def _cost(residuals):
    return 0.5 * float(np.mean(np.einsum('ij,ij->i', residuals, residuals)))


def _result(q, iterations, evaluations, cost, start, stopped, gradients, reason, history):
    """``stopped``: by a tolerance (not the iteration limit); ``gradients``:
    dL/dq at the start and at q."""
    stationary = np.max(np.abs(gradients[1])) <= STATIONARY * np.max(np.abs(gradients[0]))
    if stopped and not stationary:
        reason += ', but not at a stationary point'
    return FitResult(q, iterations, evaluations, cost, float(np.sqrt(2.0 * cost)), time.perf_counter() - start,
                     bool(stopped and stationary), reason, history)


def fit_gauss_newton(client, body, target, q0, vertices=None, max_iterations=50, step_tolerance=1e-13):
    """Fits q of ``body`` so that its ``vertices`` (None = all) match ``target``
    (N, 3) [m], from ``q0``. One ``get_vertex_jacobians`` call per iteration.

    Stops when a step is below ``step_tolerance`` * (1 + |q|_inf), or when no
    damping lowers the cost (the floating-point floor), or after
    ``max_iterations``.
    """
    start = time.perf_counter()
    target = np.asarray(target, dtype=float).reshape(-1, 3)
    q = np.array(q0, dtype=float)
    p, J = client.vertex_jacobians(body, q, vertices)
    evaluations = 1
    r = p - target
    cost = _cost(r)
    history = [cost]
    damping = 0.0
    gradient0 = J.reshape(-1, 6).T.dot(r.ravel()) / len(r)  # dL/dq = J^T r / N
    for iteration in range(1, max_iterations + 1):
        A = J.reshape(-1, 6)
        b = r.ravel()
        gradients = (gradient0, A.T.dot(b) / len(r))
        while True:
            if damping == 0.0:
                step = -np.linalg.lstsq(A, b, rcond=None)[0]
            else:  # Levenberg-Marquardt with Marquardt's diagonal scaling
                AtA = A.T.dot(A)
                step = -np.linalg.solve(AtA + damping * np.diag(np.diag(AtA)), A.T.dot(b))
            if np.max(np.abs(step)) <= step_tolerance * (1.0 + np.max(np.abs(q))):
                return _result(q, iteration, evaluations, cost, start, True, gradients, 'step below tolerance',
                               history)
            q_new = q + step
            p_new, J_new = client.vertex_jacobians(body, q_new, vertices)
            evaluations += 1
            r_new = p_new - target
            cost_new = _cost(r_new)
            if cost_new <= cost:
                break
            if damping > 1e12:
                return _result(q, iteration, evaluations, cost, start, True, gradients,
                               'no lower cost (precision floor)', history)
            damping = max(1e-3, 10.0 * damping)
        q, r, J, cost = q_new, r_new, J_new, cost_new
        damping = damping / 10.0 if damping > 1e-3 else 0.0
        history.append(cost)
    gradients = (gradient0, J.reshape(-1, 6).T.dot(r.ravel()) / len(r))
    return _result(q, max_iterations, evaluations, cost, start, False, gradients, 'iteration limit', history)


def fit_lbfgs(client, body, target, q0, vertices=None, memory=10, max_iterations=300, step_tolerance=1e-13,
              gradient_tolerance=0.0):
    """Fits q like :func:`fit_gauss_newton`, by L-BFGS on L with gradients from
    ``backprop``. Each evaluation is two calls: positions, then dL/dq.

    Stops when a step is below ``step_tolerance`` * (1 + |q|_inf), when
    |dL/dq|_inf <= ``gradient_tolerance``, when the line search cannot lower
    L (the floating-point floor), or after ``max_iterations``.
    """
    start = time.perf_counter()
    target = np.asarray(target, dtype=float).reshape(-1, 3)
    count = len(target)
    evaluations = [0]

    def evaluate(q):
        r = client.positions(body, q, vertices) - target
        gradient = client.backprop(body, r / count, q, vertices)  # dL/dp_v = r_v / N
        evaluations[0] += 2
        return _cost(r), np.array(gradient)

    q = np.array(q0, dtype=float)
    cost, gradient = evaluate(q)
    gradient0 = gradient
    history = [cost]
    s_list, y_list = [], []
    for iteration in range(1, max_iterations + 1):
        if np.max(np.abs(gradient)) <= gradient_tolerance:
            return _result(q, iteration - 1, evaluations[0], cost, start, True, (gradient0, gradient),
                           'gradient below tolerance', history)
        # Two-loop recursion: direction = -H gradient.
        d = -gradient
        alphas = []
        for s, y in reversed(list(zip(s_list, y_list))):
            a = s.dot(d) / y.dot(s)
            alphas.append(a)
            d = d - a * y
        if s_list:
            d *= s_list[-1].dot(y_list[-1]) / y_list[-1].dot(y_list[-1])
        else:  # first step: at most 0.1 (rad or m) along the steepest descent
            d *= 0.1 / np.max(np.abs(d))
        for (s, y), a in zip(zip(s_list, y_list), reversed(alphas)):
            d = d + (a - y.dot(d) / y.dot(s)) * s
        slope = gradient.dot(d)
        if slope >= 0.0:  # not a descent direction: restart from steepest descent
            s_list, y_list = [], []
            d = -gradient * (0.1 / np.max(np.abs(gradient)))
            slope = gradient.dot(d)
        # Armijo backtracking.
        t = 1.0
        while True:
            step = t * d
            if np.max(np.abs(step)) <= step_tolerance * (1.0 + np.max(np.abs(q))):
                return _result(q, iteration, evaluations[0], cost, start, True, (gradient0, gradient),
                               'step below tolerance', history)
            cost_new, gradient_new = evaluate(q + step)
            if cost_new <= cost + 1e-4 * t * slope:
                break
            t *= 0.5
        s, y = step, gradient_new - gradient
        if s.dot(y) > 1e-12 * np.sqrt(s.dot(s) * y.dot(y)):  # keep H positive definite
            s_list.append(s)
            y_list.append(y)
            if len(s_list) > memory:
                s_list.pop(0)
                y_list.pop(0)
        q, cost, gradient = q + step, cost_new, gradient_new
        history.append(cost)
    return _result(q, max_iterations, evaluations[0], cost, start, False, (gradient0, gradient), 'iteration limit',
                   history)


def fit_least_squares(client, body, target, q0, vertices=None, max_evaluations=100, tolerance=1e-15):
    """Fits q like :func:`fit_gauss_newton`, by ``scipy.optimize.least_squares``
    on the residuals p - target (3N) with ``jac`` = J (3N, 6) of the same
    ``get_vertex_jacobians`` call. Stops on SciPy's xtol/ftol/gtol =
    ``tolerance`` or after ``max_evaluations``.
    """
    start = time.perf_counter()
    target = np.asarray(target, dtype=float).reshape(-1, 3)
    last = {}

    def evaluate(q):
        if last.get('q') is None or not np.array_equal(last['q'], q):
            p, J = client.vertex_jacobians(body, q, vertices)
            last.update(q=np.array(q), r=(p - target).ravel(), J=J.reshape(-1, 6), calls=last.get('calls', 0) + 1)
        return last

    gradient0 = evaluate(q0)['J'].T.dot(last['r']) / len(target)
    result = scipy.optimize.least_squares(lambda q: evaluate(q)['r'], np.array(q0, dtype=float),
                                          jac=lambda q: evaluate(q)['J'], method='trf', xtol=tolerance,
                                          ftol=tolerance, gtol=tolerance, max_nfev=max_evaluations)
    r = evaluate(result.x)['r'].reshape(-1, 3)
    gradients = (gradient0, last['J'].T.dot(last['r']) / len(target))
    return _result(result.x, result.njev, last['calls'], _cost(r), start, result.status > 0, gradients,
                   result.message.rstrip('.'), [])
