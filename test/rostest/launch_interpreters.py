#!/usr/bin/python3
"""Every Python node the shipped launch files start runs under Debian's /usr/bin/python3, whatever
python3 comes first on PATH (launch_interpreters.test).

Oracle: the executable roslaunch would run for each node (found as rosrun finds it) and its first
line. A node whose script starts '#!/usr/bin/env python...' picks the first python3 on PATH (a pyenv
or conda one has no rospy), so it must be started through a launch-prefix that names an absolute
interpreter. Checked on demo.launch with every node switched on (joint_state_publisher:=true and
:=gui, rviz, arm, the client), server.launch and pool.launch.
"""
import os
import sys
import unittest

import roslaunch.config
import roslib.packages
import rospkg
import rostest

PKG = 'diff_rigid_body'
LAUNCH = os.path.join(rospkg.RosPack().get_path(PKG), 'launch')
CASES = [
    ('demo.launch', ['joint_state_publisher:=true', 'rviz:=true', 'client:=true', 'arm:=true']),
    ('demo.launch', ['joint_state_publisher:=gui']),
    ('server.launch', []),
    ('pool.launch', ['instances:=4']),
]


def nodes(launch, arguments):
    sys.argv = [sys.argv[0]] + arguments  # roslaunch reads command-line args from sys.argv
    config = roslaunch.config.load_config_default([os.path.join(LAUNCH, launch)], None, verbose=False)
    return config.nodes


def first_line(path):
    with open(path, 'rb') as f:
        return f.readline().decode('utf-8', 'replace').strip()


class LaunchInterpreters(unittest.TestCase):

    def test_env_python_nodes_run_under_an_absolute_interpreter(self):
        checked = set()
        argv = list(sys.argv)
        try:
            for launch, arguments in CASES:
                for node in nodes(launch, arguments):
                    executable = roslib.packages.find_node(node.package, node.type)
                    self.assertTrue(executable, '%s: no executable for %s/%s' % (launch, node.package, node.type))
                    line = first_line(executable[0])
                    if not (line.startswith('#!') and 'python' in line):
                        continue
                    checked.add(node.type)
                    where = '%s %s: node %s (%s, "%s")' % (launch, ' '.join(arguments), node.name, executable[0],
                                                          line)
                    if line.startswith('#!/usr/bin/env'):
                        prefix = (node.launch_prefix or '').split()
                        self.assertTrue(prefix and os.path.isabs(prefix[0]) and 'python' in prefix[0],
                                        where + ': needs launch-prefix="/usr/bin/python3"')
                    else:
                        self.assertTrue(line.startswith('#!/usr/bin/python'), where)
        finally:
            sys.argv = argv
        for expected in ('joint_state_publisher', 'joint_state_publisher_gui', 'demo_client.py', 'scene_rviz.py'):
            self.assertIn(expected, checked, 'the cases did not start %s' % expected)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'launch_interpreters', LaunchInterpreters, sys.argv)
