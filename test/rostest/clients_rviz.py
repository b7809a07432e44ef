#!/usr/bin/python3
"""The rviz visual check (clients_rviz.test).

rviz/demo.rviz is rendered headless (this node runs under xvfb-run; rviz
uses software OpenGL) at the initial state of the default scene, then again
after set_state moves the knot. On the two screenshots:

- body pixels are present: the knot's mesh (teal, from RobotModel posed by
  tf) and both bodies' vertex markers (from get_vertex_jacobians) - not an
  empty grid;
- the knot's markers sit on its mesh (tf and the services agree);
- the images differ, and only where the knot was or went: the rock, the
  table and the grid did not change;
- the knot moved on screen.

The screenshots are saved beside the test's XML result.
"""
import os
import sys
import tempfile
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body import rviz_capture as rc
from diff_rigid_body.client import RigidBodyClient

PKG = 'diff_rigid_body'
MIN_BODY_PIXELS = 300        # per mask: knot mesh, knot markers, rock markers
ON_MESH_RADIUS = 4           # [px] a knot marker pixel must have mesh pixels this close...
ON_MESH_FRACTION = 0.85      # ...for this fraction of them
CHANGE_THRESHOLD = 40        # per-channel difference that counts as a changed pixel
MIN_CHANGED_PIXELS = 2000
BOX_MARGIN = 25              # [px] around the knot's boxes (its tf axes and label)
MAX_CHANGED_ELSEWHERE = 0.02  # fraction of the changed pixels outside the knot's boxes
MIN_KNOT_SHIFT = 30          # [px] centroid shift of the knot on screen
MOVED_KNOT = [0.6, 0.4, 1.3, -0.03, 0.0, 0.58]  # phi theta psi [rad], COM [m]: right, higher, turned


def results_directory():
    for arg in sys.argv:
        if arg.startswith('--gtest_output=xml:'):
            return os.path.dirname(arg[len('--gtest_output=xml:'):])
    return tempfile.gettempdir()


def knot_pixels(image):
    return rc.knot_mesh_mask(image) | rc.yellow_mask(image)


class RvizVisualCheck(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.directory = results_directory()
        os.makedirs(cls.directory, exist_ok=True)
        cls.client = RigidBodyClient('/rigid_body_server', timeout=60.0).connect()
        cls.log = open(os.path.join(cls.directory, 'clients_rviz_rviz.log'), 'w')
        cls.rviz = rc.start_rviz(log=cls.log)

    @classmethod
    def tearDownClass(cls):
        rc.stop(cls.rviz)
        cls.log.close()

    def assert_scene_visible(self, image, name):
        counts = rc.scene_counts(image)
        for what, count in counts.items():
            self.assertGreaterEqual(count, MIN_BODY_PIXELS, '%s: too few %s pixels: %s' % (name, what, counts))
        markers = rc.yellow_mask(image)
        near_mesh = rc.dilate(rc.knot_mesh_mask(image), ON_MESH_RADIUS)
        fraction = (markers & near_mesh).sum() / markers.sum()
        self.assertGreaterEqual(fraction, ON_MESH_FRACTION,
                                '%s: only %.2f of the knot marker pixels lie on its mesh' % (name, fraction))
        rospy.loginfo('%s: %s, %.3f of the knot marker pixels on its mesh', name, counts, fraction)

    def test_rendered_scene_follows_set_state(self):
        path_a, a = rc.wait_for_frame(self.directory, 'clients_rviz_initial.png', rc.scene_visible, timeout=120.0,
                                         rviz=self.rviz)
        self.assert_scene_visible(a, path_a)
        knot_a = knot_pixels(a)

        self.client.set_state({'knot': MOVED_KNOT})

        def knot_moved(image):
            shift = np.linalg.norm(rc.centroid(knot_pixels(image)) - rc.centroid(knot_a))
            return rc.scene_visible(image) and shift >= MIN_KNOT_SHIFT

        path_b, b = rc.wait_for_frame(self.directory, 'clients_rviz_moved.png', knot_moved, timeout=60.0, rviz=self.rviz)
        self.assert_scene_visible(b, path_b)
        knot_b = knot_pixels(b)

        changed = np.any(np.abs(a.astype(int) - b.astype(int)) > CHANGE_THRESHOLD, axis=2)
        self.assertGreaterEqual(changed.sum(), MIN_CHANGED_PIXELS, 'the images barely differ')
        knot_region = (rc.box_mask(changed.shape, rc.bounding_box(knot_a, BOX_MARGIN)) |
                       rc.box_mask(changed.shape, rc.bounding_box(knot_b, BOX_MARGIN)))
        elsewhere = (changed & ~knot_region).sum() / changed.sum()
        self.assertLessEqual(elsewhere, MAX_CHANGED_ELSEWHERE,
                             '%.3f of the changed pixels are away from the knot' % elsewhere)
        # The rock did not move: its markers cover the same pixels.
        rock_a, rock_b = rc.magenta_mask(a), rc.magenta_mask(b)
        overlap = (rock_a & rock_b).sum() / (rock_a | rock_b).sum()
        self.assertGreaterEqual(overlap, 0.9, 'the rock markers changed (IoU %.2f)' % overlap)
        rospy.loginfo('rviz check: %d changed pixels, %.4f of them away from the knot; rock IoU %.3f',
                      changed.sum(), elsewhere, overlap)


if __name__ == '__main__':
    rospy.init_node('clients_rviz_test')
    rostest.rosrun(PKG, 'clients_rviz', RvizVisualCheck)
