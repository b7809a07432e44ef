#!/usr/bin/python3
"""Starts rviz in the scene's own fixed frame.

Waits for the server's ``get_bodies``, reads its ``fixed_frame`` (which
already carries the server's ``~frame_prefix``) and replaces itself with
``rviz -d CONFIG -f FRAME``. So ``demo.launch urdf:=<robot> rviz:=true``
shows any robot in its root frame without editing the config. When the
server has a ``~frame_prefix`` ending in '/' (e.g. 'a/'), rviz runs on a copy
of the config whose RobotModel has the matching "TF Prefix" ('a'): rviz joins
that prefix and a link name with '/'.

The camera is framed on the served scene: the bounding box of every body's
vertices at the current state (``get_vertex_jacobians_compact``, positions
only). With ``~frame: auto`` a config whose orbit view already sees the whole
box keeps its camera; otherwise the copy of the config looks at the box's
centre from the distance at which the box's bounding sphere fills the
vertical field of view (with a margin), keeping the view's pitch and yaw. So a
1.5 m robot is not cropped by the Panda's camera.

This script registers no ROS node: rviz, which replaces it, does, under the
name and namespace roslaunch gave (the remapping arguments are passed on).

Parameters (read from the parameter server before rviz starts):
  ~server   the server node (default: rigid_body_server, relative to the namespace)
  ~config   rviz config (default: rviz/demo.rviz of this package)
  ~wait     [s] longest wait for get_bodies (default 120); then exit 1
  ~frame    'auto' (default), 'always' or 'never': when to frame the camera on the vertices
"""
import math
import os
import re
import sys

import numpy as np
import rospkg
import rospy
import yaml

from diff_rigid_body.client import RigidBodyClient
from diff_rigid_body.srv import GetBodies

MARGIN = 1.15  # framed: the view's half-height at the focal point over the bounding sphere's radius


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
    return write_copy(text, 'scene_rviz_%s.rviz' % tf_prefix)


def vertex_box(server):
    """(lower, upper) corners [m, fixed frame] of every body's vertices at the node's current state,
    or None for a scene without vertices."""
    client = RigidBodyClient(server, timeout=10.0)
    bodies = client.bodies()
    points = [client.vertex_jacobians_compact(name, positions_only=True)[0]
              for name, count in zip(bodies.names, bodies.vertex_counts) if count]
    if not points:
        return None
    points = np.concatenate(points)
    return points.min(axis=0), points.max(axis=0)


def orbit_view(text):
    """(focal point (3,), distance [m], vertical field of view [rad]) of a config's current orbit view,
    or None when it has none."""
    try:
        view = yaml.safe_load(text)['Visualization Manager']['Views']['Current']
        focal = view['Focal Point']
        return (np.array([focal['X'], focal['Y'], focal['Z']], dtype=float), float(view['Distance']),
                float(view.get('Field of View', 0.785398)))
    except (KeyError, TypeError, ValueError, yaml.YAMLError):
        return None


def framing(view, box, mode):
    """(focal point, distance) that show the whole box, or None to keep the view: with mode 'auto'
    when the box's bounding sphere already lies within the view's vertical field of view at its
    focal point, to within the margin the framing itself leaves."""
    focal, distance, fov = view
    centre, radius = (box[0] + box[1]) / 2.0, max(np.linalg.norm(box[1] - box[0]) / 2.0, 1e-3)
    half_height = distance * math.tan(fov / 2.0)
    if mode == 'never' or (mode == 'auto' and np.linalg.norm(centre - focal) + radius <= MARGIN * half_height):
        return None
    return centre, MARGIN * radius / math.tan(fov / 2.0)


def framed_config(config, server, mode='auto'):
    """A copy of ``config`` whose orbit view frames the served scene's vertices (see the module
    docstring); ``config`` itself when it already does, or cannot."""
    with open(config) as f:
        text = f.read()
    view = orbit_view(text)
    box = vertex_box(server) if view is not None and mode != 'never' else None
    framed = framing(view, box, mode) if box is not None else None
    if framed is None:
        return config
    (x, y, z), distance = framed
    views = text.index('Views:')  # orbit_view found it: edit only the view, not a display's fields
    view_text = re.sub(r'^(\s*Distance:).*$', r'\g<1> %.6g' % distance, text[views:], count=1, flags=re.MULTILINE)
    view_text = re.sub(r'^(\s*Focal Point:\s*\n\s*X:).*\n(\s*Y:).*\n(\s*Z:).*$',
                       r'\g<1> %.6g\n\g<2> %.6g\n\g<3> %.6g' % (x, y, z), view_text, count=1, flags=re.MULTILINE)
    return write_copy(text[:views] + view_text, 'framed_' + os.path.basename(config))


def write_copy(text, name):
    """Writes ``text`` to ``name`` in ~/.ros/diff_rigid_body; returns its path."""
    folder = os.path.join(rospkg.get_ros_home(), 'diff_rigid_body')
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, re.sub(r'[^A-Za-z0-9_.]', '_', name))
    with open(path, 'w') as f:
        f.write(text)
    return path


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
    try:
        config = framed_config(config, server, private_param('frame', 'auto'))
    except Exception as e:  # rviz still starts, with the config's own camera
        sys.stderr.write('scene_rviz: could not frame the camera on the vertices: %s\n' % e)
    config = prefixed_config(config, rospy.get_param(server + '/frame_prefix', ''))
    remappings = [arg for arg in sys.argv[1:] if ':=' in arg]
    command = ['rviz', '-d', config, '-f', response.fixed_frame] + remappings
    sys.stderr.write('scene_rviz: %s\n' % ' '.join(command))
    sys.stderr.flush()
    os.execvp(command[0], command)


if __name__ == '__main__':
    sys.exit(main())
