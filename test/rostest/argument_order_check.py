#!/usr/bin/python3
"""One argument order for every batched call (diff_rigid_body.client_arguments), in local_scene.test.

The oracle of each call is the same call with every argument given by keyword, which no order can
re-bind. Checked, on a LocalScene of the Panda and of simple_humanoid with a floating base, and on
the Panda's node:
- a call in the current order (bodies, q, qdot, qddot or tau) gives the keyword call's bits, with
  no warning;
- a call in an earlier order (inverse_dynamics(q, qdot, qddot, bodies), forward_dynamics(q, qdot,
  tau, bodies), frame_jacobians(body, q, frames, reference, qdot), torch's inverse_dynamics(client,
  q, qdot, qddot, body)) gives the same bits, with one DeprecationWarning naming the method;
- an earlier-order call that also gives a moved argument by keyword raises TypeError;
- None or [] first (all bodies) is read in the current order.
"""
import sys
import unittest
import warnings

import numpy as np
import rospy
import rostest
import torch

import diff_rigid_body.torch as drb_torch
from diff_rigid_body import LocalScene
from diff_rigid_body.client import RigidBodyClient
from local_scene_check import assert_same

WAIT = 60.0
rng = np.random.RandomState(29)


def calling(test, expect_warning, call):
    """call()'s answer; asserts one DeprecationWarning naming the method, or none."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        answer = call()
    deprecations = [w for w in caught if issubclass(w.category, DeprecationWarning)
                    and 'positional order is deprecated' in str(w.message)]
    test.assertEqual(len(deprecations), 1 if expect_warning else 0, [str(w.message) for w in deprecations])
    return answer


class ArgumentOrder(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.panda = LocalScene(urdf_path=rospy.get_param('~panda'))
        cls.humanoid = LocalScene(urdf_path=rospy.get_param('~humanoid'), floating_base=True)
        cls.node = RigidBodyClient('/panda/rigid_body_server', timeout=WAIT)

    def backends(self):
        return (('panda', self.panda), ('humanoid', self.humanoid), ('panda node', self.node))

    def inputs(self, scene, K=3):
        body = scene.bodies().names[0]
        d = scene.dofs(body)
        return body, rng.uniform(-0.8, 0.8, (K, 1, d)), rng.uniform(-1, 1, (K, 1, d)), rng.uniform(-1, 1, (K, 1, d))

    def test_dynamics_in_every_order(self):
        for name, scene in self.backends():
            body, q, qdot, third = self.inputs(scene)
            inverse = scene.inverse_dynamics(bodies=[body], q=q, qdot=qdot, qddot=third, derivatives=True)
            forward = scene.forward_dynamics(bodies=[body], q=q, qdot=qdot, tau=inverse.tau, derivatives=True)
            assert_same(self, calling(self, False, lambda: scene.inverse_dynamics([body], q, qdot, third,
                                                                                  derivatives=True)),
                        inverse, '%s: inverse_dynamics(bodies, q, qdot, qddot)' % name)
            assert_same(self, calling(self, True, lambda: scene.inverse_dynamics(q, qdot, third, [body],
                                                                                 derivatives=True)),
                        inverse, '%s: inverse_dynamics(q, qdot, qddot, bodies)' % name)
            assert_same(self, calling(self, True, lambda: scene.inverse_dynamics(q, qdot, third, bodies=body,
                                                                                 derivatives=True)),
                        inverse, '%s: inverse_dynamics(q, qdot, qddot, bodies=...)' % name)
            assert_same(self, calling(self, False, lambda: scene.forward_dynamics(body, q, qdot, inverse.tau,
                                                                                  derivatives=True)),
                        forward, '%s: forward_dynamics(bodies, q, qdot, tau)' % name)
            assert_same(self, calling(self, True, lambda: scene.forward_dynamics(q, qdot, inverse.tau, body,
                                                                                 True)),
                        forward, '%s: forward_dynamics(q, qdot, tau, bodies, derivatives)' % name)

    def test_all_bodies_first_is_the_current_order(self):
        body, q, qdot, qddot = self.inputs(self.panda, K=1)
        expected = self.panda.inverse_dynamics(q=q, qdot=qdot, qddot=qddot)
        for first in (None, []):
            assert_same(self, calling(self, False, lambda: self.panda.inverse_dynamics(first, q, qdot, qddot)),
                        expected, 'inverse_dynamics(%r, q, qdot, qddot)' % (first,))
        # The earlier order with q None (the node's current state) and the bodies fourth.
        assert_same(self, calling(self, True, lambda: self.node.inverse_dynamics(None, qdot[0], qddot[0], [body])),
                    self.node.inverse_dynamics(bodies=[body], qdot=qdot[0], qddot=qddot[0]),
                    'inverse_dynamics(None, qdot, qddot, bodies)')

    def test_a_moved_argument_given_twice_is_refused(self):
        body, q, qdot, qddot = self.inputs(self.panda)
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')
            with self.assertRaisesRegex(TypeError, "multiple values for argument 'qdot'"):
                self.panda.inverse_dynamics(q, qdot, qddot, [body], qdot=qdot)
            with self.assertRaisesRegex(TypeError, 'at most 5 positional'):
                self.panda.forward_dynamics(q, qdot, qddot, [body], True, False)

    def test_frame_jacobians_in_every_order(self):
        for name, scene in self.backends():
            body, q, qdot, _ = self.inputs(scene)
            q, qdot = q[:, 0], qdot[:, 0]
            frames = scene.frame_jacobians(body, q=q[0]).frames[-2:]
            expected = scene.frame_jacobians(body=body, q=q, qdot=qdot, frames=frames, reference='world',
                                             acceleration_bias=True)
            assert_same(self, calling(self, False, lambda: scene.frame_jacobians(body, q, qdot, frames, 'world',
                                                                                 True)),
                        expected, '%s: frame_jacobians(body, q, qdot, frames, reference)' % name)
            assert_same(self, calling(self, True, lambda: scene.frame_jacobians(body, q, frames, 'world', qdot,
                                                                                True)),
                        expected, '%s: frame_jacobians(body, q, frames, reference, qdot)' % name)
            assert_same(self, calling(self, True, lambda: scene.frame_jacobians(body, q, None, 0, qdot, True)),
                        scene.frame_jacobians(body, q=q, qdot=qdot, reference=0, acceleration_bias=True),
                        '%s: frame_jacobians(body, q, None, 0, qdot)' % name)

    def test_torch_in_every_order(self):
        body, q, qdot, qddot = self.inputs(self.humanoid)
        q, qdot, qddot = (torch.tensor(a[:, 0]) for a in (q, qdot, qddot))
        tau = calling(self, False, lambda: drb_torch.inverse_dynamics(self.humanoid, body, q, qdot, qddot))
        self.assertTrue(torch.equal(tau, calling(
            self, True, lambda: drb_torch.inverse_dynamics(self.humanoid, q, qdot, qddot, body))))
        qddot_back = calling(self, False, lambda: drb_torch.forward_dynamics(self.humanoid, body, q, qdot, tau))
        self.assertTrue(torch.equal(qddot_back, calling(
            self, True, lambda: drb_torch.forward_dynamics(self.humanoid, q, qdot, tau, body))))
        np.testing.assert_allclose(qddot_back.numpy(), qddot.numpy(), rtol=0, atol=1e-9,
                                   err_msg='forward_dynamics(inverse_dynamics(a)) != a')


if __name__ == '__main__':
    rospy.init_node('argument_order_check', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'argument_order', ArgumentOrder, sys.argv)
