#!/usr/bin/python3
"""diff_rigid_body.dask_batches against one in-process LocalScene (local_dask.test), on a
distributed.LocalCluster of two worker processes: forward dynamics with derivatives of the floating
humanoid and backprop and M on the Panda, mapped in shards, equal the single-process answers bit for
bit (np.array_equal); a worker that dies on its first shard of a batch (os._exit, once) is replaced
and its shard recomputed by Dask, and the answer is still the same bits.
"""
import os
import sys
import tempfile
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body import LocalScene
from diff_rigid_body.dask_batches import SceneDescription, map_configurations, shard_bounds
from local_scene_check import assert_same

rng = np.random.RandomState(30)


def kill_first_shard(marker):
    """Run on every worker: the first inverse_dynamics shard that starts anywhere creates
    ``marker`` and ends its worker process at once (the nanny starts a new one, without this
    patch); every later one runs normally. (compute_shard looks the method up on each call.)"""
    from diff_rigid_body.local import LocalScene
    compute = LocalScene.inverse_dynamics

    def dying(self, *args, **kwargs):
        try:
            os.close(os.open(marker, os.O_CREAT | os.O_EXCL))
        except FileExistsError:
            return compute(self, *args, **kwargs)
        os._exit(1)

    LocalScene.inverse_dynamics = dying


class DaskBatches(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        from distributed import Client, LocalCluster
        cls.cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
        cls.client = Client(cls.cluster)
        cls.humanoid = SceneDescription.from_file(rospy.get_param('~humanoid'), floating_base=True)
        cls.panda = SceneDescription.from_file(rospy.get_param('~panda'))

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.cluster.close()

    def local(self, description):
        return LocalScene(urdf=description.urdf, **description.options)

    def test_a_shards(self):
        self.assertEqual(shard_bounds(3, 8), [(0, 3)])
        bounds = shard_bounds(101, 8)
        self.assertEqual(len(bounds), 8)
        self.assertEqual([b[0] for b in bounds[1:]], [b[1] for b in bounds[:-1]])
        self.assertEqual((bounds[0][0], bounds[-1][1]), (0, 101))
        self.assertGreaterEqual(min(stop - start for start, stop in bounds), 2)

    def test_b_forward_dynamics_bit_for_bit(self):
        d = int(self.local(self.humanoid).bodies().dofs[0])
        q, qdot, tau = (rng.uniform(-0.8, 0.8, (203, d)) for _ in range(3))
        mapped = map_configurations(self.client, self.humanoid, 'forward_dynamics', q=q, qdot=qdot, tau=tau,
                                    derivatives=True)
        assert_same(self, mapped, self.local(self.humanoid).forward_dynamics(q=q, qdot=qdot, tau=tau,
                                                                             derivatives=True), 'forward_dynamics')

    def test_c_backprop_and_mass_matrices_bit_for_bit(self):
        local = self.local(self.panda)
        bodies = local.bodies()
        body, d, count = bodies.names[0], int(bodies.dofs[0]), int(bodies.vertex_counts[0])
        q, gradients = rng.uniform(-0.8, 0.8, (41, d)), rng.standard_normal((41, count, 3))
        assert_same(self, map_configurations(self.client, self.panda, 'backprop', body=body, gradients=gradients, q=q),
                    local.backprop(body, gradients, q), 'backprop')
        assert_same(self, map_configurations(self.client, self.panda, 'mass_matrix', q=q, derivatives=True, shards=5),
                    local.mass_matrix(q=q, derivatives=True), 'mass_matrix')

    def test_d_a_worker_killed_mid_batch(self):
        marker = os.path.join(tempfile.mkdtemp(prefix='drb_dask_'), 'killed')
        self.client.run(kill_first_shard, marker)
        d = int(self.local(self.humanoid).bodies().dofs[0])
        q, qdot = rng.uniform(-0.8, 0.8, (64, d)), rng.uniform(-0.8, 0.8, (64, d))
        mapped = map_configurations(self.client, self.humanoid, 'inverse_dynamics', q=q, qdot=qdot,
                                    derivatives=True)
        self.assertTrue(os.path.exists(marker), 'no worker was killed')
        assert_same(self, mapped, self.local(self.humanoid).inverse_dynamics(q=q, qdot=qdot, derivatives=True),
                    'inverse_dynamics')


if __name__ == '__main__':
    rospy.init_node('local_dask_check', anonymous=True)
    rostest.rosrun('diff_rigid_body', 'local_dask', DaskBatches, sys.argv)
