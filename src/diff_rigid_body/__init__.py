"""Python clients of rigid_body_server.

``diff_rigid_body.client``: :class:`RigidBodyClient` (numpy arrays over
persistent service connections) and :class:`DiffRigidBodyError`.
``diff_rigid_body.local``: :class:`LocalScene`, the same queries answered in process by the
node's core (``diff_rigid_body._local``), without a node.
``diff_rigid_body.pool``: :class:`RigidBodyPool` (the same methods over several
instances: K configurations sharded, failover) and :class:`PoolError`.
The example optimisers that ``nodes/demo_client.py`` runs are the package
``diff_rigid_body_examples`` (examples/), beside this one.

The generated ``diff_rigid_body.msg`` and ``diff_rigid_body.srv`` packages sit
beside these modules (catkin merges them).
"""
from pkgutil import extend_path as _extend_path

# The compiled diff_rigid_body._local and the generated msg and srv lie in the devel (or install)
# space's diff_rigid_body folder. A process started with its parent's sys.path (Dask's worker
# processes) finds this source folder first: the folders of the same name further on sys.path join
# the package here (as catkin's devel-space __init__ does).
__path__ = _extend_path(__path__, __name__)
del _extend_path

# Imported lazily so that ``import diff_rigid_body.msg`` does not need rospy's
# service machinery or numpy.


def __getattr__(name):
    if name in ('RigidBodyClient', 'DiffRigidBodyError', 'NodeNotFoundError', 'Bodies', 'MassMatrices',
                'InverseDynamicsResult', 'ForwardDynamicsResult', 'FrameJacobians', 'CenterOfMass'):
        from diff_rigid_body import client
        return getattr(client, name)
    if name == 'LocalScene':
        from diff_rigid_body import local
        return local.LocalScene
    if name in ('RigidBodyPool', 'PoolError'):
        from diff_rigid_body import pool
        return getattr(pool, name)
    raise AttributeError("module 'diff_rigid_body' has no attribute %r" % name)
