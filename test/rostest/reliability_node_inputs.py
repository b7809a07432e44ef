#!/usr/bin/python3
"""Bad node parameters (P rows) and hostile ROS-level input (T rows) of the
catalogue in docs/robustness.md (reliability_node_inputs.test).

Each test starts the real rigid_body_server binary (reliability_node.Node)
and checks its exact message, its exit code (1 for a refused start) or that
it keeps serving, and that the catalogue row in docs/robustness.md quotes
the same message.
"""
import math
import socket
import struct
import time
import unittest

import rosgraph
import rospy
import rostest
from diff_rigid_body.msg import BodyState, BodyStateArray
from diff_rigid_body.srv import GetState, GetVertexJacobians
from reliability_node import Node, doc_row, raw_service_call, string_field

PKG = 'diff_rigid_body'


class NodeInputs(unittest.TestCase):

    def start(self, params=None, robot_description=None):
        node = Node(params, robot_description, prefix='node_inputs')
        self.addCleanup(node.stop)
        return node

    def serving(self, node):
        """Waits for `node` to serve; fails with its output if it exited."""
        if not node.wait():
            self.fail('the node exited (code %s):\n%s' % (node.process.returncode, node.stop()))

    def expect_doc(self, row, message):
        line = doc_row(row)
        self.assertTrue(line, 'docs/robustness.md has no row %s' % row)
        self.assertIn(message, line, 'docs/robustness.md row %s does not quote: %s' % (row, message))

    def expect_refused_start(self, row, message, params=None, robot_description=None):
        node = self.start(params, robot_description)
        code = node.exit_code()
        output = node.stop()
        self.assertEqual(code, 1, 'expected exit code 1, got %s. Output:\n%s' % (code, output))
        self.assertIn(message, output)
        self.expect_doc(row, message)

    def expect_serving(self, row, message, params):
        node = self.start(params)
        self.serving(node)
        self.assertTrue(node.service('get_state', GetState)(bodies=[]).success)
        output = node.stop()
        if message:
            self.assertIn(message, output)
        self.expect_doc(row, message or 'serves')

    # --- Parameters ---------------------------------------------------------

    def test_p01_geometry_unknown(self):
        self.expect_refused_start('P01', "cannot load the scene: parameter ~geometry: must be 'collision' or "
                                  "'visual', got 'visuals'", {'geometry': 'visuals'})

    def test_p02_density_not_a_number(self):
        self.expect_refused_start('P02', 'cannot load the scene: parameter ~density: must be a number [kg/m^3]',
                                  {'density': 'heavy'})

    def test_p03_density_negative(self):
        self.expect_refused_start('P03', 'cannot load the scene: parameter density: must be finite and > 0 '
                                  'kg/m^3, got -5', {'density': -5.0})

    def test_p04_bodies_not_a_list(self):
        self.expect_refused_start('P04', 'cannot load the scene: parameter ~bodies: must be a list of body names',
                                  {'bodies': 42})

    def test_p05_bodies_unknown(self):
        self.expect_refused_start('P05', "cannot load the scene: parameter bodies: unknown body 'ghost' (bodies: "
                                  "alpha, beta, gamma)", {'bodies': ['alpha', 'ghost']})

    def test_p06_fixed_frame_unknown(self):
        self.expect_refused_start('P06', "cannot load the scene: parameter fixed_frame: 'ghost' is not the root "
                                  "link 'world' or a link fixed to it", {'fixed_frame': 'ghost'})

    def test_p07_no_description(self):
        node = self.start({'urdf_path': None})
        code = node.exit_code()
        output = node.stop()
        message = "cannot load the scene: no robot description: set the parameter '%s/robot_description' or " \
                  "~urdf_path" % node.ns
        self.assertEqual(code, 1, output)
        self.assertIn(message, output)
        self.expect_doc('P07', "cannot load the scene: no robot description: set the parameter "
                        "'<ns>/robot_description' or ~urdf_path")

    def test_p08_urdf_path_missing(self):
        self.expect_refused_start('P08', "cannot load the scene: URDF file '/nonexistent/robot.urdf': no such file",
                                  {'urdf_path': '/nonexistent/robot.urdf'})

    def test_p09_robot_description_not_text(self):
        self.expect_refused_start('P09', 'cannot load the scene: parameter robot_description: must be a string '
                                  '(URDF XML)', robot_description=42)

    def test_p10_state_file_unwritable(self):
        self.expect_refused_start('P10', "cannot start: state file '/nonexistent/drb/state': cannot create a "
                                  "temporary file in '/nonexistent/drb': No such file or directory",
                                  {'state_file': '/nonexistent/drb/state'})

    def test_p11_publish_rate_negative(self):
        self.expect_serving('P11', '~publish_rate -1 Hz is out of range; using 0.1 Hz', {'publish_rate': -1.0})

    def test_p12_publish_rate_nan(self):
        self.expect_serving('P12', '~publish_rate nan Hz is out of range; using 50 Hz',
                            {'publish_rate': float('nan')})

    def test_p13_threads_zero(self):
        self.expect_serving('P13', '', {'threads': 0})

    def test_p14_floating_base_not_a_bool(self):
        self.expect_refused_start('P14', 'cannot load the scene: parameter ~floating_base: must be true or false',
                                  {'floating_base': 'yes'})

    # --- ROS transport and topics -------------------------------------------

    def raw_jacobians(self, node, request, declared_length=None):
        return raw_service_call(node.name('get_vertex_jacobians'), GetVertexJacobians._md5sum, request,
                                declared_length)

    def still_serving(self, node):
        response = node.service('get_vertex_jacobians', GetVertexJacobians)(body='alpha', vertices=[0], q=[])
        self.assertTrue(response.success, response.message)

    def test_t01_array_length_beyond_the_message(self):
        # q claims 2^24 doubles (128 MiB) but the message carries one: refused
        # by the node's bounded decoding before anything is allocated.
        node = self.start()
        self.serving(node)
        request = string_field('alpha') + struct.pack('<I', 0) + struct.pack('<I', 1 << 24) + struct.pack('<d', 0.5)
        kind, payload = self.raw_jacobians(node, request)
        self.assertEqual(kind, 'ok', payload)
        (length,) = struct.unpack('<I', payload[1:5])
        success, message = payload[0] == 1, payload[5:5 + length].decode()
        self.assertFalse(success)
        expected = "request field 'q': declares 16777216 elements, over the limit of 12582912 (refused before decoding)"
        self.assertEqual(message, expected)
        self.still_serving(node)
        self.expect_doc('T01', expected)

    def test_t02_wrong_md5sum(self):
        node = self.start()
        self.serving(node)
        kind, text = raw_service_call(node.name('get_vertex_jacobians'), '0' * 32, string_field('alpha'))
        self.assertEqual(kind, 'header-error', text)
        self.still_serving(node)
        self.assertIn('to have md5sum 00000000000000000000000000000000, but it has', text)
        self.expect_doc('T02', 'to have md5sum 00000000000000000000000000000000, but it has')

    def test_t03_truncated_request(self):
        # The length prefix promises 1000 bytes; 10 arrive, then the client disconnects.
        node = self.start()
        self.serving(node)
        uri = rosgraph.Master('/reliability_raw').lookupService(node.name('get_vertex_jacobians'))
        host, port = uri[len('rosrpc://'):].split(':')
        sock = socket.create_connection((host, int(port)), timeout=10)
        header = b''.join(struct.pack('<I', len(f)) + f for f in [
            b'callerid=/reliability_raw', ('service=' + node.name('get_vertex_jacobians')).encode(),
            ('md5sum=' + GetVertexJacobians._md5sum).encode()])
        sock.sendall(struct.pack('<I', len(header)) + header)
        time.sleep(0.2)
        sock.sendall(struct.pack('<I', 1000) + b'\x05\x00\x00\x00alpha')
        sock.close()
        time.sleep(0.5)
        self.still_serving(node)
        self.expect_doc('T03', 'serves')

    def set_states_dropped(self, row, states, fragment):
        node = self.start()
        self.serving(node)
        before = node.service('get_state', GetState)(bodies=[]).states
        publisher = rospy.Publisher(node.name('set_states'), BodyStateArray, queue_size=1, latch=True)
        deadline = time.time() + 20.0
        while publisher.get_num_connections() == 0 and time.time() < deadline:
            time.sleep(0.05)
        publisher.publish(BodyStateArray(states=states))
        deadline = time.time() + 20.0
        while fragment not in node.output() and time.time() < deadline:
            time.sleep(0.1)
        after = node.service('get_state', GetState)(bodies=[]).states
        publisher.unregister()
        output = node.stop()
        self.assertIn('set_states: message dropped: ' + fragment, output)
        self.assertEqual([(s.name, struct.pack('<6d', *s.q)) for s in after],
                         [(s.name, struct.pack('<6d', *s.q)) for s in before], 'a dropped message changed the state')
        self.expect_doc(row, 'set_states: message dropped: ' + fragment)

    def test_t04_set_states_nan(self):
        self.set_states_dropped('T04', [BodyState(name='alpha', q=[0, 0, 0, 0, 0, 0]),
                                        BodyState(name='beta', q=[0, math.nan, 0, 0, 0, 0])],
                                "states[1].q (body 'beta')[1]: not finite (nan)")

    def test_t05_set_states_unknown_body(self):
        self.set_states_dropped('T05', [BodyState(name='ghost', q=[0] * 6)],
                                "states[0].name: unknown body 'ghost' (bodies: alpha, beta, gamma)")


if __name__ == '__main__':
    rospy.init_node('reliability_node_inputs')
    rostest.rosrun(PKG, 'reliability_node_inputs', NodeInputs)
