#!/usr/bin/python3
"""diff_rigid_body.torch_frames against the real nodes of frames.test: the Franka Panda (a
fixed-base body, d = 9 with its fingers) and the default scene's rock (a free body).

torch.autograd.gradcheck (float64, central differences of the served poses, eps = 1e-6) of
frame_pose (a loss on a frame's position and orientation) and center_of_mass in q, for one
configuration (d,) and a batch (K, d): the backward passes (the served frame Jacobian in
LOCAL_WORLD_ALIGNED, dc/dx) against finite differences of the forward passes. Positions are
below 2 m, so the differences' rounding is ~2 eps / h = 4e-10: atol = 1e-8.
"""
import unittest

import numpy as np
import rospy
import rostest
import torch
from torch.autograd.gradcheck import GradcheckError

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body import torch_frames

EPS = 1e-6
ATOL = 1e-8
TIMEOUT = 100.0


class TorchFrames(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        panda = RigidBodyClient(rospy.get_param('~server'), timeout=TIMEOUT)
        scene = RigidBodyClient(rospy.get_param('~scene_server'), timeout=TIMEOUT)
        rng = np.random.default_rng(29)
        body = panda.bodies().names[0]
        d = int(panda.bodies().dofs[0])
        cls.cases = [('panda', panda, body, 'panda_hand', rng.uniform(-0.8, 0.8, (3, d))),
                     ('rock', scene, 'rock', 'rock_handle', rng.uniform(-1.0, 1.0, (3, 6)))]

    def gradcheck(self, function, q, where):
        try:
            torch.autograd.gradcheck(function, (q,), eps=EPS, atol=ATOL, rtol=0.0)
        except GradcheckError as error:
            self.fail('%s: %s' % (where, error))

    def test_a_frame_pose_position_and_orientation(self):
        for name, client, body, frame, x in self.cases:
            for q in (torch.tensor(x[0], requires_grad=True), torch.tensor(x, requires_grad=True)):
                def pose(q):
                    return torch_frames.frame_pose(client, body, frame, q)
                self.gradcheck(pose, q, '%s %s, q %s' % (name, frame, tuple(q.shape)))

    def test_b_a_loss_on_position_and_orientation_backpropagates(self):
        for name, client, body, frame, x in self.cases:
            target = torch.eye(3, dtype=torch.float64)
            q = torch.tensor(x, requires_grad=True)

            def loss(q):
                position, rotation = torch_frames.frame_pose(client, body, frame, q)
                return (position ** 2).sum() + ((rotation - target) ** 2).sum()
            self.gradcheck(loss, q, name)

    def test_c_center_of_mass(self):
        for name, client, body, _, x in self.cases:
            for q in (torch.tensor(x[0], requires_grad=True), torch.tensor(x, requires_grad=True)):
                self.gradcheck(lambda q: torch_frames.center_of_mass(client, body, q), q,
                               '%s, q %s' % (name, tuple(q.shape)))

    def test_d_forward_passes_are_the_numpy_clients(self):
        name, client, body, frame, x = self.cases[0]
        position, rotation = torch_frames.frame_pose(client, body, frame, torch.tensor(x))
        answer = client.frame_jacobians(body, q=x, frames=[frame])
        self.assertTrue(np.array_equal(position.numpy(), answer.positions[:, 0]))
        self.assertTrue(np.array_equal(rotation.numpy(), answer.rotations[:, 0]))


if __name__ == '__main__':
    rospy.init_node('torch_frames', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'torch_frames', TorchFrames)
