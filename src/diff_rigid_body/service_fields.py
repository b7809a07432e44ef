"""The fields of a service, read from its .srv text: the one declaration of what a request and
its answer hold, and of which of their arrays run over the K configurations of a batched call.

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

__all__ = ['Field', 'PER_CONFIGURATION', 'parse_fields', 'parse_service', 'per_configuration']

#: The marker that opens a per-configuration field's comment.
PER_CONFIGURATION = '[per configuration]'

#: One field: its ROS type (``float64[]``), name and whether it runs over the configurations.
Field = collections.namedtuple('Field', 'type name per_configuration')

_FIELD = re.compile(r'^\s*([A-Za-z_][\w/]*(?:\[\d*\])?)\s+([A-Za-z_]\w*)\s*(?:#\s*(.*))?$')


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
