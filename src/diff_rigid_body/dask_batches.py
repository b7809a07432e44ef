"""K configurations of one query over a Dask cluster (``python3-distributed``), each worker
answering its shard in process with a :class:`~diff_rigid_body.local.LocalScene`:

    from distributed import Client
    from diff_rigid_body.dask_batches import SceneDescription, map_configurations
    client = Client('tcp://scheduler-host:8786')                 # or distributed.LocalCluster()
    scene = SceneDescription.from_file('robot.urdf', floating_base=True)
    result = map_configurations(client, scene, 'forward_dynamics', q=x, qdot=xd, derivatives=True)

The URDF text and the load options are scattered to the workers once per call (``broadcast``); a
worker loads the scene on first use and keeps it for later shards of the same description. The
K configurations are cut into consecutive shards of at least two configurations (so that every
shard's answer keeps its K axis), mapped to the workers, gathered in order and joined along K:
the same result type and bits as ``LocalScene(...).<method>(...)`` on all K at once, since each
configuration is computed on its own by the core. A worker lost mid-batch has its shards
recomputed elsewhere by Dask's own retries (the scheduler's ``allowed-failures``).

Per-configuration arguments are ``q`` and those of q's length (``qdot``, ``qddot``, ``tau``,
``gradients``); every other argument goes to each shard as it is. Mesh paths in the URDF must be
absolute or ``package://`` (found over each worker's ``ROS_PACKAGE_PATH``); meshes are read from
the workers' own file systems.
"""
import collections
import hashlib

import numpy as np

__all__ = ['SceneDescription', 'map_configurations', 'compute_shard', 'PER_CONFIGURATION']

#: Keyword arguments cut along K with q.
PER_CONFIGURATION = ('q', 'qdot', 'qddot', 'tau', 'gradients')
#: Most configurations in one shard by default: keeps each shard's answer within the core's request
#: limits (RequestLimits) and its transfer small, e.g. 1000 x 3711 doubles (30 MB) of forward
#: dynamics with derivatives of a 35-dof humanoid.
SHARD_CONFIGURATIONS = 1000
#: Answer fields that are per body or per frame, the same in every shard (taken from the first).
SHARED_FIELDS = ('bodies', 'frames', 'masses')


class SceneDescription(collections.namedtuple('SceneDescription', 'urdf options')):
    """What a worker needs to load the scene: the URDF XML and LocalScene's keyword options."""

    @classmethod
    def from_file(cls, path, **options):
        with open(path) as f:
            return cls(f.read(), options)

    def key(self):
        """Identifies the scene in a worker's cache."""
        return hashlib.sha1(repr((self.urdf, sorted(self.options.items()))).encode()).hexdigest()


_scenes = {}  # per worker process: SceneDescription.key() -> LocalScene


def compute_shard(description, method, arguments):
    """One shard, on a worker: ``LocalScene.<method>(**arguments)`` on the described scene."""
    from diff_rigid_body.local import LocalScene
    key = description.key()
    scene = _scenes.get(key)
    if scene is None:
        scene = _scenes[key] = LocalScene(urdf=description.urdf, **description.options)
    return getattr(scene, method)(**arguments)


def shard_bounds(configurations, shards):
    """[start, stop) of at most ``shards`` consecutive shards of K configurations, each of at
    least two (one shard when K < 4)."""
    count = max(1, min(shards, configurations // 2))
    edges = np.linspace(0, configurations, count + 1).round().astype(int)
    return list(zip(edges[:-1], edges[1:]))


def join(parts, field=None):
    """Shard answers joined along K, field by field (named tuples, tuples, per-body lists)."""
    first = parts[0]
    if first is None or field in SHARED_FIELDS or isinstance(first, (str, float, int)):
        return first
    if isinstance(first, tuple) and hasattr(first, '_fields'):
        return type(first)(*(join([getattr(p, f) for p in parts], f) for f in first._fields))
    if isinstance(first, (tuple, list)):
        return type(first)(join([p[i] for p in parts]) for i in range(len(first)))
    return np.concatenate(parts, axis=0)


def map_configurations(client, description, method, shards=None, **arguments):
    """``LocalScene.<method>(**arguments)`` for K configurations (``q`` of shape (K, ...)),
    computed in shards on the workers of ``client`` (a ``distributed.Client``): by default two
    per worker thread, and more if needed to keep each to SHARD_CONFIGURATIONS. Returns what the
    method returns for all K at once, bit for bit. A refusal raises DiffRigidBodyError (that of
    the first refused shard)."""
    q = np.asarray(arguments['q'])
    if q.ndim < 2 or q.shape[0] == 0:
        raise ValueError('q: K configurations along the first axis, got shape %s' % (q.shape,))
    if shards is None:
        shards = max(2 * max(1, sum(client.nthreads().values())), -(-q.shape[0] // SHARD_CONFIGURATIONS))
    # In a list (scatter would split a tuple); hash=False: a key of its own, which an earlier call's
    # released copy of the same description cannot take away while this call runs.
    scattered = client.scatter([description], broadcast=True, hash=False)[0]
    futures = []
    for start, stop in shard_bounds(q.shape[0], shards):
        part = {name: (np.asarray(value)[start:stop] if name in PER_CONFIGURATION and value is not None else value)
                for name, value in arguments.items()}
        futures.append(client.submit(compute_shard, scattered, method, part, pure=False))
    return join(client.gather(futures))
