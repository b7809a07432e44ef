"""A numpy client for rigid_body_server.

Wraps the node's services (those of include/diff_rigid_body_ros/services.h
that have a client method) with persistent connections and returns numpy
arrays. Response arrays are deserialised straight from the wire with
``np.frombuffer`` (``rospy.numpy_msg``): no per-element Python loop. The
arrays returned are read-only views on the received buffer; ``.copy()`` one
to modify it.

Shapes (n bodies, N vertices, K configurations). A body's coordinates x
have d = dof values (``bodies().dofs``): a free body's x is
q = (phi, theta, psi, tx, ty, tz), d = 6; an articulated body's x is its
floating root's q (if it floats), then its joint positions (interface.md,
"Version 2"). Every ``q`` argument holds x:

==============================  ===============================================
``mass_matrix(...).M``          (n, d, d), or (K, n, d, d) for a batched ``q``;
                                when the bodies' d differ, a list of n arrays,
                                (d_i, d_i) or (K, d_i, d_i)
``mass_matrix(...).dM``         (n, d, d, d): ``dM[i, j]`` = dM/dx_j of body i
                                (a d x d matrix); (K, n, d, d, d) when batched
                                (a list per body when the d differ)
``vertex_jacobians(...)``       positions (N, 3) [m], J (N, 3, d): ``J[v]`` = dp_v/dx;
                                (K, N, 3) and (K, N, 3, d) for a q of shape (K, d)
``vertex_jacobians_compact()``  positions (N, 3) [m], Jr (N, 3, c): the columns
                                of J that are not always I3 (free body: c = 3,
                                ``Jr[v]`` = dp_v/d(phi, theta, psi), J = [Jr | I3];
                                floating root: c = d - 3; fixed base: c = d);
                                float32 with ``single_precision``; (K, N, 3),
                                (K, N, 3, c) for a q of shape (K, d)
``backprop(...)``               dL/dx, (d,); (K, d) for a q of shape (K, d)
``get_state()``                 dict name -> x (d,)
==============================  ===============================================

A flat ``q`` of K d values (K > 1) is K configurations too; to tell, the
client asks ``get_bodies`` once for the bodies' d (and again after a reconnection).

A service that answers ``success: False`` raises :class:`DiffRigidBodyError`
with the node's message. If a persistent connection drops (the node was
restarted), the call reconnects once, waiting up to ``timeout`` for the
service, and is retried; every service is idempotent, so a retry is safe.

A client is not thread-safe (persistent connections are not): use one per
thread.
"""
import collections

import numpy as np
import rospy
from rospy.numpy_msg import numpy_msg

from diff_rigid_body.msg import BodyState
from diff_rigid_body.srv import (Backprop, GetBodies, GetMassMatrix, GetState, GetVertexJacobians,
                                 GetVertexJacobiansCompact, SetState)

__all__ = ['DiffRigidBodyError', 'RigidBodyClient', 'Bodies', 'MassMatrices']


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


def _numpy_service(service_class):
    """The service type with a response that deserialises its arrays with np.frombuffer."""
    return type('Numpy' + service_class.__name__, (object,), {
        '_type': service_class._type,
        '_md5sum': service_class._md5sum,
        '_request_class': service_class._request_class,
        '_response_class': numpy_msg(service_class._response_class),
    })


def _floats(values):
    """A flat list of floats for a float64[] request field (struct.pack takes lists fastest)."""
    return np.asarray(values, dtype=np.float64).ravel().tolist()


def _indices(vertices):
    return [] if vertices is None else np.asarray(vertices, dtype=np.uint32).ravel().tolist()


def _pose(q):
    """A request's optional q: empty = the node's current state, else the body's x (d values,
    or K d for K configurations)."""
    return [] if q is None else _floats(q)


def _configurations(q, dofs):
    """K for a vertex request's q of shape (K, d) (or K d flat values, K > 1), or None for one
    configuration (None, empty or (d,)); ``dofs()`` gives d, asked only for a flat q. A size the
    node refuses is left to the node's message."""
    if q is None:
        return None
    if np.ndim(q) >= 2:
        if np.shape(q)[0] == 0:  # an empty q would mean the current state
            raise ValueError('q: at least one configuration, got shape %s' % (np.shape(q),))
        return int(np.shape(q)[0])
    size = int(np.size(q))
    if size == 0:
        return None
    d = dofs()
    return None if d == 0 or size == d or size % d else size // d


def _blocks(values, configurations, vertices, columns=None):
    """``values`` as (N, 3) (or (N, 3, columns)), with a leading K axis when ``configurations`` = K
    is not None. ``vertices`` = N."""
    shape = (vertices, 3) if columns is None else (vertices, 3, columns)
    values = np.asarray(values)
    return values.reshape(shape if configurations is None else (configurations,) + shape)


def _per_body(values, dofs, configurations, power):
    """The matrices of a get_mass_matrix field (d_i^power values per matrix, configuration-major)
    of each body, as a list of (K,) + (d_i,) * power arrays."""
    sizes = [d ** power for d in dofs]
    rows = np.asarray(values).reshape(configurations, sum(sizes))
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    return [rows[:, starts[i]:starts[i + 1]].reshape((configurations,) + (d,) * power)
            for i, d in enumerate(dofs)]


class RigidBodyClient(object):
    """Persistent-connection client of one rigid_body_server.

    :param server: the node's name, resolved like any ROS name (a relative name
        lands in the caller's namespace), e.g. ``/rigid_body_server`` or
        ``/robot1/rigid_body_server``.
    :param timeout: [s] how long to wait for a service when connecting or
        reconnecting.

    ``rospy.init_node`` is not required for calls.
    """

    SERVICES = {
        'get_bodies': GetBodies,
        'set_state': SetState,
        'get_state': GetState,
        'get_mass_matrix': GetMassMatrix,
        'get_vertex_jacobians': GetVertexJacobians,
        'backprop': Backprop,
        'get_vertex_jacobians_compact': GetVertexJacobiansCompact,
    }

    def __init__(self, server='rigid_body_server', timeout=30.0):
        self.server = rospy.resolve_name(server)
        self.timeout = timeout
        self._proxies = {}
        self._dofs = None  # body name -> d, from get_bodies when first needed

    # ------------------------------------------------------------------ plumbing
    def _proxy(self, name):
        proxy = self._proxies.get(name)
        if proxy is None:
            resolved = '%s/%s' % (self.server, name)
            rospy.wait_for_service(resolved, timeout=self.timeout)
            proxy = rospy.ServiceProxy(resolved, _numpy_service(self.SERVICES[name]), persistent=True)
            self._proxies[name] = proxy
        return proxy

    def _drop(self, name):
        self._dofs = None  # the node restarted: perhaps with another scene
        proxy = self._proxies.pop(name, None)
        if proxy is not None:
            proxy.close()

    def call(self, name, **request):
        """Calls service ``name`` with the request fields given; returns the
        response (numpy arrays) or raises :class:`DiffRigidBodyError`."""
        request_class = self.SERVICES[name]._request_class
        message = request_class(**request)
        try:
            response = self._proxy(name).call(message)
        except (rospy.ServiceException, rospy.exceptions.TransportException, OSError):
            # The persistent connection dropped (e.g. the node restarted):
            # reconnect once and retry. A second failure propagates.
            self._drop(name)
            response = self._proxy(name).call(message)
        if not response.success:
            raise DiffRigidBodyError('%s/%s' % (self.server, name), response.message)
        return response

    def connect(self, services=None):
        """Opens the persistent connections now (``services``: names, None =
        all of SERVICES), so that the first calls do not pay for the set-up."""
        for name in services or self.SERVICES:
            self._proxy(name)
        return self

    def close(self):
        """Closes every persistent connection (they reopen on the next call)."""
        for name in list(self._proxies):
            self._drop(name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def dofs(self, body):
        """d = len(x) of ``body`` (``get_bodies``, asked once per connection); 0 for an unknown body."""
        if self._dofs is None or body not in self._dofs:
            answer = self.call('get_bodies')
            self._dofs = dict(zip(answer.names, (int(d) for d in answer.dofs)))
        return self._dofs.get(body, 0)

    def _configurations(self, body, q):
        return _configurations(q, lambda: self.dofs(body))

    # ------------------------------------------------------------------ services
    def bodies(self):
        """The scene: a :data:`Bodies` tuple."""
        r = self.call('get_bodies')
        n = len(r.names)
        return Bodies(r.fixed_frame, list(r.names), np.asarray(r.masses), np.asarray(r.inertias).reshape(n, 3, 3),
                      np.asarray(r.com_offsets).reshape(n, 3), np.asarray(r.vertex_counts), np.asarray(r.dofs),
                      _split(r.joint_counts, [Joint(name, lower, upper) for name, lower, upper in
                                              zip(r.joint_names, r.joint_lower, r.joint_upper)]),
                      _split(r.link_counts, _links(r)))

    def get_state(self, bodies=None):
        """dict body name -> x (d,), in the node's order (``bodies`` None = all)."""
        r = self.call('get_state', bodies=list(bodies or []))
        return collections.OrderedDict((s.name, np.asarray(s.q)) for s in r.states)

    def set_state(self, states):
        """Sets states, all or nothing. ``states``: dict name -> x (d,), or
        pairs (name, x)."""
        items = states.items() if hasattr(states, 'items') else states
        self.call('set_state', states=[BodyState(name=name, q=_floats(q)) for name, q in items])

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
        r = self.call('get_mass_matrix', bodies=list(bodies or []), q=_pose(q), derivatives=bool(derivatives))
        n, dofs = len(r.bodies), [int(d) for d in r.dofs]
        K = len(r.cos_theta) // n if n else 0
        batched = (q is not None and np.ndim(q) == 3) or K > 1
        shape = (K, n) if batched else (n,)
        cos_theta = np.asarray(r.cos_theta).reshape(shape)
        if len(set(dofs)) <= 1:
            d = dofs[0] if dofs else 0
            M = np.asarray(r.mass_matrices).reshape(shape + (d, d))
            dM = np.asarray(r.derivatives).reshape(shape + (d, d, d)) if derivatives else None
            return MassMatrices(list(r.bodies), M, dM, cos_theta)
        M = _per_body(r.mass_matrices, dofs, K, 2)
        dM = _per_body(r.derivatives, dofs, K, 3) if derivatives else None
        if not batched:
            M = [m[0] for m in M]
            dM = None if dM is None else [m[0] for m in dM]
        return MassMatrices(list(r.bodies), M, dM, cos_theta)

    def vertex_jacobians(self, body, q=None, vertices=None):
        """positions (N, 3) [m, fixed frame] and J (N, 3, d) = dp/dx of ``body``'s
        ``vertices`` (None = all) at ``q`` (None = current state, else x, (d,)).

        A ``q`` of shape (K, d) evaluates K configurations in one call:
        positions (K, N, 3) and J (K, N, 3, d), each configuration's block the
        same bits as a call with that q alone. The node's state is not changed."""
        K = self._configurations(body, q)
        r = self.call('get_vertex_jacobians', body=body, vertices=_indices(vertices), q=_pose(q))
        N = len(r.positions) // (3 * (K or 1))
        d = len(r.jacobians) // len(r.positions) if len(r.positions) else self.dofs(body)
        return _blocks(r.positions, K, N), _blocks(r.jacobians, K, N, d)

    def vertex_jacobians_compact(self, body, q=None, vertices=None, positions_only=False, single_precision=False):
        """The reduced transport of :meth:`vertex_jacobians`: positions (N, 3) [m]
        and Jr (N, 3, c), the columns of J that are not always I3 (for a free
        body ``Jr[v]`` = dp_v/d(phi, theta, psi), J = [Jr | I3]; see the module
        docstring); Jr is None with ``positions_only``. With
        ``single_precision`` both are float32 (the float64 values rounded).
        A ``q`` of shape (K, d): (K, N, 3) and (K, N, 3, c)."""
        K = self._configurations(body, q)
        r = self.call('get_vertex_jacobians_compact', body=body, vertices=_indices(vertices), q=_pose(q),
                      positions_only=bool(positions_only), single_precision=bool(single_precision))
        if single_precision:
            positions, jacobians = r.positions_f32, r.rotation_jacobians_f32
        else:
            positions, jacobians = r.positions, r.rotation_jacobians
        N = len(positions) // (3 * (K or 1))
        if positions_only:
            return _blocks(positions, K, N), None
        c = len(jacobians) // len(positions) if len(positions) else 0
        return _blocks(positions, K, N), _blocks(jacobians, K, N, c)

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
        r = self.call('backprop', body=body, vertices=_indices(vertices), gradients=_floats(gradients), q=_pose(q))
        gradient = np.asarray(r.gradient)
        return gradient.reshape(-1) if K is None else gradient.reshape(K, -1)
