"""The Dask rows of bench/local_throughput.py (its --parts dask): forward dynamics with derivatives
of the floating humanoid, K configurations, over a distributed.LocalCluster of 1 and of 2 worker
processes, against LocalScene in this process, bit for bit."""
import time

import numpy as np

from local_throughput import HUMANOID, configurations, log, same_result

REFERENCE_K = 5000  # configurations per in-process reference call of the Dask batch


def local_reference(scene, request, K):
    """forward_dynamics of all K in this process: LocalScene calls of REFERENCE_K configurations
    (one call of all K is over the core's answer limit, 25.2 M values), joined along K
    (each configuration is computed on its own: the bits of one call)."""
    from diff_rigid_body.dask_batches import join
    parts = []
    for start in range(0, K, REFERENCE_K):
        part = dict((name, value[start:start + REFERENCE_K] if name in ('q', 'qdot', 'tau') else value)
                    for name, value in request.items())
        parts.append(scene.forward_dynamics(**part))
    return join(parts)


def compute_only(client, description, request):
    """[s] map_configurations' shards computed with their answers left on the workers (no
    gather, no join): the cluster's computation and scheduling without the answer's transfer."""
    from distributed import wait
    from diff_rigid_body import dask_batches as db
    K = request['q'].shape[0]
    shards = max(2 * sum(client.nthreads().values()), -(-K // db.SHARD_CONFIGURATIONS))
    start = time.perf_counter()
    scattered = client.scatter([description], broadcast=True, hash=False)[0]
    futures = [client.submit(db.compute_shard, scattered, 'forward_dynamics',
                             dict((name, value[a:b] if name in db.PER_CONFIGURATION else value)
                                  for name, value in request.items()), pure=False)
               for a, b in db.shard_bounds(K, shards)]
    wait(futures)
    elapsed = time.perf_counter() - start
    client.cancel(futures)
    return elapsed


def measure_dask(args):
    """forward_dynamics with derivatives, K configurations of the floating humanoid, over a
    LocalCluster of n = 1 and 2 worker processes; the single-process call for reference."""
    from distributed import Client, LocalCluster
    from diff_rigid_body import LocalScene
    from diff_rigid_body.dask_batches import SceneDescription, map_configurations
    description = SceneDescription.from_file(HUMANOID, floating_base=True)
    scene = LocalScene(urdf=description.urdf, **description.options)
    d = int(sum(scene.bodies().dofs))
    q = configurations(args.dask_k, d)
    qdot, tau = np.ascontiguousarray(q[::-1] * 0.5), np.ascontiguousarray(np.roll(q, 1, axis=1))
    request = dict(q=q, qdot=qdot, tau=tau, derivatives=True)
    start = time.perf_counter()
    reference = local_reference(scene, request, args.dask_k)
    out = dict(K=args.dask_k, coordinates=d, single_process=time.perf_counter() - start,
               reference_calls=-(-args.dask_k // REFERENCE_K),
               answer_bytes=int(sum(np.asarray(x).nbytes for x in reference[1:5])))
    log('dask: in process, %d LocalScene calls: %.2f s' % (out['reference_calls'], out['single_process']))
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
                Client(cluster) as client:
            mapped = map_configurations(client, description, 'forward_dynamics', **request)  # loads the scenes
            seconds, computing = [], []
            for _ in range(args.dask_repeats):
                start = time.perf_counter()
                map_configurations(client, description, 'forward_dynamics', **request)
                seconds.append(time.perf_counter() - start)
                computing.append(compute_only(client, description, request))
            out['workers_%d' % workers] = dict(median=float(np.median(seconds)), best=float(min(seconds)),
                                               compute_only=float(np.median(computing)),
                                               same_bits=bool(same_result(mapped, reference)))
            del mapped
        log('dask: %d worker(s): %.2f s' % (workers, out['workers_%d' % workers]['median']))
    return out
