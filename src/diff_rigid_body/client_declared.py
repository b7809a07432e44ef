"""Client methods that follow from a service's declaration (its .srv, ``service_fields``).

Every state-free service (a ``core:`` declaration) can be called as ``query(service, ...)``:
its request fields are the arguments, by position in the client argument order
(``service_fields.client_order``: the body or bodies, q, the other per-configuration fields, then
the rest, each group in the .srv's order) or by name, each optional (an array or name left out is
empty, a flag False, a number 0, as in an unset ROS request), and converted by type:

=============  =============================================================================
``string[]``   one name or a list of names (``client_names.body_names``)
``string``     a name (str, or bytes as UTF-8); None = ''
``float64[]``  any array-like, flattened; None = empty (for q: the node's current state)
``uint32[]``   indices (``vertices``: checked, ``client_arrays.indices``); None = empty
``bool``       anything truthy
``uint8``      a whole number 0..255, or the name of a .srv constant (``'world'`` for WORLD)
=============  =============================================================================

The answer is a named tuple, ``<SrvType>Answer``, with the response's fields but success and
message: arrays as numpy, names as lists, numbers as they are. A per-configuration field
(``[per configuration]`` in the .srv) is (K, values per configuration) when the request's q has
two or more axes (K configurations, one per row; such a q holding no value is refused, as an
empty q would mean the node's current state), else flat.

A service whose .srv declares a Python method that no hand-written method of
:class:`~diff_rigid_body.client_queries.SceneQueries` defines gets that method: ``energy(...)`` is
``query('get_energy', ...)``. Both clients, both pools (sharded by the per-configuration fields)
and :class:`~diff_rigid_body.local.LocalScene` have them. A hand-written method keeps its richer
result type. A pool shards the K-configuration services over its instances and sends the others
(get_bodies) whole to one live instance; the C++ pool answers the K-configuration ones only.

A refusal raises :class:`~diff_rigid_body.client_types.DiffRigidBodyError` as any call does; an
argument that is not a request field raises TypeError naming it, and a value its field cannot take
(a uint8 of 1.5 or 300, a q of two or more axes holding no value) ValueError naming the service and the field.
"""
import collections
import inspect

import numpy as np

from diff_rigid_body.client_arrays import indices, optional_values, wire_array
from diff_rigid_body.client_names import body_names
from diff_rigid_body.service_fields import client_order, declared_services, parse_fields

__all__ = ['DeclaredService', 'declared_core_services', 'add_declared_methods']

_STATUS_FIELDS = ('success', 'message')
_CONSTANT = '='


class DeclaredService(object):
    """One state-free service as its .srv declares it: ``name``, the Python ``method``, the
    request fields and the constants of its uint8 fields, and the answer's named tuple."""

    def __init__(self, service_class, declaration):
        request_text = service_class._request_class._full_text
        response_text = service_class._response_class._full_text
        self.name = declaration.name
        self.method = declaration.python
        self.request = client_order(parse_fields(request_text))
        self.response = [f for f in parse_fields(response_text) if f.name not in _STATUS_FIELDS]
        self.constants = _constants(request_text)
        self.answer_type = collections.namedtuple(service_class.__name__ + 'Answer',
                                                  [f.name for f in self.response])
        self.answer_type.__doc__ = '~%s: the response fields of %s.srv but success and message.' % (
            self.name, service_class.__name__)

    def signature(self):
        """The arguments: every request field, in the client argument order, defaulting to None."""
        return inspect.Signature([inspect.Parameter(f.name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=None)
                                  for f in self.request])

    def request_fields(self, args, kwargs):
        """The request's fields (name -> wire value) from a call's arguments, and the q given."""
        try:
            given = self.signature().bind(*args, **kwargs).arguments
        except TypeError as error:
            raise TypeError('%s: %s (its request fields: %s)'
                            % (self.name, error, ', '.join(f.name for f in self.request))) from None
        return {f.name: self._convert(f, given.get(f.name)) for f in self.request}, given.get('q')

    def _convert(self, field, value):
        if field.type == 'string[]':
            return body_names(value)
        if field.type == 'string':
            if isinstance(value, bytes):
                return value.decode('utf-8')
            return '' if value is None else str(value)
        if field.type == 'float64[]':
            return optional_values(value)
        if field.type == 'uint32[]':
            return indices(value) if field.name == 'vertices' else wire_array([] if value is None else value, '<u4')
        if field.type == 'bool':
            return bool(value)
        if field.type == 'uint8':
            return self._number(field, value)
        raise TypeError('%s: request field %s %s has no conversion' % (self.name, field.type, field.name))

    def _number(self, field, value):
        if value is None:
            return 0
        if isinstance(value, bytes):
            value = value.decode('utf-8', 'replace')
        if isinstance(value, str):
            if value.upper() not in self.constants:
                raise ValueError('%s: %s: one of %s, got %r'
                                 % (self.name, field.name, ', '.join(sorted(n.lower() for n in self.constants)), value))
            return self.constants[value.upper()]
        try:
            number = float(value)
        except (TypeError, ValueError, OverflowError):
            number = float('nan')  # refused below, naming the service and the field
        if not (number.is_integer() and 0 <= number <= 255):
            raise ValueError('%s: %s: %r is not a uint8 (a whole number 0 to 255)' % (self.name, field.name, value))
        return int(number)

    def answer(self, response, q):
        """The response as :attr:`answer_type`, per-configuration fields (K, -1) for a q of 2+ axes."""
        batched = q is not None and np.ndim(q) >= 2 and np.shape(q)[0] > 0
        values = []
        for field in self.response:
            value = getattr(response, field.name)
            if field.type.endswith('[]') and field.type != 'string[]':
                value = np.asarray(value)
                if batched and field.per_configuration and value.size % np.shape(q)[0] == 0:
                    value = value.reshape(np.shape(q)[0], -1)
            elif field.type == 'string[]':
                value = list(value)
            values.append(value)
        return self.answer_type(*values)

    def call(self, client, args, kwargs):
        """``client.call`` of this service with the arguments converted, its answer shaped."""
        fields, q = self.request_fields(args, kwargs)
        if q is not None and np.ndim(q) >= 2 and np.size(q) == 0:  # empty would mean the current state
            raise ValueError('%s: q: at least one configuration of at least one value, got shape %s'
                             % (self.name, np.shape(q)))
        return self.answer(client.call(self.name, **fields), q)


def _constants(text):
    """NAME -> value of the integer constants of a .srv part (``uint8 WORLD=0``)."""
    constants = {}
    for line in text.splitlines():
        code = line.split('#', 1)[0].strip()
        if _CONSTANT in code:
            declared, value = code.split(_CONSTANT, 1)
            constants[declared.split()[-1]] = int(value.strip())
    return constants


def declared_core_services(srv_module):
    """name -> :class:`DeclaredService` of every state-free service with a Python method."""
    return {name: DeclaredService(service_class, declaration)
            for name, (service_class, declaration) in declared_services(srv_module).items()
            if declaration.core and declaration.python}


def _method(service):
    def method(self, *args, **kwargs):
        return service.call(self, args, kwargs)
    method.__name__ = service.method
    method.declared_service = service.name  # generated, not written (service_registry.test)
    method.__signature__ = inspect.Signature([inspect.Parameter('self', inspect.Parameter.POSITIONAL_OR_KEYWORD)]
                                             + list(service.signature().parameters.values()))
    method.__doc__ = ("~%s (generated from its declaration, diff_rigid_body.client_declared): the request fields "
                      "%s; returns %s." % (service.name, ', '.join(f.name for f in service.request),
                                           service.answer_type.__name__))
    return method


def add_declared_methods(cls, services):
    """Gives ``cls`` the method of every service in ``services`` (:func:`declared_core_services`)
    that it does not define, and ``query(service, ...)`` for all of them."""
    for service in services.values():
        if not hasattr(cls, service.method):
            setattr(cls, service.method, _method(service))

    def query(self, service, *args, **kwargs):
        """State-free service ``service`` (e.g. 'get_mass_matrix') called with its request fields
        (module docstring of diff_rigid_body.client_declared); returns its <SrvType>Answer."""
        if service not in services:
            raise ValueError('query: %r is not a state-free service (those: %s)'
                             % (service, ', '.join(sorted(services))))
        return services[service].call(self, args, kwargs)
    cls.query = query
