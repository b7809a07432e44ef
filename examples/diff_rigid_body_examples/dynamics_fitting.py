"""Fitting a tossed body through its equations of motion.

The body's state is s = (x, x') in R^(2d) (a free body: x = q = (phi, theta,
psi, tx, ty, tz), d = 6). The node's ``forward_dynamics`` gives
x'' = M(x)^-1 (tau - c(x, x') - g(x)) with gravity from its ``~gravity``;
here tau = 0 (a free toss). :func:`integrate` advances s with classical RK4,

    s' = f(s) = (x', x''(x, x')),

and, with ``sensitivities``, the forward sensitivities S = ds/ds0 (2d x 2d)
along with it from the variational equations

    S' = [[0, I], [dx''/dx, dx''/dx']] S,   S(0) = I,

integrated by the same RK4 stages (the Jacobians are those of the stage's
own ``forward_dynamics`` call, ``derivatives=True``). Differentiating the
RK4 map stage by stage gives exactly these stages, so S is the exact
derivative of the computed trajectory, not an approximation of it.

Every RK4 stage is one ``forward_dynamics`` call for all K trajectories
integrated together (s0 of shape (K, 2d)): the stages of one trajectory are
sequential, but K tosses advance in lockstep (the demo's finite-difference
check of S integrates 1 + 2 x 2d trajectories that way).

Observations are positions of some of the body's vertices at T frames,
t_k = k dt (k = 0..T-1); the residuals r_kv = p_v(x(t_k)) - observed_kv,
cost 1/2 sum |r|^2 [m^2]. Their Jacobian in s0 is J_v(x(t_k)) S_k[:d] (J from
one batched ``get_vertex_jacobians`` call for all T frames). Two solvers:

* :func:`fit_least_squares`: ``scipy.optimize.least_squares`` (trust region
  reflective) with that Jacobian as ``jac``.
* :func:`fit_torch`: ``torch.optim.LBFGS`` (strong Wolfe line search) on
  the cost through :class:`Trajectory` (an autograd function: forward
  :func:`integrate`, backward S_k[:d]^T grad_x(t_k)) and
  :func:`diff_rigid_body.torch.vertex_positions` (backward: ``backprop``).

The standard deviations of the estimate follow from the Gauss-Newton
covariance noise^2 (A^T A)^-1, A = dr/ds0 at the solution
(:func:`standard_errors`). ``drop_dqddot_dq`` (every function that
integrates takes it) leaves dx''/dx out of the variational equations: a
deliberately wrong gradient, to show that the checks catch one.
"""
import collections
import time

import numpy as np
import scipy.optimize
import torch
from torch.autograd.function import once_differentiable

from diff_rigid_body import torch as drb_torch
from diff_rigid_body_examples.trajectory_fitting import CallCounter

__all__ = ['integrate', 'Trajectory', 'residuals', 'covariance', 'standard_errors', 'fit_least_squares', 'fit_torch', 'fit_growing',
           'Fit', 'rpy_matrix', 'body_rates', 'rpy_rates', 'angular_momentum', 'sign_change', 'flip_times']

#: s0 (2d,), iterations, evaluations (trajectories integrated), calls (service
#: round trips), rms residual [m], wall_time [s], converged, reason.
Fit = collections.namedtuple('Fit', 'x iterations evaluations calls residual_rms wall_time converged reason')


def _stage(client, body, s, d, sensitivities, drop_dqddot_dq):
    """f(s) (K, 2d) and, with ``sensitivities``, df/ds (K, 2d, 2d) of the K states ``s``: one call."""
    K = len(s)
    answer = client.forward_dynamics([body], s[:, None, :d], s[:, None, d:], derivatives=sensitivities)
    f = np.concatenate([s[:, d:], np.asarray(answer.qddot).reshape(K, d)], axis=1)
    if not sensitivities:
        return f, None
    A = np.zeros((K, 2 * d, 2 * d))
    A[:, :d, d:] = np.eye(d)
    if not drop_dqddot_dq:
        A[:, d:, :d] = np.asarray(answer.dqddot_dq).reshape(K, d, d)
    A[:, d:, d:] = np.asarray(answer.dqddot_dqdot).reshape(K, d, d)
    return f, A


def integrate(client, body, s0, dt, frames, substeps=1, sensitivities=False, drop_dqddot_dq=False):
    """RK4 from s0 = (x0, x0') over ``frames`` - 1 frame intervals of ``dt`` [s],
    each in ``substeps`` steps. ``s0``: (2d,) or K trajectories (K, 2d).

    Returns the states at the frames, (T, 2d) or (T, K, 2d) (frame 0 = s0),
    and with ``sensitivities`` S = ds(t_k)/ds0, (T, 2d, 2d) or (T, K, 2d, 2d),
    else None. Every stage is one ``forward_dynamics`` call for all K; a
    singular M on the way raises DiffRigidBodyError."""
    s = np.array(s0, dtype=np.float64)
    single = s.ndim == 1
    s = s.reshape(-1, s.shape[-1])
    K, n = s.shape
    d = n // 2
    h = dt / substeps
    S = np.repeat(np.eye(n)[None], K, axis=0) if sensitivities else None
    states, sens = [s.copy()], [S.copy()] if sensitivities else None
    for _ in range(frames - 1):
        for _ in range(substeps):
            k1, A1 = _stage(client, body, s, d, sensitivities, drop_dqddot_dq)
            k2, A2 = _stage(client, body, s + 0.5 * h * k1, d, sensitivities, drop_dqddot_dq)
            k3, A3 = _stage(client, body, s + 0.5 * h * k2, d, sensitivities, drop_dqddot_dq)
            k4, A4 = _stage(client, body, s + h * k3, d, sensitivities, drop_dqddot_dq)
            if sensitivities:
                # The same RK4 stages applied to S' = A(s) S: the exact derivative of the step.
                L1 = A1 @ S
                L2 = A2 @ (S + 0.5 * h * L1)
                L3 = A3 @ (S + 0.5 * h * L2)
                L4 = A4 @ (S + h * L3)
                S = S + (h / 6.0) * (L1 + 2.0 * L2 + 2.0 * L3 + L4)
            s = s + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        states.append(s.copy())
        if sensitivities:
            sens.append(S.copy())
    states = np.stack(states)
    sens = np.stack(sens) if sensitivities else None
    if single:
        return states[:, 0], (sens[:, 0] if sensitivities else None)
    return states, sens


class Trajectory(torch.autograd.Function):
    """x(t_k) (T, d) from s0 (2d,) by :func:`integrate`; the backward pass is
    grad_s0 = sum_k S_k[:d]^T grad_x(t_k) (no service call)."""

    @staticmethod
    def forward(ctx, s0, client, body, dt, frames, substeps, drop_dqddot_dq):
        states, S = integrate(client, body, s0.detach().numpy(), dt, frames, substeps, sensitivities=True,
                              drop_dqddot_dq=drop_dqddot_dq)
        d = states.shape[1] // 2
        ctx.S = S[:, :d, :]  # (T, d, 2d)
        return torch.from_numpy(states[:, :d].copy())

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_x):
        grad = np.einsum('ka,kab->b', grad_x.numpy(), ctx.S)
        return (torch.from_numpy(grad),) + (None,) * 6


def residuals(client, body, s0, observed, dt, substeps, vertices, jacobian=False, drop_dqddot_dq=False):
    """r = p(x(t_k)) - observed, flattened (T N 3,), and with ``jacobian``
    dr/ds0 (T N 3, 2d) = J(x(t_k)) S_k[:d], else None. One integration and
    one ``get_vertex_jacobians`` call for all T frames."""
    observed = np.asarray(observed)
    states, S = integrate(client, body, s0, dt, len(observed), substeps, sensitivities=jacobian,
                          drop_dqddot_dq=drop_dqddot_dq)
    d = states.shape[1] // 2
    p, J = client.vertex_jacobians(body, states[:, :d], vertices)
    r = (np.asarray(p) - observed).ravel()
    if not jacobian:
        return r, None
    return r, np.einsum('kvad,kdj->kvaj', J, S[:, :d, :]).reshape(len(r), -1)


def covariance(client, body, s0, observed, dt, substeps, vertices, noise):
    """The Gauss-Newton covariance noise^2 (A^T A)^-1 (2d, 2d) of the least-squares
    estimate of s0 under Gaussian noise of ``noise`` [m] per coordinate, A = dr/ds0 at ``s0``."""
    _, A = residuals(client, body, s0, observed, dt, substeps, vertices, jacobian=True)
    return noise ** 2 * np.linalg.inv(A.T.dot(A))


def standard_errors(client, body, s0, observed, dt, substeps, vertices, noise):
    """Standard deviations (2d,) of the least-squares estimate of s0: the square
    roots of the diagonal of :func:`covariance`."""
    return np.sqrt(np.diag(covariance(client, body, s0, observed, dt, substeps, vertices, noise)))


def fit_least_squares(client, body, observed, dt, substeps, s_start, vertices=None, drop_dqddot_dq=False,
                      max_evaluations=100):
    """scipy.optimize.least_squares (trf) with dr/ds0 from the sensitivities
    as ``jac`` (computed with every residual: SciPy asks for the Jacobian at
    each accepted point)."""
    start = time.perf_counter()
    counter = CallCounter(client)
    cache = {}

    def evaluate(x):
        if cache.get('x') is None or not np.array_equal(cache['x'], x):
            r, A = residuals(client, body, x, observed, dt, substeps, vertices, jacobian=True,
                             drop_dqddot_dq=drop_dqddot_dq)
            cache.update(x=np.array(x), r=r, A=A, count=cache.get('count', 0) + 1)
        return cache

    try:
        result = scipy.optimize.least_squares(lambda x: evaluate(x)['r'], s_start, jac=lambda x: evaluate(x)['A'],
                                              method='trf', xtol=1e-12, ftol=1e-12, gtol=1e-10,
                                              max_nfev=max_evaluations)
    finally:
        client.call = counter._call
    cost = 0.5 * float(result.fun.dot(result.fun))
    return Fit(result.x, result.njev, cache['count'], counter.count, float(np.sqrt(2.0 * cost / np.size(observed))),
               time.perf_counter() - start, bool(result.status > 0), result.message)


def fit_torch(client, body, observed, dt, substeps, s_start, vertices=None, whiten=True, drop_dqddot_dq=False,
              max_iterations=100, stationary=1e-6):
    """torch.optim.LBFGS (strong Wolfe) on 1/2 sum |p(x(t_k)) - observed|^2,
    gradients by autograd through :class:`Trajectory` and
    :func:`diff_rigid_body.torch.vertex_positions`.

    With ``whiten``, LBFGS works on z, s0 = s_start + W z, W = L^-T where
    L L^T = A^T A is the Gauss-Newton matrix at s_start (one more
    integration): the units of s0 (rad, m, rad/s, m/s) and the flip's
    amplification of some directions make the plain problem badly scaled
    (LBFGS then needs about four times as many evaluations). Converged when
    LBFGS stops on its tolerances and the gradient's max norm has dropped to
    ``stationary`` times its start value."""
    start = time.perf_counter()
    counter = CallCounter(client)
    try:
        s_start = np.asarray(s_start, dtype=np.float64)
        W = np.eye(len(s_start))
        if whiten:
            _, A = residuals(client, body, s_start, observed, dt, substeps, vertices, jacobian=True,
                             drop_dqddot_dq=drop_dqddot_dq)
            W = np.linalg.inv(np.linalg.cholesky(A.T.dot(A))).T
        observed_t = torch.from_numpy(np.asarray(observed, dtype=np.float64))
        W_t, origin = torch.from_numpy(W), torch.from_numpy(s_start.copy())
        z = torch.zeros(len(s_start), dtype=torch.float64, requires_grad=True)
        optimizer = torch.optim.LBFGS([z], lr=1.0, max_iter=max_iterations, max_eval=2 * max_iterations,
                                      tolerance_grad=1e-14, tolerance_change=1e-24, history_size=20,
                                      line_search_fn='strong_wolfe')
        gradients = []

        def closure():
            optimizer.zero_grad()
            x = Trajectory.apply(origin + W_t @ z, client, body, dt, len(observed), substeps, drop_dqddot_dq)
            p = drb_torch.vertex_positions(client, body, x, vertices)
            loss = 0.5 * ((p - observed_t) ** 2).sum()
            loss.backward()
            gradients.append(float(z.grad.abs().max()))
            return loss

        optimizer.step(closure)
        iterations = optimizer.state[optimizer._params[0]]['n_iter']
        loss = float(closure())  # cost and gradient at the final point (the last evaluation may be a trial)
    finally:
        client.call = counter._call
    stopped = iterations < max_iterations
    is_stationary = gradients[-1] <= stationary * gradients[0]
    reason = 'iteration limit' if not stopped else 'tolerance' + ('' if is_stationary else ', not stationary')
    s = (origin + W_t @ z).detach().numpy().copy()
    return Fit(s, iterations, len(gradients) + int(whiten), counter.count,
               float(np.sqrt(2.0 * loss / np.size(observed))), time.perf_counter() - start,
               bool(stopped and is_stationary), reason)


def fit_growing(fit, client, body, observed, dt, substeps, s_start, horizons, vertices=None, **options):
    """``fit`` (:func:`fit_least_squares` or :func:`fit_torch`) on the first
    h frames for each h in ``horizons`` (increasing, the last usually all
    T), each stage starting where the previous one ended. The flip makes the
    cost over all frames non-convex far from the truth; before the flip it is
    nearly quadratic, and each longer horizon starts close to its optimum.
    Returns one :data:`Fit` (iterations, evaluations, calls and time summed;
    converged if every stage did; the reason of the first stage that did
    not, else of the last)."""
    start = time.perf_counter()
    s, stages = np.asarray(s_start, dtype=np.float64), []
    for h in horizons:
        stages.append(fit(client, body, np.asarray(observed)[:h], dt, substeps, s, vertices, **options))
        s = stages[-1].x
    failed = [r for r in stages if not r.converged]
    return Fit(s, sum(r.iterations for r in stages), sum(r.evaluations for r in stages),
               sum(r.calls for r in stages), stages[-1].residual_rms, time.perf_counter() - start,
               not failed, (failed or stages)[-1 if not failed else 0].reason)


# ---------------------------------------------------------------------------- a free body's rotation
def rpy_matrix(angles):
    """R = Rz(psi) Ry(theta) Rx(phi) (3, 3) of angles (phi, theta, psi); (..., 3) -> (..., 3, 3)."""
    angles = np.asarray(angles, dtype=np.float64)
    cx, cy, cz = np.cos(angles[..., 0]), np.cos(angles[..., 1]), np.cos(angles[..., 2])
    sx, sy, sz = np.sin(angles[..., 0]), np.sin(angles[..., 1]), np.sin(angles[..., 2])
    R = np.empty(angles.shape[:-1] + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 0, 2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
    R[..., 1, 0], R[..., 1, 1], R[..., 1, 2] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
    R[..., 2, 0], R[..., 2, 1], R[..., 2, 2] = -sy, cy * sx, cy * cx
    return R


def body_rates(angles, rates):
    """omega_b = A(phi, theta) (phi', theta', psi')' [rad/s] in body axes; (..., 3)."""
    angles, rates = np.asarray(angles, dtype=np.float64), np.asarray(rates, dtype=np.float64)
    cx, sx = np.cos(angles[..., 0]), np.sin(angles[..., 0])
    cy, sy = np.cos(angles[..., 1]), np.sin(angles[..., 1])
    dphi, dtheta, dpsi = rates[..., 0], rates[..., 1], rates[..., 2]
    return np.stack([dphi - sy * dpsi, cx * dtheta + sx * cy * dpsi, -sx * dtheta + cx * cy * dpsi], axis=-1)


def rpy_rates(angles, omega_b):
    """(phi', theta', psi') = A(phi, theta)^-1 omega_b: the angle rates of body rates omega_b (3,)."""
    phi, theta = angles[0], angles[1]
    A = np.array([[1.0, 0.0, -np.sin(theta)], [0.0, np.cos(phi), np.sin(phi) * np.cos(theta)],
                  [0.0, -np.sin(phi), np.cos(phi) * np.cos(theta)]])
    return np.linalg.solve(A, omega_b)


def angular_momentum(states, inertia):
    """L = R I_b omega_b [kg m^2/s] about the COM, fixed-frame axes, of free-body
    states (..., 12); ``inertia`` (3, 3) about the COM in body axes."""
    states = np.asarray(states)
    R = rpy_matrix(states[..., 0:3])
    return np.einsum('...ab,bc,...c->...a', R, inertia, body_rates(states[..., 0:3], states[..., 6:9]))


def sign_change(times, values):
    """The first t where ``values`` (sampled at ``times``) changes sign, by
    linear interpolation between the two samples around it; None if it never does."""
    values = np.asarray(values)
    crossing = np.nonzero(np.sign(values[1:]) != np.sign(values[0]))[0]
    if crossing.size == 0:
        return None
    k = crossing[0]
    a, b = values[k], values[k + 1]
    return float(times[k] + (times[k + 1] - times[k]) * a / (a - b))


def flip_times(client, body, s0, inertia, axis, dt, frames, substeps=1, step=1e-6):
    """When each toss's body axis ``axis`` (0, 1, 2: x, y, z) first turns
    perpendicular to its angular momentum L: the first sign change of
    (R(t) e_axis) . L(0)/|L(0)|, with t on the RK4 grid of dt / substeps and
    linear interpolation between steps (None if it never flips).

    ``s0`` (n, 12): n free-body tosses. They are integrated together with
    their central differences (each s0 moved by +-``step`` along each of its
    12 coordinates): n (1 + 24) trajectories in lockstep, one
    ``forward_dynamics`` call per RK4 stage. Returns the flip times (n,) [s]
    and their gradients d t_flip / d s0 (n, 12) (NaN where a flip is missing)."""
    s0 = np.atleast_2d(np.asarray(s0, dtype=np.float64))
    n, m = s0.shape
    offsets = np.concatenate([np.zeros((1, m)), step * np.eye(m), -step * np.eye(m)])  # (1 + 2m, m)
    batch = (s0[:, None, :] + offsets[None]).reshape(-1, m)
    steps = (frames - 1) * substeps + 1
    states, _ = integrate(client, body, batch, dt / substeps, steps)
    times = np.arange(steps) * dt / substeps
    L0 = angular_momentum(states[0], inertia)
    direction = L0 / np.linalg.norm(L0, axis=1, keepdims=True)
    along = np.einsum('tka,ka->tk', rpy_matrix(states[..., 0:3])[..., :, axis], direction)
    flips = np.array([np.nan if t is None else t for t in (sign_change(times, along[:, k]) for k in range(len(batch)))])
    flips = flips.reshape(n, 1 + 2 * m)
    gradients = (flips[:, 1:1 + m] - flips[:, 1 + m:]) / (2.0 * step)
    return flips[:, 0], gradients
