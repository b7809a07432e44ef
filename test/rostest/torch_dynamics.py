#!/usr/bin/python3
"""diff_rigid_body.torch's inverse_dynamics and forward_dynamics against the real nodes of
dynamics.test: the Franka Panda (one fixed-base body, d = 8) and the default scene's rock (a
free body, d = 6).

- torch.autograd.gradcheck (float64, central differences of the forward pass, eps = 1e-6) of
  both functions in all three inputs, for one configuration (d,) and a batch (K, d): the
  backward passes (the served dtau/dx, dtau/dx', M; dx''/dx, dx''/dx', M^-1) against finite
  differences of the served tau and x'';
- batched and per-frame calls give the same values and gradients bit for bit;
- the forward passes equal the numpy client's answers; forward_dynamics(inverse_dynamics(a)) = a;
- a gradient for some inputs only, mismatched shapes and a singular M.

gradcheck's atol (rtol = 0): its central differences err by h^2 |f'''| / 6 (< 1e-10 here) plus
their rounding. For tau that is ~2 eps max |tau| / h (|tau| reaches 22 N m on the Panda and
16 N on the rock, mostly gravity): atol = 20 eps max |tau| / h, 1e-7 and 7e-8 (measured errors
<= 6.5e-9 and 1.8e-9); the rock's rotational dtau/dx, ~4e-3, still fails at a relative error of
2e-5. x'' = M^-1 (tau - c - g) carries the rounding of tau times M^-1 (the Panda's finger
coordinate weighs 0.03 kg): atol = 1e-6 (measured <= 1.4e-7), against derivatives up to 600.
"""
import unittest

import numpy as np
import rospy
import rostest
import torch
from torch.autograd.gradcheck import GradcheckError

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body import torch as drb_torch

PKG = 'diff_rigid_body'
EPS = 1e-6            # [rad, m, rad/s, m/s, N m, N]: gradcheck's step
ATOL_FORWARD = 1e-6   # see the module docstring
TIMEOUT = 100.0


def tensor(values, grad=True):
    return torch.tensor(np.asarray(values, dtype=np.float64), dtype=torch.float64, requires_grad=grad)


class TorchDynamics(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        panda = RigidBodyClient(rospy.get_param('~panda_server', '/rigid_body_server'), timeout=TIMEOUT)
        scene = RigidBodyClient(rospy.get_param('~scene_server', '/scene/rigid_body_server'), timeout=TIMEOUT)
        joints = panda.bodies().joints[0]
        panda_x = [j.lower + (0.3 + 0.05 * k) * (j.upper - j.lower) for k, j in enumerate(joints)]
        rng = np.random.default_rng(21)
        cls.cases = []  # (name, client, body, x (K, d), xdot (K, d), xddot (K, d)) with K = 3
        for name, client, body, x in (('panda', panda, panda.bodies().names[0], panda_x),
                                      ('rock', scene, 'rock', [0.3, -0.6, 1.1, 0.2, -0.1, 0.6])):
            x = np.array([x, np.add(x, 0.1), np.subtract(x, 0.15)])
            cls.cases.append((name, client, body, x, rng.uniform(-1, 1, x.shape), rng.uniform(-2, 2, x.shape)))

    def gradcheck(self, function, inputs, where, atol):
        try:
            torch.autograd.gradcheck(function, inputs, eps=EPS, atol=atol, rtol=0.0)
        except GradcheckError as error:
            self.fail('gradcheck failed: %s: %s' % (where, error))

    def test_inverse_dynamics_gradcheck(self):
        for name, client, body, x, xdot, xddot in self.cases:
            def inverse(q, qdot, qddot):
                return drb_torch.inverse_dynamics(client, body, q, qdot, qddot)
            tau = inverse(tensor(x, False), tensor(xdot, False), tensor(xddot, False))
            atol = 20 * np.finfo(float).eps * float(tau.abs().max()) / EPS
            self.gradcheck(inverse, (tensor(x[0]), tensor(xdot[0]), tensor(xddot[0])), name + ', one configuration',
                           atol)
            self.gradcheck(inverse, (tensor(x), tensor(xdot), tensor(xddot)), name + ', K = 3', atol)

    def test_forward_dynamics_gradcheck(self):
        for name, client, body, x, xdot, xddot in self.cases:
            tau = client.inverse_dynamics([body], x[:, None], xdot[:, None], xddot[:, None]).tau[:, 0]

            def forward(q, qdot, tau):
                return drb_torch.forward_dynamics(client, body, q, qdot, tau)
            self.gradcheck(forward, (tensor(x[0]), tensor(xdot[0]), tensor(tau[0])), name + ', one configuration',
                           ATOL_FORWARD)
            self.gradcheck(forward, (tensor(x), tensor(xdot), tensor(tau)), name + ', K = 3', ATOL_FORWARD)

    def test_values_against_the_numpy_client(self):
        for name, client, body, x, xdot, xddot in self.cases:
            tau = drb_torch.inverse_dynamics(client, body, tensor(x, False), tensor(xdot, False), tensor(xddot, False))
            served = client.inverse_dynamics([body], x[:, None], xdot[:, None], xddot[:, None]).tau[:, 0]
            self.assertTrue(np.array_equal(tau.numpy(), served), '%s: tau differs from the numpy client' % name)
            qddot = drb_torch.forward_dynamics(client, body, tensor(x, False), tensor(xdot, False), tau)
            served = client.forward_dynamics([body], x[:, None], xdot[:, None], served[:, None]).qddot[:, 0]
            self.assertTrue(np.array_equal(qddot.numpy(), served), '%s: qddot differs from the numpy client' % name)
            np.testing.assert_allclose(qddot.numpy(), xddot, rtol=0, atol=1e-10 * np.abs(xddot).max(),
                                       err_msg='%s: forward_dynamics(inverse_dynamics(a)) != a' % name)

    def test_batched_equals_per_frame(self):
        for name, client, body, x, xdot, xddot in self.cases:
            results = []
            for per_frame in (False, True):
                inputs = [tensor(v) for v in (x, xdot, xddot)]
                tau = drb_torch.inverse_dynamics(client, body, *inputs, per_frame=per_frame)
                qddot = drb_torch.forward_dynamics(client, body, inputs[0], inputs[1], tau, per_frame=per_frame)
                (tau.sum() + (qddot ** 2).sum()).backward()
                results.append([tau.detach().numpy(), qddot.detach().numpy()] + [v.grad.numpy() for v in inputs])
            for what, batched, single in zip(('tau', 'qddot', 'dL/dq', 'dL/dqdot', 'dL/dqddot'), *results):
                self.assertTrue(np.array_equal(batched, single), '%s: %s batched differs from per-frame by %.3g'
                                % (name, what, np.abs(batched - single).max()))

    def test_gradient_of_some_inputs_only(self):
        name, client, body, x, xdot, xddot = self.cases[0]
        q = tensor(x)
        tau = drb_torch.inverse_dynamics(client, body, q, tensor(xdot, False), tensor(xddot, False))
        tau.sum().backward()
        full = tensor(x), tensor(xdot), tensor(xddot)
        drb_torch.inverse_dynamics(client, body, *full).sum().backward()
        self.assertTrue(np.array_equal(q.grad.numpy(), full[0].grad.numpy()), 'dL/dq with and without other grads')
        qddot = tensor(xddot)
        drb_torch.inverse_dynamics(client, body, tensor(x, False), tensor(xdot, False), qddot).sum().backward()
        M = client.mass_matrix([body], x[:, None]).M[:, 0]
        np.testing.assert_allclose(qddot.grad.numpy(), M.sum(axis=-2), rtol=1e-14, err_msg='dL/dqddot = 1^T M')

    def test_refusals(self):
        name, client, body, x, xdot, xddot = self.cases[0]
        with self.assertRaises(ValueError, msg='qdot of another shape than q'):
            drb_torch.inverse_dynamics(client, body, tensor(x), tensor(xdot[0]), tensor(xddot))
        with self.assertRaises(ValueError, msg='q of the wrong width'):
            drb_torch.forward_dynamics(client, body, tensor(x[:, :3]), tensor(xdot[:, :3]), tensor(xddot[:, :3]))
        name, client, body, x, xdot, xddot = self.cases[1]
        locked = x.copy()
        locked[1, 1] = np.pi / 2
        with self.assertRaises(DiffRigidBodyError, msg='forward_dynamics at gimbal lock') as refusal:
            drb_torch.forward_dynamics(client, tensor(locked), tensor(xdot), tensor(xddot), body)
        self.assertIn('configuration 1', refusal.exception.message)


if __name__ == '__main__':
    rospy.init_node('torch_dynamics', anonymous=True)
    rostest.rosrun(PKG, 'torch_dynamics', TorchDynamics)
