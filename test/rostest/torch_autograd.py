#!/usr/bin/python3
"""diff_rigid_body.torch against the real node on the default scene
(torch_autograd.test).

- torch.autograd.gradcheck (float64, central differences) of vertex_positions,
  mass_matrix and kinetic_energy at ordinary states and near gimbal lock
  (theta = +-(pi/2 - 1e-3)), for one configuration (6,) and a batch (K, 6):
  the analytic backward (backprop / dM from the node) against finite
  differences of the forward (positions / M from the node);
- batched and per-frame calls give the same values and gradients bit for bit;
- positions against R(q) p_body + t with p_body from the node at q = 0, and
  kinetic_energy against 1/2 qdot^T M qdot of the numpy client;
- the README's PyTorch example runs as written.

Tolerances of gradcheck (|analytic - numerical| <= atol, rtol = 0): eps = 1e-6
(rad or m). Central differences err by eps^2 |f'''| / 6 (< 1e-12 here) plus
rounding ~2^-52 |f| / eps: ~2e-10 for positions (|p| ~ 1 m; measured <= 1e-10),
~1e-12 for M (its q-dependent entries are below 1e-2; the m I block is
constant; measured <= 3e-13, the largest near the lock), ~8e-10 for E
(|E| < 4 J; measured <= 2.2e-10). Hence atol = 1e-9 (positions), 1e-11 (M)
and 2e-9 (E). The derivatives reach 1 (dp/dq), 2e-3 (dM/dq), 7e-4 (dE/dq)
and 3 (dE/dqdot): a relative error of 1e-5 in one of them fails.
"""
import os
import re
import unittest

import numpy as np
import rospy
import rostest
import torch
from torch.autograd.gradcheck import GradcheckError

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body_examples import pose_fitting
from diff_rigid_body import torch as drb_torch

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'
EPS = 1e-6
ATOL_POSITIONS, ATOL_MASS, ATOL_ENERGY = 1e-9, 1e-11, 2e-9
VERTICES = np.arange(0, 4096, 256)  # 16 of the knot's 4096 vertices
ORDINARY = [0.3, -0.4, 1.1, 0.05, -0.1, 0.6]
NEAR_LOCK = [[0.7, np.pi / 2 - 1e-3, -0.2, 0.1, 0.2, 0.3], [-1.2, -np.pi / 2 + 1e-3, 2.5, -0.3, 0.0, 1.0]]
QDOT = [0.5, -1.0, 2.0, 0.3, 0.2, -0.4]
README = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'README.md')
README_MARKER = '<!-- test: torch_autograd.py runs this block -->'


def tensor(values, grad=True):
    return torch.tensor(values, dtype=torch.float64, requires_grad=grad)


class TorchAutograd(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.client = RigidBodyClient(SERVER, timeout=60.0)

    def gradcheck(self, function, inputs, where, atol):
        try:
            torch.autograd.gradcheck(function, inputs, eps=EPS, atol=atol, rtol=0.0)
        except GradcheckError as error:
            self.fail('gradcheck failed: %s: %s' % (where, error))

    def test_vertex_positions_single(self):
        for q in [ORDINARY] + NEAR_LOCK:
            self.gradcheck(lambda x: drb_torch.vertex_positions(self.client, 'knot', x, VERTICES), (tensor(q),),
                           'vertex_positions, knot, q = %s' % q, ATOL_POSITIONS)

    def test_mass_matrix_and_energy_single(self):
        for body in ('knot', 'rock'):
            for q in [ORDINARY] + NEAR_LOCK:
                self.gradcheck(lambda x: drb_torch.mass_matrix(self.client, body, x), (tensor(q),),
                               'mass_matrix, %s, q = %s' % (body, q), ATOL_MASS)
                self.gradcheck(lambda x, v: drb_torch.kinetic_energy(self.client, body, x, v),
                               (tensor(q), tensor(QDOT)), 'kinetic_energy, %s, q = %s' % (body, q),
                               ATOL_ENERGY)

    def test_mass_matrix_and_energy_batched(self):
        q = tensor([ORDINARY] + NEAR_LOCK)
        qdot = tensor([QDOT, QDOT[::-1], [1.0] * 6])
        self.gradcheck(lambda x: drb_torch.mass_matrix(self.client, 'rock', x), (q,), 'mass_matrix, K = 3',
                       ATOL_MASS)
        self.gradcheck(lambda x, v: drb_torch.kinetic_energy(self.client, 'rock', x, v), (q, qdot),
                       'kinetic_energy, K = 3', ATOL_ENERGY)

    def test_energy_against_numpy_client(self):
        q, qdot = np.array([ORDINARY] + NEAR_LOCK), np.array([QDOT, QDOT[::-1], [1.0] * 6])
        M = self.client.mass_matrix(['rock'], q[:, None, :]).M[:, 0]
        expected = 0.5 * np.einsum('ka,kab,kb->k', qdot, M, qdot)
        energy = drb_torch.kinetic_energy(self.client, 'rock', tensor(q, False), tensor(qdot, False))
        self.assertEqual(energy.shape, (3,))
        np.testing.assert_allclose(energy.numpy(), expected, rtol=1e-14, err_msg='E vs 1/2 qdot^T M qdot')

    def test_positions_against_rigid_transform(self):
        body_points = self.client.positions('knot', np.zeros(6), VERTICES)  # R = I, t = 0: body frame
        for q in [ORDINARY] + NEAR_LOCK:
            p = drb_torch.vertex_positions(self.client, 'knot', tensor(q, False), VERTICES).numpy()
            expected = body_points.dot(pose_fitting.rpy_to_matrix(q[:3]).T) + q[3:]
            np.testing.assert_allclose(p, expected, atol=1e-14, err_msg='p = R(q) p_body + t at q = %s' % q)

    def test_bad_shape(self):
        with self.assertRaises(ValueError, msg='q of shape (2, 3) must be refused'):
            drb_torch.mass_matrix(self.client, 'knot', torch.zeros(2, 3, dtype=torch.float64))

    def test_readme_example(self):
        with open(README) as f:
            text = f.read()
        self.assertIn(README_MARKER, text, 'README.md: the PyTorch example has no marker')
        block = re.search(r'```python\n(.*?)```', text[text.index(README_MARKER):], re.S)
        self.assertIsNotNone(block, 'README.md: no python block after the marker')
        namespace = {}
        exec(compile(block.group(1), 'README.md (PyTorch example)', 'exec'), namespace)
        self.assertEqual(namespace['q'].grad.shape, namespace['q'].shape, 'README example: no gradient for q')

    def test_vertex_positions_batched(self):
        self.gradcheck(lambda x: drb_torch.vertex_positions(self.client, 'knot', x, VERTICES),
                       (tensor([ORDINARY] + NEAR_LOCK),), 'vertex_positions, knot, K = 3', ATOL_POSITIONS)

    def test_batched_equals_per_frame(self):
        rng = np.random.default_rng(7)
        q = rng.uniform(-1.0, 1.0, size=(5, 6))
        results = []
        for per_frame in (False, True):
            x = tensor(q)
            p = drb_torch.vertex_positions(self.client, 'knot', x, VERTICES, per_frame=per_frame)
            E = drb_torch.kinetic_energy(self.client, 'rock', x, tensor(q[::-1].copy(), False), per_frame)
            ((p ** 2).sum() + E.sum()).backward()
            results.append((p.detach().numpy(), E.detach().numpy(), x.grad.numpy()))
        for name, batched, single in zip(('positions', 'energies', 'dL/dq'), *results):
            self.assertEqual(batched.shape, single.shape, name)
            self.assertTrue(np.array_equal(batched, single), '%s: batched differs from per-frame by %.3e' % (
                name, np.max(np.abs(batched - single))))


if __name__ == '__main__':
    rospy.init_node('torch_autograd_test', anonymous=True)
    rostest.rosrun(PKG, 'torch_autograd', TorchAutograd)
