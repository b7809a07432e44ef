#!/usr/bin/python3
"""diff_rigid_body.LocalScene against the node (local_scene.test): the same URDF and options give
the same answers bit for bit (np.array_equal, never a tolerance) for every state-free method, on
the Panda, the UR5 (a gravity of its own), simple_humanoid with a floating base and the default
scene of free bodies. Also: refusals raise DiffRigidBodyError with the node's message; an answer's
arrays are views of the buffer the core filled (their base is the module's capsule, not a numpy
copy); float64 inputs reach the core as the caller's buffers; threads calling one scene at once get
the answers of serial calls; the PyTorch functions give the node's values and gradients over it.
"""
import concurrent.futures
import sys
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body import LocalScene, _local
from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body.local import local_services

WAIT = 60.0
K = 5
rng = np.random.RandomState(30)

#: name -> (the node, the LocalScene options of its launch)
SCENES = {
    'panda': ('/panda/rigid_body_server', {}),
    'ur5': ('/ur5/rigid_body_server', {'gravity': (0.5, 0.0, -9.0)}),
    'humanoid': ('/humanoid/rigid_body_server', {'floating_base': True}),
    'scene': ('/scene/rigid_body_server', {}),
}


def assert_same(test, local, node, where):
    """Equal bit for bit, field by field: named tuples, lists, arrays (shape and dtype too), None."""
    if isinstance(node, tuple) and hasattr(node, '_fields'):
        test.assertEqual(type(local), type(node), where)
        for field in node._fields:
            assert_same(test, getattr(local, field), getattr(node, field), '%s.%s' % (where, field))
    elif isinstance(node, (list, tuple)):
        test.assertEqual(len(local), len(node), where)
        for i, (a, b) in enumerate(zip(local, node)):
            assert_same(test, a, b, '%s[%d]' % (where, i))
    elif node is None or isinstance(node, (str, int, float)):
        test.assertEqual(local, node, where)
    else:
        a, b = np.asarray(local), np.asarray(node)
        test.assertEqual((a.shape, a.dtype), (b.shape, b.dtype), where)
        test.assertTrue(np.array_equal(a, b), '%s: not the same bits' % where)


def owner(array):
    """The object at the end of an array's chain of bases (a view's buffer owner)."""
    while isinstance(array, np.ndarray) and array.base is not None:
        array = array.base
    return array


class LocalSceneAgainstNode(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.pairs = {}
        for name, (server, options) in SCENES.items():
            node = RigidBodyClient(server, timeout=WAIT)
            local = LocalScene(urdf_path=rospy.get_param('~' + name), **options)
            cls.pairs[name] = (local, node, node.bodies())

    def configurations(self, bodies, names=None):
        """K random x of the bodies ``names`` (None = all) concatenated: (K, D)."""
        dofs = [int(d) for n, d in zip(bodies.names, bodies.dofs) if names is None or n in names]
        return rng.uniform(-1.0, 1.0, (K, sum(dofs))) * 0.8

    def test_a_every_state_free_service(self):
        """LocalScene answers every service of the client but the two about the node's state."""
        self.assertEqual(set(local_services()), set(RigidBodyClient.SERVICES) - {'get_state', 'set_state'})

    def test_a_bodies(self):
        for name, (local, node, bodies) in self.pairs.items():
            assert_same(self, local.bodies(), bodies, name)

    def test_b_mass_matrices_and_dynamics(self):
        for name, (local, node, bodies) in self.pairs.items():
            q, qdot, other = (self.configurations(bodies) for _ in range(3))
            for method, args in (('mass_matrix', dict(q=q, derivatives=True)),
                                 ('mass_matrix', dict(q=q[0])),
                                 ('inverse_dynamics', dict(q=q, qdot=qdot, qddot=other, coriolis_matrices=True,
                                                           derivatives=True)),
                                 ('forward_dynamics', dict(q=q, qdot=qdot, tau=other, derivatives=True)),
                                 ('forward_dynamics', dict(q=q[1], qdot=qdot[1])),
                                 ('center_of_mass', dict(q=q, qdot=qdot, jacobians=True))):
                assert_same(self, getattr(local, method)(**args), getattr(node, method)(**args),
                            '%s.%s' % (name, method))

    def test_c_vertices_and_frames(self):
        for name, (local, node, bodies) in self.pairs.items():
            for body, count in zip(bodies.names, bodies.vertex_counts):
                q = self.configurations(bodies, [body])
                gradients = rng.standard_normal((K, int(count), 3))
                vertices = [0, int(count) - 1, 0]
                for method, args in (('vertex_jacobians', dict(q=q)),
                                     ('vertex_jacobians', dict(q=q[0], vertices=vertices)),
                                     ('vertex_jacobians_compact', dict(q=q)),
                                     ('vertex_jacobians_compact', dict(q=q, single_precision=True)),
                                     ('positions', dict(q=q[2])),
                                     ('backprop', dict(q=q, gradients=gradients)),
                                     ('backprop', dict(q=q[3], gradients=gradients[3, vertices], vertices=vertices)),
                                     ('frame_jacobians', dict(q=q, reference='world', qdot=q[::-1],
                                                              acceleration_bias=True)),
                                     ('frame_jacobians', dict(q=q[4], reference='local'))):
                    assert_same(self, getattr(local, method)(body, **args), getattr(node, method)(body, **args),
                                '%s.%s(%s)' % (name, method, body))

    def test_c_generated_queries(self):
        """query(service, ...) (client_declared) answers in process as through the node, bit for bit."""
        for name, (local, node, bodies) in self.pairs.items():
            body = bodies.names[0]
            q = self.configurations(bodies, [body])
            for service, args in (('get_mass_matrix', (body, q, True)),
                                  ('get_vertex_jacobians_compact', (body, q, [0, 1])),
                                  ('get_frame_jacobians', (body, q, q[::-1], None, 'local', True))):
                assert_same(self, local.query(service, *args), node.query(service, *args), '%s %s' % (name, service))

    def assert_same_refusal(self, local, node, method, *args, **kwargs):
        with self.assertRaises(DiffRigidBodyError) as node_refusal:
            getattr(node, method)(*args, **kwargs)
        with self.assertRaises(DiffRigidBodyError) as local_refusal:
            getattr(local, method)(*args, **kwargs)
        self.assertEqual(local_refusal.exception.message, node_refusal.exception.message)
        self.assertEqual(local_refusal.exception.service, node_refusal.exception.service.rsplit('/', 1)[-1])

    def test_d_refusals_carry_the_nodes_message(self):
        local, node, bodies = self.pairs['panda']
        d = int(bodies.dofs[0])
        q = np.zeros(d)
        self.assert_same_refusal(local, node, 'mass_matrix', ['no_such_body'], q)
        self.assert_same_refusal(local, node, 'vertex_jacobians', 'no_such_body', q)
        self.assert_same_refusal(local, node, 'mass_matrix', None, np.zeros(d + 1))
        self.assert_same_refusal(local, node, 'inverse_dynamics', q, np.zeros(d - 1))
        self.assert_same_refusal(local, node, 'frame_jacobians', bodies.names[0], q, frames=['no_such_link'])
        nan = q.copy()
        nan[2] = np.nan
        self.assert_same_refusal(local, node, 'forward_dynamics', nan)
        self.assert_same_refusal(local, node, 'backprop', bodies.names[0], np.zeros((3, 3)), q, vertices=[0, 1, 10**7])
        self.assert_same_refusal(local, node, 'call', 'get_frame_jacobians', body=bodies.names[0], q=q, reference=3)
        for reference in (256, -1):  # not a uint8: the node's client cannot send it, the local scene refuses it
            with self.assertRaises(DiffRigidBodyError) as refusal:
                local.call('get_frame_jacobians', body=bodies.names[0], q=q, reference=reference)
            self.assertIn('reference: %d is not a uint8' % reference, refusal.exception.message)

    def test_e_q_is_required(self):
        local, _, bodies = self.pairs['scene']
        for call in (lambda: local.mass_matrix(), lambda: local.vertex_jacobians(bodies.names[0]),
                     lambda: local.inverse_dynamics(q=[])):
            with self.assertRaises(DiffRigidBodyError) as refusal:
                call()
            self.assertIn('q: required', refusal.exception.message)

    def test_f_answers_are_the_cores_buffers(self):
        local, _, bodies = self.pairs['panda']
        q = self.configurations(bodies)
        answer = local.mass_matrix(q=q, derivatives=True)
        positions, J = local.vertex_jacobians(bodies.names[0], q=q)
        for array in (answer.M, answer.dM, answer.cos_theta, positions, J):
            self.assertFalse(array.flags.owndata)
            self.assertEqual(type(owner(array)).__name__, 'PyCapsule')
        self.assertFalse(np.shares_memory(positions, J))

    def test_f_inputs_reach_the_core_in_place(self):
        """Through LocalScene's methods, C-contiguous float64 q and gradients arrive at the module
        as the caller's own buffers (the address the core reads); a float32 q is converted."""
        local, _, bodies = self.pairs['panda']
        body, count = bodies.names[0], int(bodies.vertex_counts[0])
        seen = {}
        module_scene = local._scene

        class Recorder(object):
            def __getattr__(self, name):
                def call(**fields):
                    seen.update((field, _local.buffer_address(value)) for field, value in fields.items()
                                if isinstance(value, np.ndarray) and value.dtype == np.float64)
                    return getattr(module_scene, name)(**fields)
                return call

        def address(array):
            return array.__array_interface__['data'][0]

        q, gradients = self.configurations(bodies), rng.standard_normal((K, count, 3))
        local._scene = Recorder()
        try:
            local.backprop(body, gradients, q)
            self.assertEqual((seen['q'], seen['gradients']), (address(q), address(gradients)))
            local.forward_dynamics(q=q, qdot=q[::-1].copy(), tau=q)
            self.assertEqual((seen['q'], seen['tau']), (address(q), address(q)))
            q32 = q.astype(np.float32)
            local.mass_matrix(q=q32)
            self.assertNotEqual(seen['q'], address(q32))
        finally:
            local._scene = module_scene

    def test_g_threads_share_one_scene(self):
        local, _, bodies = self.pairs['humanoid']
        body, count = bodies.names[0], int(bodies.vertex_counts[0])
        inputs = [(self.configurations(bodies), rng.standard_normal((K, count, 3))) for _ in range(16)]

        def work(item):
            q, gradients = item
            return (local.backprop(body, gradients, q), local.forward_dynamics(q=q, qdot=q, derivatives=True),
                    local.frame_jacobians(body, q=q, acceleration_bias=True, qdot=q))

        serial = [work(item) for item in inputs]
        with concurrent.futures.ThreadPoolExecutor(max_workers=4) as pool:
            for _ in range(3):
                concurrent_answers = list(pool.map(work, inputs))
                for i, (a, b) in enumerate(zip(concurrent_answers, serial)):
                    assert_same(self, a, b, 'item %d' % i)

    def test_i_torch_functions_take_either_backend(self):
        """diff_rigid_body.torch and torch_frames over a LocalScene: the node's values and gradients."""
        import torch
        from diff_rigid_body import torch as drb_torch
        from diff_rigid_body import torch_frames
        local, node, bodies = self.pairs['panda']
        body, count = bodies.names[0], int(bodies.vertex_counts[0])
        frame = bodies.links[0][-1].name
        x = self.configurations(bodies)
        losses = (
            lambda c, q: drb_torch.vertex_positions(c, body, q, vertices=list(range(0, count, 7))).sum(),
            lambda c, q: drb_torch.kinetic_energy(c, body, q, q.detach() + 0.5).sum(),
            lambda c, q: drb_torch.inverse_dynamics(c, body, q, q * 0.5, q * 0.25).sum(),
            lambda c, q: drb_torch.forward_dynamics(c, body, q, q * 0.5, q * 0.25).sum(),
            lambda c, q: sum(part.sum() for part in torch_frames.frame_pose(c, body, frame, q)),
            lambda c, q: torch_frames.center_of_mass(c, body, q).sum(),
        )
        for i, loss in enumerate(losses):
            answers = []
            for backend in (local, node):
                q = torch.tensor(x, requires_grad=True)
                value = loss(backend, q)
                value.backward()
                answers.append((value.detach().numpy(), q.grad.numpy()))
            assert_same(self, answers[0], answers[1], 'torch loss %d' % i)

    def test_h_load_refusals(self):
        with self.assertRaises(DiffRigidBodyError) as refusal:
            LocalScene(urdf='<robot name="r"><link name="a"/><joint')
        self.assertEqual(refusal.exception.service, 'load')
        with self.assertRaises(DiffRigidBodyError) as refusal:
            LocalScene(urdf_path=rospy.get_param('~panda'), bodies=['no_such_body'])
        self.assertIn('no_such_body', refusal.exception.message)
        for options in (dict(geometry='mesh'), dict(joints='rigid'), dict(gravity=(0.0, np.inf, 0.0))):
            with self.assertRaises(ValueError):
                LocalScene(urdf_path=rospy.get_param('~scene'), **options)
        with self.assertRaises(ValueError):
            LocalScene()


if __name__ == '__main__':
    rospy.init_node('local_scene_check', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'local_scene', LocalSceneAgainstNode, sys.argv)
