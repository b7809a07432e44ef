"""A numpy client for rigid_body_server.

Wraps the node's services (those whose .srv declares a Python method,
``diff_rigid_body.service_fields``) with persistent connections and returns numpy
arrays, with no per-element Python loop either way: a request's numeric
arrays are flat numpy buffers of their wire type (``client_arrays.wire_message``)
written to the socket as they are, and a response's arrays are
``np.frombuffer`` views of the buffer it was received into
(``diff_rigid_body.tcpros``; ``transport='rospy'``: ``rospy.ServiceProxy``
with ``rospy.numpy_msg`` both ways, the same bytes, read-only arrays).
``.copy()`` a returned array before modifying it.

Shapes (n bodies, N vertices, K configurations). A body's coordinates x
have d = dof values (``bodies().dofs``): a free body's x is
q = (phi, theta, psi, tx, ty, tz), d = 6; an articulated body's x is its
floating root's q (if it floats), then its joint positions (docs/interface.md,
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
``inverse_dynamics(...)``       tau = M x'' + c + g, c, g: (n, d) [N m, N]; C,
                                dtau/dx, dtau/dx': (n, d, d), row = tau component;
                                K configurations and bodies of different d as M
``forward_dynamics(...)``       x'' = M^-1 (tau - c - g): (n, d); dx''/dx,
                                dx''/dx', dx''/dtau: (n, d, d); as inverse_dynamics
``frame_jacobians(...)``        link frames: positions (F, 3), rotations (F, 3, 3),
                                J (F, 6, d) (rows linear then angular, in the
                                reference asked for), bias J'x' (F, 6); a
                                leading K axis for a q of shape (K, d)
                                (``client_frames``)
``center_of_mass(...)``         com (n, 3) [m], J = dc/dx (n, 3, d), bias (n, 3);
                                K configurations and bodies of different d as M
``get_state()``                 dict name -> x (d,)
==============================  ===============================================

A flat ``q`` of K d values (K > 1) is K configurations too; to tell, the
client asks ``get_bodies`` once for the bodies' d (and again after a reconnection).

A service that answers ``success: False`` raises :class:`DiffRigidBodyError`
with the node's message. If a persistent connection drops (the node was
restarted), the call reconnects once, waiting up to ``timeout`` for the
service, and is retried; every service is idempotent, so a retry is safe.
With ``reconnect=False`` the call raises instead (one of
:data:`CONNECTION_ERRORS`): :class:`~diff_rigid_body.pool.RigidBodyPool`
sends the work to another instance at once.

A ``bodies`` argument given as one string is one body (``mass_matrix('knot')``);
a vertex index that is negative or not a whole number raises ValueError
before anything is sent.

A client is not thread-safe (persistent connections are not): use one per
thread.
"""
import collections

import numpy as np
import rospy
from rospy.numpy_msg import numpy_msg

from diff_rigid_body.client_arrays import floats, wire_message
from diff_rigid_body.client_frames import CenterOfMass, FrameJacobians
from diff_rigid_body.client_names import NodeNotFoundError, body_names, missing_node_message
from diff_rigid_body.client_queries import SceneQueries
from diff_rigid_body.client_types import (Bodies, DiffRigidBodyError, ForwardDynamicsResult,
                                         InverseDynamicsResult, Joint, Link, MassMatrices)
from diff_rigid_body import srv
from diff_rigid_body.msg import BodyState
from diff_rigid_body.service_fields import declared_services
from diff_rigid_body.tcpros import ServiceConnection

__all__ = ['DiffRigidBodyError', 'RigidBodyClient', 'Bodies', 'Joint', 'Link', 'MassMatrices', 'InverseDynamicsResult',
           'ForwardDynamicsResult', 'FrameJacobians', 'CenterOfMass', 'CONNECTION_ERRORS', 'NodeNotFoundError']

#: What a call raises when the node cannot be reached or the connection drops (not a refusal).
CONNECTION_ERRORS = (rospy.ServiceException, rospy.ROSException, rospy.exceptions.TransportException, OSError)


def _numpy_service(service_class):
    """The service type whose request writes its arrays with ndarray.tobytes and whose response
    reads them with np.frombuffer (rospy.numpy_msg both ways)."""
    return type('Numpy' + service_class.__name__, (object,), {
        '_type': service_class._type,
        '_md5sum': service_class._md5sum,
        '_request_class': numpy_msg(service_class._request_class),
        '_response_class': numpy_msg(service_class._response_class),
    })


class RigidBodyClient(SceneQueries):
    """Persistent-connection client of one rigid_body_server.

    :param server: the node's name, resolved like any ROS name (a relative name
        lands in the caller's namespace), e.g. ``/rigid_body_server`` or
        ``/robot1/rigid_body_server``.
    :param timeout: [s] how long to wait for a service when connecting or
        reconnecting; then :class:`NodeNotFoundError` says whether a node of
        that name runs (e.g. ``no node at /rigid_body_srever (is it running?
        rosnode list): ...``).
    :param reconnect: reconnect once and retry when a connection drops
        (False: raise at once).
    :param transport: ``'tcpros'`` (:class:`~diff_rigid_body.tcpros.ServiceConnection`: the
        request's arrays go to the socket without a copy, the answer lands in one buffer) or
        ``'rospy'`` (``rospy.ServiceProxy`` with ``numpy_msg`` both ways). Same bytes on the wire.

    ``rospy.init_node`` is not required for calls.
    """

    #: service name -> srv class: the services whose .srv declares a Python method (``service_fields``).
    SERVICES = {name: service_class for name, (service_class, declaration) in declared_services(srv).items()
                if declaration.python}

    def __init__(self, server='rigid_body_server', timeout=30.0, reconnect=True, transport='tcpros'):
        if transport not in ('tcpros', 'rospy'):
            raise ValueError("transport: 'tcpros' or 'rospy', got %r" % (transport,))
        self.server = rospy.resolve_name(server)
        self.timeout = timeout
        self.reconnect = reconnect
        self.transport = transport
        self._proxies = {}
        self._dofs = None  # body name -> d, from get_bodies when first needed

    # ------------------------------------------------------------------ plumbing
    def _proxy(self, name):
        proxy = self._proxies.get(name)
        if proxy is None:
            resolved = '%s/%s' % (self.server, name)
            try:
                rospy.wait_for_service(resolved, timeout=self.timeout)
            except rospy.ROSInterruptException:
                raise
            except rospy.ROSException:
                raise NodeNotFoundError(missing_node_message(self.server, resolved, self.timeout)) from None
            if self.transport == 'tcpros':
                proxy = ServiceConnection(resolved, self.SERVICES[name], self.timeout)
            else:
                proxy = rospy.ServiceProxy(resolved, _numpy_service(self.SERVICES[name]), persistent=True)
            self._proxies[name] = proxy
        return proxy

    def _drop(self, name):
        self._dofs = None  # the node restarted: perhaps with another scene
        proxy = self._proxies.pop(name, None)
        if proxy is not None:
            proxy.close()

    def request(self, name, **fields):
        """The request message of service ``name`` with ``fields``, its numeric arrays flat numpy
        buffers of their wire types (an array not given is empty)."""
        return wire_message(numpy_msg(self.SERVICES[name]._request_class), fields)

    def send(self, name, message):
        """Sends the request ``message`` (from :meth:`request`) to service ``name``; returns the
        response (numpy arrays) or raises :class:`DiffRigidBodyError`."""
        try:
            response = self._proxy(name).call(message)
        except (rospy.ServiceException, rospy.exceptions.TransportException, OSError):
            # The persistent connection dropped (e.g. the node restarted):
            # reconnect once and retry. A second failure propagates.
            self._drop(name)
            if not self.reconnect:
                raise
            response = self._proxy(name).call(message)
        if not response.success:
            raise DiffRigidBodyError('%s/%s' % (self.server, name), response.message)
        return response

    def call(self, name, **request):
        """Calls service ``name`` with the request fields given; returns the
        response (numpy arrays) or raises :class:`DiffRigidBodyError`."""
        return self.send(name, self.request(name, **request))

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

    # ------------------------------------------------------------------ the node's state
    def get_state(self, bodies=None):
        """dict body name -> x (d,), in the node's order (``bodies`` None = all)."""
        r = self.call('get_state', bodies=body_names(bodies))
        return collections.OrderedDict((s.name, np.asarray(s.q)) for s in r.states)

    def set_state(self, states):
        """Sets states, all or nothing. ``states``: dict name -> x (d,), or
        pairs (name, x)."""
        items = states.items() if hasattr(states, 'items') else states
        self.call('set_state', states=[BodyState(name=name, q=floats(q)) for name, q in items])
