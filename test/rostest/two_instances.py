#!/usr/bin/python3
"""Two instances of the default scene in one graph (two_instances.test).

The instances run in the namespaces a and b with ~frame_prefix "a/" and
"b/". Each must answer its own get_bodies with a prefixed fixed frame; every
frame on tf must carry one of the two prefixes; set_state on a's knot must
move a/knot and a/rock in tf and leave b's bodies where they were.

Oracles: the fixed frame is the prefix plus the URDF root link (parsed here
from each namespace's robot_description); a body's link frame in the fixed
frame is R = Rz(psi) Ry(theta) Rx(phi) and origin t - R c, with q = (phi,
theta, psi, t) from get_state and c the COM offset from get_bodies.
"""
import sys
import time
import unittest
import xml.etree.ElementTree as ET

import numpy as np
import rospy
import rostest
import tf2_ros
import yaml
from diff_rigid_body.msg import BodyState, BodyStateArray
from diff_rigid_body.srv import GetBodies, GetState, SetState

PKG = 'diff_rigid_body'
INSTANCES = {'a': 'a/', 'b': 'b/'}  # namespace -> frame prefix (two_instances.test)
WAIT = 60.0  # [s] longest wait for a service, a tf frame or a message
TOLERANCE = 1e-9  # [m] and [1] (rotation matrix entries): tf carries the doubles the node computed
Q_MOVED = {'knot': [0.2, -0.3, 1.0, 0.1, 0.2, 0.7], 'rock': [-0.5, 0.4, 2.0, 0.3, -0.2, 0.9]}  # a's bodies go here


def rpy_matrix(phi, theta, psi):
    """R = Rz(psi) Ry(theta) Rx(phi)."""
    cx, sx, cy, sy, cz, sz = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz.dot(Ry).dot(Rx)


def quaternion_matrix(x, y, z, w):
    """Rotation matrix of a unit quaternion (x, y, z, w)."""
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def link_pose(q, com_offset):
    """(R, origin) of the body's link frame in the fixed frame."""
    R = rpy_matrix(*q[:3])
    return R, np.asarray(q[3:6]) - R.dot(com_offset)


def urdf_root(namespace):
    """The URDF root link: the one link that is no joint's child."""
    robot = ET.fromstring(rospy.get_param('/%s/robot_description' % namespace))
    children = {joint.find('child').get('link') for joint in robot.findall('joint')}
    roots = [link.get('name') for link in robot.findall('link') if link.get('name') not in children]
    assert len(roots) == 1, 'robot_description of %s: roots %s' % (namespace, roots)
    return roots[0]


def service(namespace, name, service_class):
    full = '/%s/rigid_body_server/%s' % (namespace, name)
    rospy.wait_for_service(full, timeout=WAIT)
    return rospy.ServiceProxy(full, service_class)


class TwoInstances(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        rospy.init_node('two_instances')
        cls.tf = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.tf)
        cls.bodies = {ns: service(ns, 'get_bodies', GetBodies)() for ns in INSTANCES}
        cls.fixed = {ns: INSTANCES[ns] + urdf_root(ns) for ns in INSTANCES}

    def link_in_tf(self, namespace, body):
        """(R, origin) of prefix+body in prefix+fixed frame, the latest on tf."""
        t = self.tf.lookup_transform(self.fixed[namespace], INSTANCES[namespace] + body, rospy.Time(0),
                                     rospy.Duration(WAIT)).transform
        r = t.rotation
        return quaternion_matrix(r.x, r.y, r.z, r.w), np.array([t.translation.x, t.translation.y, t.translation.z])

    def com_offset(self, namespace, body):
        bodies = self.bodies[namespace]
        i = list(bodies.names).index(body)
        return np.asarray(bodies.com_offsets[3 * i:3 * i + 3])

    def state(self, namespace, body):
        response = service(namespace, 'get_state', GetState)(bodies=[body])
        self.assertTrue(response.success, '%s get_state: %s' % (namespace, response.message))
        return np.asarray(response.states[0].q)

    def assertPose(self, actual, expected, what):
        R, origin = actual
        R_expected, origin_expected = expected
        self.assertLess(np.max(np.abs(origin - origin_expected)), TOLERANCE,
                        '%s: origin %s, expected %s' % (what, origin, origin_expected))
        self.assertLess(np.max(np.abs(R - R_expected)), TOLERANCE, '%s: R %s, expected %s' % (what, R, R_expected))

    def test_each_instance_answers_get_bodies_with_its_prefixed_frame(self):
        for ns, bodies in self.bodies.items():
            self.assertTrue(bodies.success, '%s get_bodies: %s' % (ns, bodies.message))
            self.assertEqual(bodies.fixed_frame, self.fixed[ns], '%s get_bodies fixed_frame' % ns)
            self.assertEqual(list(bodies.names), ['knot', 'rock'], '%s get_bodies names' % ns)

    def test_tf_carries_both_prefixed_trees_and_no_bare_frame(self):
        for ns in INSTANCES:
            for body in ('knot', 'rock', 'table'):  # table: fixed to the root, on /tf_static
                self.assertTrue(
                    self.tf.can_transform(self.fixed[ns], INSTANCES[ns] + body, rospy.Time(0), rospy.Duration(WAIT)),
                    'tf: no transform %s -> %s%s' % (self.fixed[ns], INSTANCES[ns], body))
        frames = yaml.safe_load(self.tf.all_frames_as_yaml()) or {}
        named = set(frames) | {info['parent'] for info in frames.values()}
        bare = sorted(f for f in named if not f.startswith(tuple(INSTANCES.values())))
        self.assertEqual(bare, [], 'tf frames without an instance prefix: %s' % bare)

    def test_states_header_carries_the_prefixed_frame(self):
        for ns in INSTANCES:
            message = rospy.wait_for_message('/%s/rigid_body_server/states' % ns, BodyStateArray, timeout=WAIT)
            self.assertEqual(message.header.frame_id, self.fixed[ns], '%s ~states header.frame_id' % ns)

    def test_set_state_on_a_moves_a_bodies_only(self):
        # The knot's COM is its link origin; the rock's is not (c != 0 tests t - R c).
        q_b = {body: self.state('b', body) for body in Q_MOVED}
        b_before = {body: self.link_in_tf('b', body) for body in Q_MOVED}
        for body, q in Q_MOVED.items():
            self.assertPose(b_before[body], link_pose(q_b[body], self.com_offset('b', body)),
                            'b/%s in tf before, vs b get_state' % body)
            self.assertGreater(np.max(np.abs(self.link_in_tf('a', body)[1] - link_pose(q, np.zeros(3))[1])), 0.01,
                               'a/%s already sits near the pose this test sets' % body)

        request = [BodyState(name=body, q=q) for body, q in Q_MOVED.items()]
        response = service('a', 'set_state', SetState)(states=request)
        self.assertTrue(response.success, 'a set_state: %s' % response.message)
        for body, q in Q_MOVED.items():
            self.assertEqual(list(self.state('a', body)), q, 'a get_state of %s after set_state' % body)

        for body, q in Q_MOVED.items():
            # Wait (bounded) for tf to carry the new pose: it follows the state at the publish rate.
            expected = link_pose(q, self.com_offset('a', body))
            deadline = time.monotonic() + WAIT
            a_after = self.link_in_tf('a', body)
            while np.max(np.abs(a_after[1] - expected[1])) > TOLERANCE and time.monotonic() < deadline:
                rospy.sleep(0.05)
                a_after = self.link_in_tf('a', body)
            self.assertPose(a_after, expected, 'a/%s in tf after set_state on a' % body)

        for body in Q_MOVED:
            self.assertEqual(list(self.state('b', body)), list(q_b[body]), 'b get_state of %s after set_state on a'
                             % body)
            self.assertPose(self.link_in_tf('b', body), b_before[body],
                            'b/%s in tf after set_state on a, vs before' % body)

if __name__ == '__main__':
    rostest.rosrun(PKG, 'two_instances', TwoInstances, sys.argv)
