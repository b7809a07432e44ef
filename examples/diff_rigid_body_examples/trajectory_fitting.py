"""Trajectory fitting: recover a tossed body's initial pose and velocity.

Ballistic model with parameters x = (q0, qdot0) in R^12 (q = (phi, theta,
psi, tx, ty, tz)): the angles change linearly and the frame origin falls,

    q(t) = q0 + qdot0 t + 1/2 (0, 0, 0, g) t^2,   g = (0, 0, -9.81) m/s^2,

so dq(t)/dx = [I6 | t I6]. Observations are vertex positions at T frames;
residuals r_kv = p_v(q(t_k)) - observed_kv, cost 1/2 sum |r|^2 [m^2]. Two
solvers, each evaluating all T frames in one batched service call:

* :func:`fit_torch`: torch.optim.LBFGS (strong Wolfe line search) through
  :func:`diff_rigid_body.torch.vertex_positions` (forward: positions, backward:
  ``backprop``: two calls per evaluation).
* :func:`fit_least_squares`: scipy.optimize.least_squares with the residual
  Jacobian dr/dx = J(q(t_k)) [I6 | t_k I6] from ``get_vertex_jacobians``
  (one call per evaluation; the Jacobian of the last evaluation is reused).

``per_frame=True`` makes T calls per evaluation instead; :class:`CallCounter`
counts the round trips either way.
"""
import collections
import time

import numpy as np
import scipy.optimize
import torch

from diff_rigid_body import torch as drb_torch

__all__ = ['GRAVITY', 'standard_errors', 'trajectory', 'make_problem', 'fit_torch', 'fit_least_squares', 'errors', 'CallCounter',
           'TrajectoryFit', 'jacobians_batch']

GRAVITY = np.array([0.0, 0.0, 0.0, 0.0, 0.0, -9.81])  # d^2q/dt^2 [m/s^2] (angles: 0)
STATIONARY = 1e-6  # |dcost/dx|_inf at the end, relative to its value at the start

#: x (12,) = (q0, qdot0), iterations, evaluations (cost evaluations), calls
#: (service round trips), per_frame_calls (round trips the same evaluations take
#: with one call per frame), rms residual [m], wall_time [s], converged, reason.
TrajectoryFit = collections.namedtuple(
    'TrajectoryFit', 'x iterations evaluations calls per_frame_calls residual_rms wall_time converged reason')


class CallCounter(object):
    """Counts the service round trips of ``client`` (wraps its ``call``)."""

    def __init__(self, client):
        self.count = 0
        self._call = client.call

        def counted(name, **request):
            self.count += 1
            return self._call(name, **request)
        client.call = counted


def trajectory(x, times):
    """q(t_k) (T, 6) for x = (q0, qdot0); numpy arrays or torch tensors."""
    times = times.reshape(-1, 1)
    if isinstance(x, torch.Tensor):
        gravity = torch.as_tensor(GRAVITY, dtype=x.dtype)
        return x[:6] + x[6:] * times + 0.5 * gravity * times ** 2
    return x[:6] + x[6:] * times + 0.5 * GRAVITY * times ** 2


def jacobians_batch(client, body, q, vertices=None, per_frame=False):
    """positions (K, N, 3) and J (K, N, 3, 6) at the K rows of ``q``."""
    if per_frame:
        answers = [client.vertex_jacobians(body, qk, vertices) for qk in q]
        return np.stack([a[0] for a in answers]), np.stack([a[1] for a in answers])
    return client.vertex_jacobians(body, q, vertices)


def make_problem(client, body, x_true, times, vertices, noise, seed=0, start_offsets=(0.1, 0.05, 0.3, 0.3),
                 per_frame=False):
    """Observed positions (T, N, 3) at the hidden ``x_true`` plus Gaussian noise
    of ``noise`` [m] per coordinate, and a start x whose angles, position,
    angular rates and velocity are off by ``start_offsets`` (rad, m, rad/s,
    m/s) in random directions. Returns (observed, x_start)."""
    rng = np.random.default_rng(seed)
    exact = drb_torch.positions_batch(client, body, trajectory(np.asarray(x_true), times), vertices,
                                      per_frame)
    observed = exact + noise * rng.normal(size=exact.shape)
    x_start = np.array(x_true, dtype=float)
    for block, offset in enumerate(start_offsets):
        direction = rng.normal(size=3)
        x_start[3 * block:3 * block + 3] += offset * direction / np.linalg.norm(direction)
    return observed, x_start


def standard_errors(client, body, x, times, vertices, noise, per_frame=False):
    """Standard deviations (12,) of the least-squares estimate of x under Gaussian
    noise of ``noise`` [m] per coordinate: sqrt(diag(noise^2 (A^T A)^-1)), A = dr/dx."""
    _, J = jacobians_batch(client, body, trajectory(np.asarray(x), times), vertices, per_frame)
    A = np.concatenate([J, J * np.asarray(times)[:, None, None, None]], axis=-1).reshape(-1, 12)
    return noise * np.sqrt(np.diag(np.linalg.inv(A.T.dot(A))))


def errors(x, x_true):
    """Max abs errors: (angles [rad], position [m], angular rates [rad/s], velocity [m/s])."""
    d = np.abs(np.asarray(x) - np.asarray(x_true))
    return d[0:3].max(), d[3:6].max(), d[6:9].max(), d[9:12].max()


def fit_torch(client, body, observed, times, x_start, vertices=None, per_frame=False, max_iterations=200):
    """LBFGS on 1/2 sum |p(q(t_k)) - observed|^2 with gradients by autograd."""
    start = time.perf_counter()
    counter = CallCounter(client)
    observed_t = torch.from_numpy(np.asarray(observed, dtype=np.float64))
    times_t = torch.from_numpy(np.asarray(times, dtype=np.float64))
    x = torch.tensor(x_start, dtype=torch.float64, requires_grad=True)
    optimizer = torch.optim.LBFGS([x], lr=1.0, max_iter=max_iterations, max_eval=2 * max_iterations,
                                  tolerance_grad=1e-12, tolerance_change=1e-20, history_size=20,
                                  line_search_fn='strong_wolfe')
    evaluations, gradients = [0], []

    def closure():
        optimizer.zero_grad()
        p = drb_torch.vertex_positions(client, body, trajectory(x, times_t), vertices, per_frame)
        loss = 0.5 * ((p - observed_t) ** 2).sum()
        loss.backward()
        evaluations[0] += 1
        gradients.append(float(x.grad.abs().max()))
        return loss

    optimizer.step(closure)
    iterations = optimizer.state[optimizer._params[0]]['n_iter']
    calls = counter.count
    loss = float(closure())  # cost and gradient at the final x (the last evaluation may be a trial point)
    client.call = counter._call
    stopped = iterations < max_iterations
    stationary = gradients[-1] <= STATIONARY * gradients[0]
    reason = 'iteration limit' if not stopped else 'tolerance' + ('' if stationary else ', not stationary')
    frames = len(times)
    return TrajectoryFit(x.detach().numpy().copy(), iterations, evaluations[0] - 1, calls,
                         calls if per_frame else calls * frames, float(np.sqrt(2.0 * loss / observed.size)),
                         time.perf_counter() - start, bool(stopped and stationary), reason)


def fit_least_squares(client, body, observed, times, x_start, vertices=None, per_frame=False):
    """scipy.optimize.least_squares (trust region reflective) with the node's Jacobians."""
    start = time.perf_counter()
    counter = CallCounter(client)
    observed = np.asarray(observed, dtype=np.float64)
    times = np.asarray(times, dtype=np.float64)
    cache = {}

    def evaluate(x):
        if cache.get('x') is None or not np.array_equal(cache['x'], x):
            p, J = jacobians_batch(client, body, trajectory(x, times), vertices, per_frame)
            cache.update(x=np.array(x), r=(p - observed).ravel(), J=J)
        return cache

    def jac(x):
        J = evaluate(x)['J']  # dr/dx = J [I6 | t I6]
        return np.concatenate([J, J * times[:, None, None, None]], axis=-1).reshape(-1, 12)

    result = scipy.optimize.least_squares(lambda x: evaluate(x)['r'], x_start, jac=jac, method='trf',
                                          xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200)
    calls = counter.count
    client.call = counter._call
    cost = 0.5 * float(result.fun.dot(result.fun))
    frames = len(times)
    return TrajectoryFit(result.x, result.njev, result.nfev, calls, calls if per_frame else calls * frames,
                         float(np.sqrt(2.0 * cost / observed.size)), time.perf_counter() - start,
                         bool(result.status > 0), result.message)
