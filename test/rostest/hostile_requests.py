#!/usr/bin/python3
"""Hostile requests over raw TCPROS (hostile_requests.test, catalogue row T06).

Every array field of every service's request gets a length prefix that
roscpp's own reader would trust: for fixed-size elements n = 2^32 / size + 1,
whose byte count uint32_t(size * n) wraps to `size` (so the message carries
just one element), and n = 2^27 for strings and messages. Without a guard in
front of roscpp, each such request of a few dozen bytes makes the node
allocate 4 GiB or more. With the node's bounded decoding each one is answered
success=false naming the field, on the same connection, and the node's peak
resident memory (VmHWM) stays under a bound.
"""
import struct
import unittest

import rospy
import rostest
from diff_rigid_body.srv import (Backprop, Echo, GetMassMatrix, GetState, GetVertexJacobians,
                                 GetVertexJacobiansCompact, SetState)
from reliability_node import Node, raw_service_call, string_field

PKG = 'diff_rigid_body'
PEAK_MEMORY_BOUND_KB = 512 * 1024   # the node serves the reliability scene in well under 100 MB
STRING_OR_MESSAGE_CLAIM = 1 << 27


def claim(element_size):
    """A length prefix whose uint32 byte count wraps to one element, and that element."""
    if element_size is None:  # strings or messages: no wrap, just a huge count
        return struct.pack('<I', STRING_OR_MESSAGE_CLAIM) + struct.pack('<I', 0)
    n = (1 << 32) // element_size + 1
    return struct.pack('<I', n) + b'\0' * element_size


def empty_array():
    return struct.pack('<I', 0)


# service -> (srv class, [(field, element size or None)], other fields' encodings in order)
# Each request is built field by field: the attacked field gets claim(), the others are empty or small.
SERVICES = {
    'set_state': (SetState, ['states'], {'states': None}),
    'get_state': (GetState, ['bodies'], {'bodies': None}),
    'get_mass_matrix': (GetMassMatrix, ['bodies', 'q', 'derivatives'], {'bodies': None, 'q': 8}),
    'get_vertex_jacobians': (GetVertexJacobians, ['body', 'vertices', 'q'], {'vertices': 4, 'q': 8}),
    'backprop': (Backprop, ['body', 'vertices', 'gradients', 'q'], {'vertices': 4, 'gradients': 8, 'q': 8}),
    'get_vertex_jacobians_compact': (GetVertexJacobiansCompact,
                                     ['body', 'vertices', 'q', 'positions_only', 'single_precision'],
                                     {'vertices': 4, 'q': 8}),
    'echo': (Echo, ['data', 'response_size'], {'data': 8}),
}
SCALARS = {'body': string_field('alpha'), 'derivatives': b'\0', 'positions_only': b'\0',
           'single_precision': b'\0', 'response_size': struct.pack('<I', 0)}


def hostile_request(fields, arrays, attacked):
    parts = []
    for field in fields:
        if field == attacked:
            parts.append(claim(arrays[field]))
        elif field in arrays:
            parts.append(empty_array())
        else:
            parts.append(SCALARS[field])
    return b''.join(parts)


def success_and_message(payload):
    (length,) = struct.unpack('<I', payload[1:5])
    return payload[0] == 1, payload[5:5 + length].decode(errors='replace')


def peak_resident_kb(pid):
    with open('/proc/%d/status' % pid) as status:
        for line in status:
            if line.startswith('VmHWM:'):
                return int(line.split()[1])
    raise AssertionError('no VmHWM for pid %d' % pid)


class HostileRequests(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.node = Node({'benchmark_services': True}, prefix='hostile_requests')
        if not cls.node.wait():
            raise AssertionError('the node did not start:\n' + cls.node.stop())

    @classmethod
    def tearDownClass(cls):
        cls.node.stop()

    def still_serving(self):
        response = self.node.service('get_state', GetState)(bodies=[])
        self.assertTrue(response.success, response.message)

    def test_every_array_field_of_every_service(self):
        for service, (kind, fields, arrays) in sorted(SERVICES.items()):
            for field in arrays:
                with self.subTest(service=service, field=field):
                    request = hostile_request(fields, arrays, field)
                    self.assertLess(len(request), 64, 'the attack is a small request')
                    outcome, payload = raw_service_call(self.node.name(service), kind._md5sum, request)
                    self.assertEqual(outcome, 'ok', '%s %s: %s' % (service, field, payload))
                    success, message = success_and_message(payload)
                    self.assertFalse(success)
                    self.assertIn("request field '%s': declares" % field, message)
                    self.assertIn('(refused before decoding)', message)
                    self.still_serving()
        peak = peak_resident_kb(self.node.process.pid)
        rospy.loginfo('hostile_requests: peak resident memory of the node %d kB', peak)
        self.assertLess(peak, PEAK_MEMORY_BOUND_KB, 'the node allocated for a hostile length prefix')

    def test_a_well_formed_request_is_still_served(self):
        response = self.node.service('get_vertex_jacobians', GetVertexJacobians)(body='alpha', vertices=[0], q=[])
        self.assertTrue(response.success, response.message)
        self.assertEqual(len(response.positions), 3)


if __name__ == '__main__':
    rospy.init_node('hostile_requests', anonymous=True)
    rostest.rosrun(PKG, 'hostile_requests', HostileRequests)
