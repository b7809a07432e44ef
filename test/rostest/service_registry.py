#!/usr/bin/python3
"""The service registry (DIFF_RIGID_BODY_SERVICES of include/diff_rigid_body_ros/services.h, written
from the first line of each .srv into service_tables.h) against everything that must agree with it
(service_registry.test):

- the running node advertises exactly the registry's services: without
  ~benchmark_services the others, with it all of them;
- every srv type is a file in srv/, listed in CMakeLists.txt's
  DRB_SERVICE_FILES (add_service_files and service_tables.h) and included by services.h (through
  the generated service_messages.h);
- the Python client (RigidBodyClient) has each service in SERVICES, with its
  srv type, and a method that calls it (written, or generated from the declaration:
  client_declared.py);
- the C++ client header declares each C++ method, and calls the service with
  its srv type, unless the method is generated from the declaration (DRB_CLIENT_METHODS,
  client_declared.h);
- README.md has a row for each service in its Services table (and none for a
  service that is not in the registry), a row for each Python method in the
  Python client's method table and one for each C++ method in the C++ one.
A service without a client method (`none`) must be benchmark-only.
Every service that takes K configurations (a request field `float64[] q`) is in both pools'
sharding tables (pool_shards.py from the srv classes, service_tables.h generated from srv/*.srv),
sharding every float array of its request and every per-configuration float array of its answer:
a .srv field without its "[per configuration]" marker would silently stop being split across
instances.
Every service a core member answers (DRB_CORE_SERVICES, `core:` in its declaration) declares its
answer struct in scene_queries.h from its own response fields, so that the node and the in-process
module move exactly the response's fields, and its SceneQueries member takes the request's fields
under their names and in the .srv's order (every binding passes them by position). The node
answers the other services itself; the in-process module (_local.SERVICES) answers exactly the
core ones.
GetBodies.srv and BodyState.msg comment every field in the user's terms, `rossrv show -r` prints the
comments, and README.md names that command.
"""
import inspect
import os
import re
import subprocess
import time
import unittest

import rosgraph
import rospkg
import rostest

from diff_rigid_body import service_fields
from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.pool_shards import SHARDED

PKG = 'diff_rigid_body'
SERVER = '/rigid_body_server'              # ~benchmark_services unset
BENCH_SERVER = '/rigid_body_server_bench'  # ~benchmark_services:=true
WAIT = 60.0                                # [s] for the nodes to come up
ROSCPP_SERVICES = {'get_loggers', 'set_logger_level'}  # roscpp's own, on every node

ENTRY = re.compile(r'^\s*X\(\s*(\w+)\s*,\s*(\w+)\s*,\s*(\w+)\s*,\s*(\w+)\s*,\s*(\w+)\s*,\s*(true|false)\s*\)', re.M)
FIELDS = ('name', 'srv_type', 'handler', 'python_method', 'cpp_method', 'benchmark_only')
CORE_ROW = re.compile(r'X\((\w+), (\w+), (\w+), (\w+), (\w+)\)')  # DRB_CORE_SERVICES' rows
CPP_SHARDING = re.compile(r'X\((\w+), \(([^)]*)\), \(([^)]*)\)\)')  # DRB_SHARDED_SERVICES' rows
PER_BODY_FIELDS = {'masses'}  # answer arrays of one value per body, the same in every shard


def package_file(*parts):
    return os.path.join(rospkg.RosPack().get_path(PKG), *parts)


def generated_service_tables(name='service_tables.h'):
    """The text of service_tables.h (or of service_messages.h), generated from srv/*.srv into the
    devel (or install) space."""
    for prefix in os.environ.get('CMAKE_PREFIX_PATH', '').split(os.pathsep):
        path = os.path.join(prefix, 'include', PKG, 'services', name)
        if prefix and os.path.isfile(path):
            with open(path) as f:
                return f.read()
    raise AssertionError('%s is in no include/%s/services of CMAKE_PREFIX_PATH' % (name, PKG))


def read(*parts):
    with open(package_file(*parts)) as f:
        return f.read()


def registry():
    """The entries of DIFF_RIGID_BODY_SERVICES (services.h, from the generated service_tables.h), as
    dicts, in order."""
    text = generated_service_tables()
    body = text[text.index('#define DIFF_RIGID_BODY_SERVICES'):]
    body = body[:body.index('\n\n')]
    entries = [dict(zip(FIELDS, match)) for match in ENTRY.findall(body)]
    for entry in entries:
        entry['benchmark_only'] = entry['benchmark_only'] == 'true'
    return entries


def markdown_section(text, heading):
    """The lines of `text` from the line `heading` to the next heading of the same or a higher level."""
    lines = text.splitlines()
    start = lines.index(heading)
    level = len(heading) - len(heading.lstrip('#'))
    in_code = False
    for end in range(start + 1, len(lines)):
        if lines[end].startswith('```'):
            in_code = not in_code
        stripped = lines[end].lstrip('#')
        if not in_code and lines[end].startswith('#') and len(lines[end]) - len(stripped) <= level \
                and stripped.startswith(' '):
            return lines[start:end]
    return lines[start:]


def table_keys(lines, pattern):
    """First-column matches of `pattern` in the markdown table rows among `lines`."""
    keys = []
    for line in lines:
        match = re.match(r'^\|\s*' + pattern, line)
        if match:
            keys.append(match.group(1))
    return keys


def advertised(node):
    """The names (private, without the node's prefix) of the services `node` provides."""
    _, _, services = rosgraph.Master('/service_registry_test').getSystemState()
    return {name[len(node) + 1:] for name, providers in services
            if node in providers and name.startswith(node + '/')} - ROSCPP_SERVICES


def wait_until_serving(node):
    """Waits until `node` has subscribed to ~set_states, which it does after advertising every service."""
    deadline = time.time() + WAIT
    topic = node + '/set_states'
    while time.time() < deadline:
        _, subscriptions, _ = rosgraph.Master('/service_registry_test').getSystemState()
        if any(name == topic and node in nodes for name, nodes in subscriptions):
            return
        time.sleep(0.1)
    raise AssertionError('%s did not subscribe to %s within %g s' % (node, topic, WAIT))


class ServiceRegistry(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.entries = registry()

    def test_registry_is_well_formed(self):
        names = [e['name'] for e in self.entries]
        self.assertGreaterEqual(len(names), 9, 'services.h: fewer entries than the 9 services of srv/: %s' % names)
        self.assertEqual(len(names), len(set(names)), 'services.h: a service is listed twice: %s' % names)
        for e in self.entries:
            for side in ('python_method', 'cpp_method'):
                if e[side] == 'none':
                    self.assertTrue(e['benchmark_only'], 'services.h: %s has no %s but is not benchmark-only'
                                    % (e['name'], side))

    def test_node_advertises_exactly_the_registry(self):
        for node, with_benchmark in ((SERVER, False), (BENCH_SERVER, True)):
            wait_until_serving(node)
            expected = {e['name'] for e in self.entries if with_benchmark or not e['benchmark_only']}
            actual = advertised(node)
            self.assertEqual(actual - expected, set(), '%s advertises services not in services.h' % node)
            self.assertEqual(expected - actual, set(), '%s does not advertise services of services.h' % node)

    def test_srv_files(self):
        cmake = read('CMakeLists.txt')
        listed = ' '.join(re.findall(r'set\(DRB_SERVICE_FILES([^)]*)\)', cmake)).split()
        self.assertIn('#include "diff_rigid_body/services/service_messages.h"',
                      read('include', 'diff_rigid_body_ros', 'services.h'))
        header = generated_service_tables('service_messages.h')
        for e in self.entries:
            srv = e['srv_type'] + '.srv'
            self.assertTrue(os.path.isfile(package_file('srv', srv)), '%s: srv/%s does not exist' % (e['name'], srv))
            self.assertIn(srv, listed, '%s: %s is not in DRB_SERVICE_FILES (CMakeLists.txt)' % (e['name'], srv))
            self.assertIn('#include <diff_rigid_body/%s.h>' % e['srv_type'], header,
                          'service_messages.h does not include the srv header of %s' % e['name'])

    def test_python_client_wraps_every_service(self):
        wrapped = {e['name'] for e in self.entries if e['python_method'] != 'none'}
        self.assertEqual(set(RigidBodyClient.SERVICES), wrapped,
                         'RigidBodyClient.SERVICES (client.py) differs from the services.h entries with a python method')
        for e in self.entries:
            if e['python_method'] == 'none':
                continue
            self.assertEqual(RigidBodyClient.SERVICES[e['name']]._type, '%s/%s' % (PKG, e['srv_type']),
                             'client.py: SERVICES[%r] has the wrong srv type' % e['name'])
            method = getattr(RigidBodyClient, e['python_method'], None)
            self.assertTrue(callable(method), 'client.py: RigidBodyClient has no method %s() for %s'
                            % (e['python_method'], e['name']))
            if getattr(method, 'declared_service', None) == e['name']:
                continue  # generated from the declaration (client_declared.py)
            self.assertIn("'%s'" % e['name'], inspect.getsource(method),
                          'client.py: RigidBodyClient.%s() does not call %s' % (e['python_method'], e['name']))

    def test_cpp_client_wraps_every_service(self):
        header = read('include', 'diff_rigid_body_ros', 'rigid_body_client.h')
        requests = header + ''.join(read('include', 'diff_rigid_body_ros', name)  # built there or here
                                    for name in ('client_requests.h', 'client_frames.h'))
        tables = generated_service_tables()
        generated = set(re.findall(r'X\((\w+), (\w+)\)', tables[tables.index('#define DRB_CLIENT_METHODS'):]))
        self.assertIn('DeclaredQueries<RigidBodyClient>', header, 'RigidBodyClient has no generated methods')
        for e in self.entries:
            if e['cpp_method'] == 'none':
                continue
            if (e['srv_type'], e['cpp_method']) in generated:
                continue  # generated from the declaration (client_declared.h), or hand-written and hiding it
            # A line "<return type> method(" (a type may hold spaces and commas; a call starts with return).
            declaration = r'^[ \t]*(?!return\b)[^;=(/\n]*[\w>&*][ \t]+%s[ \t]*\(' % e['cpp_method']
            self.assertTrue(re.search(declaration, header, re.M),
                            'rigid_body_client.h: RigidBodyClient declares no %s() for %s'
                            % (e['cpp_method'], e['name']))
            self.assertIn('"%s"' % e['name'], header, 'rigid_body_client.h never calls %s' % e['name'])
            built = re.search(r'diff_rigid_body::%s srv\b|requestOf<diff_rigid_body::%s>' % (e['srv_type'], e['srv_type']),
                              requests)
            self.assertTrue(built,
                            'rigid_body_client.h (with client_requests.h, client_frames.h) never builds a diff_rigid_body::%s for %s'
                            % (e['srv_type'], e['name']))

    def test_pools_shard_every_batched_service(self):
        names = {e['srv_type']: e['name'] for e in self.entries}
        cpp = {names[srv]: (set(re.findall(r'&Request::(\w+)', request)), set(re.findall(r'&Response::(\w+)', response)))
               for srv, request, response in CPP_SHARDING.findall(generated_service_tables())}
        python = {name: (set(s.request), set(s.response)) for name, s in SHARDED.items()}
        batched = set()
        for e in self.entries:
            request, _, response = read('srv', e['srv_type'] + '.srv').partition('\n---')
            arrays = [set(re.findall(r'^float(?:64|32)\[\]\s+(\w+)', part, re.M)) for part in (request, response)]
            if 'q' not in arrays[0]:
                continue
            batched.add(e['name'])
            wanted = (arrays[0], arrays[1] - PER_BODY_FIELDS)
            for table, entries in (('pool_shards.py SHARDED', python), ('service_tables.h', cpp)):
                self.assertIn(e['name'], entries, '%s: no sharding for %s' % (table, e['name']))
                self.assertEqual(entries[e['name']], wanted, '%s: the sharded fields of %s' % (table, e['name']))
        for table, entries in (('pool_shards.py SHARDED', python), ('service_tables.h', cpp)):
            self.assertEqual(set(entries) - batched, set(), '%s shards services without a q' % table)

    def test_core_services_declare_their_answers_from_their_responses(self):
        text = generated_service_tables()
        table = text[text.index('#define DRB_CORE_SERVICES'):]
        rows = CORE_ROW.findall(table[:table.index('\n\n')])
        self.assertGreaterEqual(len(rows), 9, 'DRB_CORE_SERVICES: %s' % (rows,))
        header = read('include', PKG, 'services', 'scene_queries.h')
        for srv, name, _, member, answer in rows:
            self.assertRegex(header, r'struct %s\s*\{\s*DRB_ANSWER\(DRB_%s_RESPONSE_FIELDS\)' % (answer, srv),
                             '~%s: %s is not declared from %s.srv\'s response' % (name, answer, srv))
            self.assertRegex(header, r'void %s\([^;]*%s& answer\) const' % (member, answer),
                             '~%s: no SceneQueries::%s(..., %s& answer)' % (name, member, answer))
        from diff_rigid_body import _local
        self.assertEqual(set(_local.SERVICES), {name for _, name, _, _, _ in rows})

    def test_core_members_take_the_request_fields_in_srv_order(self):
        """The node, the in-process module, the fuzz target and the C++ client pass a core
        service's request fields by position: the member's parameters must be the .srv's request
        fields, named alike and in the same order (two fields of one type could swap unseen)."""
        text = generated_service_tables()
        table = text[text.index('#define DRB_CORE_SERVICES'):]
        header = read('include', PKG, 'services', 'scene_queries.h')
        for srv, name, _, member, answer in CORE_ROW.findall(table[:table.index('\n\n')]):
            pattern = r'void %s\(const SceneState& current((?:,[^;{,]+)*),\s*%s& answer\) const' % (member, answer)
            declared = re.search(pattern, header)
            self.assertIsNotNone(declared, '~%s: no SceneQueries::%s(current, ..., %s& answer)'
                                 % (name, member, answer))
            parameters = [re.search(r'(\w+)\s*$', p).group(1) for p in declared.group(1).split(',')[1:]]
            request, _ = service_fields.parse_service(read('srv', srv + '.srv'))
            self.assertEqual(parameters, [f.name for f in request],
                             '~%s: SceneQueries::%s\'s parameters against %s.srv\'s request fields'
                             % (name, member, srv))

    def test_readme_services_table(self):
        rows = table_keys(markdown_section(read('README.md'), '### Services'), r'`~(\w+)`')
        self.assertEqual(len(rows), len(set(rows)), 'README.md Services table: a service has two rows: %s' % rows)
        names = {e['name'] for e in self.entries}
        self.assertEqual(names - set(rows), set(), 'README.md Services table: no row for these services')
        self.assertEqual(set(rows) - names, set(), 'README.md Services table: rows for services not in services.h')

    def test_readme_client_tables(self):
        readme = read('README.md')
        for heading, side, pattern in (('### Python: `diff_rigid_body.client`', 'python_method', r'`(\w+)\('),
                                       ('### C++: `include/diff_rigid_body_ros/rigid_body_client.h`', 'cpp_method',
                                        r'`(\w+)(?:<\w+>)?\(')):
            rows = set(table_keys(markdown_section(readme, heading), pattern))
            for e in self.entries:
                if e[side] != 'none':
                    self.assertIn(e[side], rows, 'README.md, %s: no method-table row for %s() (service %s)'
                                  % (heading, e[side], e['name']))

    def test_field_comments_say_what_fields_mean(self):
        """GetBodies.srv's response and BodyState.msg comment every field, in the user's terms, and
        `rossrv show -r` (which the README names; plain `rossrv show` strips comments) prints them."""
        wanted = {
            ('srv', 'GetBodies'): {'names': ['root link'], 'masses': ['total'],
                                   'inertias': ["root link's group", 'about its own COM'],
                                   'com_offsets': ["root link's group", 'root link frame']},
            ('msg', 'BodyState'): {'name': ['root link'], 'q': []},
        }
        for (kind, name), phrases in wanted.items():
            text = read(kind, name + '.' + kind)
            fields = text.split('---')[-1] if kind == 'srv' else text
            for line in fields.splitlines():
                if line.strip() and not line.startswith('#') and line.split()[1] not in ('success', 'message'):
                    self.assertIn('#', line, '%s/%s.%s: field without a comment: %s' % (kind, name, kind, line))
            for field, fragments in phrases.items():
                line = next(l for l in fields.splitlines() if re.match(r'^\S+\s+%s\b' % field, l))
                for fragment in fragments:
                    self.assertIn(fragment, line, '%s.%s, field %s: its comment should say %r'
                                  % (name, kind, field, fragment))
            shown = subprocess.run(['ros%s' % kind, 'show', '-r', '%s/%s' % (PKG, name)], stdout=subprocess.PIPE,
                                   universal_newlines=True, check=True).stdout
            self.assertIn(text.strip().splitlines()[0], shown, 'ros%s show -r does not print the comments' % kind)
        body_state = read('msg', 'BodyState.msg')
        for fragment in ('CENTRE OF MASS', 'fixed frame', 'NOT of the root', 'com_offsets'):
            self.assertIn(fragment, body_state, 'BodyState.msg: a free body\'s t should be explained: %r' % fragment)
        readme = read('README.md')
        for command in ('rossrv show -r diff_rigid_body/GetBodies', 'rosmsg show -r diff_rigid_body/BodyState'):
            self.assertIn(command, readme, 'README.md does not show `%s`' % command)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'service_registry', ServiceRegistry)
