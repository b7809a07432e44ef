#!/usr/bin/python3
"""What the Python clients make of ambiguous or wrong arguments (client_inputs.test: the default
scene at /rigid_body_server and in the namespaces /pool1 and /pool2).

- A string where a list of bodies is expected is one body, in every method that takes ``bodies``
  and in the pool; the answers equal those for the one-element list.
- A vertex index that is negative, not whole or beyond uint32 is refused by the client, naming
  it, before anything is sent (numpy would wrap -1 to 4294967295).
- RigidBodyPool takes namespaces or node names, or both.
- A node name nobody answers to raises NodeNotFoundError within the client's timeout, saying
  there is no node there (or what lies below the name when it is a namespace).
"""
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body.client import RigidBodyClient
import rospy
NodeNotFoundError = rospy.ROSException
from diff_rigid_body.pool import RigidBodyPool

PKG = 'diff_rigid_body'
WAIT = 60.0  # [s] for the nodes to come up
Q_KNOT = [0.1, 0.2, 0.3, -0.2, 0.05, 0.5]


class ClientInputs(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient('/rigid_body_server', timeout=WAIT).connect()
        for namespace in ('/pool1', '/pool2'):
            rospy.wait_for_service(namespace + '/rigid_body_server/get_bodies', timeout=WAIT)

    def test_a_string_of_bodies_is_one_body(self):
        one = self.client.mass_matrix('knot', q=[Q_KNOT])
        listed = self.client.mass_matrix(['knot'], q=[Q_KNOT])
        self.assertEqual(one.bodies, ['knot'])
        np.testing.assert_array_equal(one.M, listed.M)
        self.assertEqual(list(self.client.get_state('knot')), ['knot'])
        tau = self.client.inverse_dynamics(q=[Q_KNOT], bodies='knot')
        self.assertEqual(tau.bodies, ['knot'])
        np.testing.assert_array_equal(tau.tau, self.client.inverse_dynamics(q=[Q_KNOT], bodies=['knot']).tau)
        qddot = self.client.forward_dynamics(q=[Q_KNOT], bodies='knot')
        self.assertEqual(qddot.bodies, ['knot'])
        pool = RigidBodyPool('/pool1', timeout=WAIT)
        self.assertEqual(len(pool.status()), 1, 'a pool of one namespace given as a string')
        np.testing.assert_array_equal(pool.mass_matrix('knot', q=[[Q_KNOT], [Q_KNOT]]).M[0], listed.M)

    def test_b_negative_vertex_indices_are_refused_by_the_client(self):
        calls = {
            'vertex_jacobians': lambda v: self.client.vertex_jacobians('knot', vertices=v),
            'vertex_jacobians_compact': lambda v: self.client.vertex_jacobians_compact('knot', vertices=v),
            'positions': lambda v: self.client.positions('knot', vertices=v),
            'backprop': lambda v: self.client.backprop('knot', np.ones((len(v), 3)), vertices=v),
        }
        for name, call in calls.items():
            for vertices, shown in (([0, -1], 'vertices[1]: -1 '), ([2.5], 'vertices[0]: 2.5 '),
                                    ([2 ** 32], 'vertices[0]: 4294967296 ')):
                with self.assertRaises(ValueError, msg='%s(vertices=%s)' % (name, vertices)) as caught:
                    call(vertices)
                self.assertIn(shown + 'is not a vertex index', str(caught.exception))
        # Whole numbers as floats and numpy integers still work.
        p_float = self.client.positions('knot', vertices=[0.0, 5.0])
        np.testing.assert_array_equal(p_float, self.client.positions('knot', vertices=np.array([0, 5], np.int64)))

    def test_c_a_pool_takes_namespaces_or_node_names(self):
        pool = RigidBodyPool(['/pool1/rigid_body_server', '/pool2'], timeout=10.0, log=lambda text: None)
        status = pool.status()
        self.assertEqual([server for server, _, _, _ in status],
                         ['/pool1/rigid_body_server', '/pool2/rigid_body_server'])
        self.assertEqual([up for _, up, _, _ in status], [True, True], status)
        M = pool.mass_matrix(['knot'], q=np.tile(Q_KNOT, (4, 1, 1))).M
        np.testing.assert_array_equal(M[0], self.client.mass_matrix(['knot'], q=[Q_KNOT]).M)

    def test_d_a_wrong_node_name_says_no_node_there(self):
        client = RigidBodyClient('/rigid_body_srever', timeout=1.0)
        with self.assertRaises(NodeNotFoundError) as caught:
            client.bodies()
        message = str(caught.exception)
        self.assertIn('no node at /rigid_body_srever (is it running? rosnode list)', message)
        self.assertIn('/rigid_body_srever/get_bodies did not appear within 1 s', message)

    def test_e_a_namespace_given_as_the_node_names_the_node_below_it(self):
        with self.assertRaises(NodeNotFoundError) as caught:
            RigidBodyClient('/pool1', timeout=1.0).bodies()
        self.assertIn('below /pool1 there is /pool1/rigid_body_server', str(caught.exception))


if __name__ == '__main__':
    rospy.init_node('client_inputs')
    rostest.rosrun(PKG, 'client_inputs', ClientInputs)
