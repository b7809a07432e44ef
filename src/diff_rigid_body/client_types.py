"""What :class:`~diff_rigid_body.client.RigidBodyClient` returns and raises (numpy arrays in
named tuples), and how a get_bodies response becomes :data:`Bodies`."""
import collections

import numpy as np

__all__ = ['DiffRigidBodyError', 'Bodies', 'Joint', 'Link', 'MassMatrices', 'InverseDynamicsResult',
           'ForwardDynamicsResult', 'bodies_from_response']


class DiffRigidBodyError(RuntimeError):
    """A service of rigid_body_server refused a request (``success: False``).

    ``service`` is the service's name, ``message`` the node's explanation (it
    names the body, index or field at fault). The node's state is unchanged.
    """

    def __init__(self, service, message):
        super().__init__('%s: %s' % (service, message))
        self.service = service
        self.message = message


#: ``get_bodies``: fixed_frame (str), names (list of str), masses (n,) [kg],
#: inertias (n, 3, 3) [kg m^2] about the COM in body axes, com_offsets (n, 3) [m]
#: in the link frame, vertex_counts (n,); dofs (n,), joints (per body: a list of
#: :data:`Joint`) and links (per body: a list of :data:`Link`, in vertex order).
Bodies = collections.namedtuple('Bodies', 'fixed_frame names masses inertias com_offsets vertex_counts dofs joints '
                                          'links')

#: One joint coordinate of a body: name, lower and upper limit [rad or m] (+-inf where none).
Joint = collections.namedtuple('Joint', 'name lower upper')

#: One link of a body: name, mass [kg] (0 for a massless frame), inertia (3, 3) [kg m^2]
#: about its COM in link axes, com_offset (3,) [m] in its frame, and its vertices:
#: the body's vertices first..first+vertex_count-1 (contiguous, in link order).
Link = collections.namedtuple('Link', 'name mass inertia com_offset first_vertex vertex_count')

#: ``get_mass_matrix``: bodies (list of str), M, dM (None unless derivatives
#: were asked for) and cos_theta ((n,) or (K, n): the gimbal-lock diagnostic).
MassMatrices = collections.namedtuple('MassMatrices', 'bodies M dM cos_theta')

#: ``inverse_dynamics``: bodies, tau = M x'' + c + g [N m, N], c = C x' (velocity terms), g
#: (gravity terms), C (None unless coriolis_matrices were asked for), dtau_dq and dtau_dqdot
#: (None unless derivatives were: ``dtau_dq[..., a, b]`` = dtau_a/dx_b), cos_theta.
InverseDynamicsResult = collections.namedtuple('InverseDynamicsResult', 'bodies tau c g C dtau_dq dtau_dqdot cos_theta')

#: ``forward_dynamics``: bodies, qddot = M^-1 (tau - c - g) [rad/s^2, m/s^2], and with derivatives
#: dqddot_dq, dqddot_dqdot, dqddot_dtau (= M^-1; ``[..., a, b]`` = dx''_a/d(.)_b), else None; cos_theta.
ForwardDynamicsResult = collections.namedtuple('ForwardDynamicsResult',
                                               'bodies qddot dqddot_dq dqddot_dqdot dqddot_dtau cos_theta')


def _split(counts, items):
    """``items`` cut into consecutive lists of ``counts[i]`` items."""
    ends = np.cumsum(np.asarray(counts, dtype=np.int64))
    return [list(items[end - count:end]) for count, end in zip(counts, ends)]


def _links(r):
    """The links of a get_bodies response, flattened, with their first vertex within their body."""
    inertias = np.asarray(r.link_inertias).reshape(-1, 3, 3)
    coms = np.asarray(r.link_com_offsets).reshape(-1, 3)
    links = []
    for body_links in _split(r.link_counts, list(range(len(r.link_names)))):
        first = 0
        for k in body_links:
            links.append(Link(r.link_names[k], r.link_masses[k], inertias[k], coms[k], first,
                              int(r.link_vertex_counts[k])))
            first += int(r.link_vertex_counts[k])
    return links


def bodies_from_response(r):
    """A get_bodies response as :data:`Bodies`."""
    n = len(r.names)
    return Bodies(r.fixed_frame, list(r.names), np.asarray(r.masses), np.asarray(r.inertias).reshape(n, 3, 3),
                  np.asarray(r.com_offsets).reshape(n, 3), np.asarray(r.vertex_counts), np.asarray(r.dofs),
                  _split(r.joint_counts, [Joint(name, lower, upper) for name, lower, upper in
                                          zip(r.joint_names, r.joint_lower, r.joint_upper)]),
                  _split(r.link_counts, _links(r)))
