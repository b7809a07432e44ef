#!/usr/bin/python3
"""Runs rigid_body_server on a bad description and expects a clean refusal.

The real node binary is started as a subprocess against the rostest master.
The test passes when the node exits by itself with a non-zero code (not by a
signal, not by hanging) and its output contains every expected fragment.

Private parameters of this test node (set them in the .test file):
  ~expected                 string or list of strings the output must contain
  ~node_params/<name>       set as the node's private parameter ~<name>
  ~robot_description_file   file whose text becomes the node's robot_description
  ~timeout                  [s] how long the node may take to give up (default 30)
"""
import subprocess
import sys
import unittest

import rospy
import roslib.packages
import rostest

PKG = 'diff_rigid_body'
NODE_TYPE = 'rigid_body_server'
NODE_NAMESPACE = '/refusal'  # its robot_description is /refusal/robot_description
NODE_NAME = 'rigid_body_server'


def find_node_executable():
    paths = roslib.packages.find_node(PKG, NODE_TYPE)
    if not paths:
        raise RuntimeError('cannot find the %s executable of package %s (is the workspace built and sourced?)'
                           % (NODE_TYPE, PKG))
    return paths[0]


class ExpectRefusal(unittest.TestCase):

    def test_node_refuses_description(self):
        expected = rospy.get_param('~expected')
        if isinstance(expected, str):
            expected = [expected]
        node_params = rospy.get_param('~node_params', {})
        description_file = rospy.get_param('~robot_description_file', '')
        timeout = float(rospy.get_param('~timeout', 30.0))

        node = NODE_NAMESPACE + '/' + NODE_NAME
        for name, value in node_params.items():
            rospy.set_param(node + '/' + name, value)
        if description_file:
            with open(description_file) as description:
                rospy.set_param(NODE_NAMESPACE + '/robot_description', description.read())

        command = [find_node_executable(), '__ns:=' + NODE_NAMESPACE, '__name:=' + NODE_NAME]
        try:
            run = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                 universal_newlines=True, timeout=timeout)
        except subprocess.TimeoutExpired as e:
            output = e.output.decode(errors='replace') if isinstance(e.output, bytes) else (e.output or '')
            self.fail('%s was still running after %g s: it did not refuse the description.\nOutput:\n%s'
                      % (NODE_TYPE, timeout, output))
        output = run.stdout
        sys.stdout.write('--- %s output (exit code %d) ---\n%s\n' % (NODE_TYPE, run.returncode, output))
        self.assertGreater(run.returncode, 0,
                           'expected a non-zero exit code (and no signal), got %d. Output:\n%s'
                           % (run.returncode, output))
        for fragment in expected:
            self.assertIn(fragment, output, 'the output does not say %r. Output:\n%s' % (fragment, output))
        self.assertTrue('[FATAL]' in output or '[ERROR]' in output,
                        'the refusal is not logged as an error (ROS_ERROR / ROS_FATAL). Output:\n%s' % output)


if __name__ == '__main__':
    rospy.init_node('expect_refusal')
    rostest.rosrun(PKG, 'expect_refusal', ExpectRefusal)
