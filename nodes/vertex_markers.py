#!/usr/bin/python3
"""Publishes every body's vertices as rviz markers, from the services.

The points come from ``get_vertex_jacobians`` (positions in the fixed
frame) at the q of each ``~states`` message, so in rviz they must sit on the
meshes that RobotModel draws from tf: a visual check that tf and the
services agree. Optionally the Jacobian column dp/dq_j of one coordinate is
drawn as arrows (line segments from each vertex along dp/dq_j) at a subset
of the vertices. With ``~color_by: link`` every link of a body (get_bodies'
links: a body's vertices are its links', contiguous, in link order) has its
own colour, so the links of an articulated body are told apart.

Subscribes: ``<server>/states`` (diff_rigid_body/BodyStateArray)
Publishes:  ``~markers`` (visualization_msgs/MarkerArray, latched), only when
            a state changes, at most ``~max_rate`` times a second.

Parameters:
  ~server          the node to ask (default: rigid_body_server)
  ~point_size      [m] point marker width (default 0.0025)
  ~stride          draw every stride-th vertex (default 1: all)
  ~jacobian_column -1 (default): no arrows; j >= 0: arrows of dp/dq_j, for the
                   bodies with more than j coordinates (d: 6 for a free body)
  ~arrow_stride    arrow every arrow_stride-th vertex (default 32)
  ~arrow_length    [m] length of a body's longest arrow (default 0.04); the
                   others in proportion to |dp/dq_j|
  ~max_rate        [Hz] (default 10)
  ~color_by        'body' (default): one colour per body; 'link': one per link
  ~colors          {name: [r, g, b]} point colours, names of bodies or of links
                   as ~color_by says (unlisted names: a fixed palette, in order)
"""
import colorsys
import threading

import numpy as np
import rospy
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from diff_rigid_body.client import DiffRigidBodyError, RigidBodyClient
from diff_rigid_body.msg import BodyStateArray

# Saturated colours, unlike the meshes', so markers stand out (and the
# visual test can find them): yellow, magenta, then around the hue circle.
PALETTE = [(1.0, 1.0, 0.0), (1.0, 0.0, 1.0)] + [colorsys.hsv_to_rgb(h, 1.0, 1.0) for h in (0.55, 0.08, 0.75, 0.33)]


def to_points(array):
    return [Point(x, y, z) for x, y, z in array.tolist()]


class VertexMarkers(object):

    def __init__(self):
        server = rospy.get_param('~server', 'rigid_body_server')
        self.client = RigidBodyClient(server)
        self.point_size = float(rospy.get_param('~point_size', 0.0025))
        self.stride = max(1, int(rospy.get_param('~stride', 1)))
        self.column = int(rospy.get_param('~jacobian_column', -1))
        self.arrow_stride = max(1, int(rospy.get_param('~arrow_stride', 32)))
        self.arrow_length = float(rospy.get_param('~arrow_length', 0.04))
        self.min_period = rospy.Duration(1.0 / max(float(rospy.get_param('~max_rate', 10.0)), 0.1))
        colors = rospy.get_param('~colors', {})
        color_by = rospy.get_param('~color_by', 'body')
        if self.column < -1:
            raise ValueError('~jacobian_column must be -1 (none) or a coordinate index >= 0, not %d' % self.column)
        if color_by not in ('body', 'link'):
            raise ValueError("~color_by must be 'body' or 'link', not %r" % color_by)

        bodies = self.client.bodies()
        self.fixed_frame = bodies.fixed_frame
        self.names = bodies.names
        self.dofs = dict(zip(self.names, (int(d) for d in bodies.dofs)))
        self.vertices = {name: np.arange(0, count, self.stride)
                         for name, count in zip(self.names, bodies.vertex_counts)}
        self.groups = self.colour_groups(bodies, color_by, colors)

        self.lock = threading.Lock()
        self.last_q = None
        self.last_publish = rospy.Time(0)
        self.pending = None
        self.publisher = rospy.Publisher('~markers', MarkerArray, queue_size=1, latch=True)
        self.subscriber = rospy.Subscriber(rospy.resolve_name(server) + '/states', BodyStateArray, self.on_states,
                                           queue_size=1)
        self.timer = rospy.Timer(self.min_period, self.on_timer)

    def colour_groups(self, bodies, color_by, colors):
        """Per body: [(name, colour, rows)], the rows of ``self.vertices[body]``
        drawn in that colour: all of them (by body) or each link's (by link;
        links without vertices have none)."""
        groups, used = {}, 0
        for body, links in zip(self.names, bodies.links):
            vertices = self.vertices[body]
            if color_by == 'body':
                parts = [(body, np.arange(len(vertices)))]
            else:
                parts = [(link.name, np.nonzero((vertices >= link.first_vertex) &
                                                (vertices < link.first_vertex + link.vertex_count))[0])
                         for link in links if link.vertex_count > 0]
            groups[body] = []
            for name, rows in parts:
                groups[body].append((name, colors.get(name, PALETTE[used % len(PALETTE)]), rows))
                used += 1
        return groups

    def on_states(self, message):
        q = {state.name: tuple(state.q) for state in message.states}
        with self.lock:
            if q != self.last_q:
                self.pending = q

    def on_timer(self, _event):
        with self.lock:
            q, self.pending = self.pending, None
        if q is None:
            return
        try:
            self.publish(q)
        except (DiffRigidBodyError, rospy.ServiceException, rospy.ROSException) as e:
            rospy.logwarn_throttle(5.0, 'vertex_markers: %s' % e)
            return
        with self.lock:
            self.last_q = q

    def publish(self, states):
        stamp = rospy.Time.now()
        markers = MarkerArray()
        for index, name in enumerate(self.names):
            if name not in states:
                continue
            positions, J = self.client.vertex_jacobians(name, q=states[name], vertices=self.vertices[name])
            for part, (label, colour, rows) in enumerate(self.groups[name]):
                # ns 'vertices/<body>', or 'vertices/<body>/<link>' for a body's other links
                ns = 'vertices/' + name + ('' if label == name else '/' + label)
                marker = Marker(type=Marker.POINTS, action=Marker.ADD, ns=ns, id=part)
                marker.header.frame_id = self.fixed_frame
                marker.header.stamp = stamp
                marker.pose.orientation.w = 1.0
                marker.scale.x = marker.scale.y = self.point_size
                marker.color = ColorRGBA(*(list(colour) + [1.0]))
                marker.points = to_points(positions[rows])
                markers.markers.append(marker)
            if 0 <= self.column < self.dofs[name]:
                arrows = Marker(type=Marker.LINE_LIST, action=Marker.ADD, ns='jacobian/' + name, id=index)
                arrows.header.frame_id = self.fixed_frame
                arrows.header.stamp = stamp
                arrows.pose.orientation.w = 1.0
                arrows.scale.x = 0.0015
                arrows.color = ColorRGBA(0.2, 1.0, 0.2, 1.0)
                tail = positions[::self.arrow_stride]
                column = J[::self.arrow_stride, :, self.column]
                longest = np.max(np.linalg.norm(column, axis=1)) if len(column) else 0.0
                head = tail + (self.arrow_length / longest if longest > 0 else 0.0) * column
                arrows.points = to_points(np.stack([tail, head], axis=1).reshape(-1, 3))
                markers.markers.append(arrows)
        self.publisher.publish(markers)


def main():
    rospy.init_node('vertex_markers')
    VertexMarkers()
    rospy.spin()


if __name__ == '__main__':
    main()
