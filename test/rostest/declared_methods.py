#!/usr/bin/python3
"""The client methods that follow from a service's declaration (diff_rigid_body.client_declared),
against the real node on the Franka Panda (frames.test) and a pool of two instances.

(a) ``query(service, ...)`` of every state-free service answers with the values of its hand-written
method (which the other rostests check against oracles), in the .srv's layout, per-configuration
fields (K, -1) for K configurations; (b) a class with only ``call`` gets a method per declared
service, with the request fields as its signature, and the frame poses of its frame_jacobians equal
the test's own URDF forward kinematics (robot_joints_check.py: xml.etree and numpy); (c) through a
pool, the generated methods answer K configurations with the bits of one instance; (d) arguments:
a .srv constant by name, a request field that does not exist, a constant that does not exist and a
refusal each give a clear error.
"""
import inspect
import sys
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body import srv
from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body.client_declared import add_declared_methods, declared_core_services
from diff_rigid_body.pool import RigidBodyPool
from robot_joints_check import forward_kinematics, read_joints

WAIT = 60.0
K = 3
POSE_TOLERANCE = 1e-12  # [m] frame positions against the URDF oracle
rng = np.random.RandomState(4)


#: The generated methods' arguments (docs/interface.md, "Client argument order"), written out.
CLIENT_ORDER = {
    'get_bodies': [],
    'get_mass_matrix': ['bodies', 'q', 'derivatives'],
    'inverse_dynamics': ['bodies', 'q', 'qdot', 'qddot', 'coriolis_matrices', 'derivatives'],
    'forward_dynamics': ['bodies', 'q', 'qdot', 'tau', 'derivatives'],
    'get_vertex_jacobians': ['body', 'q', 'vertices'],
    'get_vertex_jacobians_compact': ['body', 'q', 'vertices', 'positions_only', 'single_precision'],
    'backprop': ['body', 'q', 'gradients', 'vertices'],
    'get_frame_jacobians': ['body', 'q', 'qdot', 'frames', 'reference', 'acceleration_bias'],
    'get_center_of_mass': ['bodies', 'q', 'qdot', 'jacobians'],
}


class Bare(object):
    """Only a backend's call: every method it has comes from the declarations."""

    def __init__(self, backend):
        self.call = backend.call


add_declared_methods(Bare, declared_core_services(srv))


class DeclaredMethods(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(rospy.get_param('~server'), timeout=WAIT).connect()
        bodies = cls.client.bodies()
        cls.body, cls.d = bodies.names[0], int(bodies.dofs[0])
        cls.vertices = [0, 7, int(bodies.vertex_counts[0]) - 1]
        cls.joint_names = [j.name for j in bodies.joints[0]]
        cls.q = rng.uniform(-1.0, 1.0, (K, cls.d)) * 0.8
        cls.q[:, -1] = 0.02  # a finger: prismatic [m]
        cls.qdot = rng.uniform(-1.0, 1.0, (K, cls.d))
        cls.urdf_joints = read_joints(rospy.get_param('~urdf'))

    def assert_same(self, generic, hand_written, what):
        generic, hand_written = np.asarray(generic), np.asarray(hand_written)
        self.assertEqual(generic.size, hand_written.size, what)
        self.assertTrue(np.array_equal(generic.reshape(-1), hand_written.reshape(-1)), what)

    def test_a_query_answers_as_the_hand_written_methods(self):
        c, body, q, qdot = self.client, self.body, self.q, self.qdot
        mm = c.query('get_mass_matrix', [body], q, True)
        self.assertEqual(mm.mass_matrices.shape, (K, self.d * self.d))
        hand = c.mass_matrix(body, q[:, None, :], derivatives=True)
        self.assert_same(mm.mass_matrices, hand.M, 'M')
        self.assert_same(mm.derivatives, hand.dM, 'dM')
        self.assertEqual(mm.bodies, [body])
        tau = c.query('inverse_dynamics', bodies=body, q=q, qdot=qdot, qddot=-qdot, derivatives=True)
        self.assert_same(tau.tau, c.inverse_dynamics(body, q[:, None, :], qdot[:, None, :], -qdot[:, None, :]).tau,
                         'tau')
        qddot = c.query('forward_dynamics', body, q, qdot, qdot)
        self.assert_same(qddot.qddot, c.forward_dynamics(body, q[:, None, :], qdot[:, None, :], qdot[:, None, :]).qddot,
                         'qddot')
        vj = c.query('get_vertex_jacobians', body, q, self.vertices)
        positions, J = c.vertex_jacobians(body, q, self.vertices)
        self.assert_same(vj.positions, positions, 'positions')
        self.assert_same(vj.jacobians, J, 'J')
        compact = c.query('get_vertex_jacobians_compact', body, q, self.vertices, single_precision=True)
        self.assertEqual(compact.positions.size, 0)
        self.assert_same(compact.rotation_jacobians_f32,
                         c.vertex_jacobians_compact(body, q, self.vertices, single_precision=True)[1], 'Jr float32')
        gradients = rng.normal(size=(K, len(self.vertices), 3))
        self.assert_same(c.query('backprop', body, q, gradients, self.vertices).gradient,
                         c.backprop(body, gradients, q, self.vertices), 'dL/dx')
        fj = c.query('get_frame_jacobians', body, q, qdot, ['panda_hand'], 'local', True)
        hand = c.frame_jacobians(body, q, qdot, ['panda_hand'], 'local', acceleration_bias=True)
        self.assert_same(fj.jacobians, hand.J, 'frame J')
        self.assert_same(fj.acceleration_bias, hand.bias, "J'x'")
        self.assertEqual(fj.dofs, self.d)
        com = c.query('get_center_of_mass', body, q, qdot, True)
        hand = c.center_of_mass(body, q[:, None, :], qdot[:, None, :], jacobians=True)
        self.assert_same(com.com, hand.com, 'COM')
        self.assert_same(com.jacobians, hand.J, 'dc/dx')
        described = c.query('get_bodies')
        self.assertEqual(described.names, c.bodies().names)
        self.assert_same(described.link_masses, [link.mass for link in c.bodies().links[0]], 'link masses')

    def test_b_a_bare_class_gets_every_method_and_its_poses_are_the_urdf_kinematics(self):
        bare = Bare(self.client)
        self.assertEqual(set(declared_core_services(srv)), set(CLIENT_ORDER))
        for name, service in declared_core_services(srv).items():
            method = getattr(bare, service.method)
            self.assertEqual(list(inspect.signature(method).parameters), CLIENT_ORDER[name], name)
        answer = bare.frame_jacobians(self.body, self.q)  # frames None: every link of the body
        poses = answer.poses.reshape(K, len(answer.frames), 12)
        for k in range(K):
            oracle = forward_kinematics(self.urdf_joints, dict(zip(self.joint_names, self.q[k])))
            for f, frame in enumerate(answer.frames):
                np.testing.assert_allclose(poses[k, f, :3], oracle[frame][:3, 3], rtol=0, atol=POSE_TOLERANCE,
                                           err_msg='%s, configuration %d' % (frame, k))
                np.testing.assert_allclose(poses[k, f, 3:].reshape(3, 3), oracle[frame][:3, :3], rtol=0,
                                           atol=POSE_TOLERANCE, err_msg='%s, configuration %d' % (frame, k))

    def test_c_through_a_pool_the_bits_of_one_instance(self):
        pool = RigidBodyPool(rospy.get_param('~pool'), timeout=WAIT)
        q = rng.uniform(-1.0, 1.0, (8, self.d))
        for service, args in (('get_vertex_jacobians_compact', (self.body, q, self.vertices)),
                              ('get_frame_jacobians', (self.body, q, q, ['panda_link4', 'panda_hand'], 2, True))):
            shared, one = pool.query(service, *args), self.client.query(service, *args)
            for field, value in zip(one._fields, one):
                if isinstance(value, np.ndarray):
                    self.assertEqual(shared._asdict()[field].tobytes(), value.tobytes(), '%s %s' % (service, field))

    def test_d_arguments_and_refusals_are_named(self):
        c = self.client
        by_name = c.query('get_frame_jacobians', self.body, self.q[0], frames=['panda_hand'], reference='world')
        by_value = c.query('get_frame_jacobians', self.body, self.q[0], frames=['panda_hand'], reference=0)
        self.assertEqual(by_name.jacobians.tobytes(), by_value.jacobians.tobytes())
        with self.assertRaisesRegex(TypeError, r'get_mass_matrix: .*frames.*bodies, q, derivatives'):
            c.query('get_mass_matrix', frames=['panda_hand'])
        with self.assertRaisesRegex(ValueError, r"reference: one of local, local_world_aligned, world, got 'up'"):
            c.query('get_frame_jacobians', self.body, reference='up')
        with self.assertRaisesRegex(ValueError, r'get_frame_jacobians: reference: 1.5 is not a uint8'):
            c.query('get_frame_jacobians', self.body, self.q[0], reference=1.5)
        with self.assertRaisesRegex(ValueError, r'get_frame_jacobians: reference: \[1\] is not a uint8'):
            c.query('get_frame_jacobians', self.body, self.q[0], reference=[1])
        for empty in (np.zeros((0, len(self.q[0]))), np.zeros((3, 0))):
            with self.assertRaisesRegex(ValueError, r'get_mass_matrix: q: at least one configuration'):
                c.query('get_mass_matrix', self.body, empty)
        with self.assertRaisesRegex(ValueError, r"'get_state' is not a state-free service"):
            c.query('get_state')
        with self.assertRaisesRegex(DiffRigidBodyError, r"unknown frame 'no_such_link'"):
            Bare(c).frame_jacobians(self.body, frames=['no_such_link'])


if __name__ == '__main__':
    rospy.init_node('declared_methods', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'declared_methods', DeclaredMethods, sys.argv)
