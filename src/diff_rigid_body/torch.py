"""PyTorch autograd functions over a :class:`~diff_rigid_body.client.RigidBodyClient`.

Shapes follow torch conventions, with a leading batch axis of K
configurations of the body's coordinates x, d = its dof (float64 tensors on
the CPU; a free body's x is q = (phi, theta, psi, tx, ty, tz), d = 6):

=======================================  ==========================================
``vertex_positions(client, body, q)``    q (K, d) -> p (K, N, 3) [m]; q (d,) -> (N, 3)
``mass_matrix(client, body, q)``         q (K, d) -> M (K, d, d); q (d,) -> (d, d)
``kinetic_energy(client, body, q, qd)``  q, qdot (K, d) -> E (K,) [J]; (d,) -> ()
``inverse_dynamics(client, body, q, qd,  q, qdot, qddot (K, d) -> tau (K, d) [N m, N];
qdd)``                                   (d,) -> (d,)
``forward_dynamics(client, body, q, qd,  q, qdot, tau (K, d) -> qddot (K, d)
tau)``                                   [rad/s^2, m/s^2]; (d,) -> (d,)
=======================================  ==========================================

Each forward pass is one service call for all K configurations
(``get_vertex_jacobians_compact`` with positions_only, or ``get_mass_matrix``
with derivatives); the
backward pass of :func:`vertex_positions` is one ``backprop`` call with
grad_output as dL/dp (J is never formed), that of :func:`mass_matrix` is
dL/dq_j = sum_ab grad_M[a, b] dM[a, b]/dq_j from the dM of the forward call.
:func:`inverse_dynamics` (tau = M qddot + c + g) asks ``inverse_dynamics``,
with derivatives (dtau/dq, dtau/dqdot) when q or qdot needs a gradient, and
``get_mass_matrix`` for M = dtau/dqddot when qddot does;
:func:`forward_dynamics` (qddot = M^-1 (tau - c - g)) asks
``forward_dynamics``, with derivatives (dqddot/dq, dqddot/dqdot, M^-1) when
an input needs a gradient: their backward passes multiply grad_output by
these Jacobians and call nothing.
``per_frame=True`` makes one call per configuration instead (same numbers:
for comparisons). The node's state is never changed. First derivatives only.
Arguments come in the clients' order (``client_arguments``): the body, then the
per-configuration tensors; the earlier ``inverse_dynamics(client, q, qd, qdd, body)``
still works, with a DeprecationWarning.
"""
import numpy as np
import torch
from torch.autograd.function import once_differentiable

from diff_rigid_body.client_arguments import earlier_order, numbers_before_names

__all__ = ['vertex_positions', 'mass_matrix', 'kinetic_energy', 'inverse_dynamics', 'forward_dynamics',
           'positions_batch', 'backprop_batch', 'inverse_dynamics_batch', 'forward_dynamics_batch']


def _numpy(tensor):
    return tensor.detach().cpu().numpy().astype(np.float64)


def _positions(client, body, q, vertices):
    """Positions only (``get_vertex_jacobians_compact`` with positions_only: no J on the wire)."""
    return client.vertex_jacobians_compact(body, q, vertices, positions_only=True)[0]


def positions_batch(client, body, q, vertices=None, per_frame=False):
    """positions (K, N, 3) of ``body``'s ``vertices`` at the K rows of ``q`` (K, d)."""
    if per_frame:
        return np.stack([_positions(client, body, qk, vertices) for qk in q])
    return _positions(client, body, q, vertices)


def backprop_batch(client, body, gradients, q, vertices=None, per_frame=False):
    """dL/dq (K, d) from dL/dp ``gradients`` (K, N, 3) at ``q`` (K, d)."""
    if per_frame:
        return np.stack([client.backprop(body, g, qk, vertices) for g, qk in zip(gradients, q)])
    return client.backprop(body, gradients, q, vertices)


def _rows(*arrays):
    """The K rows of (K, d) arrays as K tuples of (1, 1, d) arrays (one configuration of one body)."""
    return zip(*(array[:, None, None, :] for array in arrays))


def inverse_dynamics_batch(client, body, q, qdot, qddot, derivatives=True, mass_matrix=True, per_frame=False):
    """tau (K, d), dtau/dq and dtau/dqdot (K, d, d; None without ``derivatives``) and M = dtau/dqddot
    (K, d, d; None without ``mass_matrix``) of ``body`` at the K rows of q, qdot, qddot (K, d)."""
    if per_frame:
        frames = [inverse_dynamics_batch(client, body, *row, derivatives=derivatives, mass_matrix=mass_matrix)
                  for row in _rows(q, qdot, qddot)]
        return tuple(None if part[0] is None else np.concatenate(part) for part in zip(*frames))
    q3 = q.reshape(len(q), 1, -1)  # (K, 1, d): K configurations of one body, batched however small K is
    answer = client.inverse_dynamics([body], q3, qdot.reshape(q3.shape), qddot.reshape(q3.shape),
                                      derivatives=derivatives)
    M = client.mass_matrix([body], q3).M[:, 0] if mass_matrix else None
    if not derivatives:
        return answer.tau[:, 0], None, None, M
    return answer.tau[:, 0], answer.dtau_dq[:, 0], answer.dtau_dqdot[:, 0], M


def forward_dynamics_batch(client, body, q, qdot, tau, derivatives=True, per_frame=False):
    """qddot (K, d) and dqddot/dq, dqddot/dqdot, dqddot/dtau = M^-1 (K, d, d; None without
    ``derivatives``) of ``body`` at the K rows of q, qdot, tau (K, d)."""
    if per_frame:
        frames = [forward_dynamics_batch(client, body, *row, derivatives=derivatives) for row in _rows(q, qdot, tau)]
        return tuple(None if part[0] is None else np.concatenate(part) for part in zip(*frames))
    q3 = q.reshape(len(q), 1, -1)
    answer = client.forward_dynamics([body], q3, qdot.reshape(q3.shape), tau.reshape(q3.shape),
                                     derivatives=derivatives)
    if not derivatives:
        return answer.qddot[:, 0], None, None, None
    return answer.qddot[:, 0], answer.dqddot_dq[:, 0], answer.dqddot_dqdot[:, 0], answer.dqddot_dtau[:, 0]


class _VertexPositions(torch.autograd.Function):

    @staticmethod
    def forward(ctx, q, client, body, vertices, per_frame):
        ctx.client, ctx.body, ctx.vertices, ctx.per_frame = client, body, vertices, per_frame
        ctx.q = _numpy(q)
        return torch.from_numpy(positions_batch(client, body, ctx.q, vertices, per_frame).copy()).to(q.dtype)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_positions):
        gradient = backprop_batch(ctx.client, ctx.body, _numpy(grad_positions), ctx.q, ctx.vertices, ctx.per_frame)
        return torch.from_numpy(np.array(gradient)).to(grad_positions.dtype), None, None, None, None


class _MassMatrix(torch.autograd.Function):

    @staticmethod
    def forward(ctx, q, client, body, per_frame):
        q_np = _numpy(q)
        if per_frame:
            answers = [client.mass_matrix([body], qk[None], derivatives=True) for qk in q_np]
            M = np.stack([a.M[0] for a in answers])
            dM = np.stack([a.dM[0] for a in answers])
        else:
            answer = client.mass_matrix([body], q_np[:, None, :], derivatives=True)
            M, dM = answer.M[:, 0], answer.dM[:, 0]  # (K, d, d), (K, d, d, d): dM[k, j] = dM/dq_j
        ctx.dM = np.array(dM)
        return torch.from_numpy(np.array(M)).to(q.dtype)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_M):
        gradient = np.einsum('kab,kjab->kj', _numpy(grad_M), ctx.dM)
        return torch.from_numpy(gradient).to(grad_M.dtype), None, None, None


def _vector_jacobian(grad, jacobian, needed):
    """grad (K, d) times the Jacobians (K, d, d) (rows: output components), as a tensor; None
    when the input needs no gradient."""
    if not needed:
        return None
    return torch.from_numpy(np.einsum('ka,kab->kb', _numpy(grad), jacobian)).to(grad.dtype)


class _DynamicsFunction(torch.autograd.Function):
    """y(a, b, c) of three (K, d) inputs and (client, body, per_frame); the
    forward stores ctx.jacobians, dy/da, dy/db and dy/dc as (K, d, d) arrays
    (None where not needed), and the backward is grad_y^T times each."""

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_y):
        return tuple(_vector_jacobian(grad_y, jacobian, needs)
                     for jacobian, needs in zip(ctx.jacobians, ctx.needs_input_grad[:3])) + (None, None, None)


class _InverseDynamics(_DynamicsFunction):
    """tau(q, qdot, qddot): dtau/dq, dtau/dqdot and M."""

    @staticmethod
    def forward(ctx, q, qdot, qddot, client, body, per_frame):
        needs_q, needs_qdot, needs_qddot = ctx.needs_input_grad[:3]
        tau, dtau_dq, dtau_dqdot, M = inverse_dynamics_batch(
            client, body, _numpy(q), _numpy(qdot), _numpy(qddot), derivatives=needs_q or needs_qdot,
            mass_matrix=needs_qddot, per_frame=per_frame)
        ctx.jacobians = (dtau_dq, dtau_dqdot, M)
        return torch.from_numpy(np.array(tau)).to(q.dtype)


class _ForwardDynamics(_DynamicsFunction):
    """qddot(q, qdot, tau): dqddot/dq, dqddot/dqdot and M^-1."""

    @staticmethod
    def forward(ctx, q, qdot, tau, client, body, per_frame):
        qddot, *ctx.jacobians = forward_dynamics_batch(
            client, body, _numpy(q), _numpy(qdot), _numpy(tau), derivatives=any(ctx.needs_input_grad[:3]),
            per_frame=per_frame)
        return torch.from_numpy(np.array(qddot)).to(q.dtype)


def _batched(q, client, body):
    """(q as (K, d), whether q was a single (d,) configuration); d = ``body``'s dof."""
    d = client.dofs(body)
    if q.dim() == 1 and q.shape[0] == d:
        return q.reshape(1, d), True
    if q.dim() != 2 or q.shape[1] != d:
        raise ValueError('q of body %r must have shape (%d,) or (K, %d), not %s' % (body, d, d, tuple(q.shape)))
    return q, False


def vertex_positions(client, body, q, vertices=None, per_frame=False):
    """Positions [m] of ``body``'s ``vertices`` (None = all): (K, N, 3) for q
    (K, d), (N, 3) for q (d,). Differentiable in q (backward: ``backprop``)."""
    q2, single = _batched(q, client, body)
    p = _VertexPositions.apply(q2, client, body, vertices, per_frame)
    return p[0] if single else p


def mass_matrix(client, body, q, per_frame=False):
    """M(q) of ``body``: (K, d, d) for q (K, d), (d, d) for q (d,).
    Differentiable in q (backward from dM/dq of the same call)."""
    q2, single = _batched(q, client, body)
    M = _MassMatrix.apply(q2, client, body, per_frame)
    return M[0] if single else M


def kinetic_energy(client, body, q, qdot, per_frame=False):
    """E = 1/2 qdot^T M(q) qdot [J] per configuration: (K,) for (K, d), () for (d,).
    Differentiable in q and qdot."""
    M = mass_matrix(client, body, q, per_frame)
    return 0.5 * torch.einsum('...a,...ab,...b->...', qdot, M, qdot)


def _batched_like(q, others, client, body):
    """q as (K, d) (see _batched) and ``others`` (name -> tensor of q's shape) reshaped alike."""
    q2, single = _batched(q, client, body)
    reshaped = []
    for name, value in others:
        if value.shape != q.shape:
            raise ValueError('%s of body %r must have the shape of q, %s, not %s'
                             % (name, body, tuple(q.shape), tuple(value.shape)))
        reshaped.append(value.reshape(q2.shape))
    return q2, reshaped, single


@earlier_order(('q', 'qdot', 'qddot', 'body', 'per_frame'), numbers_before_names(3), leading=1)
def inverse_dynamics(client, body, q, qdot, qddot, per_frame=False):
    """tau = M(q) qddot + c(q, qdot) + g(q) [N m, N] of ``body``: (K, d) for inputs (K, d), (d,)
    for (d,). Differentiable in q, qdot and qddot (backward from the same call's dtau/dq,
    dtau/dqdot, and M = dtau/dqddot from get_mass_matrix)."""
    q2, (qdot2, qddot2), single = _batched_like(q, (('qdot', qdot), ('qddot', qddot)), client, body)
    tau = _InverseDynamics.apply(q2, qdot2, qddot2, client, body, per_frame)
    return tau[0] if single else tau


@earlier_order(('q', 'qdot', 'tau', 'body', 'per_frame'), numbers_before_names(3), leading=1)
def forward_dynamics(client, body, q, qdot, tau, per_frame=False):
    """qddot = M(q)^-1 (tau - c(q, qdot) - g(q)) [rad/s^2, m/s^2] of ``body``: (K, d) for inputs
    (K, d), (d,) for (d,). Differentiable in q, qdot and tau (backward from the same call's
    dqddot/dq, dqddot/dqdot and dqddot/dtau = M^-1). A singular M raises DiffRigidBodyError."""
    q2, (qdot2, tau2), single = _batched_like(q, (('qdot', qdot), ('tau', tau)), client, body)
    qddot = _ForwardDynamics.apply(q2, qdot2, tau2, client, body, per_frame)
    return qddot[0] if single else qddot
