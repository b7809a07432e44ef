#!/usr/bin/python3
"""Runs rigid_body_server as a user would and expects it to serve.

The real node binary is started as a subprocess against the rostest master,
its standard output a pipe (as under `roslaunch ... output:=log`, a pipeline or
a service manager: not a terminal), read line by line while it runs. The
test passes when the node serves get_bodies with the expected bodies, and (if
~expected_line is given) its ready line ("serving N bodies ...") has come
through the pipe while the node is still running, not only at its exit.

Private parameters of this test node (set them in the .test file):
  ~node_params/<name>       set as the node's private parameter ~<name>
  ~package_path             folders put first on the node's ROS_PACKAGE_PATH
  ~decoy_packages           names of empty packages made in a temporary folder
                            that goes before ~package_path (an upstream copy
                            that would shadow ours)
  ~expected_bodies          {body name: vertex count} that get_bodies must list
  ~expected_line            strings that one line of the node's output must
                            contain while it runs (default: none; then the
                            test waits for get_bodies to be advertised)
  ~timeout                  [s] how long the node may take to serve (default 60)
"""
import os
import queue
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import roslib.packages
import rospy
import rostest
from diff_rigid_body.srv import GetBodies

PKG = 'diff_rigid_body'
NODE_NAMESPACE = '/serving'


def make_decoys(names):
    """A temporary folder holding one empty catkin package per name; returns its path."""
    folder = tempfile.mkdtemp(prefix='drb_decoy_')
    for name in names:
        os.makedirs(os.path.join(folder, name))
        with open(os.path.join(folder, name, 'package.xml'), 'w') as f:
            f.write('<?xml version="1.0"?>\n<package format="2"><name>%s</name><version>0.0.0</version>'
                    '<description>decoy</description><maintainer email="a@b.c">a</maintainer>'
                    '<license>BSD</license></package>\n' % name)
    return folder


class ExpectServing(unittest.TestCase):

    def start_node(self, environment):
        binary = roslib.packages.find_node(PKG, 'rigid_body_server')[0]
        process = subprocess.Popen([binary, '__ns:=' + NODE_NAMESPACE, '__name:=rigid_body_server'],
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=environment,
                                   universal_newlines=True)
        self.addCleanup(self.stop, process)
        lines = queue.Queue()

        def read():
            for line in process.stdout:
                lines.put(line)
            lines.put(None)
        threading.Thread(target=read, daemon=True).start()
        return process, lines

    @staticmethod
    def stop(process):
        if process.poll() is None:
            process.terminate()
            try:
                process.wait(20.0)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()

    def environment(self):
        environment = dict(os.environ)
        folders = list(rospy.get_param('~package_path', []))
        decoys = rospy.get_param('~decoy_packages', [])
        if decoys:
            folder = make_decoys(decoys)
            self.addCleanup(shutil.rmtree, folder, True)
            folders.insert(0, folder)
        environment['ROS_PACKAGE_PATH'] = ':'.join(folders + [environment.get('ROS_PACKAGE_PATH', '')])
        return environment

    def wait_until_ready(self, process, lines, expected_line, deadline):
        """The node's output so far and its line with every fragment of ``expected_line`` (with none:
        its output once get_bodies is advertised); stops at the deadline or when the node exits."""
        seen, ready = [], None
        service = NODE_NAMESPACE + '/rigid_body_server/get_bodies'
        while ready is None and time.time() < deadline and process.poll() is None:
            try:
                line = lines.get(timeout=0.5)
            except queue.Empty:
                line = ''
            if line is None:
                break
            seen.append(line)
            if expected_line and line and all(fragment in line for fragment in expected_line):
                ready = line
            elif not expected_line:
                try:
                    rospy.wait_for_service(service, timeout=0.1)
                    ready = ''
                except rospy.ROSException:
                    pass
        return ''.join(seen), ready

    def test_node_serves(self):
        for name, value in rospy.get_param('~node_params', {}).items():
            rospy.set_param(NODE_NAMESPACE + '/rigid_body_server/' + name, value)
        expected_line = rospy.get_param('~expected_line', [])
        expected_bodies = rospy.get_param('~expected_bodies', {})
        deadline = time.time() + float(rospy.get_param('~timeout', 60.0))
        process, lines = self.start_node(self.environment())
        output, ready = self.wait_until_ready(process, lines, expected_line, deadline)
        sys.stdout.write('--- rigid_body_server output so far ---\n%s\n' % output)
        self.assertIsNone(process.poll(), 'the node exited (code %s) instead of serving:\n%s'
                          % (process.returncode, output))
        self.assertIsNotNone(ready, 'no line with %s came through the pipe while the node ran:\n%s'
                             % (expected_line, output) if expected_line else
                             'the node did not serve get_bodies in time:\n%s' % output)
        answer = rospy.ServiceProxy(NODE_NAMESPACE + '/rigid_body_server/get_bodies', GetBodies)()
        served = dict(zip(answer.names, answer.vertex_counts))
        for body, vertices in expected_bodies.items():
            self.assertIn(body, served, 'get_bodies: no body %r (%s)' % (body, served))
            self.assertEqual(served[body], vertices, 'get_bodies: body %r' % body)

if __name__ == '__main__':
    rospy.init_node('expect_serving')
    rostest.rosrun(PKG, 'expect_serving', ExpectServing)
