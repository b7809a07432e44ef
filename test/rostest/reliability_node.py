"""Helpers of the reliability rostests: run the real rigid_body_server binary
as a subprocess in its own namespace, with its output captured, and talk raw
TCPROS to a service.

Imported by reliability_state_file.py and reliability_node_inputs.py (the
tests' own folder is first on sys.path).
"""
import itertools
import os
import socket
import struct
import subprocess
import tempfile
import time

import roslib.packages
import rosgraph
import rospkg
import rospy

from diff_rigid_body import service_fields, srv

PKG = 'diff_rigid_body'
SCENE = os.path.join(rospkg.RosPack().get_path(PKG), 'test', 'urdf', 'reliability_scene.urdf')
DOC = os.path.join(rospkg.RosPack().get_path(PKG), 'docs', 'robustness.md')
_NUMBERS = itertools.count()  # each node gets its own namespace


class Node:
    """rigid_body_server in a fresh namespace, its output captured in a file.

    params: the node's private parameters; robot_description (text) is set in
    its namespace when given; urdf_path defaults to the reliability scene
    unless robot_description or urdf_path=None is given.
    """

    def __init__(self, params=None, robot_description=None, prefix='reliability_node'):
        self.ns = '/%s_%d_%d' % (prefix, os.getpid(), next(_NUMBERS))
        params = dict(params or {})
        if robot_description is None and 'urdf_path' not in params:
            params['urdf_path'] = SCENE
        params.setdefault('joints', 'free')  # version 1: gamma (revolute) is a free body
        for name, value in params.items():
            if value is not None:
                rospy.set_param(self.ns + '/rigid_body_server/' + name, value)
        if robot_description is not None:
            rospy.set_param(self.ns + '/robot_description', robot_description)
        self.log = tempfile.TemporaryFile(mode='w+')
        binary = roslib.packages.find_node(PKG, 'rigid_body_server')[0]
        # Line-buffered, so that ROS_INFO (stdout) is not lost when the node is stopped.
        self.process = subprocess.Popen(['stdbuf', '-oL', binary, '__ns:=' + self.ns, '__name:=rigid_body_server'],
                                        stdout=self.log, stderr=subprocess.STDOUT)

    def name(self, service):
        return self.ns + '/rigid_body_server/' + service

    def service(self, name, kind):
        return rospy.ServiceProxy(self.name(name), kind)

    def wait(self, timeout=60.0):
        """Waits until it serves every declared service (it advertises them one by one); returns
        False if it exited instead."""
        deadline = time.time() + timeout
        waiting = sorted(name for name, (_, declaration) in service_fields.declared_services(srv).items()
                         if not declaration.benchmark_only)
        while time.time() < deadline:
            if self.process.poll() is not None:
                return False
            try:
                rospy.wait_for_service(self.name(waiting[0]), timeout=0.5)
                waiting.pop(0)
                if not waiting:
                    return True
            except rospy.ROSException:
                pass
        raise AssertionError('the node neither served %s nor exited within %g s' % (', '.join(waiting), timeout))

    def exit_code(self, timeout=30.0):
        """Waits for the node to exit by itself; None if it is still running."""
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def output(self):
        self.log.seek(0)
        return self.log.read()

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(20.0)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        return self.output()


def doc_row(row_id):
    """The line of docs/robustness.md's catalogue for `row_id`, with \\| unescaped."""
    with open(DOC) as doc:
        for line in doc:
            if line.startswith('| %s |' % row_id):
                return line.replace('\\|', '|')
    return ''


def _frame(fields):
    body = b''.join(struct.pack('<I', len(f)) + f for f in fields)
    return struct.pack('<I', len(body)) + body


def _read_exact(sock, n):
    data = b''
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            raise ConnectionError('connection closed after %d of %d bytes' % (len(data), n))
        data += chunk
    return data


def raw_service_call(service_name, md5sum, request, declared_length=None, timeout=30.0):
    """Sends `request` (serialised bytes) to a service over raw TCPROS.

    Returns ('header-error', text) if the server refuses the connection
    header, ('error', text) for a service error reply (ok byte 0),
    ('ok', payload) for a response, or ('closed', text) if the server closed
    the connection. declared_length overrides the request's length prefix.
    """
    uri = rosgraph.Master('/reliability_raw').lookupService(service_name)
    host, port = uri[len('rosrpc://'):].split(':')
    sock = socket.create_connection((host, int(port)), timeout=timeout)
    try:
        sock.sendall(_frame([b'callerid=/reliability_raw', b'service=' + service_name.encode(),
                             b'md5sum=' + md5sum.encode(), b'persistent=1']))
        (length,) = struct.unpack('<I', _read_exact(sock, 4))
        header = _read_exact(sock, length)
        fields = {}
        at = 0
        while at < len(header):
            (n,) = struct.unpack('<I', header[at:at + 4])
            key, _, value = header[at + 4:at + 4 + n].decode(errors='replace').partition('=')
            fields[key] = value
            at += 4 + n
        if 'error' in fields:
            return 'header-error', fields['error']
        n = len(request) if declared_length is None else declared_length
        sock.sendall(struct.pack('<I', n) + request)
        try:
            ok = _read_exact(sock, 1)
            (length,) = struct.unpack('<I', _read_exact(sock, 4))
            payload = _read_exact(sock, length)
        except (ConnectionError, socket.timeout, OSError) as e:
            return 'closed', str(e)
        if ok == b'\x00':
            return 'error', payload.decode(errors='replace')
        return 'ok', payload
    finally:
        sock.close()


def string_field(text):
    data = text.encode()
    return struct.pack('<I', len(data)) + data
