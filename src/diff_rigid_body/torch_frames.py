"""PyTorch autograd functions for link frames and centres of mass, over a
:class:`~diff_rigid_body.client.RigidBodyClient` (see :mod:`diff_rigid_body.torch` for the shapes'
conventions: float64 CPU tensors, a leading batch axis of K configurations of the body's x):

=========================================  ==========================================
``frame_pose(client, body, frame, q)``     q (K, d) -> position (K, 3) [m], rotation
                                           (K, 3, 3) in fixed_frame; q (d,) -> (3,), (3, 3)
``center_of_mass(client, body, q)``        q (K, d) -> c (K, 3) [m]; q (d,) -> (3,)
=========================================  ==========================================

Each forward pass is one service call for all K configurations (``get_frame_jacobians`` in
LOCAL_WORLD_ALIGNED, ``get_center_of_mass`` with Jacobians); the backward passes multiply by the
served Jacobians and call nothing. For the rotation, dR/dx_j = [w_j]x R with w_j the angular
column j of J (fixed-frame axes), so for G = dL/dR, dL/dx_j = <G, [w_j]x R> = w_j . s(G R^T) with
s(A) = (A_32 - A_23, A_13 - A_31, A_21 - A_12). The node's state is never changed.
"""
import numpy as np
import torch
from torch.autograd.function import once_differentiable

from diff_rigid_body.torch import _batched, _numpy

__all__ = ['frame_pose', 'center_of_mass']


def _skew_part(A):
    """(A_32 - A_23, A_13 - A_31, A_21 - A_12) of each (3, 3) matrix of A (K, 3, 3): (K, 3)."""
    return np.stack([A[:, 2, 1] - A[:, 1, 2], A[:, 0, 2] - A[:, 2, 0], A[:, 1, 0] - A[:, 0, 1]], axis=1)


class _FramePose(torch.autograd.Function):

    @staticmethod
    def forward(ctx, q, client, body, frame):
        answer = client.frame_jacobians(body, q=_numpy(q), frames=[frame], reference='local_world_aligned')
        ctx.J = np.array(answer.J[:, 0])               # (K, 6, d)
        ctx.R = np.array(answer.rotations[:, 0])       # (K, 3, 3)
        position = torch.from_numpy(np.array(answer.positions[:, 0])).to(q.dtype)
        return position, torch.from_numpy(ctx.R.copy()).to(q.dtype)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_position, grad_rotation):
        gradient = np.einsum('ka,kab->kb', _numpy(grad_position), ctx.J[:, :3])
        A = np.einsum('kab,kcb->kac', _numpy(grad_rotation), ctx.R)  # G R^T
        gradient += np.einsum('ka,kab->kb', _skew_part(A), ctx.J[:, 3:])
        return torch.from_numpy(gradient).to(grad_position.dtype), None, None, None


class _CenterOfMass(torch.autograd.Function):

    @staticmethod
    def forward(ctx, q, client, body):
        answer = client.center_of_mass([body], q=_numpy(q)[:, None, :], jacobians=True)
        ctx.J = np.array(answer.J[:, 0])  # (K, 3, d)
        return torch.from_numpy(np.array(answer.com[:, 0])).to(q.dtype)

    @staticmethod
    @once_differentiable
    def backward(ctx, grad_com):
        return torch.from_numpy(np.einsum('ka,kab->kb', _numpy(grad_com), ctx.J)).to(grad_com.dtype), None, None


def frame_pose(client, body, frame, q):
    """(position, rotation) of link ``frame`` of ``body`` in fixed_frame: (K, 3), (K, 3, 3) for q
    (K, d), (3,), (3, 3) for q (d,). Differentiable in q (backward: the served frame Jacobian)."""
    q2, single = _batched(q, client, body)
    position, rotation = _FramePose.apply(q2, client, body, frame)
    return (position[0], rotation[0]) if single else (position, rotation)


def center_of_mass(client, body, q):
    """The centre of mass [m] of ``body`` in fixed_frame: (K, 3) for q (K, d), (3,) for q (d,).
    Differentiable in q (backward: the served dc/dx)."""
    q2, single = _batched(q, client, body)
    c = _CenterOfMass.apply(q2, client, body)
    return c[0] if single else c
