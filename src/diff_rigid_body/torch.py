"""PyTorch autograd functions over a :class:`~diff_rigid_body.client.RigidBodyClient`.

Shapes follow torch conventions, with a leading batch axis of K
configurations of the body's coordinates x, d = its dof (float64 tensors on
the CPU; a free body's x is q = (phi, theta, psi, tx, ty, tz), d = 6):

=======================================  ==========================================
``vertex_positions(client, body, q)``    q (K, d) -> p (K, N, 3) [m]; q (d,) -> (N, 3)
``mass_matrix(client, body, q)``         q (K, d) -> M (K, d, d); q (d,) -> (d, d)
``kinetic_energy(client, body, q, qd)``  q, qdot (K, d) -> E (K,) [J]; (d,) -> ()
=======================================  ==========================================

Each forward pass is one service call for all K configurations
(``get_vertex_jacobians_compact`` with positions_only, or ``get_mass_matrix``
with derivatives); the
backward pass of :func:`vertex_positions` is one ``backprop`` call with
grad_output as dL/dp (J is never formed), that of :func:`mass_matrix` is
dL/dq_j = sum_ab grad_M[a, b] dM[a, b]/dq_j from the dM of the forward call.
``per_frame=True`` makes one call per configuration instead (same numbers:
for comparisons). The node's state is never changed. First derivatives only.
"""
import numpy as np
import torch
from torch.autograd.function import once_differentiable

__all__ = ['vertex_positions', 'mass_matrix', 'kinetic_energy', 'positions_batch', 'backprop_batch']


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
