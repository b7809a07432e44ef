#!/usr/bin/python3
"""The shipped launch files as a user runs them, one roslaunch after another on the same master
(launch_files.test): each `roslaunch` runs as a subprocess against the rostest master.

- An option given to one launch (bodies, gravity) never applies to the next one: the node's
  private namespace starts clean (server.launch's clear_params), in server.launch and pool.launch.
- A pool instance that dies (SIGKILL) leaves the other instances and the roslaunch running, and a
  RigidBodyPool over both namespaces still answers (its failover gets its chance).
- A URDF that does not exist (urdf:=) is refused by the node in one line, without a roslaunch
  traceback, and the roslaunch ends.
Oracles: get_bodies' names (the default scene has the bodies knot and rock), the parameter server,
and tau_z = m |gamma| of a body held still (inverse dynamics at rest, m from get_bodies).
"""
import os
import signal
import subprocess
import tempfile
import time
import unittest
import xmlrpc.client

import numpy as np
import rosgraph
import rospy
import rostest

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.pool import RigidBodyPool

PKG = 'diff_rigid_body'
WAIT = 60.0  # [s] for a launch to come up or end
RELATIVE = 1e-12


class Launch(object):
    """`roslaunch diff_rigid_body <file> <args>` in a subprocess, its output in a file."""

    def __init__(self, launch_file, *arguments):
        self.command = ['roslaunch', PKG, launch_file] + list(arguments)
        self.log = tempfile.TemporaryFile(mode='w+')
        self.process = subprocess.Popen(self.command, stdout=self.log, stderr=subprocess.STDOUT,
                                        start_new_session=True)

    def output(self):
        self.log.seek(0)
        return self.log.read()

    def running(self):
        return self.process.poll() is None

    def wait_for_output(self, text, timeout=WAIT):
        """True once `text` is in the output; False if roslaunch ended or the time ran out first."""
        deadline = time.time() + timeout
        while time.time() < deadline:
            if text in self.output():
                return True
            if not self.running():
                return text in self.output()
            time.sleep(0.2)
        return False

    def wait_for_exit(self, timeout=WAIT):
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def stop(self):
        if self.running():
            self.process.send_signal(signal.SIGINT)
            if self.wait_for_exit(40.0) is None:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
        return self.output()


class LaunchFiles(unittest.TestCase):

    def launch(self, launch_file, *arguments):
        launched = Launch(launch_file, *arguments)
        self.addCleanup(launched.stop)
        return launched

    def wait_for_server(self, launched, server):
        """Waits until `server`'s get_bodies is advertised; fails with roslaunch's output if it ends."""
        deadline = time.time() + WAIT
        while time.time() < deadline and launched.running():
            try:
                rospy.wait_for_service(server + '/get_bodies', timeout=0.5)
                return RigidBodyClient(server, timeout=5.0)
            except rospy.ROSException:
                pass
        self.fail('%s did not come up (roslaunch %s):\n%s' % (server, 'ended' if not launched.running() else
                                                            'still running', launched.output()))

    def held_still_force(self, client, body):
        """(tau_z, m) for `body` held still at a level pose: tau_z = m |gamma_z| is its weight."""
        mass = dict(zip(client.bodies().names, client.bodies().masses))[body]
        result = client.inverse_dynamics(q=[[0, 0, 0, 0, 0, 1.0]], bodies=[body])
        return float(result.tau[0][5]), float(mass)

    def stop_and_wait_for_node_gone(self, launched, server):
        launched.stop()
        master = rosgraph.Master('/launch_files')
        deadline = time.time() + WAIT
        while time.time() < deadline:
            try:
                master.lookupService(server + '/get_bodies')
            except rosgraph.MasterError:
                return
            time.sleep(0.2)
        self.fail('%s is still registered after its roslaunch ended' % server)

    # ------------------------------------------------------------------ options do not leak
    def test_server_launch_bodies_do_not_outlive_their_launch(self):
        server = '/leak_bodies/rigid_body_server'
        first = self.launch('server.launch', 'ns:=leak_bodies', 'bodies:=knot')
        self.assertEqual(self.wait_for_server(first, server).bodies().names, ['knot'])
        self.stop_and_wait_for_node_gone(first, server)
        second = self.launch('server.launch', 'ns:=leak_bodies')
        self.assertEqual(self.wait_for_server(second, server).bodies().names, ['knot', 'rock'],
                         'the second launch (no bodies:=) still served only the first launch\'s bodies')
        self.assertFalse(rospy.has_param(server + '/bodies'), 'the first launch\'s ~bodies is still set')

    def test_server_launch_bad_gravity_does_not_outlive_its_launch(self):
        server = '/leak_gravity/rigid_body_server'
        first = self.launch('server.launch', 'ns:=leak_gravity', 'gravity:=[0, 0]')
        self.assertIsNotNone(first.wait_for_exit(), 'the node should refuse gravity [0, 0] and end the launch')
        self.assertIn('parameter ~gravity: must be a list of three finite numbers', first.output())
        second = self.launch('server.launch', 'ns:=leak_gravity')
        tau_z, mass = self.held_still_force(self.wait_for_server(second, server), 'rock')
        self.assertAlmostEqual(tau_z, mass * 9.81, delta=RELATIVE * mass * 9.81)

    def test_pool_launch_gravity_does_not_outlive_its_launch(self):
        servers = ['/leak_pool1/rigid_body_server', '/leak_pool2/rigid_body_server']
        first = self.launch('pool.launch', 'prefix:=leak_pool', 'gravity:=[0, 0, -1.62]')
        for server in servers:
            tau_z, mass = self.held_still_force(self.wait_for_server(first, server), 'knot')
            self.assertAlmostEqual(tau_z, mass * 1.62, delta=RELATIVE * mass * 1.62)
        for server in servers:
            self.stop_and_wait_for_node_gone(first, server)
        second = self.launch('pool.launch', 'prefix:=leak_pool')
        for server in servers:
            tau_z, mass = self.held_still_force(self.wait_for_server(second, server), 'knot')
            self.assertAlmostEqual(tau_z, mass * 9.81, delta=RELATIVE * mass * 9.81,
                                   msg='%s: the first launch\'s gravity:=[0, 0, -1.62] still applies' % server)

    # ------------------------------------------------------------------ pool instances
    def test_a_dead_pool_instance_leaves_the_others_running(self):
        servers = ['/dying_pool1/rigid_body_server', '/dying_pool2/rigid_body_server']
        launched = self.launch('pool.launch', 'prefix:=dying_pool')
        for server in servers:
            self.wait_for_server(launched, server)
        master = rosgraph.Master('/launch_files')
        code, _, pid = xmlrpc.client.ServerProxy(master.lookupNode(servers[0])).getPid('/launch_files')
        self.assertEqual(code, 1)
        os.kill(pid, signal.SIGKILL)
        self.assertTrue(launched.wait_for_output('process has died'),
                        'roslaunch did not notice the killed instance:\n%s' % launched.output())
        # A required node's death makes roslaunch shut everything down at once, in the same check.
        self.assertIsNone(launched.wait_for_exit(5.0),
                          'roslaunch ended when one instance died:\n%s' % launched.output())
        self.assertEqual(RigidBodyClient(servers[1], timeout=5.0).bodies().names, ['knot', 'rock'])
        pool = RigidBodyPool(['/dying_pool1', '/dying_pool2'], timeout=5.0, log=lambda text: None)
        q = np.tile([0.1, 0.2, 0.3, 0.0, 0.0, 0.5], (4, 1))
        M = pool.mass_matrix(['knot'], q=q[:, None, :]).M
        self.assertEqual(M.shape, (4, 1, 6, 6))
        self.assertEqual([up for _, up, _, _ in pool.status()], [False, True])

    # ------------------------------------------------------------------ a missing URDF file
    def test_a_missing_urdf_is_refused_by_the_node_in_one_line(self):
        missing = '/nonexistent/drb/robot.urdf'
        launched = self.launch('server.launch', 'ns:=missing_urdf', 'urdf:=' + missing)
        self.assertIsNotNone(launched.wait_for_exit(), 'roslaunch kept running on a missing URDF')
        output = launched.output()
        self.assertNotIn('Traceback', output)
        refusals = [line for line in output.splitlines() if "URDF file '%s'" % missing in line]
        self.assertEqual(len(refusals), 1, 'expected one line naming the file:\n%s' % output)
        self.assertIn('rigid_body_server: cannot load the scene', refusals[0])
        self.assertIn('no such file', refusals[0])


if __name__ == '__main__':
    rospy.init_node('launch_files')
    rostest.rosrun(PKG, 'launch_files', LaunchFiles)
