#!/usr/bin/python3
"""The Franka Panda in rviz (robot_panda_rviz.test).

rviz (config ``~config``, in the fixed frame that get_bodies reports) is
rendered headless (this node runs under xvfb-run; rviz uses software
OpenGL) with the Panda's visual meshes (RobotModel, posed by tf) and every
body's vertex markers (vertex_markers.py, from get_vertex_jacobians, one
saturated colour per body, read from ``<~markers_node>/colors``). On the
screenshot, inside rviz's 3D view:

- robot mesh pixels are present (the meshes are white/grey: near the grey
  axis r = g = b, unlike the tinted background and grid);
- marker pixels (within MARKER_DISTANCE of a body's colour) are present,
  for every body of at least SEEN_VERTICES vertices (the arm links; the
  fingers are mostly behind the hand in this view);
- the markers lie on the meshes: at least ON_MESH_FRACTION of the marker
  pixels, and of each of those bodies' marker pixels, have a mesh pixel
  within ON_MESH_RADIUS (tf, the Collada placement and the served vertices
  agree). Markers shifted by 2 cm give 0.84 (link6 0.67), by 10 cm below 0.5.

The screenshot is saved beside the test's XML result and, when
DRB_SAVE_SCREENSHOT names a path and every check passed, copied there too.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import rospy
import rostest

from diff_rigid_body import rviz_capture as rc
from diff_rigid_body.client import RigidBodyClient

PKG = 'diff_rigid_body'
SCREENSHOT = 'robot_panda_rviz.png'
MESH_CHROMA = 12             # max(r, g, b) - min(r, g, b) of a mesh pixel, at most
MARKER_DISTANCE = 100        # RGB distance (0..255 per channel) of a marker pixel to its body's colour, at most
MIN_MESH_PIXELS = 5000
MIN_MARKER_PIXELS = 3000     # all bodies together
MIN_BODY_MARKER_PIXELS = 200  # each body of at least SEEN_VERTICES vertices
SEEN_VERTICES = 1000
ON_MESH_RADIUS = 4           # [px] a marker pixel must have mesh pixels this close...
ON_MESH_FRACTION = 0.85      # ...for this fraction of the marker pixels
VIEW_BACKGROUND = 0.2        # a row or column of the 3D view is at least this fraction background


def results_directory():
    for arg in sys.argv:
        if arg.startswith('--gtest_output=xml:'):
            return os.path.dirname(arg[len('--gtest_output=xml:'):])
    return tempfile.gettempdir()


def background_colour(config):
    """rviz's "Background Color: r; g; b" from the config file, as (3,) ints."""
    with open(config) as f:
        match = re.search(r'Background Color:\s*(\d+);\s*(\d+);\s*(\d+)', f.read())
    if match is None:
        raise ValueError('%s names no Background Color' % config)
    return np.array([int(v) for v in match.groups()])


def start_rviz(config, fixed_frame, log):
    """rviz on $DISPLAY with ``config`` in ``fixed_frame``, in its own process group (see rc.stop)."""
    return subprocess.Popen(['rviz', '-d', config, '-f', fixed_frame, '__name:=rviz_capture'],
                            env=rc.software_gl_environment(), stdout=log, stderr=subprocess.STDOUT,
                            start_new_session=True)


class PandaMasks(object):
    """Pixel masks of one screenshot, restricted to rviz's 3D view: the box of
    rows and columns that are at least VIEW_BACKGROUND background."""

    def __init__(self, image, background, colours, required):
        image = image.astype(int)
        is_background = np.all(image == background, axis=2)
        rows = np.nonzero(is_background.mean(axis=1) >= VIEW_BACKGROUND)[0]
        cols = np.nonzero(is_background.mean(axis=0) >= VIEW_BACKGROUND)[0]
        self.view = np.zeros(is_background.shape, dtype=bool)
        if rows.size and cols.size:
            self.view[rows.min():rows.max() + 1, cols.min():cols.max() + 1] = True
        chroma = image.max(axis=2) - image.min(axis=2)
        self.mesh = self.view & (chroma <= MESH_CHROMA)
        self.names = sorted(colours)
        distance = np.stack([np.linalg.norm(image - 255.0 * np.asarray(colours[name], dtype=float), axis=2)
                             for name in self.names])  # (n, H, W)
        nearest = distance.argmin(axis=0)
        self.markers = self.view & (distance.min(axis=0) <= MARKER_DISTANCE)
        self.body = {name: self.markers & (nearest == i) for i, name in enumerate(self.names)}
        self.required = required

    def counts(self):
        counts = {'mesh': int(self.mesh.sum()), 'markers': int(self.markers.sum())}
        counts.update({name: int(mask.sum()) for name, mask in self.body.items()})
        return counts

    def visible(self):
        return (self.mesh.sum() >= MIN_MESH_PIXELS and self.markers.sum() >= MIN_MARKER_PIXELS and
                all(self.body[name].sum() >= MIN_BODY_MARKER_PIXELS for name in self.required))

    def on_mesh(self, markers):
        """Fraction of the ``markers`` pixels with a mesh pixel within ON_MESH_RADIUS."""
        total = markers.sum()
        return (markers & rc.dilate(self.mesh, ON_MESH_RADIUS)).sum() / total if total else 0.0


class PandaInRviz(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.directory = results_directory()
        os.makedirs(cls.directory, exist_ok=True)
        cls.config = rospy.get_param('~config')
        cls.background = background_colour(cls.config)
        bodies = RigidBodyClient('/rigid_body_server', timeout=60.0).connect().bodies()
        cls.fixed_frame, cls.names = bodies.fixed_frame, list(bodies.names)
        cls.required = [name for name, count in zip(bodies.names, bodies.vertex_counts) if count >= SEEN_VERTICES]
        cls.colours = rospy.get_param(rospy.get_param('~markers_node', '/vertex_markers') + '/colors')
        cls.log = open(os.path.join(cls.directory, 'robot_panda_rviz_rviz.log'), 'w')
        cls.rviz = start_rviz(cls.config, cls.fixed_frame, cls.log)

    @classmethod
    def tearDownClass(cls):
        rc.stop(cls.rviz)
        cls.log.close()

    def masks(self, image):
        return PandaMasks(image, self.background, {name: self.colours[name] for name in self.names}, self.required)

    def test_markers_lie_on_the_panda_meshes(self):
        self.assertEqual(sorted(self.colours), sorted(self.names),
                         'the test gives vertex_markers one colour per body of get_bodies')
        try:
            path, image = rc.wait_for_frame(self.directory, SCREENSHOT, lambda im: self.masks(im).visible(),
                                            timeout=180.0)
        except RuntimeError:
            path = os.path.join(self.directory, SCREENSHOT)
            counts = self.masks(rc.without_status_bar(rc.read_rgb(path))).counts()
            self.fail('rviz did not show the Panda meshes and the markers of %s within 180 s; pixels of the last '
                      'frame %s: %s' % (', '.join(self.required), path, counts))
        masks = self.masks(image)
        counts = masks.counts()
        self.assertGreaterEqual(counts['mesh'], MIN_MESH_PIXELS, '%s: too few robot mesh pixels: %s' % (path, counts))
        self.assertGreaterEqual(counts['markers'], MIN_MARKER_PIXELS, '%s: too few marker pixels: %s' % (path, counts))
        for name in self.required:
            self.assertGreaterEqual(counts[name], MIN_BODY_MARKER_PIXELS,
                                    '%s: too few marker pixels of body %s: %s' % (path, name, counts))
        fraction = masks.on_mesh(masks.markers)
        per_body = {name: round(masks.on_mesh(masks.body[name]), 3) for name in self.names}
        rospy.loginfo('%s: pixels %s; %.3f of the marker pixels on the meshes (per body %s)', path, counts,
                      fraction, per_body)
        self.assertGreaterEqual(fraction, ON_MESH_FRACTION,
                                '%s: only %.3f of the marker pixels lie within %d px of mesh pixels (per body %s)' % (
                                    path, fraction, ON_MESH_RADIUS, per_body))
        for name in self.required:
            self.assertGreaterEqual(per_body[name], ON_MESH_FRACTION,
                                    '%s: only %.3f of the marker pixels of body %s lie within %d px of mesh pixels' % (
                                        path, per_body[name], name, ON_MESH_RADIUS))
        save = os.environ.get('DRB_SAVE_SCREENSHOT')
        if save:
            os.makedirs(os.path.dirname(os.path.abspath(save)), exist_ok=True)
            shutil.copyfile(path, save)


if __name__ == '__main__':
    rospy.init_node('robot_panda_rviz_test')
    rostest.rosrun(PKG, 'robot_panda_rviz', PandaInRviz)
