#!/usr/bin/python3
"""K configurations in one call through the Python client (batched_calls.test),
against K single-configuration calls to the same node on the default scene:
vertex_jacobians, positions, vertex_jacobians_compact (double, float32,
positions_only) and backprop, for K = 1, 2 and 7, all vertices and a subset
with repeats, configurations at and next to gimbal lock. Every block must
equal its single call bit for bit, with the documented shapes. Refusals of
sizes that do not fit K name the field. The node's state is not changed.
"""
import unittest

import numpy as np
import rostest

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'
HALF_PI = 1.5707963267948966
TABLE = np.array([
    [0.3, -0.4, 1.1, 0.05, -0.1, 0.6],
    [0.7, HALF_PI, -0.2, 1.0, 2.0, 3.0],
    [-1.2, np.nextafter(HALF_PI, 0.0), 2.5, -1e3, 0.0, 7.0],
    [2.9, -HALF_PI, 0.4, 0.0, 0.0, 0.0],
    [1e6, np.nextafter(-HALF_PI, 0.0), -3e5, 1e8, -1e8, 5e7],
    [0.0, 0.0, 0.0, -0.5, 0.5, -0.5],
    [-0.9, 1.2, 3.1, 4.0, -4.0, 1e-300],
])


def configurations(K):
    """K configurations (K, 6): generic, at gimbal lock, one ulp from it, large values."""
    return TABLE[np.arange(K) % len(TABLE)]


def some_gradients(K, N):
    """dL/dp (K, N, 3): both signs, mixed magnitudes."""
    i = np.arange(K * N * 3)
    return (np.sin(0.7 * i + 0.3) * 10.0 ** (i % 5 - 2.0)).reshape(K, N, 3)


def same_bits(a, b):
    """True when `a` and `b` have one shape and dtype and equal bits."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


class PythonBatchedCalls(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(SERVER, timeout=60.0)

    def check(self, body, vertices, K):
        c = self.client
        qs = configurations(K)
        where = '%s, vertices %s, K = %d' % (body, vertices, K)
        P, J = c.vertex_jacobians(body, q=qs, vertices=vertices)
        N = P.shape[1]
        self.assertEqual((P.shape, J.shape), ((K, N, 3), (K, N, 3, 6)), where)
        Pc, Jr = c.vertex_jacobians_compact(body, q=qs, vertices=vertices)
        Pf, Jf = c.vertex_jacobians_compact(body, q=qs, vertices=vertices, single_precision=True)
        Po, none = c.vertex_jacobians_compact(body, q=qs, vertices=vertices, positions_only=True)
        self.assertIsNone(none, where)
        self.assertEqual((Jr.shape, Jf.shape, Jf.dtype), ((K, N, 3, 3), (K, N, 3, 3), np.float32), where)
        self.assertTrue(same_bits(c.positions(body, q=qs, vertices=vertices), P), 'positions(), ' + where)
        g = some_gradients(K, N)
        dL_dq = c.backprop(body, g, q=qs, vertices=vertices)
        self.assertEqual(dL_dq.shape, (K, 6), where)
        for k in range(K):
            at = '%s, configuration %d' % (where, k)
            p1, j1 = c.vertex_jacobians(body, q=qs[k], vertices=vertices)
            self.assertEqual(p1.shape, (N, 3), at)
            self.assertTrue(same_bits(P[k], p1), 'positions, ' + at)
            self.assertTrue(same_bits(J[k], j1), 'J, ' + at)
            pc1, jr1 = c.vertex_jacobians_compact(body, q=qs[k], vertices=vertices)
            self.assertTrue(same_bits(Pc[k], pc1) and same_bits(Jr[k], jr1), 'compact, ' + at)
            pf1, jf1 = c.vertex_jacobians_compact(body, q=qs[k], vertices=vertices, single_precision=True)
            self.assertTrue(same_bits(Pf[k], pf1) and same_bits(Jf[k], jf1), 'compact float32, ' + at)
            self.assertTrue(same_bits(Po[k], P[k]), 'positions_only, ' + at)
            single = c.backprop(body, g[k], q=qs[k], vertices=vertices)
            self.assertEqual(single.shape, (6,), at)
            self.assertTrue(same_bits(dL_dq[k], single), 'backprop, %s: %s vs %s' % (at, dL_dq[k], single))

    def test_batched_equals_single_calls_bit_for_bit(self):
        for K in (1, 2, 7):
            for body in ('knot', 'rock'):
                self.check(body, None, K)
                self.check(body, [5, 0, 17, 17, 3], K)

    def test_sizes_that_do_not_fit_k_are_refused(self):
        c = self.client
        with self.assertRaises(DiffRigidBodyError) as e:
            c.call('get_vertex_jacobians', body='rock', vertices=[], q=[0.0] * 13)
        self.assertIn('q: expected 6 values per configuration', e.exception.message)
        self.assertIn('got 13 values', e.exception.message)
        with self.assertRaises(DiffRigidBodyError) as e:
            c.backprop('rock', some_gradients(1, 2), q=configurations(2), vertices=[0, 1])
        self.assertIn('gradients: expected 3 per vertex and configuration = 3 x 2 vertices x 2 configurations = 12, '
                      'got 6 values', e.exception.message)
        with self.assertRaises(ValueError):
            c.vertex_jacobians('rock', q=np.zeros((0, 6)))

    def test_flat_q_of_several_configurations_gives_batched_shapes(self):
        qs = configurations(3)
        P, J = self.client.vertex_jacobians('knot', q=qs.ravel().tolist(), vertices=[0, 1])
        self.assertEqual((P.shape, J.shape), ((3, 2, 3), (3, 2, 3, 6)))
        self.assertTrue(same_bits(P, self.client.positions('knot', q=qs, vertices=[0, 1])), 'flat q vs (K, 6) q')
        dL_dq = self.client.backprop('knot', some_gradients(3, 2), q=qs.ravel(), vertices=[0, 1])
        self.assertEqual(dL_dq.shape, (3, 6))


if __name__ == '__main__':
    rostest.rosrun(PKG, 'batched_calls_python', PythonBatchedCalls)
