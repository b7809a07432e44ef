"""A persistent TCPROS connection to one ROS service that moves numpy buffers without copies.

The wire format is ROS's own (http://wiki.ros.org/ROS/TCPROS): a handshake header, then per call
the request as [uint32 length][fields] and the answer as [uint8 ok][uint32 length][fields], the
fields serialised by genpy's generated ``serialize_numpy``/``deserialize_numpy``. What differs from
``rospy.ServiceProxy`` is only where the bytes sit in this process:

- a request's numeric arrays go to the socket as views of the caller's numpy arrays (no
  ``BytesIO`` staging, no copy);
- an answer is received straight into one buffer of its announced size, and its arrays are views
  of that buffer (no copy either).

rospy stages both directions in a ``BytesIO`` that it shrinks to empty after every message, so
each large call maps and faults fresh pages (docs/benchmarks.md, "Client (PyTorch) trajectories",
times both transports on the same bytes). Not thread-safe:
one connection per thread.
"""
import socket
import struct

import numpy as np
import rosgraph
import rosgraph.network
import rospy

__all__ = ['ServiceConnection', 'shut_down']

_LENGTH = struct.Struct('<I')
_ANSWER_HEAD = struct.Struct('<BI')  # ok byte, answer length
_SMALL = 4096  # [bytes] chunks below this are joined before sending (fewer syscalls)


class _Chunks(object):
    """A write-only buffer for genpy's serialize_numpy: keeps the pieces (small ones joined, array
    views as they are) instead of copying them into one bytes object."""

    def __init__(self):
        self.pieces, self.small, self.size = [], [], 0

    def write(self, data):
        view = memoryview(data).cast('B')
        self.size += view.nbytes
        if view.nbytes < _SMALL:
            self.small.append(bytes(view))
        else:
            self._flush_small()
            self.pieces.append(view)

    def _flush_small(self):
        if self.small:
            self.pieces.append(b''.join(self.small))
            self.small = []

    def finish(self):
        self._flush_small()
        return self.pieces


class _Received(np.ndarray):
    """The bytes of one answer (uint8). genpy's deserialize_numpy slices it per field: a slice is a
    view (no copy), numpy.frombuffer of it too, and a string field's slice decodes like bytes."""

    def decode(self, *args):
        return self.tobytes().decode(*args)


def shut_down(sock):
    """Shuts ``sock`` down both ways, so that a call blocked on it in another thread raises (None or
    an already closed socket: nothing to do)."""
    if sock is not None:
        try:
            sock.shutdown(socket.SHUT_RDWR)
        except OSError:
            pass


class ServiceConnection(object):
    """A persistent connection to service ``name`` of type ``service_class`` (the generated srv
    class). ``call(request)`` takes a request whose numeric arrays are numpy arrays
    (client_arrays.wire_message) and returns the response with numpy arrays. Connection failures
    raise ``rospy.ServiceException`` or ``OSError``; the connection is then closed."""

    def __init__(self, name, service_class, timeout):
        self.name = name
        self.response_class = service_class._response_class
        try:
            uri = rosgraph.Master(rospy.names.get_caller_id()).lookupService(name)
        except rosgraph.MasterError as error:
            raise rospy.ServiceException('service [%s] unavailable: %s' % (name, error))
        host, port = rospy.core.parse_rosrpc_uri(uri)
        self.sock = socket.create_connection((host, port), timeout=timeout)
        try:
            self.sock.settimeout(None)
            self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.sock.sendall(rosgraph.network.encode_ros_handshake_header({
                'callerid': rospy.names.get_caller_id(), 'service': name, 'md5sum': service_class._md5sum,
                'persistent': '1'}))
            header = rosgraph.network.decode_ros_handshake_header(self._read_frame())
        except BaseException:
            self.close()
            raise
        if 'error' in header:
            self.close()
            raise rospy.ServiceException('service [%s] refused the connection: %s' % (name, header['error']))

    def call(self, request):
        if self.sock is None:
            raise rospy.ServiceException('service [%s]: the connection is closed' % self.name)
        try:
            chunks = _Chunks()
            request.serialize_numpy(chunks, np)
            pieces = chunks.finish()
            self.sock.sendall(_LENGTH.pack(chunks.size))
            for piece in pieces:
                self.sock.sendall(piece)
            head = bytearray(_ANSWER_HEAD.size)
            self._read_into(head)
            ok, size = _ANSWER_HEAD.unpack(head)
            data = np.empty(size, dtype=np.uint8).view(_Received)  # the answer's arrays will be views of it
            self._read_into(data)
        except BaseException:
            self.close()  # the stream's position is unknown: never reuse it
            raise
        if not ok:
            raise rospy.ServiceException('service [%s] responded with an error: %s' % (
                self.name, data.decode('utf-8', 'replace')))
        response = self.response_class()
        response.deserialize_numpy(data, np)
        return response

    def interrupt(self):
        """Unblocks a call in flight in another thread (it raises): shuts the socket down."""
        shut_down(self.sock)

    def close(self):
        sock, self.sock = self.sock, None
        if sock is not None:
            sock.close()

    def _read_frame(self):
        size = bytearray(_LENGTH.size)
        self._read_into(size)
        data = bytearray(_LENGTH.unpack(size)[0])
        self._read_into(data)
        return bytes(size + data)

    def _read_into(self, buffer):
        view, got = memoryview(buffer), 0
        while got < len(buffer):
            count = self.sock.recv_into(view[got:])
            if count == 0:
                raise rospy.ServiceException('service [%s]: the connection closed' % self.name)
            got += count
