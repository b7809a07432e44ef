#!/usr/bin/python3
"""Articulated bodies at node level: the Panda (fixed base, one body, 9 moving links) driven through
joint_states, and the UR5's mass matrix (docs/interface.md, "Version 2").

Independent oracle: forward kinematics written here from the URDF XML (xml.etree, numpy): a
link's pose is parent pose * joint origin (xyz, rpy: R = Rz(y) Ry(p) Rx(r)) * joint motion
(revolute/continuous: rotation by the joint value about the unit axis, Rodrigues; prismatic:
translation along the axis; mimic: multiplier * master + offset). No package code is used for it.

Private parameters:
  ~urdf          the Panda URDF the node under ~server was given
  ~server        (default /rigid_body_server)
  ~ur5_server    a node serving the UR5 (default /ur5/rigid_body_server)

Checks: (a) after a JointState on joint_states, every link's tf equals the oracle within 1e-9;
(b) get_state returns those joint values bit for bit; (c) J = dp/dx matches central differences
of positions at x +- h within 1e-6 (relative to max |J|); (d) backprop = J^T g; (e) the UR5's
M(x) is symmetric positive definite at its home poses; (f) an unknown joint name is ignored and
logged once, and a message with a NaN position changes nothing; (g) joint_states, set_state and
~set_states that put a joint outside its URDF <limit> are accepted and warned about once per joint.
"""
import math
import sys
import threading
import unittest
import xml.etree.ElementTree as ET

import numpy as np
import rospy
import rostest
import tf2_ros
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import JointState

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.msg import BodyState, BodyStateArray

PKG = 'diff_rigid_body'
TF_TOLERANCE = 1e-9  # [m], and on rotation matrix entries
FD_STEP = 1e-6       # [rad or m]
FD_TOLERANCE = 1e-6  # relative to max |J|
WAIT = 30.0          # [s] for the node to take a message (no assertion is timed)


def floats(text):
    return np.array([float(v) for v in text.split()])


def rpy_matrix(r, p, y):
    """R = Rz(y) Ry(p) Rx(r)."""
    Rx = np.array([[1, 0, 0], [0, math.cos(r), -math.sin(r)], [0, math.sin(r), math.cos(r)]])
    Ry = np.array([[math.cos(p), 0, math.sin(p)], [0, 1, 0], [-math.sin(p), 0, math.cos(p)]])
    Rz = np.array([[math.cos(y), -math.sin(y), 0], [math.sin(y), math.cos(y), 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def axis_angle(axis, angle):
    """Rodrigues: I + sin(a) K + (1 - cos(a)) K^2, K = [u]x."""
    u = axis / np.linalg.norm(axis)
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def homogeneous(R, t):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def read_joints(path):
    """URDF joints: name -> dict(type, parent, child, origin (4x4), axis, mimic (master, mult, offset))."""
    joints = {}
    for j in ET.parse(path).getroot().findall('joint'):
        origin = j.find('origin')
        xyz = floats(origin.get('xyz', '0 0 0')) if origin is not None else np.zeros(3)
        rpy = floats(origin.get('rpy', '0 0 0')) if origin is not None else np.zeros(3)
        axis = j.find('axis')
        mimic = j.find('mimic')
        joints[j.get('name')] = {
            'type': j.get('type'), 'parent': j.find('parent').get('link'), 'child': j.find('child').get('link'),
            'origin': homogeneous(rpy_matrix(*rpy), xyz),
            'axis': floats(axis.get('xyz')) if axis is not None else np.array([1.0, 0, 0]),
            'mimic': None if mimic is None else (mimic.get('joint'), float(mimic.get('multiplier', '1')),
                                                 float(mimic.get('offset', '0')))}
    return joints


def forward_kinematics(joints, values):
    """Pose (4x4) of every link in the root link's frame, with joint values {name: value}."""
    by_child = {j['child']: name for name, j in joints.items()}
    poses = {}

    def pose(link):
        if link not in poses:
            if link not in by_child:
                poses[link] = np.eye(4)  # the root
            else:
                j = joints[by_child[link]]
                s = 0.0
                if j['mimic'] is not None:
                    master, multiplier, offset = j['mimic']
                    s = multiplier * values.get(master, 0.0) + offset
                elif j['type'] in ('revolute', 'continuous', 'prismatic'):
                    s = values.get(by_child[link], 0.0)
                motion = np.eye(4)
                if j['type'] in ('revolute', 'continuous'):
                    motion[:3, :3] = axis_angle(j['axis'], s)
                elif j['type'] == 'prismatic':
                    motion[:3, 3] = s * j['axis'] / np.linalg.norm(j['axis'])
                poses[link] = pose(j['parent']) @ j['origin'] @ motion
        return poses[link]

    for j in joints.values():
        pose(j['child'])
    return poses


def quaternion_matrix(q):
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


class RosoutRecorder(object):
    """Messages of one node on /rosout."""

    def __init__(self):
        self.lines, self.lock = [], threading.Lock()
        self.subscriber = rospy.Subscriber('/rosout', Log, self.on_log, queue_size=1000)

    def on_log(self, log):
        with self.lock:
            self.lines.append(log.msg)

    def count(self, text):
        with self.lock:
            return sum(text in line for line in self.lines)


class RobotJoints(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.urdf = rospy.get_param('~urdf')
        cls.joints = read_joints(cls.urdf)
        cls.client = RigidBodyClient(rospy.get_param('~server', '/rigid_body_server'), timeout=100.0).connect()
        cls.ur5 = RigidBodyClient(rospy.get_param('~ur5_server', '/ur5/rigid_body_server'), timeout=100.0)
        cls.bodies = cls.client.bodies()
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        cls.rosout = RosoutRecorder()
        cls.publisher = rospy.Publisher('joint_states', JointState, queue_size=100)
        deadline = rospy.Time.now() + rospy.Duration(WAIT)
        while cls.publisher.get_num_connections() == 0 and rospy.Time.now() < deadline:
            rospy.sleep(0.05)
        cls.body = cls.bodies.names[0]
        cls.names = [j.name for j in cls.bodies.joints[0]]
        # A configuration away from 0 inside every limit: 30% .. 65% of the way from lower to upper.
        cls.x = np.array([j.lower + (0.3 + 0.05 * k) * (j.upper - j.lower)
                          for k, j in enumerate(cls.bodies.joints[0])])

    def publish(self, names, positions):
        self.publisher.publish(JointState(name=list(names), position=list(positions)))

    def wait_for_state(self, expected, what):
        """Waits until get_state returns ``expected`` for the body (bit for bit); True if it did."""
        deadline = rospy.Time.now() + rospy.Duration(WAIT)
        while rospy.Time.now() < deadline:
            if np.array_equal(self.client.get_state([self.body])[self.body], expected):
                return True
            rospy.sleep(0.02)
        self.fail('%s: get_state never returned %s (last %s)' % (what, expected,
                                                                  self.client.get_state([self.body])[self.body]))

    def test_a_one_body_with_nine_moving_links(self):
        self.assertEqual(len(self.bodies.names), 1, 'Panda: bodies %s, expected one' % self.bodies.names)
        moving = {j['child'] for j in self.joints.values() if j['type'] in ('revolute', 'continuous', 'prismatic')}
        self.assertEqual(len(moving), 9, 'Panda URDF: %d moving links' % len(moving))
        served = {link.name for link in self.bodies.links[0]}
        self.assertLessEqual(moving, served, 'Panda: moving links not served: %s' % (moving - served))
        independent = [n for n, j in self.joints.items()
                       if j['type'] in ('revolute', 'continuous', 'prismatic') and j['mimic'] is None]
        self.assertEqual(self.names, independent, 'Panda: x joints in URDF order')
        self.assertEqual(int(self.bodies.dofs[0]), len(independent), 'Panda: dofs')
        self.assertAlmostEqual(float(self.bodies.masses[0]), sum(link.mass for link in self.bodies.links[0]),
                               delta=1e-12, msg='Panda: body mass is the sum of its links')

    def test_b_joint_states_move_tf_and_state(self):
        order = np.argsort(self.names)[::-1]  # names in another order than x: matched by name
        self.publish([self.names[k] for k in order], self.x[order])
        self.wait_for_state(self.x, 'joint_states')  # (b), bit for bit
        published_after = rospy.Time.now()
        oracle = forward_kinematics(self.joints, dict(zip(self.names, self.x)))
        worst = [0.0, 0.0]
        for link in self.bodies.links[0]:
            deadline = rospy.Time.now() + rospy.Duration(WAIT)
            while True:  # the first tf message stamped after the state was seen
                stamped = self.tf_buffer.lookup_transform(self.bodies.fixed_frame, link.name, rospy.Time(0),
                                                          rospy.Duration(WAIT))
                if stamped.header.stamp >= published_after or rospy.Time.now() > deadline:
                    break
                rospy.sleep(0.02)
            t = stamped.transform
            position = np.array([t.translation.x, t.translation.y, t.translation.z])
            expected = oracle[link.name]
            error = [np.abs(position - expected[:3, 3]).max(),
                     np.abs(quaternion_matrix(t.rotation) - expected[:3, :3]).max()]
            worst = np.maximum(worst, error)
            self.assertLessEqual(max(error), TF_TOLERANCE, 'Panda link %s at x = %s: tf %s, oracle %s (errors %s)'
                                 % (link.name, self.x, position, expected[:3, 3], error))
        sys.stdout.write('tf vs oracle: max %.3g m, %.3g (rotation entries)\n' % tuple(worst))

    def test_c_jacobians_match_central_differences(self):
        count = int(self.bodies.vertex_counts[0])
        vertices = list(range(0, count, 7))
        p, J = self.client.vertex_jacobians(self.body, q=self.x, vertices=vertices)
        d = len(self.x)
        self.assertEqual(J.shape, (len(vertices), 3, d), 'Panda: J shape')
        steps = np.vstack([self.x + FD_STEP * e for e in np.eye(d)] + [self.x - FD_STEP * e for e in np.eye(d)])
        moved = self.client.positions(self.body, q=steps, vertices=vertices)  # (2d, N, 3), one call
        fd = np.stack([(moved[j] - moved[d + j]) / (2 * FD_STEP) for j in range(d)], axis=-1)  # (N, 3, d)
        error = np.abs(fd - J).max() / np.abs(J).max()
        sys.stdout.write('J vs central differences (h = %g): max relative error %.3g\n' % (FD_STEP, error))
        self.assertLessEqual(error, FD_TOLERANCE, 'Panda J at x = %s: central differences differ by %.3g (rel.)'
                             % (self.x, error))
        self.assertTrue(np.array_equal(p, self.client.positions(self.body, q=self.x, vertices=vertices)))

    def test_d_backprop_is_J_transpose_g(self):
        rng = np.random.default_rng(12)
        vertices = list(range(0, int(self.bodies.vertex_counts[0]), 3))
        g = rng.standard_normal((len(vertices), 3))
        _, J = self.client.vertex_jacobians(self.body, q=self.x, vertices=vertices)
        expected = np.einsum('nij,ni->j', J, g)
        got = self.client.backprop(self.body, g, q=self.x, vertices=vertices)
        self.assertEqual(got.shape, (len(self.x),), 'backprop shape')
        error = np.abs(got - expected).max() / np.abs(expected).max()
        sys.stdout.write('backprop vs J^T g: max relative difference %.3g\n' % error)
        self.assertLessEqual(error, 1e-12, 'backprop %s, J^T g %s' % (got, expected))

    def test_e_ur5_mass_matrix_is_spd(self):
        name = self.ur5.bodies().names[0]
        d = self.ur5.dofs(name)
        for pose in (np.zeros(d), np.array([0.0, -math.pi / 2, 0.0, -math.pi / 2, 0.0, 0.0])):
            M = self.ur5.mass_matrix([name], q=pose).M[0]
            self.assertEqual(M.shape, (d, d), 'UR5 M shape')
            asymmetry = np.abs(M - M.T).max() / np.abs(M).max()
            eigenvalues = np.linalg.eigvalsh(0.5 * (M + M.T))
            sys.stdout.write('UR5 at %s: asymmetry %.3g, eigenvalues %s\n' % (pose, asymmetry, eigenvalues))
            self.assertLessEqual(asymmetry, 1e-14, 'UR5 M(%s) is not symmetric' % pose)
            self.assertGreater(eigenvalues.min(), 1e-9 * eigenvalues.max(), 'UR5 M(%s) is not positive definite'
                               % pose)

    def test_f_unknown_names_and_nan(self):
        base = self.client.get_state([self.body])[self.body].copy()
        first = base.copy()
        first[0] += 0.125
        self.publish([self.names[0], 'no_such_joint'], [first[0], 1.0])
        self.wait_for_state(first, 'a message with an unknown name')
        second = first.copy()
        second[0] += 0.125
        self.publish(['no_such_joint', self.names[0]], [2.0, second[0]])
        self.wait_for_state(second, 'a second message with an unknown name')
        # NaN: dropped whole (the valid joint in it too); the next message shows it was taken in order.
        self.publish([self.names[1], self.names[2]], [float('nan'), second[2] + 0.25])
        third = second.copy()
        third[3] += 0.0625
        self.publish([self.names[3]], [third[3]])
        self.wait_for_state(third, 'the message after a NaN message')
        deadline = rospy.Time.now() + rospy.Duration(WAIT)
        while (self.rosout.count("'no_such_joint'") < 1 or self.rosout.count(self.names[1]) < 1) \
                and rospy.Time.now() < deadline:
            rospy.sleep(0.05)
        self.assertEqual(self.rosout.count("'no_such_joint'"), 1, 'the unknown joint is not logged exactly once')
        self.assertGreaterEqual(self.rosout.count("joint '%s'" % self.names[1]), 1,
                                'the NaN message was dropped without a warning naming %s' % self.names[1])

    def test_g_joints_outside_their_limits_are_accepted_and_warned_once(self):
        """joint_states, set_state and ~set_states may put a joint outside its URDF <limit>: the state
        is accepted, and the node warns once per joint, naming the joint, the value and the limits
        (read here from the URDF's <limit> attributes, as written)."""
        limits = {j.get('name'): (j.find('limit').get('lower'), j.find('limit').get('upper'))
                  for j in ET.parse(self.urdf).getroot().findall('joint') if j.find('limit') is not None}
        setter = rospy.Publisher('/rigid_body_server/set_states', BodyStateArray, queue_size=10)
        x = self.client.get_state([self.body])[self.body].copy()
        cases = [('panda_joint1', 3.5, lambda x: self.publish(['panda_joint1'], [x[0]])),
                 ('panda_joint4', 0.5, lambda x: self.client.set_state({self.body: x})),
                 ('panda_joint6', -1.25, lambda x: setter.publish(states=[BodyState(name=self.body, q=list(x))]))]
        deadline = rospy.Time.now() + rospy.Duration(WAIT)
        while setter.get_num_connections() == 0 and rospy.Time.now() < deadline:
            rospy.sleep(0.05)
        for name, value, send in cases:
            x[self.names.index(name)] = value
            send(x)
            self.wait_for_state(x, '%s = %g, outside its limits' % (name, value))
            lower, upper = limits[name]
            expected = "joint '%s' of body '%s' at %g is outside its URDF limits [%s, %s]" % (
                name, self.body, value, lower, upper)
            deadline = rospy.Time.now() + rospy.Duration(WAIT)
            while self.rosout.count(expected) < 1 and rospy.Time.now() < deadline:
                rospy.sleep(0.05)
            self.assertEqual(self.rosout.count(expected), 1, 'no warning %r' % expected)
        # Again beyond the same limit: accepted, no second warning (the next joint's warning, which the
        # node logs after it, shows that the node has handled it).
        x[0] = 3.75
        self.publish(['panda_joint1'], [x[0]])
        self.wait_for_state(x, 'panda_joint1 = 3.75')
        x[self.names.index('panda_joint2')] = 2.5
        self.client.set_state({self.body: x})
        deadline = rospy.Time.now() + rospy.Duration(WAIT)
        while self.rosout.count("joint 'panda_joint2' of body") < 1 and rospy.Time.now() < deadline:
            rospy.sleep(0.05)
        self.assertEqual(self.rosout.count("joint 'panda_joint1' of body"), 1, 'panda_joint1 warned twice')
        self.assertEqual(self.rosout.count("joint 'panda_joint2' of body"), 1)


if __name__ == '__main__':
    rospy.init_node('robot_joints_check')
    rostest.rosrun(PKG, 'robot_joints_check', RobotJoints)
