#!/usr/bin/python3
"""The durable-state cycle (reliability_respawn.test).

server.launch runs rigid_body_server with respawn:=true and a ~state_file.
This test streams set_state calls from a thread, kills the node with SIGKILL
in the middle of the stream, waits for roslaunch to respawn it, and checks
that the restored state equals the last acknowledged one bit for bit.
A last cycle kills the node after the stream has stopped, when the
restored state must be exactly the last acknowledged one.

A call that was in flight when the node died was never acknowledged; the
node may or may not have saved it before it died (it saves before it
answers). So the restored state must be the last acknowledged state or, only
if a call was cut off, that call's state; anything else (the URDF state, an
older state, a mix) fails. The cycle runs ~cycles times.

Private parameters: ~state_file (the node's), ~cycles (default 2),
~min_acks (acknowledged calls before the kill, default 200).
"""
import os
import random
import signal
import struct
import sys
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from diff_rigid_body.msg import BodyState
from diff_rigid_body.srv import GetState, SetState

PKG = 'diff_rigid_body'
NODE = '/rigid_body_server'


def node_pid(node):
    """The pid of a running node, from its XML-RPC API; None while it is not registered."""
    master = rosgraph.Master('/reliability_respawn')
    try:
        uri = master.lookupNode(node)
        code, _, pid = xmlrpc.client.ServerProxy(uri).getPid('/reliability_respawn')
        return pid if code == 1 else None
    except Exception:  # not registered yet, or the registered API is dead
        return None


def bits(states):
    """Names and the exact IEEE bits of every q."""
    return [(s.name, struct.pack('<6d', *s.q)) for s in states]


def awkward_q(rng, k):
    """Values that need every bit: random mantissas, -0.0, subnormals, large magnitudes."""
    q = [rng.uniform(-4.0, 4.0) for _ in range(6)]
    q[5] = float(k)  # also says which call it was
    if k % 7 == 0:
        q[0] = -0.0
    if k % 11 == 0:
        q[1] = 5e-324 * (k + 1)
    if k % 13 == 0:
        q[3] = rng.uniform(-1.0, 1.0) * 1e12
    return q


class Streamer(threading.Thread):
    """Calls set_state back to back over one persistent connection until it fails."""

    def __init__(self, names, seed, max_acks=None):
        super().__init__(daemon=True)
        self.max_acks = max_acks
        self.names = names
        self.rng = random.Random(seed)
        self.acks = 0
        self.last_acked = None   # states of the last acknowledged call
        self.cut_off = None      # states of the call that failed, if any
        self.error = None

    def run(self):
        proxy = rospy.ServiceProxy(NODE + '/set_state', SetState, persistent=True)
        k = 0
        while self.max_acks is None or self.acks < self.max_acks:
            states = [BodyState(name=name, q=awkward_q(self.rng, k)) for name in self.names]
            try:
                response = proxy(states=states)
            except Exception as e:  # the node died under the call
                self.cut_off = states
                self.error = e
                return
            if not response.success:
                self.error = RuntimeError('set_state refused: ' + response.message)
                return
            self.last_acked = states
            self.acks += 1
            k += 1


class Respawn(unittest.TestCase):

    def wait_for_node(self, old_pid, timeout=60.0):
        deadline = time.time() + timeout
        while time.time() < deadline:
            pid = node_pid(NODE)
            if pid is not None and pid != old_pid:
                rospy.wait_for_service(NODE + '/get_state', timeout=max(1.0, deadline - time.time()))
                return pid
            time.sleep(0.1)
        self.fail('the node was not respawned within %g s' % timeout)

    def get_state(self):
        return rospy.ServiceProxy(NODE + '/get_state', GetState)(bodies=[]).states

    def test_restored_state_is_last_acknowledged(self):
        state_file = rospy.get_param('~state_file')
        def remove_files():
            folder, base = os.path.split(state_file)
            for name in os.listdir(folder):
                if name == base or name.startswith(base + '.'):
                    os.remove(os.path.join(folder, name))
        self.addCleanup(remove_files)
        cycles = int(rospy.get_param('~cycles', 2))
        min_acks = int(rospy.get_param('~min_acks', 200))
        rospy.wait_for_service(NODE + '/set_state', timeout=60.0)
        pid = self.wait_for_node(None)
        names = [s.name for s in self.get_state()]
        self.assertTrue(os.path.isfile(state_file), 'the node did not create %s at start' % state_file)

        # Mid-stream kills, then one kill after the stream has stopped (no call
        # in flight: the restored state must be the last acknowledged one).
        for cycle in range(cycles + 1):
            quiescent = cycle == cycles
            streamer = Streamer(names, seed=cycle, max_acks=min_acks if quiescent else None)
            streamer.start()
            deadline = time.time() + 60.0
            while streamer.acks < min_acks and streamer.is_alive() and time.time() < deadline:
                time.sleep(0.01)
            self.assertIsNone(streamer.error, 'set_state failed before the kill: %s' % streamer.error)
            self.assertGreaterEqual(streamer.acks, min_acks, 'too few acknowledged calls before the kill')
            if quiescent:
                streamer.join(30.0)
            else:
                time.sleep(random.Random(cycle).uniform(0.0, 0.05))  # somewhere mid-stream
            os.kill(pid, signal.SIGKILL)
            streamer.join(30.0)
            self.assertFalse(streamer.is_alive(), 'set_state kept succeeding after SIGKILL')
            acked = bits(streamer.last_acked)

            pid = self.wait_for_node(pid)
            restored = bits(self.get_state())
            if restored == acked:
                outcome = 'the last acknowledged state'
            elif not quiescent and streamer.cut_off is not None and restored == bits(streamer.cut_off):
                outcome = 'the state of the call cut off by the kill (saved, never acknowledged)'
            else:
                self.fail('cycle %d: after %d acknowledged calls the respawned node has\n%s\nnot the last '
                          'acknowledged state\n%s' % (cycle, streamer.acks, restored, acked))
            sys.stdout.write('cycle %d (%s): killed after %d acknowledged set_state calls; restored %s\n'
                             % (cycle, 'stream stopped' if quiescent else 'mid-stream', streamer.acks, outcome))
            folder, base = os.path.split(state_file)
            leftovers = [f for f in os.listdir(folder) if f.startswith(base + '.tmp.')]
            self.assertEqual(leftovers, [], 'the respawned node left temporary files of a cut-off save')
            self.assertEqual(restored, acked if outcome.startswith('the last') else bits(streamer.cut_off))



if __name__ == '__main__':
    rospy.init_node('reliability_respawn')
    rostest.rosrun(PKG, 'reliability_respawn', Respawn)
