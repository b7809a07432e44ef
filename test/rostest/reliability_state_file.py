#!/usr/bin/python3
"""The node's use of ~state_file (reliability_state_file.test).

Runs the real rigid_body_server binary as a subprocess (like
expect_refusal.py) on test/urdf/reliability_scene.urdf with a ~state_file in a
private temporary folder, and checks:
  - a valid file is resumed bit for bit;
  - a corrupt file (one flipped byte), a file of other bodies and a file of
    the same bodies with other mass properties each get a clear ROS_WARN
    naming the problem, are moved to <file>.bad, and the URDF state is used;
  - a ~state_file in a folder that does not exist stops the node at start
    with a clear error (exit code 1);
  - when the file cannot be written any more, set_state is refused with
    success=false naming the file, and the state does not change.
"""
import os
import shutil
import struct
import sys
import tempfile
import unittest

import rospy
import rostest
from reliability_node import SCENE, Node
from diff_rigid_body.msg import BodyState
from diff_rigid_body.srv import GetState, SetState

PKG = 'diff_rigid_body'


def bits(states):
    return [(s.name, struct.pack('<6d', *s.q)) for s in states]


class StateFileHandling(unittest.TestCase):

    def setUp(self):
        self.folder = tempfile.mkdtemp(prefix='drb_state_file_')
        self.addCleanup(shutil.rmtree, self.folder, True)
        self.path = os.path.join(self.folder, 'state')

    def start(self, state_file=None, urdf=SCENE):
        node = Node({'urdf_path': urdf, 'state_file': self.path if state_file is None else state_file},
                    prefix='state_file')
        self.addCleanup(node.stop)
        return node

    def serving(self, node):
        """Waits for `node` to serve; fails with its output if it exited."""
        if not node.wait():
            self.fail('the node exited (code %s):\n%s' % (node.process.returncode, node.stop()))

    def urdf_state(self):
        """The scene's URDF initial state, from a node without a state file."""
        node = self.start(state_file='')
        self.serving(node)
        states = node.service('get_state', GetState)(bodies=[]).states
        node.stop()
        return states

    def saved_state(self):
        """Runs a node, sets a state, stops it; returns the state now in self.path."""
        node = self.start()
        self.serving(node)
        names = [s.name for s in node.service('get_state', GetState)(bodies=[]).states]
        states = [BodyState(name=n, q=[0.1 * i + 0.01 * k for k in range(6)]) for i, n in enumerate(names)]
        states[0].q = [-0.0, 5e-324, 1.0 / 3.0, 1e12, -2.5, 0.7]
        self.assertTrue(node.service('set_state', SetState)(states=states).success)
        node.stop()
        return states

    def expect_fallback(self, fragment):
        """Starts a node on the current (bad) file: it must warn, set the file aside and use the URDF state."""
        expected = bits(self.urdf_state())
        bad = open(self.path, 'rb').read()
        node = self.start()
        self.serving(node)
        restored = bits(node.service('get_state', GetState)(bodies=[]).states)
        output = node.stop()
        sys.stdout.write(output)
        self.assertEqual(restored, expected, 'the node did not fall back to the URDF state')
        self.assertIn('ignoring the state file', output)
        self.assertIn(fragment, output)
        self.assertIn("starting from the URDF state; the file was moved to '%s.bad'" % self.path, output)
        self.assertEqual(open(self.path + '.bad', 'rb').read(), bad, 'the bad file was not kept')
        self.assertTrue(os.path.isfile(self.path), 'no new state file was written')

    def test_valid_file_is_resumed(self):
        saved = self.saved_state()
        node = self.start()
        self.serving(node)
        restored = node.service('get_state', GetState)(bodies=[]).states
        output = node.stop()
        self.assertEqual(bits(restored), bits(saved))
        self.assertIn("resumed the state saved in '%s'" % self.path, output)

    def test_corrupt_file_is_set_aside(self):
        self.saved_state()
        data = bytearray(open(self.path, 'rb').read())
        data[data.index(b'\nbody ') + 12] ^= 0x04  # inside the first body line
        open(self.path, 'wb').write(bytes(data))
        self.expect_fallback('checksum mismatch: the file is corrupt')

    def test_truncated_file_is_set_aside(self):
        self.saved_state()
        data = open(self.path, 'rb').read()
        open(self.path, 'wb').write(data[:len(data) // 2])
        self.expect_fallback('truncated')

    def test_file_of_other_bodies_is_set_aside(self):
        self.saved_state()
        other = os.path.join(self.folder, 'other.urdf')
        open(other, 'w').write(open(SCENE).read().replace('alpha', 'delta'))
        node = self.start(urdf=other)  # writes its own state (bodies delta, beta, gamma) over self.path
        self.serving(node)
        node.stop()
        self.expect_fallback('saved for other bodies: the file has [delta, beta, gamma], '
                             'the scene has [alpha, beta, gamma]')

    def test_file_of_other_mass_properties_is_set_aside(self):
        other = os.path.join(self.folder, 'heavier.urdf')
        open(other, 'w').write(open(SCENE).read().replace('<mass value="1.5"/>', '<mass value="1.6"/>'))
        node = self.start(urdf=other)
        self.serving(node)
        node.stop()
        self.expect_fallback('saved for another scene: fingerprint')

    def test_unwritable_folder_stops_the_node_at_start(self):
        node = self.start(state_file=os.path.join(self.folder, 'missing', 'state'))
        self.assertFalse(node.wait(), 'the node started with an unwritable state file')
        self.assertEqual(node.exit_code(), 1, node.output())
        output = node.stop()
        self.assertIn("cannot start: state file '%s/missing/state'" % self.folder, output)
        self.assertIn('cannot create a temporary file', output)

    def test_failed_save_refuses_the_change(self):
        subfolder = os.path.join(self.folder, 'sub')
        os.mkdir(subfolder)
        node = self.start(state_file=os.path.join(subfolder, 'state'))
        self.serving(node)
        before = node.service('get_state', GetState)(bodies=[]).states
        shutil.rmtree(subfolder)  # the folder goes away under the running node
        states = [BodyState(name=s.name, q=[1, 2, 3, 4, 5, 6]) for s in before]
        response = node.service('set_state', SetState)(states=states)
        after = node.service('get_state', GetState)(bodies=[]).states
        node.stop()
        self.assertFalse(response.success)
        self.assertIn("state file '%s/state'" % subfolder, response.message)
        self.assertIn('cannot create a temporary file', response.message)
        self.assertEqual(bits(after), bits(before), 'a refused change changed the state')


if __name__ == '__main__':
    rospy.init_node('reliability_state_file')
    rostest.rosrun(PKG, 'reliability_state_file', StateFileHandling)
