"""How :class:`~diff_rigid_body.client.RigidBodyClient` lays out request
fields and shapes response fields (numpy), apart from the service calls.

A body's coordinates x have d values; K configurations of n listed bodies
travel configuration-major, then body: configuration k, body i.

Every numeric array of a request travels as one buffer: :func:`wire_message`
makes each float64[]/float32[]/uint32[]/int32[] field a flat numpy array of
its wire type, which genpy's ``serialize_numpy`` (``rospy.numpy_msg``)
writes with one copy instead of packing a Python list element by element.
"""
import numpy as np

_UINT32_MAX = np.iinfo(np.uint32).max

#: numpy dtype (little-endian, as ROS serialises) of each numeric array slot type.
WIRE_DTYPES = {'float64[]': '<f8', 'float32[]': '<f4', 'uint32[]': '<u4', 'int32[]': '<i4'}


class WireArray(np.ndarray):
    """A flat contiguous numpy array that genpy's ``serialize_numpy`` writes as one buffer: the
    generated code calls ``tostring()`` (which numpy 2 no longer has); this one returns a view of
    the array's bytes, not a copy."""

    def tostring(self):
        return memoryview(np.ndarray.view(self, np.ndarray)).cast('B')


def wire_array(values, dtype):
    """``values`` flattened into a contiguous :class:`WireArray` of ``dtype`` (no copy when they
    already are a contiguous array of that dtype)."""
    return np.ascontiguousarray(values, dtype=dtype).reshape(-1).view(WireArray)


def to_wire(message):
    """Makes every numeric array field of ``message``, and of the messages in its message-array
    fields (e.g. SetState's BodyState[] states), a :class:`WireArray`; returns ``message``."""
    for slot, slot_type in zip(message.__slots__, message._slot_types):
        dtype = WIRE_DTYPES.get(slot_type)
        if dtype is not None:
            setattr(message, slot, wire_array(getattr(message, slot), dtype))
        elif slot_type.endswith('[]') and '/' in slot_type:
            for item in getattr(message, slot):
                to_wire(item)
    return message


def wire_message(message_class, fields):
    """``message_class(**fields)`` with its numeric arrays as wire buffers (:func:`to_wire`); an
    array field not given is empty."""
    return to_wire(message_class(**fields))


def floats(values):
    """A flat float64 array for a float64[] request field."""
    return wire_array(values, '<f8')


def indices(vertices):
    """A uint32[] request field of vertex indices: empty (all vertices) for None. An index that is
    negative, not a whole number or beyond uint32 raises ValueError naming it (numpy would wrap -1
    to 4294967295, which the node could only call out of range)."""
    if vertices is None:
        return wire_array([], '<u4')
    flat = np.asarray(vertices).reshape(-1)
    if flat.dtype.kind in 'ui':
        bad = (flat < 0) | (flat > _UINT32_MAX)
    elif flat.dtype.kind == 'f':
        bad = ~np.isfinite(flat) | (flat != np.floor(flat)) | (flat < 0) | (flat > _UINT32_MAX)
    else:
        bad = np.ones(flat.shape, dtype=bool)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError("vertices[%d]: %r is not a vertex index: a whole number from 0 to N - 1 (the body's vertex "
                         "count - 1); a negative index does not count from the end" % (i, flat[i].item()))
    return wire_array(flat, '<u4')


def optional_values(values):
    """An optional float64[] request field (q, qdot, qddot, tau): empty for None (the node's
    current state for q, zeros for the others), else the values flattened."""
    return wire_array([] if values is None else values, '<f8')


def vertex_configurations(q, dofs):
    """K for a vertex request's q of shape (K, d) (or K d flat values, K > 1), or None for one
    configuration (None, empty or (d,)); ``dofs()`` gives d, asked only for a flat q. A size the
    node refuses is left to the node's message."""
    if q is None:
        return None
    if np.ndim(q) >= 2:
        if np.shape(q)[0] == 0:  # an empty q would mean the current state
            raise ValueError('q: at least one configuration, got shape %s' % (np.shape(q),))
        return int(np.shape(q)[0])
    size = int(np.size(q))
    if size == 0:
        return None
    d = dofs()
    return None if d == 0 or size == d or size % d else size // d


def vertex_blocks(values, configurations, vertices, columns=None):
    """``values`` as (N, 3) (or (N, 3, columns)), with a leading K axis when ``configurations`` = K
    is not None. ``vertices`` = N."""
    shape = (vertices, 3) if columns is None else (vertices, 3, columns)
    values = np.asarray(values)
    return values.reshape(shape if configurations is None else (configurations,) + shape)


def per_body(values, dofs, configurations, power):
    """A response field of d_i^power values per body and configuration (configuration-major),
    as a list with one (K,) + (d_i,) * power array per body."""
    sizes = [d ** power for d in dofs]
    rows = np.asarray(values).reshape(configurations, sum(sizes))
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    return [rows[:, starts[i]:starts[i + 1]].reshape((configurations,) + (d,) * power)
            for i, d in enumerate(dofs)]


class AnswerShape(object):
    """How the fields of a response with ``bodies``, ``dofs`` and one ``cos_theta`` per body and
    configuration (get_mass_matrix, inverse_dynamics, forward_dynamics) are shaped for a request
    with ``q``: batched (a leading K axis) when q has 3 axes (K, n, d) or holds K > 1
    configurations; then the body axis, or a list per body when the bodies' d differ."""

    def __init__(self, response, q):
        self.n, self.dofs = len(response.bodies), [int(d) for d in response.dofs]
        self.configurations = len(response.cos_theta) // self.n if self.n else 0
        self.batched = (q is not None and np.ndim(q) == 3) or self.configurations > 1

    def field(self, values, power, asked=True):
        """A field of d_i^power values per body and configuration (:func:`body_arrays`), or None
        when it was not ``asked`` for."""
        return body_arrays(values, self.dofs, self.configurations, self.batched, power) if asked else None

    def per_body_scalars(self, values):
        """A field of one value per body and configuration: (n,), or (K, n) when batched."""
        return np.asarray(values).reshape((self.configurations, self.n) if self.batched else (self.n,))


def body_arrays(values, dofs, configurations, batched, power):
    """A response field of d_i^power values per body and configuration, shaped as ``mass_matrix``
    shapes M: (n,) + (d,) * power, with a leading K axis when ``batched``; when the bodies' d
    differ, a list with one (d_i,) * power array per body (a leading K axis when ``batched``)."""
    if len(set(dofs)) <= 1:
        d = dofs[0] if dofs else 0
        shape = ((configurations, len(dofs)) if batched else (len(dofs),)) + (d,) * power
        return np.asarray(values).reshape(shape)
    arrays = per_body(values, dofs, configurations, power)
    return arrays if batched else [array[0] for array in arrays]
