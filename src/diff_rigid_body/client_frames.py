"""Frame and centre-of-mass Jacobians (``~get_frame_jacobians``, ``~get_center_of_mass``) for
:class:`~diff_rigid_body.client.RigidBodyClient`: the methods and their result types.

Columns are d/dx' of the body's coordinates x (for a floating root: the Euler-angle rates). A
frame's rows are linear then angular, in the reference asked for (Pinocchio's meanings):

==========================  ======================================================================
``'world'`` (0)             fixed_frame axes; the linear rows are the velocity of the point of the
                            link that is at fixed_frame's origin (spatial velocity)
``'local'`` (1)             the link frame's axes; the velocity of its origin
``'local_world_aligned'``   fixed_frame axes; the velocity of the link frame's origin (the usual
(2)                         end-effector Jacobian of inverse kinematics)
==========================  ======================================================================
"""
import collections

import numpy as np

from diff_rigid_body.client_arguments import earlier_order, names_at
from diff_rigid_body.client_arrays import AnswerShape, optional_values, vertex_configurations
from diff_rigid_body.client_names import body_names

__all__ = ['FrameJacobians', 'CenterOfMass', 'REFERENCES', 'FrameQueries']

#: ``frame_jacobians``: frames (list of str), positions (F, 3) [m] and rotations (F, 3, 3) of the
#: frames in fixed_frame, J (F, 6, d) (rows linear [m/s] then angular [rad/s] per unit x'),
#: bias (F, 6): J'x', the classical acceleration at x'' = 0 (None unless asked), and cos_theta
#: (a float); with a q of shape (K, d) every field has a leading K axis (cos_theta (K,)).
FrameJacobians = collections.namedtuple('FrameJacobians', 'frames positions rotations J bias cos_theta')

#: ``center_of_mass``: bodies, masses (n,) [kg], com (n, 3) [m, fixed_frame], J (n, 3, d) = dc/dx
#: and bias (n, 3) = c'' at x'' = 0 [m/s^2] (both None unless asked; J a list of (3, d_i) arrays
#: when the bodies' d differ), cos_theta (n,); K configurations add a leading K axis as for
#: ``mass_matrix``.
CenterOfMass = collections.namedtuple('CenterOfMass', 'bodies masses com J bias cos_theta')

#: The values of GetFrameJacobians' ``reference``.
REFERENCES = {'world': 0, 'local': 1, 'local_world_aligned': 2}


def reference_value(reference):
    """``reference`` as the request's uint8: a name of :data:`REFERENCES` or 0, 1, 2."""
    if isinstance(reference, str):
        if reference.lower() not in REFERENCES:
            raise ValueError('reference: one of %s, got %r' % (', '.join(sorted(REFERENCES)), reference))
        return REFERENCES[reference.lower()]
    if reference not in REFERENCES.values():
        raise ValueError('reference: 0 (world), 1 (local) or 2 (local_world_aligned), got %r' % (reference,))
    return int(reference)


def com_jacobians(values, dofs, configurations, batched):
    """get_center_of_mass' jacobians (3 d_i per body and configuration) as (n, 3, d), (K, n, 3, d)
    when ``batched``, or a list of (3, d_i) / (K, 3, d_i) arrays when the bodies' d differ."""
    rows = np.asarray(values).reshape(configurations, 3 * sum(dofs))
    if len(set(dofs)) <= 1:
        d = dofs[0] if dofs else 0
        shape = (len(dofs), 3, d)
        return rows.reshape(((configurations,) + shape) if batched else shape)
    starts = np.concatenate([[0], np.cumsum([3 * d for d in dofs])]).astype(int)
    blocks = [rows[:, starts[i]:starts[i + 1]].reshape(configurations, 3, d) for i, d in enumerate(dofs)]
    return blocks if batched else [block[0] for block in blocks]


class FrameQueries(object):
    """The frame and centre-of-mass methods of :class:`~diff_rigid_body.client.RigidBodyClient`."""

    @earlier_order(('body', 'q', 'frames', 'reference', 'qdot', 'acceleration_bias'),
                   names_at(2, or_value_at=3, values=tuple(REFERENCES) + tuple(REFERENCES.values())), leading=1)
    def frame_jacobians(self, body, q=None, qdot=None, frames=None, reference='local_world_aligned',
                        acceleration_bias=False):
        """Poses and Jacobians of ``body``'s link ``frames`` (None = every link of the body; merged
        links and static links are frames too) at ``q`` (None = current state, (d,), or (K, d)), as
        :data:`FrameJacobians`. ``reference``: 'world', 'local' or 'local_world_aligned' (see the
        module docstring). ``acceleration_bias`` adds J'x' at ``qdot`` (q's shape, None = zeros).
        The node's state is not changed."""
        K = vertex_configurations(q, lambda: self.dofs(body))
        r = self.call('get_frame_jacobians', body=body, frames=body_names(frames), q=optional_values(q),
                      qdot=optional_values(qdot), reference=reference_value(reference),
                      acceleration_bias=bool(acceleration_bias))
        lead = () if K is None else (K,)
        F, d = len(r.frames), int(r.dofs)
        poses = np.asarray(r.poses).reshape(lead + (F, 12))
        bias = np.asarray(r.acceleration_bias).reshape(lead + (F, 6)) if acceleration_bias else None
        cos_theta = np.asarray(r.cos_theta)
        return FrameJacobians(list(r.frames), poses[..., :3], poses[..., 3:].reshape(lead + (F, 3, 3)),
                              np.asarray(r.jacobians).reshape(lead + (F, 6, d)), bias,
                              float(cos_theta[0]) if K is None else cos_theta)

    def center_of_mass(self, bodies=None, q=None, qdot=None, jacobians=False):
        """The centre of mass of each of ``bodies`` (None = all) as :data:`CenterOfMass`; ``q`` as
        for :meth:`mass_matrix`. ``jacobians`` adds dc/dx and the acceleration bias J'x' at
        ``qdot`` (q's shape, None = zeros). The node's state is not changed."""
        r = self.call('get_center_of_mass', bodies=body_names(bodies), q=optional_values(q),
                      qdot=optional_values(qdot), jacobians=bool(jacobians))
        shape = AnswerShape(r, q)
        lead = (shape.configurations, shape.n) if shape.batched else (shape.n,)
        J = com_jacobians(r.jacobians, shape.dofs, shape.configurations, shape.batched) if jacobians else None
        bias = np.asarray(r.acceleration_bias).reshape(lead + (3,)) if jacobians else None
        return CenterOfMass(list(r.bodies), np.asarray(r.masses), np.asarray(r.com).reshape(lead + (3,)), J, bias,
                            shape.per_body_scalars(r.cos_theta))
