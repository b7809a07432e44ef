#!/usr/bin/python3
"""The Python client library and the example optimisers against the real
node on the default scene (clients_python.test).

- shapes and axis order of every answer (dM[i, j] = dM/dq_j of body i,
  checked by central differences of M);
- success=false raises DiffRigidBodyError with the node's message;
- the three pose fits recover a hidden pose within 1e-8 without noise;
- both trajectory fits (torch LBFGS, SciPy least_squares) of a toss land
  within 5 standard deviations of the hidden q0, qdot0 with 1 mm noise;
- batched and per-call trajectory energies agree, and agree with
  1/2 w^T I w + 1/2 m v^2 from get_bodies alone;
- persistent connections survive a restart of the node.
"""
import os
import signal
import time
import unittest
import xmlrpc.client

import numpy as np
import rosgraph
import rospy
import rostest

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body_examples import pose_fitting, trajectory_energy, trajectory_fitting

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'
FIT_TOLERANCE = 1e-8        # rad, m: |q_fit - q_hidden|_inf without noise
ENERGY_TOLERANCE = 1e-12    # relative: batched against per-call energies
ORACLE_TOLERANCE = 1e-10    # relative: against 1/2 w^T I w + 1/2 m v^2
FD_TOLERANCE = 1e-7         # dM/dq against central differences, relative to max |M|
Q_HIDDEN = np.array([0.3, -0.4, 1.1, 0.05, -0.1, 0.6])
X_HIDDEN = np.array([0.2, -0.3, 0.5, 0.0, 0.0, 1.0, 1.5, 0.8, -1.0, 0.5, -0.3, 4.0])  # q0, qdot0 of a toss


class PythonClient(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(SERVER, timeout=60.0)

    def test_shapes_and_axis_order(self):
        c = self.client
        bodies = c.bodies()
        self.assertEqual(bodies.names, ['knot', 'rock'])
        self.assertEqual(bodies.inertias.shape, (2, 3, 3))
        self.assertEqual(bodies.com_offsets.shape, (2, 3))
        # Links in vertex order: the rock's own link, then its merged handle (masses from the URDF).
        self.assertEqual([link.name for link in bodies.links[1]], ['rock', 'rock_handle'])
        self.assertEqual([link.mass for link in bodies.links[1]], [1.39997, 0.05])
        self.assertEqual(bodies.links[1][1].first_vertex, bodies.links[1][0].vertex_count)
        self.assertEqual(sum(link.vertex_count for link in bodies.links[1]), bodies.vertex_counts[1])
        self.assertEqual(list(bodies.dofs), [6, 6])
        self.assertEqual(bodies.joints, [[], []])
        states = c.get_state()
        self.assertEqual(list(states), ['knot', 'rock'])
        self.assertEqual(states['knot'].shape, (6,))

        answer = c.mass_matrix(derivatives=True)
        self.assertEqual(answer.M.shape, (2, 6, 6))
        self.assertEqual(answer.dM.shape, (2, 6, 6, 6))
        self.assertEqual(answer.cos_theta.shape, (2,))
        np.testing.assert_allclose(answer.M[1, 3:, 3:], bodies.masses[1] * np.eye(3), rtol=1e-15)

        # dM[i, j] = dM/dq_j of body i, by central differences at a general q.
        q = np.array([[0.3, -0.7, 0.2, 0.0, 0.0, 0.0], [-0.5, 0.4, 1.0, 0.1, 0.2, 0.3]])
        h = 1e-6
        dM = c.mass_matrix(q=q, derivatives=True).dM
        for j in range(6):
            dq = np.zeros(6)
            dq[j] = h
            fd = (c.mass_matrix(q=q + dq).M - c.mass_matrix(q=q - dq).M) / (2 * h)
            scale = np.max(np.abs(c.mass_matrix(q=q).M))
            self.assertLess(np.max(np.abs(dM[:, j] - fd)), FD_TOLERANCE * scale, 'column %d' % j)

        K = 5
        batch = c.mass_matrix(['rock', 'knot'], q=np.tile(q[::-1], (K, 1, 1)), derivatives=True)
        self.assertEqual(batch.bodies, ['rock', 'knot'])
        self.assertEqual(batch.M.shape, (K, 2, 6, 6))
        self.assertEqual(batch.dM.shape, (K, 2, 6, 6, 6))
        self.assertEqual(batch.cos_theta.shape, (K, 2))

        positions, J = c.vertex_jacobians('rock', Q_HIDDEN)
        self.assertEqual(positions.shape, (bodies.vertex_counts[1], 3))
        self.assertEqual(J.shape, (bodies.vertex_counts[1], 3, 6))
        np.testing.assert_array_equal(J[:, :, 3:], np.broadcast_to(np.eye(3), (len(J), 3, 3)))
        subset = [5, 0, 17]
        np.testing.assert_array_equal(c.positions('rock', Q_HIDDEN, subset), positions[subset])
        g = np.random.default_rng(1).normal(size=(3, 3))
        np.testing.assert_allclose(c.backprop('rock', g, Q_HIDDEN, subset),
                                   np.einsum('vij,vi->j', J[subset], g), rtol=1e-12, atol=1e-14)

    def test_refusal_raises_with_the_message(self):
        before = self.client.get_state()
        with self.assertRaises(DiffRigidBodyError) as caught:
            self.client.set_state({'knot': [0, 0, 0, 0, 0, 0], 'no_such_body': [0, 0, 0, 0, 0, 0]})
        self.assertIn('no_such_body', caught.exception.message)
        self.assertIn('set_state', caught.exception.service)
        with self.assertRaises(DiffRigidBodyError) as caught:
            self.client.vertex_jacobians('rock', vertices=[99999])
        self.assertIn('99999', str(caught.exception))
        after = self.client.get_state()
        for name in before:
            np.testing.assert_array_equal(before[name], after[name])

    def check_fit(self, fit):
        target, q_start = pose_fitting.make_problem(self.client, 'knot', Q_HIDDEN, noise=0.0, seed=3)
        angle, distance = pose_fitting.pose_error(q_start, Q_HIDDEN)
        self.assertAlmostEqual(np.degrees(angle), 30.0, places=6)
        self.assertAlmostEqual(distance, 0.2, places=12)
        result = fit(self.client, 'knot', target, q_start)
        error = np.max(np.abs(result.q - Q_HIDDEN))
        rospy.loginfo('%s: %d iterations, %d calls, residual %.3e m, |q - q_hidden| %.3e, %.3f s',
                      fit.__name__, result.iterations, result.evaluations, result.residual_rms, error,
                      result.wall_time)
        self.assertTrue(result.converged, result.reason)
        self.assertLess(error, FIT_TOLERANCE, 'q = %r' % (result.q,))
        return result

    def test_gauss_newton_recovers_the_hidden_pose(self):
        result = self.check_fit(pose_fitting.fit_gauss_newton)
        self.assertLessEqual(result.iterations, 15)

    def test_lbfgs_with_backprop_recovers_the_hidden_pose(self):
        self.check_fit(pose_fitting.fit_lbfgs)

    def test_scipy_least_squares_recovers_the_hidden_pose(self):
        result = self.check_fit(pose_fitting.fit_least_squares)
        self.assertLessEqual(result.iterations, 15)

    def test_trajectory_fits_reach_the_noise_level(self):
        # A toss of T = 100 frames of 64 knot vertices with 1 mm noise; both
        # solvers, one call for all frames per evaluation.
        times, noise = np.arange(100) / 100.0, 1e-3
        vertices = np.linspace(0, 4095, 64).astype(np.uint32)
        observed, x_start = trajectory_fitting.make_problem(self.client, 'knot', X_HIDDEN, times, vertices, noise,
                                                            seed=11)
        sigma = trajectory_fitting.standard_errors(self.client, 'knot', X_HIDDEN, times, vertices, noise)
        fits = [fit(self.client, 'knot', observed, times, x_start, vertices)
                for fit in (trajectory_fitting.fit_torch, trajectory_fitting.fit_least_squares)]
        for fit in fits:
            self.assertTrue(fit.converged, fit.reason)
            self.assertLess(np.max(np.abs(fit.x - X_HIDDEN) / sigma), 5.0, 'x = %r, sigma = %r' % (fit.x, sigma))
            self.assertAlmostEqual(fit.residual_rms / noise, 1.0, delta=0.05, msg='rms residual / noise')
            self.assertEqual(fit.per_frame_calls, 100 * fit.calls, 'one call per evaluation for all 100 frames')
        np.testing.assert_allclose(fits[0].x, fits[1].x, atol=1e-6, err_msg='torch LBFGS vs least_squares')

    def test_batched_and_per_call_energies_agree(self):
        bodies = self.client.bodies()
        q0 = np.array([self.client.get_state()[name] for name in bodies.names])
        _, q, qdot = trajectory_energy.demo_trajectory(q0, count=100)
        batched, _ = trajectory_energy.energy_batched(self.client, bodies.names, q, qdot)
        per_call, _ = trajectory_energy.energy_per_call(self.client, bodies.names, q, qdot)
        oracle = trajectory_energy.energy_from_inertia(bodies.masses, bodies.inertias, q, qdot)
        self.assertEqual(batched.shape, (100, 2))
        self.assertGreater(np.min(batched), 0.0)
        np.testing.assert_allclose(batched, per_call, rtol=ENERGY_TOLERANCE)
        np.testing.assert_allclose(batched, oracle, rtol=ORACLE_TOLERANCE)

    def test_reconnects_after_the_node_restarts(self):
        c = RigidBodyClient(SERVER, timeout=60.0)
        first = c.mass_matrix(['knot']).M
        c.positions('knot')  # two persistent connections open
        master = rosgraph.Master(rospy.get_name())
        uri = master.lookupNode(SERVER)
        code, _, pid = xmlrpc.client.ServerProxy(uri).getPid(rospy.get_name())
        self.assertEqual(code, 1)
        os.kill(pid, signal.SIGKILL)  # roslaunch respawns it (respawn:=true)
        deadline = time.time() + 60.0
        while time.time() < deadline:  # wait for the new process to register
            try:
                if master.lookupNode(SERVER) != uri:
                    break
            except rosgraph.MasterError:
                pass
            time.sleep(0.2)
        else:
            self.fail('%s was not respawned within 60 s' % SERVER)
        np.testing.assert_array_equal(c.mass_matrix(['knot']).M, first)
        self.assertEqual(c.positions('knot').shape, (4096, 3))


if __name__ == '__main__':
    rospy.init_node('clients_python_test')
    rostest.rosrun(PKG, 'clients_python', PythonClient)
