#!/usr/bin/python3
"""~get_frame_jacobians and ~get_center_of_mass (docs/interface.md, Version 4) at node level, on the
Franka Panda (fixed base) and the default scene (free bodies), through the numpy client and a pool.

Independent oracle: the URDF forward kinematics of robot_joints_check.py (xml.etree, numpy; no
package code), get_bodies' link masses and COM offsets, and central differences of it:
(a) frame poses equal the oracle's and J (LOCAL_WORLD_ALIGNED) its central differences: linear rows
of the origin's position, angular rows vee(dR/dx R^T); (b) LOCAL and WORLD follow from it by
Pinocchio's definitions (rotate by R^T; the linear rows of the point at the world origin,
v - w x p); (c) J'x' equals the second difference of the position along x' (linear rows) and the
difference of J along x' times x' (angular rows); (d) the COM is the mass-weighted link COM of the
oracle, its Jacobian the COM's central differences, its bias the second difference; a free body's
COM is its (tx, ty, tz) and its Jacobian [0 | I3]; (e) a pool of two instances answers K
configurations with the bits of one instance; (f) a static link (the fixed frame here) is a frame with zero columns, and
refusals name what is wrong and change nothing.
"""
import sys
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body.pool import RigidBodyPool
from robot_joints_check import forward_kinematics, read_joints

WAIT = 60.0
H = 1e-6          # [rad, m] central differences of positions and rotations
H_SECOND = 1e-4   # [s] second differences along x'
rng = np.random.RandomState(29)


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def vee(S):
    return np.array([S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]]) / 2.0


class Frames(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(rospy.get_param('~server'), timeout=WAIT).connect()
        cls.scene = RigidBodyClient(rospy.get_param('~scene_server'), timeout=WAIT)
        bodies = cls.client.bodies()
        cls.body, cls.d = bodies.names[0], int(bodies.dofs[0])
        cls.links = bodies.links[0]
        cls.mass = float(bodies.masses[0])
        cls.joint_names = [j.name for j in bodies.joints[0]]
        cls.urdf_joints = read_joints(rospy.get_param('~urdf'))

    def oracle(self, x):
        """Link name -> 4x4 pose in the root link's frame (the fixed frame here)."""
        return forward_kinematics(self.urdf_joints, dict(zip(self.joint_names, x)))

    def oracle_com(self, x):
        poses = self.oracle(x)
        return sum(link.mass * (poses[link.name][:3, :3] @ link.com_offset + poses[link.name][:3, 3])
                   for link in self.links) / self.mass

    def random_x(self, K=None):
        return rng.uniform(-1.0, 1.0, (self.d,) if K is None else (K, self.d)) * 0.8

    def test_a_poses_and_jacobians_against_the_urdf_kinematics(self):
        xs = self.random_x(3)
        answer = self.client.frame_jacobians(self.body, q=xs, reference='local_world_aligned')
        self.assertEqual(answer.frames, [link.name for link in self.links])
        for k, x in enumerate(xs):
            poses = self.oracle(x)
            plus = [self.oracle(x + H * e) for e in np.eye(self.d)]
            minus = [self.oracle(x - H * e) for e in np.eye(self.d)]
            for f, name in enumerate(answer.frames):
                self.assertLess(np.abs(answer.positions[k, f] - poses[name][:3, 3]).max(), 1e-12, name)
                self.assertLess(np.abs(answer.rotations[k, f] - poses[name][:3, :3]).max(), 1e-12, name)
                linear = np.array([(p[name][:3, 3] - m[name][:3, 3]) / (2 * H) for p, m in zip(plus, minus)]).T
                angular = np.array([vee((p[name][:3, :3] - m[name][:3, :3]) / (2 * H) @ poses[name][:3, :3].T)
                                    for p, m in zip(plus, minus)]).T
                self.assertLess(np.abs(answer.J[k, f] - np.vstack([linear, angular])).max(), 1e-8, name)

    def test_b_local_and_world_follow_pinocchios_definitions(self):
        x = self.random_x()
        aligned = self.client.frame_jacobians(self.body, q=x)
        local = self.client.frame_jacobians(self.body, q=x, reference='local')
        world = self.client.frame_jacobians(self.body, q=x, reference=0)
        for f, name in enumerate(aligned.frames):
            R, p, J = aligned.rotations[f], aligned.positions[f], aligned.J[f]
            self.assertLess(np.abs(local.J[f] - np.vstack([R.T @ J[:3], R.T @ J[3:]])).max(), 1e-13, name)
            self.assertLess(np.abs(world.J[f] - np.vstack([J[:3] + skew(p) @ J[3:], J[3:]])).max(), 1e-13, name)

    def test_c_acceleration_bias_by_differences_along_the_rates(self):
        x, xd = self.random_x(), self.random_x()
        answer = self.client.frame_jacobians(self.body, q=x, qdot=xd, acceleration_bias=True)
        ahead = self.client.frame_jacobians(self.body, q=x + H_SECOND * xd)
        behind = self.client.frame_jacobians(self.body, q=x - H_SECOND * xd)
        here, after, before = self.oracle(x), self.oracle(x + H_SECOND * xd), self.oracle(x - H_SECOND * xd)
        for f, name in enumerate(answer.frames):
            linear = (after[name][:3, 3] - 2 * here[name][:3, 3] + before[name][:3, 3]) / H_SECOND ** 2
            angular = (ahead.J[f, 3:] - behind.J[f, 3:]) @ xd / (2 * H_SECOND)
            self.assertLess(np.abs(answer.bias[f] - np.concatenate([linear, angular])).max(), 1e-5, name)

    def test_d_center_of_mass_against_the_links(self):
        x, xd = self.random_x(), self.random_x()
        answer = self.client.center_of_mass(self.body, q=x[None], qdot=xd[None], jacobians=True)
        self.assertEqual(answer.bodies, [self.body])
        self.assertAlmostEqual(float(answer.masses[0]), self.mass, delta=1e-12 * self.mass)
        self.assertLess(np.abs(answer.com[0] - self.oracle_com(x)).max(), 1e-12)
        J = np.array([(self.oracle_com(x + H * e) - self.oracle_com(x - H * e)) / (2 * H) for e in np.eye(self.d)]).T
        self.assertLess(np.abs(answer.J[0] - J).max(), 1e-8)
        second = (self.oracle_com(x + H_SECOND * xd) - 2 * self.oracle_com(x) + self.oracle_com(x - H_SECOND * xd))
        self.assertLess(np.abs(answer.bias[0] - second / H_SECOND ** 2).max(), 1e-5)

    def test_d_free_bodies_com_is_their_translation(self):
        names = self.scene.bodies().names
        q = np.hstack([np.concatenate([rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)]) for _ in names])
        answer = self.scene.center_of_mass(q=q, qdot=rng.uniform(-1, 1, q.shape), jacobians=True)
        for i, name in enumerate(names):
            self.assertTrue(np.array_equal(answer.com[i], q[6 * i + 3:6 * i + 6]), name)
            self.assertTrue(np.array_equal(answer.J[i], np.hstack([np.zeros((3, 3)), np.eye(3)])), name)
            self.assertLess(np.abs(answer.bias[i]).max(), 1e-14, name)  # 0, to the rounding of w x (w x 0)

    def test_e_a_pool_answers_with_the_bits_of_one_instance(self):
        pool = RigidBodyPool(rospy.get_param('~pool'), timeout=WAIT, log=lambda text: None)
        xs, xds = self.random_x(5), self.random_x(5)
        ours = pool.frame_jacobians(self.body, q=xs, qdot=xds, acceleration_bias=True)
        one = self.client.frame_jacobians(self.body, q=xs, qdot=xds, acceleration_bias=True)
        for field in ('positions', 'rotations', 'J', 'bias', 'cos_theta'):
            self.assertTrue(np.array_equal(getattr(ours, field), getattr(one, field)), field)
        ours = pool.center_of_mass(q=xs, qdot=xds, jacobians=True)
        one = self.client.center_of_mass(q=xs, qdot=xds, jacobians=True)
        for field in ('masses', 'com', 'J', 'bias', 'cos_theta'):
            self.assertTrue(np.array_equal(getattr(ours, field), getattr(one, field)), field)

    def test_f_the_fixed_frame_is_a_frame_with_zero_columns(self):
        static = [name for name in self.urdf_links() if name not in {link.name for link in self.links}]
        self.assertEqual(static, ['panda_link0'])  # the root link: the fixed frame
        answer = self.client.frame_jacobians(self.body, q=self.random_x(), frames=static, acceleration_bias=True)
        pose = self.oracle(np.zeros(self.d))['panda_link0']
        self.assertTrue(np.array_equal(answer.positions[0], pose[:3, 3]))
        self.assertTrue(np.array_equal(answer.rotations[0], pose[:3, :3]))
        self.assertFalse(answer.J.any() or answer.bias.any())

    def test_f_frames_may_carry_the_frame_prefix_as_tf_names_them(self):
        second = RigidBodyClient('/second/rigid_body_server', timeout=WAIT)  # ~frame_prefix second/
        x = self.random_x()
        frames = ['panda_link4', 'panda_link0']
        plain = second.frame_jacobians(self.body, q=x, frames=frames, acceleration_bias=True)
        prefixed = second.frame_jacobians(self.body, q=x, frames=['second/' + f for f in frames], acceleration_bias=True)
        self.assertEqual(list(prefixed.frames), frames)
        for field in ('positions', 'rotations', 'J', 'bias'):
            self.assertTrue(np.array_equal(getattr(prefixed, field), getattr(plain, field)), field)
        with self.assertRaises(DiffRigidBodyError) as caught:  # another instance's prefix is not this one's
            second.frame_jacobians(self.body, q=x, frames=['third/panda_link4'])
        self.assertIn("unknown frame 'third/panda_link4'", caught.exception.message)

    def urdf_links(self):
        return {j['parent'] for j in self.urdf_joints.values()} | {j['child'] for j in self.urdf_joints.values()}

    def test_f_refusals_name_what_is_wrong(self):
        x = self.random_x()
        cases = [
            (dict(body=self.body, q=x, frames=['panda_link4', 'no_such_link']),
             ["frames[1]", "unknown frame 'no_such_link'", 'panda_link4']),
            (dict(body='no_such_body', q=x), ["unknown body 'no_such_body'"]),
            (dict(body=self.body, q=x[:-1]), ['q: expected a multiple of %d values' % self.d]),
            (dict(body=self.body, q=np.where(np.arange(self.d) == 2, np.nan, x)), ['q[2]: not finite (nan)']),
        ]
        for kwargs, phrases in cases:
            with self.assertRaises(DiffRigidBodyError) as caught:
                self.client.frame_jacobians(**kwargs)
            for phrase in phrases:
                self.assertIn(phrase, caught.exception.message)
        with self.assertRaises(DiffRigidBodyError) as caught:
            self.client.call('get_frame_jacobians', body=self.body, q=x, reference=3)
        self.assertIn('reference: 3', caught.exception.message)
        with self.assertRaises(DiffRigidBodyError) as caught:
            self.client.center_of_mass(['no_such_body'])
        self.assertIn("unknown body 'no_such_body'", caught.exception.message)
        self.assertEqual(len(self.client.frame_jacobians(self.body).frames), len(self.links))  # still serving


if __name__ == '__main__':
    rospy.init_node('frames_check', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'frames_check', Frames, sys.argv)
