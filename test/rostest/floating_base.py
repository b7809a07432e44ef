#!/usr/bin/python3
"""~floating_base on a humanoid without a hand-written world link and floating joint
(floating_base.test: server.launch floating_base:=true on simple_humanoid.urdf, whose root link
base_link has no parent joint).

Oracles, from the URDF XML read here (robot_joints_check.py's reader and forward kinematics):
- one body named after the root link, 6 + 29 coordinates, in the fixed frame 'world', its mass the
  sum of the URDF's masses;
- holding it still takes its total weight along tz (the gravity term's force part), at any pose;
- tf places the root link (and every other link of the URDF) where q says: t is the COM of the root link's
  merged group (the root and the links fixed to it), so the root link's origin sits at
  t - R(phi, theta, psi) c0, c0 that COM in the root link's frame.
"""
import sys
import unittest
import xml.etree.ElementTree as ET

import numpy as np
import rospy
import rostest
import tf2_ros

from diff_rigid_body.client import RigidBodyClient
from robot_joints_check import floats, forward_kinematics, homogeneous, quaternion_matrix, read_joints, rpy_matrix

PKG = 'diff_rigid_body'
WAIT = 60.0          # [s] for the node and tf (no assertion is timed)
GRAVITY = 9.81       # [m/s^2]
RELATIVE = 1e-13     # of the total weight
TF_TOLERANCE = 1e-12  # [m], and rotation matrix entries


def link_masses(path):
    """link name -> (mass [kg], COM in the link frame [m]) of every link with an <inertial>."""
    masses = {}
    for link in ET.parse(path).getroot().findall('link'):
        inertial = link.find('inertial')
        if inertial is None:
            continue
        origin = inertial.find('origin')
        com = floats(origin.get('xyz', '0 0 0')) if origin is not None else np.zeros(3)
        masses[link.get('name')] = (float(inertial.find('mass').get('value')), com)
    return masses


def root_group_com(joints, masses, root):
    """The COM of `root` and the links fixed to it (transitively), in the root link's frame."""
    group, frontier, pose = {root}, [root], {root: np.eye(4)}
    while frontier:
        parent = frontier.pop()
        for j in joints.values():
            if j['parent'] == parent and j['type'] == 'fixed':
                group.add(j['child'])
                pose[j['child']] = pose[parent] @ j['origin']
                frontier.append(j['child'])
    total = sum(masses[link][0] for link in group if link in masses)
    moment = sum(masses[link][0] * (pose[link] @ np.append(masses[link][1], 1.0))[:3]
                 for link in group if link in masses)
    return moment / total


class FloatingBase(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.urdf = rospy.get_param('~urdf')
        cls.joints = read_joints(cls.urdf)
        cls.masses = link_masses(cls.urdf)
        cls.client = RigidBodyClient(rospy.get_param('~server', '/rigid_body_server'), timeout=WAIT).connect()
        cls.bodies = cls.client.bodies()
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        children = {j['child'] for j in cls.joints.values()}
        cls.root = [link for link in cls.masses.keys() | {j['parent'] for j in cls.joints.values()}
                    if link not in children][0]
        cls.independent = [name for name, j in cls.joints.items()
                           if j['type'] in ('revolute', 'continuous', 'prismatic') and j['mimic'] is None]

    def test_a_one_body_rooted_at_the_root_link_in_world(self):
        self.assertEqual(self.root, 'base_link')
        self.assertEqual(self.bodies.fixed_frame, 'world')
        self.assertEqual(list(self.bodies.names), [self.root])
        self.assertEqual(len(self.independent), 29)
        self.assertEqual(list(self.bodies.dofs), [6 + len(self.independent)])
        self.assertEqual([j.name for j in self.bodies.joints[0]], self.independent)
        total = sum(m for m, _ in self.masses.values())
        self.assertAlmostEqual(float(self.bodies.masses[0]), total, delta=1e-12 * total)

    def test_b_holding_it_still_takes_its_total_weight_along_tz(self):
        weight = sum(m for m, _ in self.masses.values()) * GRAVITY
        rng = np.random.RandomState(27)
        d = int(self.bodies.dofs[0])
        for _ in range(3):
            q = np.concatenate([rng.uniform(-1.2, 1.2, 3), rng.uniform(-1, 1, 3), rng.uniform(-0.5, 0.5, d - 6)])
            g = self.client.inverse_dynamics(q=q[None, :]).g[0]
            self.assertAlmostEqual(g[3], 0.0, delta=RELATIVE * weight)
            self.assertAlmostEqual(g[4], 0.0, delta=RELATIVE * weight)
            self.assertAlmostEqual(g[5], weight, delta=RELATIVE * weight)

    def test_c_tf_places_the_root_link_from_its_merged_com(self):
        d = int(self.bodies.dofs[0])
        angles, t = np.array([0.3, -0.4, 1.1]), np.array([0.2, -0.1, 0.8])
        joint_values = np.linspace(-0.3, 0.3, d - 6)
        x = np.concatenate([angles, t, joint_values])
        self.client.set_state({self.root: x})
        set_at = rospy.Time.now()
        R = rpy_matrix(*angles)
        root_pose = homogeneous(R, t - R @ root_group_com(self.joints, self.masses, self.root))
        below = forward_kinematics(self.joints, dict(zip(self.independent, joint_values)))
        worst = 0.0
        links = [link.name for link in self.bodies.links[0]]
        self.assertEqual(set(links), set(self.masses) | {self.root}, 'the body has every link of the URDF')
        for link in links:
            expected = root_pose @ below.get(link, np.eye(4))
            deadline = rospy.Time.now() + rospy.Duration(WAIT)
            while True:  # the first tf stamped after set_state
                stamped = self.tf_buffer.lookup_transform('world', link, rospy.Time(0), rospy.Duration(WAIT))
                if stamped.header.stamp >= set_at or rospy.Time.now() > deadline:
                    break
                rospy.sleep(0.02)
            tr = stamped.transform
            position = np.array([tr.translation.x, tr.translation.y, tr.translation.z])
            error = max(np.abs(position - expected[:3, 3]).max(),
                        np.abs(quaternion_matrix(tr.rotation) - expected[:3, :3]).max())
            worst = max(worst, error)
            self.assertLessEqual(error, TF_TOLERANCE, 'link %s: tf %s, oracle %s' % (link, position, expected[:3, 3]))
        sys.stdout.write('tf vs oracle: max error %.3g\n' % worst)


if __name__ == '__main__':
    rospy.init_node('floating_base_check')
    rostest.rosrun(PKG, 'floating_base', FloatingBase)
