#!/usr/bin/env python3
"""Writes service_tables.h, the C++ side of each service's one declaration (its .srv file), at
configure time, and service_messages.h beside it: ``service_tables.py <output header> <srv file>...``.

From each .srv's declaration (diff_rigid_body.service_fields), in the order of the arguments:
    DIFF_RIGID_BODY_SERVICES(X)     X(name, Type, node handler, Python method, C++ method,
                                      benchmark only), `none` for a benchmark-only service's methods
    DRB_<Type>_RESPONSE_FIELDS(X)   X(C++ type, name) for each response field but success, message
                                    (services whose response fields are all plain values or arrays)
    DRB_<Type>_REQUEST_FIELDS(X)    X(C++ type, name) for each request field (core services only)
    DRB_<Type>_CLIENT_FIELDS(X)     the same in the client methods' argument order (core services only;
                                    service_fields.client_order)
    DRB_CORE_SERVICES(X)            X(Type, name, node handler, SceneQueries member, answer struct)
                                    for the services whose declaration names a core member
    DRB_SHARDED_SERVICES(X)         X(Type, (&Request::field, ...), (&Response::field, ...)) for the
                                    services with per-configuration fields
    DRB_CLIENT_METHODS(X)           X(Type, C++ method) for the services of DRB_CORE_SERVICES with a
                                    C++ method (the clients' generated methods, client_declared.h)

The header is ROS-free (macros only). Its readers: the node advertises from
DIFF_RIGID_BODY_SERVICES (services.h); the core declares its answer structs with
DRB_<Type>_RESPONSE_FIELDS (scene_queries.h), which the in-process module (local_scene_queries.cpp)
and the fuzz target (fuzz_declared_services.h) also read to convert and check the answers; the
node, the in-process module and the fuzz target bind the core members with DRB_CORE_SERVICES and
DRB_<Type>_REQUEST_FIELDS; the C++ clients build
their requests with DRB_<Type>_REQUEST_FIELDS and DRB_<Type>_CLIENT_FIELDS (client_requests.h);
the C++ pool shards with DRB_SHARDED_SERVICES (pool_shards.h); and both C++ clients name their
generated methods with DRB_CLIENT_METHODS (client_declared.h). It is rewritten only when its text
changes.
"""
import importlib.util
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
_spec = importlib.util.spec_from_file_location(
    'service_fields', os.path.join(HERE, '..', 'src', 'diff_rigid_body', 'service_fields.py'))
service_fields = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(service_fields)

CPP_TYPES = {'bool': 'bool', 'string': 'std::string', 'uint8': 'std::uint8_t', 'uint32': 'std::uint32_t',
             'int32': 'std::int32_t', 'float32': 'float', 'float64': 'double'}
STATUS_FIELDS = ('success', 'message')
#: The request field types a core service's bindings convert: the in-process module's LocalField and
#: keyword (src/python/local_scene_queries.cpp) and the fuzz target's fuzzField.
CORE_REQUEST_TYPES = ('string', 'string[]', 'float64[]', 'uint32[]', 'bool', 'uint8')
#: The answer field types the in-process module's toPython converts.
CORE_ANSWER_TYPES = ('string', 'string[]', 'float64[]', 'float32[]', 'uint32[]', 'int32[]', 'uint32')
#: Names the binding macros use for their own locals, so no request field may take them:
#: rigid_body_server.cpp, local_scene_queries.cpp, fuzz_declared_services.h, client_requests.h.
#: (Request field names are lower_case, so the bindings' camelCase helpers cannot clash either.)
BINDING_NAMES = ('answer', 'current', 'in', 'index', 'queries', 'r', 'request', 'response', 'self', 'serve', 'service',
                 'srv')
LOWER_CASE = re.compile(r'^[a-z][a-z0-9_]*$')
WIDTH = 118  # the column of the line continuations


def cpp_type(ros_type):
    """The C++ type of a plain ROS field type (``float64[]`` -> ``std::vector<double>``), or None."""
    if ros_type.endswith('[]'):
        element = CPP_TYPES.get(ros_type[:-2])
        return None if element is None else 'std::vector<%s>' % element
    return CPP_TYPES.get(ros_type)


def macro(name, lines):
    body = ['#define %s' % name] + ['  %s' % line for line in lines]
    return ''.join(text.ljust(WIDTH) + ' \\\n' for text in body[:-1]) + body[-1] + '\n'


def fields_macro(name, fields):
    """``#define name(X)`` with X(C++ type, field) per field; '' when a field is not plain."""
    types = [cpp_type(f.type) for f in fields]
    if not fields or None in types:
        return ''
    return macro(name, ['X(%s, %s)' % (t, f.name) for t, f in zip(types, fields)])


def response_macro(service, response):
    return fields_macro('DRB_%s_RESPONSE_FIELDS(X)' % service, [f for f in response if f.name not in STATUS_FIELDS])


def check_core_fields(service, request, response):
    """Refuses, naming the field, what a core service's bindings cannot pass or convert."""
    answer = [f for f in response if f.name not in STATUS_FIELDS]
    for part, fields, types in (('request', request, CORE_REQUEST_TYPES), ('response', answer, CORE_ANSWER_TYPES)):
        for f in fields:
            if f.type not in types:
                raise ValueError('%s.srv: %s field %s %s: a core service\'s %s fields are of the types %s'
                                 % (service, part, f.type, f.name, part, ', '.join(types)))
    if not answer:
        raise ValueError('%s.srv: a core service answers with at least one field beside success and message'
                         % service)
    for f in request:
        if f.name in BINDING_NAMES or f.name.endswith('_held') or not LOWER_CASE.match(f.name):
            raise ValueError('%s.srv: request field %s: a core service\'s request fields are lower_case and not '
                             'named as the bindings\' locals (%s, *_held)' % (service, f.name, ', '.join(BINDING_NAMES)))


def core_row(service, declaration, request, response):
    """The DRB_CORE_SERVICES row of a service answered by a core member, and its request macros
    (X per request field, in the .srv's order and in the client order; none for a request
    without fields)."""
    check_core_fields(service, request, response)
    request_macro = ''.join(
        fields_macro('DRB_%s_%s_FIELDS(X)' % (service, kind), fields) if fields
        else macro('DRB_%s_%s_FIELDS(X)' % (service, kind), [])
        for kind, fields in (('REQUEST', request), ('CLIENT', service_fields.client_order(request))))
    return 'X(%s, %s, %s, %s, %s)' % (service, declaration.name, camel_case(declaration.name), declaration.core,
                                      declaration.answer), request_macro


def sharded_row(service, request, response):
    ours = [service_fields.per_configuration(part) for part in (request, response)]
    if not ours[0]:
        return None
    return 'X(%s, (%s), (%s))' % (service, ', '.join('&Request::' + n for n in ours[0]),
                                  ', '.join('&Response::' + n for n in ours[1]))


def camel_case(name):
    """get_mass_matrix -> getMassMatrix (the node's handler of a service)."""
    first, *rest = name.split('_')
    return first + ''.join(word.capitalize() for word in rest)


def registry_row(service, declaration):
    return 'X(%s, %s, %s, %s, %s, %s)' % (declaration.name, service, camel_case(declaration.name),
                                         declaration.python or 'none', declaration.cpp or 'none',
                                         'true' if declaration.benchmark_only else 'false')


def header(srv_files):
    parts = ['// Generated by cmake/service_tables.py from srv/*.srv at configure time: do not edit.\n'
             '// See that script for what each macro holds.\n#pragma once\n']
    registry, sharded, core, methods = [], [], [], []
    for path in srv_files:
        service = os.path.splitext(os.path.basename(path))[0]
        with open(path) as f:
            text = f.read()
        declaration = service_fields.parse_declaration(text)
        if declaration is None:
            raise ValueError('%s: its first line does not declare the service ("# [service] ~name; ...")' % path)
        registry.append(registry_row(service, declaration))
        request, response = service_fields.parse_service(text)
        parts.append(response_macro(service, response))
        if declaration.core:
            row, request_macro = core_row(service, declaration, request, response)
            core.append(row)
            parts.append(request_macro)
            if declaration.cpp:
                methods.append('X(%s, %s)' % (service, declaration.cpp))
        row = sharded_row(service, request, response)
        if row:
            sharded.append(row)
    parts.insert(1, macro('DIFF_RIGID_BODY_SERVICES(X)', registry))
    parts.append(macro('DRB_CORE_SERVICES(X)', core))
    parts.append(macro('DRB_SHARDED_SERVICES(X)', sharded))
    parts.append(macro('DRB_CLIENT_METHODS(X)', methods))
    return '\n'.join(part for part in parts if part)


def messages_header(srv_files):
    """service_messages.h: the services' message headers (diff_rigid_body/<Type>.h) and the tables."""
    lines = ['// Generated by cmake/service_tables.py from srv/*.srv at configure time: do not edit.',
             '// Every service\'s request and response types, and service_tables.h.', '#pragma once', '']
    lines += sorted('#include <diff_rigid_body/%s.h>' % os.path.splitext(os.path.basename(path))[0]
                    for path in srv_files)
    return '\n'.join(lines + ['', '#include "diff_rigid_body/services/service_tables.h"', ''])


def write_if_changed(path, text):
    if os.path.exists(path):
        with open(path) as f:
            if f.read() == text:
                return
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w') as f:
        f.write(text)


def main(output, *srv_files):
    try:
        text = header(srv_files)
    except ValueError as error:
        sys.stderr.write('service_tables.py: %s\n' % error)
        return 1
    write_if_changed(output, text)
    write_if_changed(os.path.join(os.path.dirname(output), 'service_messages.h'), messages_header(srv_files))
    return 0


if __name__ == '__main__':
    if len(sys.argv) < 3:
        sys.exit('usage: service_tables.py <output header> <srv file>...')
    sys.exit(main(*sys.argv[1:]))
