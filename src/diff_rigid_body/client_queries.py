"""The state-free queries of rigid_body_server as numpy methods, shared by both backends:
:class:`~diff_rigid_body.client.RigidBodyClient` (the node's services) and
:class:`~diff_rigid_body.local.LocalScene` (the same core in process). A backend gives
``call(service name, **request fields)``, returning an object with the response's fields (numpy
arrays, lists of names) or raising :class:`~diff_rigid_body.client_types.DiffRigidBodyError`; these
methods lay out the requests and shape the answers (shapes: the module docstring of
``diff_rigid_body.client``).
"""
import numpy as np

from diff_rigid_body import srv
from diff_rigid_body.client_arguments import earlier_order, numbers_before_names
from diff_rigid_body.client_arrays import (AnswerShape, floats, indices, optional_values, vertex_blocks,
                                          vertex_configurations)
from diff_rigid_body.client_declared import add_declared_methods, declared_core_services
from diff_rigid_body.client_frames import FrameQueries
from diff_rigid_body.client_names import body_names
from diff_rigid_body.client_types import (ForwardDynamicsResult, InverseDynamicsResult, MassMatrices,
                                         bodies_from_response)

__all__ = ['SceneQueries']


class SceneQueries(FrameQueries):
    """The methods over ``self.call`` that need no state of the backend but its bodies' d
    (cached in ``self._dofs``, which a backend resets to None when its scene may have changed)."""

    _dofs = None  # body name -> d, from get_bodies when first needed

    def dofs(self, body):
        """d = len(x) of ``body`` (``get_bodies``, asked once per connection); 0 for an unknown body."""
        if self._dofs is None or body not in self._dofs:
            answer = self.call('get_bodies')
            self._dofs = dict(zip(answer.names, (int(d) for d in answer.dofs)))
        return self._dofs.get(body, 0)

    def _configurations(self, body, q):
        return vertex_configurations(q, lambda: self.dofs(body))

    def bodies(self):
        """The scene: a :data:`Bodies` tuple."""
        return bodies_from_response(self.call('get_bodies'))

    def mass_matrix(self, bodies=None, q=None, derivatives=False):
        """M(x) of ``bodies`` (None = all), as :data:`MassMatrices`.

        ``q``: None = the current state (M is (n, d, d)); an (n, d) array (or
        the n bodies' x concatenated) = one configuration (M is (n, d, d)); a
        (K, n, d) array, or K such concatenations (flat or (K, D)), = K
        configurations in one call (M is (K, n, d, d)). The node's state is
        not changed. With ``derivatives``, dM has one more axis of d after the
        body axis: ``dM[..., i, j, :, :]`` = dM/dx_j of body i. When the
        bodies' d differ, M and dM are lists with one array per body, without
        the body axis: ``M[i]`` (d_i, d_i) or (K, d_i, d_i).
        """
        r = self.call('get_mass_matrix', bodies=body_names(bodies), q=optional_values(q),
                      derivatives=bool(derivatives))
        shape = AnswerShape(r, q)
        return MassMatrices(list(r.bodies), shape.field(r.mass_matrices, 2), shape.field(r.derivatives, 3, derivatives),
                            shape.per_body_scalars(r.cos_theta))

    @earlier_order(('q', 'qdot', 'qddot', 'bodies', 'coriolis_matrices', 'derivatives'), numbers_before_names(3),
                   leading=1)
    def inverse_dynamics(self, bodies=None, q=None, qdot=None, qddot=None, coriolis_matrices=False,
                         derivatives=False):
        """tau = M(x) x'' + c(x, x') + g(x) of ``bodies`` (None = all), as
        :data:`InverseDynamicsResult`; defined everywhere (gimbal lock too).

        ``q`` as for :meth:`mass_matrix` (None = the current state; (K, n, d)
        or K > 1 concatenations = K configurations); ``qdot`` [rad/s, m/s] and
        ``qddot`` [rad/s^2, m/s^2] have q's shape (for q None: one
        configuration), None = zeros. Vectors come as (n, d) or (K, n, d),
        matrices as (n, d, d) or (K, n, d, d), rows the tau components; lists
        per body when the bodies' d differ, as for :meth:`mass_matrix`.
        ``coriolis_matrices`` adds C (c = C x'), ``derivatives`` dtau/dx and
        dtau/dx' (= 2 C). The node's state is not changed.
        """
        r = self.call('inverse_dynamics', bodies=body_names(bodies), q=optional_values(q),
                      qdot=optional_values(qdot), qddot=optional_values(qddot),
                      coriolis_matrices=bool(coriolis_matrices), derivatives=bool(derivatives))
        shape = AnswerShape(r, q)
        return InverseDynamicsResult(list(r.bodies), shape.field(r.tau, 1), shape.field(r.velocity_terms, 1),
                                     shape.field(r.gravity_terms, 1),
                                     shape.field(r.coriolis_matrices, 2, coriolis_matrices),
                                     shape.field(r.dtau_dq, 2, derivatives), shape.field(r.dtau_dqdot, 2, derivatives),
                                     shape.per_body_scalars(r.cos_theta))

    @earlier_order(('q', 'qdot', 'tau', 'bodies', 'derivatives'), numbers_before_names(3), leading=1)
    def forward_dynamics(self, bodies=None, q=None, qdot=None, tau=None, derivatives=False):
        """x'' = M(x)^-1 (tau - c(x, x') - g(x)) of ``bodies`` (None = all), as
        :data:`ForwardDynamicsResult`.

        ``q``, ``qdot`` and the shapes of the answer as for
        :meth:`inverse_dynamics`; ``tau`` [N m, N] has q's shape, None = zeros
        (for a free root: (T^T n, f), n the torque about its COM, f the
        force, fixed-frame axes). ``derivatives`` adds dx''/dx, dx''/dx' and
        dx''/dtau = M^-1. A configuration where M is singular (gimbal lock, a
        coordinate that moves no mass) raises :class:`DiffRigidBodyError`
        naming the body and the configuration. The node's state is not changed.
        """
        r = self.call('forward_dynamics', bodies=body_names(bodies), q=optional_values(q),
                      qdot=optional_values(qdot), tau=optional_values(tau), derivatives=bool(derivatives))
        shape = AnswerShape(r, q)
        return ForwardDynamicsResult(list(r.bodies), shape.field(r.qddot, 1),
                                     shape.field(r.dqddot_dq, 2, derivatives),
                                     shape.field(r.dqddot_dqdot, 2, derivatives),
                                     shape.field(r.dqddot_dtau, 2, derivatives), shape.per_body_scalars(r.cos_theta))

    def vertex_jacobians(self, body, q=None, vertices=None):
        """positions (N, 3) [m, fixed frame] and J (N, 3, d) = dp/dx of ``body``'s
        ``vertices`` (None = all) at ``q`` (None = current state, else x, (d,)).

        A ``q`` of shape (K, d) evaluates K configurations in one call:
        positions (K, N, 3) and J (K, N, 3, d), each configuration's block the
        same bits as a call with that q alone. The node's state is not changed."""
        K = self._configurations(body, q)
        r = self.call('get_vertex_jacobians', body=body, vertices=indices(vertices), q=optional_values(q))
        N = len(r.positions) // (3 * (K or 1))
        d = len(r.jacobians) // len(r.positions) if len(r.positions) else self.dofs(body)
        return vertex_blocks(r.positions, K, N), vertex_blocks(r.jacobians, K, N, d)

    def vertex_jacobians_compact(self, body, q=None, vertices=None, positions_only=False, single_precision=False):
        """The reduced transport of :meth:`vertex_jacobians`: positions (N, 3) [m]
        and Jr (N, 3, c), the columns of J that are not always I3 (for a free
        body ``Jr[v]`` = dp_v/d(phi, theta, psi), J = [Jr | I3]; see the module
        docstring); Jr is None with ``positions_only``. With
        ``single_precision`` both are float32 (the float64 values rounded).
        A ``q`` of shape (K, d): (K, N, 3) and (K, N, 3, c)."""
        K = self._configurations(body, q)
        r = self.call('get_vertex_jacobians_compact', body=body, vertices=indices(vertices),
                      q=optional_values(q),
                      positions_only=bool(positions_only), single_precision=bool(single_precision))
        if single_precision:
            positions, jacobians = r.positions_f32, r.rotation_jacobians_f32
        else:
            positions, jacobians = r.positions, r.rotation_jacobians
        N = len(positions) // (3 * (K or 1))
        if positions_only:
            return vertex_blocks(positions, K, N), None
        c = len(jacobians) // len(positions) if len(positions) else 0
        return vertex_blocks(positions, K, N), vertex_blocks(jacobians, K, N, c)

    def positions(self, body, q=None, vertices=None):
        """positions (N, 3) [m] only, or (K, N, 3) for a q of shape (K, d) (the
        same service; J is discarded)."""
        return self.vertex_jacobians(body, q, vertices)[0]

    def backprop(self, body, gradients, q=None, vertices=None):
        """dL/dx (d,) from ``gradients`` = dL/dp, (N, 3), of ``body``'s ``vertices``
        (None = all) at ``q`` (None = current state). J is never formed.

        With ``q`` of shape (K, d) and ``gradients`` of shape (K, N, 3) (the
        dL/dp of configuration k in ``gradients[k]``): dL/dx of each
        configuration, (K, d), each row the same bits as a call with that q
        and gradients alone."""
        K = self._configurations(body, q)
        r = self.call('backprop', body=body, vertices=indices(vertices), gradients=floats(gradients),
                      q=optional_values(q))
        gradient = np.asarray(r.gradient)
        return gradient.reshape(-1) if K is None else gradient.reshape(K, -1)


# query(service, ...) for every state-free service, and the method of each one this class does not
# define (client_declared).
add_declared_methods(SceneQueries, declared_core_services(srv))
