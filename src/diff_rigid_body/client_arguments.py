"""One argument order for every batched call, in both backends and in torch:

    the body or bodies, then q, then the other per-configuration arrays in the request's order
    (qdot, then qddot or tau), then the selection (vertices, frames) and the options.

``backprop(body, gradients, q)`` keeps its required ``gradients`` before the optional ``q``.

Calls written in an earlier order (``inverse_dynamics(q, qdot, qddot, bodies)``,
``forward_dynamics(q, qdot, tau, bodies)``, ``frame_jacobians(body, q, frames, reference, qdot)``,
torch's ``inverse_dynamics(client, q, qdot, qddot, body)``) still work: their positional arguments
are recognised by type (arrays where the order now has names, or names where it now has arrays),
bound by their old names and a :class:`DeprecationWarning` says so. Keyword calls are never
affected.
"""
import functools
import warnings

__all__ = ['is_names', 'earlier_order', 'numbers_before_names', 'names_at']


def is_names(value):
    """Whether ``value`` reads as names: one string, or a non-empty list or tuple of strings."""
    if isinstance(value, (str, bytes)):
        return True
    return isinstance(value, (list, tuple)) and len(value) > 0 and all(isinstance(v, (str, bytes)) for v in value)


def numbers_before_names(names_index):
    """For an earlier order that began with arrays where the order now begins with names (the
    bodies): the first positional argument holds numbers, or it is None and the earlier order's
    names stand at ``names_index``."""
    def is_earlier(args):
        if args[0] is None or (isinstance(args[0], (list, tuple)) and len(args[0]) == 0):  # all, or current state
            return len(args) > names_index and is_names(args[names_index])
        return not is_names(args[0])
    return is_earlier


def names_at(index, or_value_at=None, values=()):
    """For an earlier order with names at ``index`` where the order now has an array: the argument
    there is names, or it is None and the one at ``or_value_at`` is one of ``values``."""
    def is_earlier(args):
        if len(args) <= index:
            return False
        if args[index] is None:
            return or_value_at is not None and len(args) > or_value_at and _is_one_of(args[or_value_at], values)
        return is_names(args[index])
    return is_earlier


def _is_one_of(value, values):
    try:
        return value in values
    except (TypeError, ValueError):  # an array: not one of the values
        return False


def earlier_order(names, is_earlier, leading=0):
    """Decorates a function written in the current order so that a call whose positional
    arguments after the first ``leading`` (self, a client) follow the earlier order ``names``, as
    ``is_earlier(those arguments)`` tells, is bound by those names, with a DeprecationWarning."""
    def decorate(function):
        @functools.wraps(function)
        def call(*args, **kwargs):
            moved = args[leading:]
            if not moved or not is_earlier(moved):
                return function(*args, **kwargs)
            if len(moved) > len(names):
                raise TypeError('%s() takes at most %d positional arguments in the earlier order (%s)'
                                % (function.__name__, len(names), ', '.join(names)))
            for name, value in zip(names, moved):
                if name in kwargs:
                    raise TypeError('%s() got multiple values for argument %r' % (function.__name__, name))
                kwargs[name] = value
            warnings.warn('%s(%s): this positional order is deprecated; the order is now the body or bodies, '
                          'then q and the other per-configuration arrays (or pass them by keyword)'
                          % (function.__name__, ', '.join(names[:len(moved)])), DeprecationWarning, stacklevel=2)
            return function(*args[:leading], **kwargs)
        return call
    return decorate
