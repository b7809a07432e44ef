"""A pool of rigid_body_server instances serving the same scene, used as one client.

``RigidBodyPool(['/a', '/b'])`` (namespaces, or node names such as ``'/a/rigid_body_server'``) has every method of
:class:`~diff_rigid_body.client.RigidBodyClient` (numpy arrays, the same shapes). A call of K > 1
configurations to ``mass_matrix``, ``vertex_jacobians``, ``vertex_jacobians_compact``,
``positions``, ``backprop``, ``inverse_dynamics`` or ``forward_dynamics`` is cut into contiguous
shards, one per live instance, sent concurrently; the answer is joined in configuration order and
has the bits of one instance's answer (the node computes each configuration alone).

- **Same scene.** Before serving, the pool asks every instance for ``get_bodies`` and refuses
  (:class:`PoolError`) an instance whose bodies, dofs, masses, inertias, joints or vertex counts
  differ from the first's (``fixed_frame`` may differ: each instance has its own frame prefix).
- **Failover.** An instance whose call fails (connection refused or dropped: the node died) or
  that gives no answer within ``call_timeout`` is logged by name and marked down, and its shard is
  cut again over the live instances; the call succeeds while one instance lives. With none left it
  raises :class:`PoolError` naming every instance and its failure. A refusal (``success:
  False``) is the answer, not a failure: it raises :class:`DiffRigidBodyError` at once.
- **Recovery.** A down instance is asked again (in the background, at most every
  ``retry_interval`` s) and rejoins once it answers with the same scene.
- **Shard sizes** follow each instance's measured throughput (configurations per second, per
  service, averaged over calls), so a slower host gets fewer configurations.

A call without ``q`` (the node's current state) or of one configuration goes whole to one live
instance; ``get_state`` asks one instance and ``set_state`` sets every live one (an instance that
is down meanwhile keeps its old state: pass q explicitly to a pool). Not thread-safe: one pool per
thread (it runs one worker thread per instance).
"""
import time

import numpy as np
import rospy

from diff_rigid_body.client import CONNECTION_ERRORS, DiffRigidBodyError, RigidBodyClient
from diff_rigid_body.client_names import body_names, pool_node_name
from diff_rigid_body.pool_shards import JoinedResponse, apportion, configuration_count, shard_message
from diff_rigid_body.pool_threads import Worker, wait_all
from diff_rigid_body.tcpros import shut_down

__all__ = ['RigidBodyPool', 'PoolError', 'scene_mismatch']

#: Weight of the newest measurement in an instance's throughput average.
RATE_SMOOTHING = 0.3


class PoolError(RuntimeError):
    """No instance of the pool could answer, or an instance serves another scene. ``failures``:
    server name -> what happened to it."""

    def __init__(self, message, failures=None):
        super().__init__(message)
        self.failures = dict(failures or {})


def scene_mismatch(reference, answer):
    """The first difference between two get_bodies answers that would change a pool's answers
    (bodies, dofs, masses, inertias, joints, vertex counts; bit for bit), or None."""
    for field in ('names', 'dofs', 'masses', 'inertias', 'vertex_counts', 'joint_names', 'joint_counts',
                  'link_names', 'link_vertex_counts', 'link_masses'):
        a, b = np.asarray(getattr(reference, field)), np.asarray(getattr(answer, field))
        if a.shape != b.shape or a.tobytes() != b.tobytes():
            return '%s %s, not %s' % (field, list(b), list(a))
    return None


class _Instance(object):
    """One node of the pool: its client (used by one thread at a time), whether it serves, and
    its measured throughput per service [configurations/s]."""

    def __init__(self, server, timeout):
        self.client = RigidBodyClient(server, timeout=timeout, reconnect=False)
        self.server = self.client.server
        self.worker = Worker(self.server)  # the one thread that uses self.client
        self.up = False
        self.busy = False  # a call or probe of this instance is in flight
        self.retry_at = 0.0
        self.failure = 'not connected yet'
        self.rates = {}

    def rate(self, service, default):
        return self.rates.get(service, default)

    def record(self, service, configurations, seconds):
        if configurations > 0 and seconds > 0.0:
            measured = configurations / seconds
            old = self.rates.get(service)
            self.rates[service] = measured if old is None else (1 - RATE_SMOOTHING) * old + RATE_SMOOTHING * measured

    def interrupt(self):
        """Unblocks a call in flight (its thread gets a transport error): shuts the client's
        connections down (tcpros.ServiceConnection.interrupt; for the 'rospy' transport, which
        has no call timeout, its socket)."""
        for proxy in list(self.client._proxies.values()):
            if hasattr(proxy, 'interrupt'):
                proxy.interrupt()
                continue
            shut_down(getattr(getattr(proxy, 'transport', None), 'socket', None))


class RigidBodyPool(RigidBodyClient):
    """Several instances of rigid_body_server used as one :class:`RigidBodyClient`.

    :param namespaces: the instances, each a namespace, e.g. ``'/a'`` (the node
        ``<namespace>/<server>``), or a node name, e.g. ``'/a/rigid_body_server'`` (an entry whose last
        name is ``server``); one string is one instance. The same node twice opens two connections to it.
    :param server: the node's name within each namespace.
    :param timeout: [s] how long to wait for each instance at the start.
    :param call_timeout: [s] an instance with no answer by then is down and its shard goes elsewhere.
    :param retry_interval: [s] how often a down instance is asked again.
    :param probe_timeout: [s] how long such a question waits for the instance's service.
    :param log: ``log(text)`` for failures and recoveries (default ``rospy.logwarn``).
    """

    def __init__(self, namespaces, server='rigid_body_server', timeout=30.0, call_timeout=30.0, retry_interval=5.0,
                 probe_timeout=2.0, log=None):
        names = [pool_node_name(entry, server) for entry in body_names(namespaces)]
        if not names:
            raise ValueError('RigidBodyPool: at least one namespace or node name')
        # RigidBodyClient's state, without its connections: the instances' clients hold those.
        self.server, self.timeout, self.reconnect, self._proxies = 'pool(%s)' % ', '.join(names), timeout, False, {}
        self.call_timeout, self.retry_interval, self.probe_timeout = call_timeout, retry_interval, probe_timeout
        self.log = log or rospy.logwarn
        self.instances = [_Instance(name, timeout) for name in names]
        self.scene = self._check_scenes()
        self._dofs = dict(zip(self.scene.names, (int(d) for d in self.scene.dofs)))
        for instance in self.instances:
            instance.client.timeout = probe_timeout

    # ------------------------------------------------------------------ instances
    def _check_scenes(self):
        """get_bodies of every instance (concurrently); the first answer is the scene. Unreachable
        instances start down; a different scene raises PoolError."""
        outcomes = wait_all([instance.worker.submit(instance.client.call, 'get_bodies')
                             for instance in self.instances], self.timeout + 5.0)
        scene = None
        for instance, (answer, seconds) in zip(self.instances, outcomes):
            if seconds is None or isinstance(answer, CONNECTION_ERRORS):
                self._mark_down(instance, answer if seconds is not None else 'no answer within %g s' % self.timeout)
                continue
            if isinstance(answer, Exception):
                raise answer
            difference = None if scene is None else scene_mismatch(scene, answer)
            if difference:
                raise PoolError('%s serves another scene than %s: %s' % (
                    instance.server, self._first_up().server, difference), {instance.server: difference})
            scene = scene or answer
            instance.up, instance.failure = True, None
        if scene is None:
            raise self._all_down('no instance answered get_bodies')
        return scene

    def _first_up(self):
        return next(instance for instance in self.instances if instance.up)

    def _mark_down(self, instance, failure):
        instance.up, instance.failure = False, '%s' % (failure,)
        instance.retry_at = time.monotonic() + self.retry_interval
        self.log('RigidBodyPool: instance %s is down (%s); its work goes to the others' % (
            instance.server, instance.failure))

    def _all_down(self, what):
        failures = dict((instance.server, instance.failure) for instance in self.instances)
        return PoolError('RigidBodyPool: %s; every instance is down: %s' % (
            what, '; '.join('%s: %s' % item for item in failures.items())), failures)

    def _probe(self, instance):
        """Asks a down instance for get_bodies (in a thread); it rejoins with the same scene."""
        try:
            instance.client.close()
            difference = scene_mismatch(self.scene, instance.client.call('get_bodies'))
            if difference:
                instance.failure = 'serves another scene: %s' % difference
                self.log('RigidBodyPool: instance %s %s; it stays out' % (instance.server, instance.failure))
            else:
                instance.up, instance.failure = True, None
                self.log('RigidBodyPool: instance %s is back' % instance.server)
        except CONNECTION_ERRORS + (DiffRigidBodyError,):
            pass
        finally:
            instance.retry_at = time.monotonic() + self.retry_interval
            instance.busy = False

    def _probe_down_instances(self):
        now = time.monotonic()
        for instance in self.instances:
            if not instance.up and not instance.busy and now >= instance.retry_at:
                instance.busy = True
                instance.worker.submit(self._probe, instance)

    def status(self):
        """[(server, up, last failure or None, {service: measured configurations/s})], in pool order."""
        return [(i.server, i.up, i.failure, dict(i.rates)) for i in self.instances]

    # ------------------------------------------------------------------ calls
    def connect(self, services=None):
        """Opens every live instance's persistent connections now."""
        for instance in self.instances:
            if instance.up:
                instance.client.connect(services)
        return self

    def close(self):
        for instance in self.instances:
            if not instance.busy:
                instance.client.close()

    def dofs(self, body):
        return self._dofs.get(body, 0)

    def send(self, name, message):
        """Sends request ``message`` to service ``name`` over the pool (see the module docstring)."""
        self._probe_down_instances()
        if name == 'set_state':
            return self._broadcast(name, message)
        K = configuration_count(name, message, self._dofs)
        pending = [(0, K)]  # configuration ranges still to answer; (0, None): the whole message
        answers = {}
        while pending:
            live = [instance for instance in self.instances if instance.up and not instance.busy]
            if not live:
                raise self._all_down('%s/%s failed' % (self.server, name))
            start, stop = pending.pop(0)  # one range per round: an instance has one call in flight
            pending += self._run(name, K, self._cut(name, message, K, start, stop, live), answers)
        if K is None or len(answers) == 1:
            return answers[0]
        return JoinedResponse(name, [answers[start] for start in sorted(answers)])

    def _cut(self, name, message, K, start, stop, live):
        """[(instance, start, stop, message)]: configurations [start, stop) over the live
        instances by throughput, or the whole (unsharded) message to the fastest one."""
        known = [rate for instance in live for rate in [instance.rates.get(name)] if rate]
        default = sum(known) / len(known) if known else 1.0
        weights = [instance.rate(name, default) for instance in live]
        if K is None:
            return [(live[weights.index(max(weights))], 0, None, message)]
        if len(live) == 1 and (start, stop) == (0, K):
            return [(live[0], 0, K, message)]
        pieces = []
        for instance, count in zip(live, apportion(stop - start, weights)):
            if count:
                pieces.append((instance, start, start + count, shard_message(name, message, K, start, start + count)))
                start += count
        return pieces

    def _run(self, name, K, pieces, answers):
        """Sends the pieces concurrently; stores each answer in ``answers[start]``; returns the
        [start, stop) ranges to send again (their instance failed or timed out)."""
        for instance, _, _, _ in pieces:
            instance.busy = True
        outcomes = wait_all([instance.worker.submit(self._timed_send, instance, name, shard)
                             for instance, _, _, shard in pieces], self.call_timeout)
        again = []
        for (instance, start, stop, _), (answer, seconds) in zip(pieces, outcomes):
            if seconds is None:  # still in flight: its worker clears busy when the call returns
                self._mark_down(instance, 'no answer within %g s' % self.call_timeout)
                instance.interrupt()
                again.append((start, stop))
            elif isinstance(answer, DiffRigidBodyError):
                raise self._refusal(answer, instance, start, stop, K)
            elif isinstance(answer, CONNECTION_ERRORS):
                self._mark_down(instance, answer)
                again.append((start, stop))
            elif isinstance(answer, Exception):
                raise answer
            else:
                answers[start] = answer
                instance.record(name, (stop - start) if K else 1, seconds)
        return again

    @staticmethod
    def _timed_send(instance, name, message):
        try:
            return instance.client.send(name, message)
        finally:
            instance.busy = False

    @staticmethod
    def _refusal(error, instance, start, stop, K):
        if K is None or (start, stop) == (0, K):
            return error
        return DiffRigidBodyError(error.service, '%s (pool: configurations %d..%d of the call, sent to %s as its '
                                                 'configurations 0..%d)' % (error.message, start, stop - 1,
                                                                            instance.server, stop - start - 1))

    def _broadcast(self, name, message):
        """The same request to every live instance (set_state); the first answer."""
        live = [instance for instance in self.instances if instance.up and not instance.busy]
        if not live:
            raise self._all_down('%s/%s failed' % (self.server, name))
        answers = {}
        self._run(name, None, [(instance, i, None, message) for i, instance in enumerate(live)], answers)
        if not answers:
            raise self._all_down('%s/%s failed' % (self.server, name))
        return answers[min(answers)]
