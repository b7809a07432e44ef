#!/usr/bin/python3
"""Starts rviz in the scene's own fixed frame.

Waits for the server's ``get_bodies``, reads its ``fixed_frame`` (which
already carries the server's ``~frame_prefix``) and replaces itself with
``rviz -d CONFIG -f FRAME``. So ``demo.launch urdf:=<robot> rviz:=true``
shows any robot in its root frame without editing the config. When the
server has a ``~frame_prefix`` ending in '/' (e.g. 'a/'), rviz runs on a copy
of the config whose RobotModel has the matching "TF Prefix" ('a'): rviz joins
that prefix and a link name with '/'.

This script registers no ROS node: rviz, which replaces it, does, under the
name and namespace roslaunch gave (the remapping arguments are passed on).

Parameters (read from the parameter server before rviz starts):
  ~server   the server node (default: rigid_body_server, relative to the namespace)
  ~config   rviz config (default: rviz/demo.rviz of this package)
  ~wait     [s] longest wait for get_bodies (default 120); then exit 1
"""
import os
import re
import sys

import rospkg
import rospy

from diff_rigid_body.srv import GetBodies


def private_param(name, default):
    """``~name`` of this launch node (roslaunch sets it before the node starts)."""
    node = [arg.split(':=', 1)[1] for arg in sys.argv if arg.startswith('__name:=')]
    if not node:
        return default
    return rospy.get_param(rospy.resolve_name(node[-1]) + '/' + name, default)


def prefixed_config(config, frame_prefix):
    """A copy of ``config`` whose RobotModel "TF Prefix" follows ``frame_prefix``;
    ``config`` itself when there is no prefix or rviz cannot express it."""
    if not frame_prefix:
        return config
    tf_prefix = frame_prefix.strip('/')
    if not frame_prefix.endswith('/') or not tf_prefix:
        sys.stderr.write("scene_rviz: rviz's RobotModel cannot follow the frame prefix %r (only 'name/' works);"
                         ' the model may stay grey\n' % frame_prefix)
        return config
    with open(config) as f:
        text = f.read()
    text, count = re.subn(r'^(\s*TF Prefix:).*$', r'\1 "%s"' % tf_prefix, text, flags=re.MULTILINE)
    if count == 0:
        return config
    folder = os.path.join(rospkg.get_ros_home(), 'diff_rigid_body')
    os.makedirs(folder, exist_ok=True)
    copy = os.path.join(folder, 'scene_rviz_%s.rviz' % re.sub(r'[^A-Za-z0-9_]', '_', tf_prefix))
    with open(copy, 'w') as f:
        f.write(text)
    return copy


def main():
    server = rospy.resolve_name(private_param('server', 'rigid_body_server'))
    config = private_param('config', '')
    if not config:
        config = os.path.join(rospkg.RosPack().get_path('diff_rigid_body'), 'rviz', 'demo.rviz')
    wait = float(private_param('wait', 120.0))
    service = server + '/get_bodies'
    try:
        rospy.wait_for_service(service, timeout=wait)
        response = rospy.ServiceProxy(service, GetBodies)()
    except (rospy.ROSException, rospy.ServiceException) as e:
        sys.stderr.write('scene_rviz: no answer from %s within %g s: %s\n' % (service, wait, e))
        return 1
    if not response.success or not response.fixed_frame:
        sys.stderr.write('scene_rviz: %s gave no fixed frame: %s\n' % (service, response.message))
        return 1
    config = prefixed_config(config, rospy.get_param(server + '/frame_prefix', ''))
    remappings = [arg for arg in sys.argv[1:] if ':=' in arg]
    command = ['rviz', '-d', config, '-f', response.fixed_frame] + remappings
    sys.stderr.write('scene_rviz: %s\n' % ' '.join(command))
    sys.stderr.flush()
    os.execvp(command[0], command)


if __name__ == '__main__':
    sys.exit(main())
