#!/usr/bin/python3
"""nodes/scene_rviz.py frames rviz's camera on the served scene (scene_rviz_camera.test).

/tall serves a 1.6 m mobile manipulator (test/urdf/tall_manipulator.urdf), /scene the default scene. Oracle: the rviz
orbit camera's geometry (rviz's OrbitViewController: the eye at focal + distance (cos pitch cos yaw,
cos pitch sin yaw, sin pitch)), and every vertex from get_vertex_jacobians: a vertex is in view when
the angle between the eye->vertex and eye->focal rays is at most half the vertical field of view.
  * rviz/demo.rviz (tuned for the default scene) crops the manipulator; the framed copy shows every
    vertex;
  * on the default scene, whose view already fits, the config is kept as it is.
"""
import importlib.util
import math
import os
import sys
import unittest

import numpy as np
import rospkg
import rostest
import yaml

from diff_rigid_body.client import RigidBodyClient

PKG = 'diff_rigid_body'
ROOT = rospkg.RosPack().get_path(PKG)
CONFIG = os.path.join(ROOT, 'rviz', 'demo.rviz')


def scene_rviz():
    spec = importlib.util.spec_from_file_location('scene_rviz', os.path.join(ROOT, 'nodes', 'scene_rviz.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def vertices(server):
    client = RigidBodyClient(server, timeout=60.0)
    bodies = client.bodies()
    return np.concatenate([client.vertex_jacobians(name)[0] for name, count in
                           zip(bodies.names, bodies.vertex_counts) if count])


def outside_view(config, points):
    """How many points lie outside the orbit camera's vertical field of view."""
    with open(config) as f:
        view = yaml.safe_load(f)['Visualization Manager']['Views']['Current']
    focal = np.array([view['Focal Point'][axis] for axis in 'XYZ'], dtype=float)
    pitch, yaw = float(view['Pitch']), float(view['Yaw'])
    eye = focal + float(view['Distance']) * np.array([math.cos(pitch) * math.cos(yaw),
                                                      math.cos(pitch) * math.sin(yaw), math.sin(pitch)])
    axis = (focal - eye) / np.linalg.norm(focal - eye)
    rays = points - eye
    angles = np.arccos(np.clip(rays.dot(axis) / np.linalg.norm(rays, axis=1), -1.0, 1.0))
    return int(np.sum(angles > float(view['Field of View']) / 2.0))


class SceneRvizCamera(unittest.TestCase):

    def test_a_tall_robot_is_framed_whole(self):
        points = vertices('/tall/rigid_body_server')
        self.assertGreater(np.ptp(points[:, 2]), 1.5, 'the manipulator should be over 1.5 m tall')
        self.assertGreater(outside_view(CONFIG, points), 0, 'demo.rviz should crop the manipulator')
        framed = scene_rviz().framed_config(CONFIG, '/tall/rigid_body_server', 'auto')
        self.assertNotEqual(framed, CONFIG)
        self.assertEqual(outside_view(framed, points), 0, 'vertices outside the framed view')

    def test_a_view_that_fits_is_kept(self):
        self.assertEqual(scene_rviz().framed_config(CONFIG, '/scene/rigid_body_server', 'auto'), CONFIG)
        framed = scene_rviz().framed_config(CONFIG, '/scene/rigid_body_server', 'always')
        self.assertEqual(outside_view(framed, vertices('/scene/rigid_body_server')), 0)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'scene_rviz_camera', SceneRvizCamera, sys.argv)
