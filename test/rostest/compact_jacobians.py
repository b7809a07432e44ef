#!/usr/bin/python3
"""RigidBodyClient.vertex_jacobians_compact (the Python client) against
vertex_jacobians of the same node on the default scene (compact_jacobians.test):
shapes and dtypes; double values bit for bit the full answer's positions and
J[:, :, :3]; float32 values the double ones rounded; positions_only gives no Jr;
a refusal raises DiffRigidBodyError with get_vertex_jacobians' message.
"""
import unittest

import numpy as np
import rostest

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'
Q = [0.3, -0.4, 1.1, 0.05, -0.1, 0.6]  # rad, m


def same_bits(a, b):
    """True when `a` and `b` have one shape and dtype and equal bits."""
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


class PythonCompactJacobians(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(SERVER, timeout=60.0)

    def test_double_is_the_full_answer_bit_for_bit(self):
        for body in ('knot', 'rock'):
            for q in (None, Q):
                where = '%s at %s' % (body, 'the current state' if q is None else 'q=%s' % Q)
                p, J = self.client.vertex_jacobians(body, q=q)
                pc, Jr = self.client.vertex_jacobians_compact(body, q=q)
                self.assertEqual(Jr.shape, (len(p), 3, 3), where)
                self.assertEqual((pc.dtype, Jr.dtype), (np.float64, np.float64), where)
                self.assertTrue(same_bits(pc, p), '%s: positions differ from get_vertex_jacobians' % where)
                self.assertTrue(same_bits(Jr, J[:, :, :3]), '%s: Jr differs from J[:, :, :3]' % where)
                self.assertTrue(np.array_equal(J[:, :, 3:], np.broadcast_to(np.eye(3), Jr.shape)),
                                '%s: the translation block of J is not I3' % where)

    def test_float32_is_the_double_answer_rounded(self):
        p, J = self.client.vertex_jacobians('rock', q=Q)
        pc, Jr = self.client.vertex_jacobians_compact('rock', q=Q, single_precision=True)
        self.assertEqual((pc.dtype, Jr.dtype), (np.float32, np.float32))
        self.assertTrue(same_bits(pc, p.astype(np.float32)), 'float32 positions are not the double ones rounded')
        self.assertTrue(same_bits(Jr, J[:, :, :3].astype(np.float32)), 'float32 Jr is not the double J rounded')

    def test_positions_only_and_subset(self):
        p, J = self.client.vertex_jacobians('knot', q=Q)
        vertices = [len(p) - 1, 0, 17, 17]
        pc, Jr = self.client.vertex_jacobians_compact('knot', q=Q, vertices=vertices, positions_only=True)
        self.assertIsNone(Jr, 'positions_only: Jr should be None')
        self.assertTrue(same_bits(pc, p[vertices]), 'positions_only subset: positions are not rows of the full answer')
        _, Jr = self.client.vertex_jacobians_compact('knot', q=Q, vertices=vertices)
        self.assertTrue(same_bits(Jr, J[vertices, :, :3]), 'subset: Jr is not rows of the full answer')

    def test_refusal_carries_the_message_of_get_vertex_jacobians(self):
        with self.assertRaises(DiffRigidBodyError) as full:
            self.client.vertex_jacobians('rock', vertices=[99999])
        with self.assertRaises(DiffRigidBodyError) as compact:
            self.client.vertex_jacobians_compact('rock', vertices=[99999], single_precision=True)
        self.assertEqual(compact.exception.message, full.exception.message)
        self.assertTrue(compact.exception.service.endswith('/get_vertex_jacobians_compact'), compact.exception.service)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'compact_jacobians_python', PythonCompactJacobians)
