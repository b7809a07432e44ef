#!/usr/bin/python3
"""The Python client's buffer path (numpy_requests.test, default scene).

Both directions of every service move numpy buffers, never Python lists:
  * a request's numeric arrays are flat numpy arrays of their wire type that share memory with the
    caller's array when it already has that type (no element-by-element conversion);
  * the bytes a request puts on the wire equal genpy's own serialisation of the same values given
    as Python lists (the reference: genpy's list path, independent of numpy), for every service,
    through both serialisers the client has (tcpros.ServiceConnection's and rospy.numpy_msg's);
  * the node's answers through the client's transports ('tcpros', 'rospy') equal, bit for bit,
    those of a plain rospy.ServiceProxy fed Python lists.
"""
import io
import sys
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.msg import BodyState
from diff_rigid_body.tcpros import _Chunks

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'
K = 50
Q = np.array([[0.3 + 0.01 * k, -0.4, 1.1, 0.05, -0.1, 0.6 + 1e-3 * k] for k in range(K)])  # knot, (K, 6)
VERTICES = np.array([0, 17, 4095, 17, 2000], dtype=np.uint32)
GRADIENTS = np.sin(np.arange(K * len(VERTICES) * 3) * 0.7).reshape(K, len(VERTICES), 3)


def requests():
    """(service, request fields) covering every numeric array field of every request."""
    both = np.concatenate([Q, Q[:, ::-1]], axis=1)  # knot then rock: (K, 12)
    return [
        ('backprop', dict(body='knot', vertices=VERTICES, gradients=GRADIENTS, q=Q)),
        ('get_vertex_jacobians', dict(body='knot', vertices=VERTICES, q=Q)),
        ('get_vertex_jacobians_compact', dict(body='rock', vertices=VERTICES[:2], q=Q, single_precision=True)),
        ('get_mass_matrix', dict(bodies=['knot', 'rock'], q=both, derivatives=True)),
        ('inverse_dynamics', dict(q=both, qdot=0.5 * both, qddot=-both, coriolis_matrices=True, derivatives=True)),
        ('forward_dynamics', dict(q=both, qdot=0.5 * both, tau=2.0 * both, derivatives=True)),
        ('set_state', dict(states=[BodyState(name='knot', q=Q[0])])),
        ('get_state', dict(bodies=['knot'])),
    ]


def as_lists(fields):
    """The same fields with every array a Python list (genpy's ordinary path)."""
    out = {}
    for name, value in fields.items():
        if isinstance(value, np.ndarray):
            out[name] = value.ravel().tolist()
        elif name == 'states':
            out[name] = [BodyState(name=s.name, q=np.asarray(s.q).ravel().tolist()) for s in value]
        else:
            out[name] = value
    return out


def serialized(message, numpy_path):
    buffer = io.BytesIO()
    if numpy_path:
        message.serialize_numpy(buffer, np)
    else:
        message.serialize(buffer)
    return buffer.getvalue()


def same_bits(a, b):
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


class NumpyRequests(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.wait_for_service(SERVER + '/get_bodies', timeout=60.0)
        cls.clients = {transport: RigidBodyClient(SERVER, transport=transport) for transport in ('tcpros', 'rospy')}

    def test_request_arrays_are_numpy_buffers_sharing_the_callers_memory(self):
        client = self.clients['tcpros']
        message = client.request('backprop', body='knot', vertices=VERTICES, gradients=GRADIENTS, q=Q)
        for field, source in (('gradients', GRADIENTS), ('q', Q), ('vertices', VERTICES)):
            value = getattr(message, field)
            self.assertIsInstance(value, np.ndarray, field)
            self.assertEqual(value.ndim, 1, field)
            self.assertTrue(np.shares_memory(value, source), '%s was copied element by element' % field)
        self.assertEqual(message.q.dtype, np.dtype('<f8'))
        self.assertEqual(message.vertices.dtype, np.dtype('<u4'))

    def test_wire_bytes_equal_genpys_list_serialisation(self):
        client = self.clients['tcpros']
        for name, fields in requests():
            plain = client.SERVICES[name]._request_class(**as_lists(fields))
            expected = serialized(plain, numpy_path=False)
            message = client.request(name, **fields)
            self.assertEqual(serialized(message, numpy_path=True), expected, '%s: rospy.numpy_msg bytes' % name)
            chunks = _Chunks()
            message.serialize_numpy(chunks, np)
            self.assertEqual(b''.join(bytes(piece) for piece in chunks.finish()), expected,
                             '%s: tcpros.ServiceConnection bytes' % name)
            self.assertEqual(chunks.size, len(expected), '%s: announced length' % name)

    def test_answers_equal_a_plain_service_proxy_bit_for_bit(self):
        for name, fields in requests():
            if name == 'set_state':
                continue
            service = self.clients['tcpros'].SERVICES[name]
            reference = rospy.ServiceProxy('%s/%s' % (SERVER, name), service)(
                service._request_class(**as_lists(fields)))
            self.assertTrue(reference.success, '%s: %s' % (name, reference.message))
            for transport, client in self.clients.items():
                answer = client.call(name, **fields)
                for slot, slot_type in zip(answer.__slots__, answer._slot_types):
                    if slot_type in ('float64[]', 'float32[]', 'uint32[]'):
                        expected = np.asarray(getattr(reference, slot), dtype=np.dtype(slot_type[:-2]))
                        self.assertTrue(same_bits(np.asarray(getattr(answer, slot)), expected),
                                        '%s.%s through %s' % (name, slot, transport))
                    elif slot == 'states':
                        self.assertTrue(all(same_bits(np.asarray(a.q), np.asarray(b.q, dtype=np.float64))
                                            for a, b in zip(answer.states, reference.states)), name)
                    else:
                        self.assertEqual(getattr(answer, slot), getattr(reference, slot), '%s.%s' % (name, slot))

    def test_set_state_takes_numpy_states(self):
        client = self.clients['tcpros']
        before = client.get_state(['knot'])['knot'].copy()
        try:
            client.set_state({'knot': Q[3]})
            self.assertTrue(same_bits(client.get_state(['knot'])['knot'], Q[3]))
        finally:
            client.set_state({'knot': before})


if __name__ == '__main__':
    rostest.rosrun(PKG, 'numpy_requests', NumpyRequests, sys.argv)
