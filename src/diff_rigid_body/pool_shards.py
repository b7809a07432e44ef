"""How :class:`~diff_rigid_body.pool.RigidBodyPool` cuts a K-configuration request into contiguous
shards and joins the answers, apart from the service calls.

Every sharded field travels configuration-major (configuration k's values are one contiguous run
of the same length for every k), so a shard of configurations [start, stop) is a slice of each
per-configuration request field, and the answer to the whole request is the concatenation of the
shards' per-configuration response fields in shard order. Each configuration is computed alone by
the node, so the joined answer has the bits of one instance's answer.
"""
import collections

import numpy as np

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.service_fields import parse_fields, per_configuration

#: Per sharded service: the request fields that hold K runs (one per configuration; an empty
#: field, e.g. qdot = zeros, stays empty in every shard) and the response fields that do: the
#: fields whose comment in the .srv begins with "[per configuration]" (``service_fields``).
Sharding = collections.namedtuple('Sharding', 'request response')


def _sharding(service_class):
    request, response = (per_configuration(parse_fields(part._full_text))
                         for part in (service_class._request_class, service_class._response_class))
    return Sharding(request, response) if request else None


SHARDED = {name: _sharding(service_class) for name, service_class in RigidBodyClient.SERVICES.items()
           if _sharding(service_class)}


def configuration_count(name, message, dofs):
    """K, the configurations of a request to service ``name`` that the pool may shard, or None
    (not a sharded service, q empty = the node's current state, or sizes that do not fit K: the
    node's own refusal is then the answer). ``dofs``: body name -> d, in the node's body order."""
    sharding = SHARDED.get(name)
    if sharding is None or len(message.q) == 0:
        return None
    if hasattr(message, 'body'):
        width = dofs.get(message.body, 0)
    else:
        bodies = list(message.bodies) or list(dofs)
        if any(body not in dofs for body in bodies):
            return None
        width = sum(dofs[body] for body in bodies)
    if width == 0 or len(message.q) % width:
        return None
    K = len(message.q) // width
    fields = [getattr(message, field) for field in sharding.request]
    if any(len(values) % K for values in fields):
        return None
    return K


def apportion(K, weights):
    """K configurations cut into len(weights) contiguous counts proportional to ``weights``
    (e.g. measured configurations per second): the largest-remainder rounding of
    K w_i / sum(w), so the counts sum to K. When K >= len(weights), every instance gets at least
    one configuration, taken from the largest count: an instance measured slow once (a cold start)
    is measured again, not starved."""
    weights = np.maximum(np.asarray(weights, dtype=np.float64), 0.0)
    if not np.isfinite(weights).all() or weights.sum() <= 0.0:
        weights = np.ones(len(weights))
    exact = K * weights / weights.sum()
    counts = np.floor(exact).astype(np.int64)
    remainder_order = np.argsort(-(exact - counts), kind='stable')
    counts[remainder_order[:K - int(counts.sum())]] += 1
    if K >= len(counts):
        for i in np.flatnonzero(counts == 0):
            counts[np.argmax(counts)] -= 1
            counts[i] = 1
    return [int(count) for count in counts]


def shard_message(name, message, K, start, stop):
    """A copy of request ``message`` holding configurations [start, stop) of its K: each sharded
    field's rows sliced (views, no copy), the other fields shared."""
    shard = type(message)(**{slot: getattr(message, slot) for slot in message.__slots__})
    for field in SHARDED[name].request:
        values = getattr(message, field)
        if len(values):
            setattr(shard, field, values.reshape(K, -1)[start:stop].reshape(-1))
    return shard


class JoinedResponse(object):
    """The answer to a whole request from its shards' answers, in configuration order: the
    per-configuration fields concatenated, every other field (bodies, dofs, success) the first
    shard's. Reads like the response message (attribute access)."""

    def __init__(self, name, responses):
        first = responses[0]
        for slot in first.__slots__:
            setattr(self, slot, getattr(first, slot))
        for field in SHARDED[name].response:
            if hasattr(first, field):
                setattr(self, field, np.concatenate([np.asarray(getattr(r, field)) for r in responses]))


def payload_bytes(message):
    """Bytes of the numeric arrays of a request or response (what dominates its size on the wire)."""
    return sum(getattr(message, slot).nbytes for slot in message.__slots__
               if isinstance(getattr(message, slot), np.ndarray))
