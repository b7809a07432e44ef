"""A service's one declaration, read from its .srv text: its name and client methods, what a
request and its answer hold, and which of their arrays run over the K configurations of a batched
call.

The first line names the service and the methods that wrap it, and, for a state-free query,
the SceneQueries member that answers it and that member's answer struct:

    # [service] ~get_mass_matrix; Python: mass_matrix; C++: massMatrices; core: massMatrices -> MassMatrixAnswer
    # [service] ~ping; benchmark only (advertised with ~benchmark_services:=true)

A core member takes (the current state, the request fields in the .srv's order and under their
names, the answer), and the answer struct holds the response fields but success and message.
From that the node's handler, the in-process module's method (``diff_rigid_body._local``) and
the fuzz target's call follow (``DRB_CORE_SERVICES`` in ``service_tables.h``).

The node advertises every declared service (``DIFF_RIGID_BODY_SERVICES`` in ``services.h``, from
``service_tables.h``), the Python client holds those with a Python method in its ``SERVICES``, and
the node's handler is the name in camelCase (``getMassMatrix``).

A field whose comment begins with ``[per configuration]`` holds configuration k's values as one
contiguous run of the same length for every k (configuration-major), so that configurations
[start, stop) of a request are a slice of each such request field, and the answer to a whole
request is the concatenation of its parts' such response fields. The pools shard by these
markers (``pool_shards``, ``pool_shards.h``), and the core's answer structs declare the response
fields from the same text (``service_tables.h``, written at build time by
``cmake/service_tables.py``).

Standard library only: the build runs this module before the package exists.
"""
import collections
import re

__all__ = ['Declaration', 'Field', 'PER_CONFIGURATION', 'client_order', 'declared_services', 'parse_declaration',
           'parse_fields', 'parse_service', 'per_configuration']

#: The marker that opens a per-configuration field's comment.
PER_CONFIGURATION = '[per configuration]'

#: One field: its ROS type (``float64[]``), name and whether it runs over the configurations.
Field = collections.namedtuple('Field', 'type name per_configuration')

#: A service's name (without ~), its Python and C++ client methods (None: benchmark only), and
#: the SceneQueries member that answers it with its answer struct (None: answered by the node).
Declaration = collections.namedtuple('Declaration', 'name python cpp benchmark_only core answer')

_DECLARATION = re.compile(r'^#\s*\[service\]\s*~(\w+)\s*;\s*(?:Python:\s*(\w+)\s*;\s*C\+\+:\s*(\w+)'
                          r'(?:\s*;\s*core:\s*(\w+)\s*->\s*(\w+))?|(benchmark only)(?:\s*\([^)\n]*\))?)[ \t\r]*(?:\n|$)')
_DECLARATION_MARK = re.compile(r'^#\s*\[service\]')
_FIELD = re.compile(r'^\s*([A-Za-z_][\w/]*(?:\[\d*\])?)\s+([A-Za-z_]\w*)\s*(?:#\s*(.*))?$')


def parse_declaration(text):
    """The :data:`Declaration` on the first line of a .srv text (or of a request's
    ``_full_text``), or None when it has none; ValueError for a first line that begins as a
    declaration but does not follow the form above."""
    text = text.lstrip()
    match = _DECLARATION.match(text)
    if match is None:
        if _DECLARATION_MARK.match(text):
            raise ValueError('not a service declaration (see service_fields.py): %r' % text.split('\n', 1)[0])
        return None
    name, python, cpp, core, answer, benchmark_only = match.groups()
    return Declaration(name, python, cpp, benchmark_only is not None, core, answer)


def declared_services(srv_module):
    """name -> (srv class, :data:`Declaration`) of every service class of ``srv_module`` (the
    generated ``diff_rigid_body.srv``) whose .srv declares it, in name order."""
    services = {}
    for attribute in sorted(dir(srv_module)):
        service_class = getattr(srv_module, attribute)
        request = getattr(service_class, '_request_class', None)
        declaration = parse_declaration(request._full_text) if request is not None else None
        if declaration is not None:
            services[declaration.name] = (service_class, declaration)
    return services


def parse_fields(part):
    """The fields of one part of a .srv (a request or a response, e.g. a genpy class's
    ``_full_text``), each a :data:`Field`, in order (constants and comments left out)."""
    fields = []
    for line in part.splitlines():
        match = _FIELD.match(line)
        if match is None:  # blank, a comment or a constant (uint8 WORLD=0)
            continue
        comment = match.group(3) or ''
        fields.append(Field(match.group(1), match.group(2), comment.startswith(PER_CONFIGURATION)))
    return fields


def parse_service(text):
    """(request fields, response fields) of a .srv text, each a list of :data:`Field` in order
    (constants and comments left out)."""
    request, separator, response = text.partition('\n---')
    if not separator:
        raise ValueError('not a service definition: no line "---"')
    return parse_fields(request), parse_fields(response)


def per_configuration(fields):
    """The names of the per-configuration fields, in order."""
    return tuple(field.name for field in fields if field.per_configuration)


#: The request fields that name the body or bodies of a query.
BODY_FIELDS = ('body', 'bodies')


def client_order(request):
    """A request's fields in the order the client methods take them (docs/interface.md, "Client
    argument order"): the body or bodies, then q, then the other per-configuration fields, then the
    rest (the selection and the options), each group in the .srv's order."""
    def group(field):
        if field.name in BODY_FIELDS:
            return 0
        if field.name == 'q':
            return 1
        return 2 if field.per_configuration else 3
    return sorted(request, key=group)
