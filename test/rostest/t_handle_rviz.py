#!/usr/bin/python3
"""The T-handle's flip in rviz (t_handle_rviz.test): docs/rviz_t_handle.png.

The demo's toss (diff_rigid_body_examples.t_handle) is integrated by RK4 through the
node's ``forward_dynamics`` (diff_rigid_body_examples.dynamics_fitting.integrate), as
nodes/demo_client.py does. A strobe picture of the flight is drawn in rviz
(headless: this node runs under xvfb-run, rviz uses software OpenGL):

- at every STRIDE-th frame (0.1 s apart) within 4 STRIDE frames of the
  flip, the T-handle's vertices at the integrated state, from one batched
  ``get_vertex_jacobians`` call: points and a wireframe of the cylinders'
  rims, the bar cyan and the grip yellow, with the time above each pose;
- the COM's path at every frame (small grey spheres);
- RobotModel's meshes (aluminium bar, red grip), posed by the node's tf
  after ``set_state`` to the frame nearest the flip; that pose's markers are
  points only, on the rendered body.

The config is rviz/demo.rviz's displays (grid, RobotModel, MarkerArray on
this node's ``~strobe``) with the grid stood up behind the flight, seen
from the side. Checks on the screenshot: the markers of both parts and the
red grip mesh are on screen; the wireframed poses are separate groups of
marker pixels, as many left of the mesh (the pose at the flip) as there are
strobe frames before the flip and as many right of it as after; and in every
pose before the flip the grip's markers lie above the bar's, in every pose
after it below: the grip has turned over. The
screenshot and its crop to the 3D view are saved beside the test's XML
result; DRB_SAVE_SCREENSHOT=PATH also copies the crop to PATH.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import rospy
import rostest
import scipy.ndimage
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from diff_rigid_body_examples import dynamics_fitting, t_handle
from diff_rigid_body import rviz_capture as rc
from diff_rigid_body.client import RigidBodyClient

PKG = 'diff_rigid_body'
SCREENSHOT = 't_handle_rviz.png'
CROPPED = 't_handle_rviz_view.png'
STRIDE = 5                    # frames between strobe poses (0.1 s)
BAR_COLOUR = (0.0, 0.85, 1.0)
GRIP_COLOUR = (1.0, 0.9, 0.0)
PATH_COLOUR = (0.7, 0.7, 0.7)
SEGMENTS = 32                 # vertices per cylinder rim (a cylinder: two rims)
MIN_BAR_PIXELS = 3000
MIN_GRIP_PIXELS = 800
MIN_MESH_PIXELS = 100         # the red grip mesh
POSE_GAP = 4                  # [px] marker pixels this close belong to one pose
MIN_POSE_PIXELS = 20          # bar and grip pixels of a pose, each at least
MIN_OFFSET = 3.0              # [px] grip centroid above (before the flip) or below (after) the bar's, at least
MESH_MARGIN = 40              # [px] poses this close to the mesh's column (the pose at the flip) are not counted
BACKGROUND = (48, 48, 48)
WAIT = 180.0                  # [s] for rviz to show the picture

RVIZ_CONFIG = """Panels:
  - Class: rviz/Displays
    Name: Displays
Visualization Manager:
  Class: ""
  Displays:
    - Alpha: 0.35
      Cell Size: 0.1
      Class: rviz/Grid
      Color: 160; 160; 164
      Enabled: true
      Line Style:
        Line Width: 0.03
        Value: Lines
      Name: Grid
      Normal Cell Count: 0
      Offset:
        X: 0
        Y: 0.4
        Z: 1.6
      Plane: XZ
      Plane Cell Count: 24
      Reference Frame: <Fixed Frame>
      Value: true
    - Alpha: 1
      Class: rviz/RobotModel
      Collision Enabled: false
      Enabled: true
      Links:
        All Links Enabled: true
      Name: RobotModel (robot_description, posed by tf)
      Robot Description: robot_description
      TF Prefix: ""
      Update Interval: 0
      Value: true
      Visual Enabled: true
    - Class: rviz/MarkerArray
      Enabled: true
      Marker Topic: %(topic)s
      Name: Strobe (get_vertex_jacobians along the RK4 toss)
      Namespaces:
        {}
      Queue Size: 100
      Value: true
  Enabled: true
  Global Options:
    Background Color: %(background)s
    Default Light: true
    Fixed Frame: world
    Frame Rate: 30
  Name: root
  Tools:
    - Class: rviz/MoveCamera
  Value: true
  Views:
    Current:
      Class: rviz/Orbit
      Distance: 1.85
      Field of View: 0.785398
      Focal Point:
        X: -0.06
        Y: 0
        Z: 1.65
      Focal Shape Fixed Size: true
      Focal Shape Size: 0.05
      Invert Z Axis: false
      Name: Current View
      Near Clip Distance: 0.01
      Pitch: 0.12
      Target Frame: <Fixed Frame>
      Yaw: 4.71238898
    Saved: ~
Window Geometry:
  Displays:
    collapsed: true
  Height: 800
  Hide Left Dock: true
  Hide Right Dock: true
  Width: 1280
  X: 0
  Y: 0
"""


def results_directory():
    for arg in sys.argv:
        if arg.startswith('--gtest_output=xml:'):
            return os.path.dirname(arg[len('--gtest_output=xml:'):])
    return tempfile.gettempdir()


def colour_mask(image, colour, distance=90.0):
    return np.linalg.norm(image.astype(float) - 255.0 * np.asarray(colour), axis=2) <= distance


def pose_rows(image):
    """The strobe poses on screen, left to right: (column, grip row - bar row) of each connected group of
    marker pixels (dilated by POSE_GAP px) that holds both parts; the rows are centroids (image y, down)."""
    bar, grip = colour_mask(image, BAR_COLOUR), colour_mask(image, GRIP_COLOUR)
    labels, count = scipy.ndimage.label(rc.dilate(bar | grip, POSE_GAP))
    poses = []
    for label in range(1, count + 1):
        inside = labels == label
        if (bar & inside).sum() >= MIN_POSE_PIXELS and (grip & inside).sum() >= MIN_POSE_PIXELS:
            column = float(rc.centroid((bar | grip) & inside)[1])
            poses.append((round(column), round(float(rc.centroid(grip & inside)[0] - rc.centroid(bar & inside)[0]),
                                               1)))
    return sorted(poses)


def red_mesh_mask(image):
    """The grip's red mesh under rviz lighting."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    return (r > 100) & (r - g > 60) & (r - b > 60)


def view_box(image):
    """(row0, row1, col0, col1): the rows and columns that are at least 20% background (rviz's 3D view)."""
    background = np.all(image == np.asarray(BACKGROUND), axis=2)
    rows = np.nonzero(background.mean(axis=1) >= 0.2)[0]
    cols = np.nonzero(background.mean(axis=0) >= 0.2)[0]
    return rows.min(), rows.max() + 1, cols.min(), cols.max() + 1


def rgba(colour, alpha=1.0):
    return ColorRGBA(colour[0], colour[1], colour[2], alpha)


def to_points(array):
    return [Point(x, y, z) for x, y, z in np.asarray(array).tolist()]


def wireframe(positions):
    """LINE_LIST points of a cylinder's two rims (SEGMENTS vertices each, as the node tessellates it):
    the rim edges and every 4th edge between the rims."""
    segments = []
    for rim in (0, SEGMENTS):
        for s in range(SEGMENTS):
            segments += [positions[rim + s], positions[rim + (s + 1) % SEGMENTS]]
    for s in range(0, SEGMENTS, 4):
        segments += [positions[s], positions[SEGMENTS + s]]
    return to_points(segments)


def strobe_markers(frame_id, times, positions, coms, bar_vertices, meshed, flip):
    """The MarkerArray: per strobe pose (positions (n, N, 3)) points and wireframes of the bar (vertices
    [0, bar_vertices)) and the grip (the rest), and a time label; the pose ``meshed`` (an index), which
    RobotModel shows, gets points only (the mesh shows between them) and the ``flip`` time [s] in its
    label. The COM path (coms (T, 3)) as small spheres."""
    markers = []
    stamp = rospy.Time(0)

    def marker(ns, index, kind, colour, scale):
        m = Marker()
        m.header.frame_id, m.header.stamp = frame_id, stamp
        m.ns, m.id, m.type, m.action = ns, index, kind, Marker.ADD
        m.pose.orientation.w = 1.0
        m.scale.x = m.scale.y = m.scale.z = scale
        m.color = rgba(colour)
        return m

    for k, (t, p) in enumerate(zip(times, positions)):
        for name, colour, part in (('bar', BAR_COLOUR, p[:bar_vertices]), ('grip', GRIP_COLOUR, p[bar_vertices:])):
            points = marker('strobe/%s/vertices' % name, k, Marker.POINTS, colour, 0.006 if k == meshed else 0.008)
            points.points = to_points(part)
            markers.append(points)
            if k != meshed:
                lines = marker('strobe/%s/rims' % name, k, Marker.LINE_LIST, colour, 0.003)
                lines.points = wireframe(part)
                markers.append(lines)
        label = marker('strobe/time', k, Marker.TEXT_VIEW_FACING, (1.0, 1.0, 1.0), 0.035)
        label.pose.position = Point(p[:, 0].mean(), p[:, 1].mean(), p[:, 2].max() + 0.06)
        label.text = '%.2f s' % t + (' (flip: %.3f s)' % flip if k == meshed else '')
        markers.append(label)
    path = marker('com_path', 0, Marker.SPHERE_LIST, PATH_COLOUR, 0.006)
    path.points = to_points(coms)
    markers.append(path)
    return MarkerArray(markers=markers)


class THandleFlipInRviz(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.directory = results_directory()
        os.makedirs(cls.directory, exist_ok=True)
        cls.client = RigidBodyClient('/rigid_body_server', timeout=60.0).connect()
        bodies = cls.client.bodies()
        index = bodies.names.index(t_handle.BODY)
        cls.bar_vertices = bodies.links[index][0].vertex_count
        s0 = t_handle.hidden_toss()
        states, _ = dynamics_fitting.integrate(cls.client, t_handle.BODY, s0, t_handle.FRAME_TIME, t_handle.FRAMES)
        times = np.arange(t_handle.FRAMES) * t_handle.FRAME_TIME
        flips, _ = dynamics_fitting.flip_times(cls.client, t_handle.BODY, s0, bodies.inertias[index],
                                               t_handle.INTERMEDIATE_AXIS, t_handle.FRAME_TIME, t_handle.FRAMES)
        cls.flip = flips[0]
        cls.flip_frame = int(round(cls.flip / t_handle.FRAME_TIME))
        strobe = np.arange(cls.flip_frame % STRIDE, t_handle.FRAMES, STRIDE)
        strobe = strobe[(strobe >= cls.flip_frame - 4 * STRIDE) & (strobe <= cls.flip_frame + 4 * STRIDE)]
        cls.strobe = strobe
        positions, _ = cls.client.vertex_jacobians(t_handle.BODY, states[strobe, :6])
        cls.client.set_state({t_handle.BODY: states[cls.flip_frame, :6]})
        cls.publisher = rospy.Publisher('~strobe', MarkerArray, queue_size=1, latch=True)
        cls.publisher.publish(strobe_markers(bodies.fixed_frame, times[strobe], positions, states[:, 3:6],
                                             cls.bar_vertices, int(np.nonzero(strobe == cls.flip_frame)[0][0]),
                                             cls.flip))
        cls.config = os.path.join(cls.directory, 't_handle_rviz.rviz')
        with open(cls.config, 'w') as f:
            f.write(RVIZ_CONFIG % {'topic': rospy.resolve_name('~strobe'),
                                   'background': '; '.join(str(v) for v in BACKGROUND)})
        cls.log = open(os.path.join(cls.directory, 't_handle_rviz_rviz.log'), 'w')
        cls.rviz = rc.start_rviz(cls.config, cls.log, bodies.fixed_frame)

    @classmethod
    def tearDownClass(cls):
        rc.stop(cls.rviz)
        cls.log.close()

    @staticmethod
    def counts(image):
        return {'bar markers': int(colour_mask(image, BAR_COLOUR).sum()),
                'grip markers': int(colour_mask(image, GRIP_COLOUR).sum()), 'grip mesh': int(red_mesh_mask(image).sum())}

    def visible(self, image):
        counts = self.counts(image)
        return (counts['bar markers'] >= MIN_BAR_PIXELS and counts['grip markers'] >= MIN_GRIP_PIXELS
                and counts['grip mesh'] >= MIN_MESH_PIXELS)

    def test_the_grip_turns_over_in_the_picture(self):
        self.assertTrue(0.3 < self.flip < 0.9, 'the toss flips at %s s' % self.flip)
        try:
            path, image = rc.wait_for_frame(self.directory, SCREENSHOT, self.visible, timeout=WAIT, rviz=self.rviz)
        except RuntimeError:
            path = os.path.join(self.directory, SCREENSHOT)
            self.fail('rviz did not show the strobe markers and the grip mesh within %g s; pixels of the last frame '
                      '%s: %s' % (WAIT, path, self.counts(rc.without_status_bar(rc.read_rgb(path)))))
        row0, row1, col0, col1 = view_box(image)
        image = image.copy()  # only rviz's 3D view counts (not the panels' icons)
        outside = np.ones(image.shape[:2], dtype=bool)
        outside[row0:row1, col0:col1] = False
        image[outside] = BACKGROUND
        counts = self.counts(image)
        poses = pose_rows(image)
        rospy.loginfo('%s: pixels %s; per pose on screen, left to right: (column, grip row - bar row) [px, image y '
                      'down] %s; flip at %.4f s (frame %d), strobe frames %s', path, counts, poses, self.flip,
                      self.flip_frame, self.strobe.tolist())
        mesh_column = rc.centroid(red_mesh_mask(image))[1]
        before = [offset for column, offset in poses if column < mesh_column - MESH_MARGIN]
        after = [offset for column, offset in poses if column > mesh_column + MESH_MARGIN]
        expected = (int(np.sum(self.strobe < self.flip_frame)), int(np.sum(self.strobe > self.flip_frame)))
        self.assertEqual((len(before), len(after)), expected,
                         '%s: poses left and right of the grip mesh (column %.0f): %s, expected %s' % (
                             path, mesh_column, poses, expected))
        self.assertTrue(all(offset < -MIN_OFFSET for offset in before),
                        '%s: before the flip every grip must lie above its bar (row offsets %s)' % (path, before))
        self.assertTrue(all(offset > MIN_OFFSET for offset in after),
                        '%s: after the flip every grip must lie below its bar (row offsets %s)' % (path, after))
        cropped = os.path.join(self.directory, CROPPED)
        subprocess.run(['convert', path, '-crop', '%dx%d+%d+%d' % (col1 - col0, row1 - row0, col0, row0), '+repage',
                        '-strip', '-define', 'png:exclude-chunks=date,time', cropped], check=True)
        save = os.environ.get('DRB_SAVE_SCREENSHOT')
        if save:
            os.makedirs(os.path.dirname(os.path.abspath(save)), exist_ok=True)
            shutil.copyfile(cropped, save)


if __name__ == '__main__':
    rospy.init_node('t_handle_rviz_test')
    rostest.rosrun(PKG, 't_handle_rviz', THandleFlipInRviz)
