#!/usr/bin/python3
"""Checks that a real robot description loads into rigid_body_server and is served right.

Independent oracles: this file reads the URDF (xml.etree), STL (binary and
ASCII) and Collada files itself, without assimp, urdfdom or package code.
Collada is placed as rviz places it: the <node> transforms of the instanced
<visual_scene> are applied, then <asset><unit meter> scales; <up_axis> is
ignored. Only positions that surface primitives (triangles, polygons) use
count as vertices: the node drops lines and points.

Private parameters (set them in the .test file):
  ~urdf       URDF file the node was given as robot_description
  ~geometry   collision | visual: the kind the node was told to use (default collision)
  ~server     node name (default /rigid_body_server)

With ~joints: model (the default, docs/interface.md "Version 2") an arm is one
body holding all its links; with ~joints: free every jointed link is its own
body. The checks hold in both modes:

Checks: (a) ~get_bodies succeeds; (b) link lists, per-link masses, COMs and
inertias, and body masses (the sum of their links'), against the URDF; (c)
every mesh vertex and box corner of every body's links, placed at the link's
tf pose, is within 1e-6 m of a served vertex (spheres and cylinders, the
node's own tessellation, are skipped); (d) conversely for links with only
meshes and boxes, and counts; (e) each body's coordinates: its joints are
1-dof, non-mimic URDF joints moving its links, in URDF order, and dofs is
their number, plus 6 when the body's first link does not hang on one of them
(a floating root or a free body).
"""
import os
import re
import sys
import unittest
import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial import cKDTree

import rospkg
import rospy
import rostest
import tf2_ros

from diff_rigid_body.srv import GetBodies, GetVertexJacobians

PKG = 'diff_rigid_body'
TOLERANCE = 1e-6  # [m] a read point and its served vertex
CHECKED_KINDS = ('mesh', 'box')
SURFACE_PRIMITIVES = ('triangles', 'polylist', 'polygons', 'tristrips', 'trifans')  # Collada


# ---------------------------------------------------------------- geometry math
def floats(text):
    return [float(v) for v in text.split()]


def rpy_matrix(rpy):
    """R = Rz(yaw) Ry(pitch) Rx(roll), as in URDF."""
    (cr, sr), (cp, sp), (cy, sy) = [(np.cos(a), np.sin(a)) for a in rpy]
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def quaternion_matrix(x, y, z, w):
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def transform_points(T, points):
    return points @ T[:3, :3].T + T[:3, 3]


def axis_angle_matrix(axis, degrees):
    """Rodrigues: R = I + sin(a) K + (1 - cos(a)) K^2, K = [u]x, u = axis / |axis|."""
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    a = np.radians(degrees)
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


# ---------------------------------------------------------------- STL reader
def read_stl(path):
    """(3 per facet, 3) vertices. Binary when the size is 84 + 50 n, else ASCII ('solid' ... 'facet')."""
    with open(path, 'rb') as f:
        data = f.read()
    if len(data) >= 84:
        n = int(np.frombuffer(data, '<u4', 1, 80)[0])
        if len(data) == 84 + 50 * n:
            facet = np.dtype([('normal', '<f4', 3), ('v', '<f4', (3, 3)), ('attribute', '<u2')])
            return np.frombuffer(data, facet, n, 84)['v'].reshape(-1, 3).astype(float)
    if data.lstrip().startswith(b'solid') and b'facet' in data:
        number = rb'([-+0-9.eE]+)'
        found = re.findall(rb'vertex\s+' + number + rb'\s+' + number + rb'\s+' + number, data)
        return np.array(found, dtype=float).reshape(-1, 3)
    raise ValueError('%s is neither a binary nor an ASCII STL file' % path)


# ---------------------------------------------------------------- Collada reader
def read_collada(path):
    """Vertex positions of every instanced geometry, in metres, in the file's frame (up_axis ignored)."""
    root = ET.parse(path).getroot()
    ns = root.tag[:root.tag.index('}') + 1] if root.tag.startswith('{') else ''
    ids = {e.get('id'): e for e in root.iter() if e.get('id')}
    unit = root.find('%sasset/%sunit' % (ns, ns))
    meter = float(unit.get('meter', '1')) if unit is not None else 1.0
    scene = root.find('%sscene/%sinstance_visual_scene' % (ns, ns))
    visual_scene = (ids[scene.get('url')[1:]] if scene is not None
                    else root.find('%slibrary_visual_scenes/%svisual_scene' % (ns, ns)))
    parts = []
    for node in visual_scene.findall(ns + 'node'):
        collect_node(node, np.eye(4), ns, ids, parts)
    return (np.concatenate(parts) if parts else np.zeros((0, 3))) * meter


def node_transform(node, ns):
    """Product of the node's transformation elements in document order (column vectors)."""
    T = np.eye(4)
    for child in node:
        tag = child.tag[len(ns):]
        if tag in ('lookat', 'skew'):
            raise ValueError('Collada <%s> is not read by this test' % tag)
        v, step = floats(child.text) if tag in ('matrix', 'translate', 'rotate', 'scale') else None, np.eye(4)
        if tag == 'matrix':
            step = np.array(v).reshape(4, 4)
        elif tag == 'translate':
            step[:3, 3] = v
        elif tag == 'rotate':  # axis x y z, angle [degrees]
            step[:3, :3] = axis_angle_matrix(v[:3], v[3])
        elif tag == 'scale':
            step = np.diag(v + [1.0])
        T = T @ step
    return T


def collect_node(node, parent, ns, ids, parts):
    T = parent @ node_transform(node, ns)
    for child in node:
        tag = child.tag[len(ns):]
        if tag == 'instance_geometry':
            parts.append(transform_points(T, geometry_positions(ids[child.get('url')[1:]], ns, ids)))
        elif tag == 'instance_node':
            collect_node(ids[child.get('url')[1:]], T, ns, ids, parts)
        elif tag == 'node':
            collect_node(child, T, ns, ids, parts)


def geometry_positions(geometry, ns, ids):
    """Positions of <vertices>' POSITION source used by surface primitives, as (n, 3).

    Lines and points carry no surface: positions only they use are left out."""
    mesh = geometry.find(ns + 'mesh')
    position = [i for i in mesh.find(ns + 'vertices').findall(ns + 'input') if i.get('semantic') == 'POSITION'][0]
    source = ids[position.get('source')[1:]]
    accessor = source.find('%stechnique_common/%saccessor' % (ns, ns))
    values = np.array(floats(source.find(ns + 'float_array').text))
    stride, offset = int(accessor.get('stride', '3')), int(accessor.get('offset', '0'))
    count = int(accessor.get('count'))
    positions = values[offset:offset + count * stride].reshape(count, stride)[:, :3]
    used = []
    for primitive in mesh:
        if primitive.tag[len(ns):] not in SURFACE_PRIMITIVES:
            continue
        inputs = primitive.findall(ns + 'input')
        step = 1 + max(int(i.get('offset', '0')) for i in inputs)
        vertex = [int(i.get('offset', '0')) for i in inputs if i.get('semantic') == 'VERTEX'][0]
        for p in primitive.findall(ns + 'p'):
            used.append(np.array(p.text.split(), dtype=int)[vertex::step])
    return positions[np.unique(np.concatenate(used))] if used else np.zeros((0, 3))


# ---------------------------------------------------------------- URDF reader
def origin_of(element):
    T = np.eye(4)
    origin = element.find('origin') if element is not None else None
    if origin is not None:
        T[:3, :3] = rpy_matrix(floats(origin.get('rpy', '0 0 0')))
        T[:3, 3] = floats(origin.get('xyz', '0 0 0'))
    return T


def resolve_uri(uri, urdf_dir):
    if uri.startswith('package://'):
        package, _, rest = uri[len('package://'):].partition('/')
        return os.path.join(rospkg.RosPack().get_path(package), rest)
    if uri.startswith('file://'):
        return uri[len('file://'):]
    return uri if os.path.isabs(uri) else os.path.join(urdf_dir, uri)


def read_geometry(element, urdf_dir):
    shape = list(element.find('geometry'))[0]
    g = {'kind': shape.tag, 'origin': origin_of(element), 'text': shape.tag}
    if shape.tag == 'mesh':
        g['path'] = resolve_uri(shape.get('filename'), urdf_dir)
        g['scale'] = floats(shape.get('scale', '1 1 1'))
        g['text'] = 'mesh ' + os.path.basename(g['path'])
    elif shape.tag == 'box':
        g['size'] = floats(shape.get('size'))
    return g


def read_urdf(path):
    """{'name', 'links': {name: link} in document order, 'joints': [joint]} of a URDF file."""
    robot = ET.parse(path).getroot()
    urdf_dir = os.path.dirname(os.path.abspath(path))
    links = {}
    for element in robot.findall('link'):
        inertial = element.find('inertial')
        mass = inertial.find('mass') if inertial is not None else None
        inertia = inertial.find('inertia') if inertial is not None else None
        I = np.zeros((3, 3))
        if inertia is not None:
            v = {k: float(inertia.get(k, '0')) for k in ('ixx', 'ixy', 'ixz', 'iyy', 'iyz', 'izz')}
            I = np.array([[v['ixx'], v['ixy'], v['ixz']], [v['ixy'], v['iyy'], v['iyz']],
                          [v['ixz'], v['iyz'], v['izz']]])
        com = origin_of(inertial)  # inertia about the COM in link axes: R I R^T, R = Rpy(inertial origin)
        links[element.get('name')] = {
            'name': element.get('name'),
            'mass': float(mass.get('value')) if mass is not None else 0.0,
            'com': com[:3, 3], 'inertia': com[:3, :3] @ I @ com[:3, :3].T,
            'collision': [read_geometry(e, urdf_dir) for e in element.findall('collision')],
            'visual': [read_geometry(e, urdf_dir) for e in element.findall('visual')]}
    joints = [{'name': j.get('name'), 'type': j.get('type'), 'parent': j.find('parent').get('link'),
               'child': j.find('child').get('link'), 'mimic': j.find('mimic') is not None}
              for j in robot.findall('joint')]
    return {'name': robot.get('name'), 'links': links, 'joints': joints}


def static_links(urdf):
    """The root link and every link joined to it by fixed joints only."""
    children = {j['child'] for j in urdf['joints']}
    roots = [name for name in urdf['links'] if name not in children]
    assert len(roots) == 1, 'the URDF has %d root links: %s' % (len(roots), roots)
    static, frontier = set(roots), list(roots)
    while frontier:
        parent = frontier.pop()
        for j in urdf['joints']:
            if j['parent'] == parent and j['type'] == 'fixed' and j['child'] not in static:
                static.add(j['child'])
                frontier.append(j['child'])
    return static


def link_geometry(link, kind):
    """The link's geometry elements of the chosen kind, or of the other kind when it has none."""
    other = 'visual' if kind == 'collision' else 'collision'
    return link[kind] or link[other]


def geometry_points(g):
    """Points of a mesh (scaled) or the 8 corners of a box, in the link frame."""
    if g['kind'] == 'mesh':
        read = read_collada if g['path'].lower().endswith('.dae') else read_stl
        local = read(g['path']) * np.asarray(g['scale'])
    else:
        half = np.asarray(g['size']) / 2
        local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    return transform_points(g['origin'], local)


# ---------------------------------------------------------------- the test
class RobotDescription(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.urdf_path = rospy.get_param('~urdf')
        cls.kind = rospy.get_param('~geometry', 'collision')
        cls.server = rospy.get_param('~server', '/rigid_body_server').rstrip('/')
        cls.urdf = read_urdf(cls.urdf_path)
        cls.robot = '%s (%s, %s geometry)' % (cls.urdf['name'], os.path.basename(cls.urdf_path), cls.kind)
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)
        cls.answer = None

    def bodies(self):
        """The ~get_bodies answer, with per-body link lists."""
        if self.answer is None:
            service = self.server + '/get_bodies'
            try:
                rospy.wait_for_service(service, timeout=100.0)
            except rospy.ROSException as e:
                self.fail('%s: the node never offered %s (did it refuse the description?): %s'
                          % (self.robot, service, e))
            type(self).answer = rospy.ServiceProxy(service, GetBodies)()
        a = self.answer
        self.assertTrue(a.success, '%s: %s/get_bodies failed: %s' % (self.robot, self.server, a.message))
        self.assertEqual(len(a.link_counts), len(a.names), '%s: link_counts is not one per body' % self.robot)
        n = len(a.link_names)
        self.assertEqual(sum(a.link_counts), n, '%s: link_counts do not add up' % self.robot)
        sizes = [len(a.link_vertex_counts), len(a.link_masses), len(a.link_inertias) / 9, len(a.link_com_offsets) / 3]
        self.assertEqual(sizes, [n] * 4, '%s: %d link_names but per-link fields for [vertex counts, masses, '
                         'inertias, COM offsets] of %s links' % (self.robot, n, sizes))
        starts = np.concatenate([[0], np.cumsum(a.link_counts)]).astype(int)
        return a, [list(range(starts[b], starts[b + 1])) for b in range(len(a.names))]

    def test_a_node_is_up(self):
        a, _ = self.bodies()
        sys.stdout.write('%s: %d bodies: %s\n' % (self.robot, len(a.names), ' '.join(a.names)))

    def test_b_masses_and_links(self):
        a, per_body = self.bodies()
        links, static = self.urdf['links'], static_links(self.urdf)
        for name in a.link_names:
            self.assertIn(name, links, '%s: served link %s is not in the URDF' % (self.robot, name))
            self.assertNotIn(name, static, '%s: link %s is fixed to the root but served in a body'
                             % (self.robot, name))
        for name in links:
            if name not in static:
                self.assertEqual(list(a.link_names).count(name), 1, '%s: link %s is in %d bodies (expected 1)'
                                 % (self.robot, name, list(a.link_names).count(name)))
        for b, indices in enumerate(per_body):
            total = 0.0
            for i in indices:
                link = links[a.link_names[i]]
                where = '%s: body %s, link %s' % (self.robot, a.names[b], link['name'])
                self.assertEqual(a.link_masses[i], link['mass'], '%s: mass %r, URDF says %r'
                                 % (where, a.link_masses[i], link['mass']))
                total += link['mass']
                if link['mass'] > 0:
                    com = np.array(a.link_com_offsets[3 * i:3 * i + 3])
                    self.assertLessEqual(np.abs(com - link['com']).max(), 1e-12, '%s: COM %s, URDF says %s'
                                         % (where, com, link['com']))
                    inertia = np.array(a.link_inertias[9 * i:9 * i + 9]).reshape(3, 3)
                    scale = max(np.abs(link['inertia']).max(), 1e-300)
                    self.assertLessEqual(np.abs(inertia - link['inertia']).max(), 1e-12 * scale,
                                         '%s: inertia about the COM %s, URDF says %s'
                                         % (where, inertia.ravel(), link['inertia'].ravel()))
            self.assertLessEqual(abs(a.masses[b] - total), 1e-12 * abs(total), '%s: body %s mass %r, its links'
                                 ' add up to %r' % (self.robot, a.names[b], a.masses[b], total))

    def link_pose(self, fixed_frame, link):
        try:
            t = self.tf_buffer.lookup_transform(fixed_frame, link, rospy.Time(0), rospy.Duration(10.0)).transform
        except tf2_ros.TransformException as e:
            self.fail('%s: no tf from %s to link %s: %s' % (self.robot, fixed_frame, link, e))
        T = np.eye(4)
        T[:3, :3] = quaternion_matrix(t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)
        T[:3, 3] = [t.translation.x, t.translation.y, t.translation.z]
        return T

    def served_vertices(self, body):
        proxy = rospy.ServiceProxy(self.server + '/get_vertex_jacobians', GetVertexJacobians)
        answer = proxy(body=body, vertices=[], q=[])
        self.assertTrue(answer.success, '%s: get_vertex_jacobians(%s) failed: %s'
                        % (self.robot, body, answer.message))
        return np.array(answer.positions).reshape(-1, 3)

    def test_c_vertices_at_tf_pose(self):
        """Read points -> served vertices (c); served vertices -> read points, and counts (d)."""
        a, per_body = self.bodies()
        worst = {'read to served': 0.0, 'served to read': 0.0}
        for b, indices in enumerate(per_body):
            served = self.served_vertices(a.names[b])
            self.assertEqual(len(served), a.vertex_counts[b], '%s: body %s serves %d vertices, vertex_counts'
                             ' says %d' % (self.robot, a.names[b], len(served), a.vertex_counts[b]))
            counts = [a.link_vertex_counts[i] for i in indices]
            self.assertEqual(sum(counts), len(served), '%s: body %s: link_vertex_counts %s do not add up to %d'
                             % (self.robot, a.names[b], counts, len(served)))
            tree, start, read, complete = cKDTree(served), 0, [], True
            for i, count in zip(indices, counts):
                points, all_checked, distance = self.check_link(a.fixed_frame, a.names[b], a.link_names[i], tree)
                worst['read to served'] = max(worst['read to served'], distance)
                if all_checked and count:
                    distance = self.check_converse(a.names[b], a.link_names[i], points, served[start:start + count])
                    worst['served to read'] = max(worst['served to read'], distance)
                read.append(points)
                complete = complete and all_checked
                start += count
            self.check_counts(a.names[b], np.concatenate(read), len(served), complete)
        sys.stdout.write('%s: max distance read to served %.3g m, served to read %.3g m\n'
                         % (self.robot, worst['read to served'], worst['served to read']))

    def check_link(self, fixed_frame, body, name, tree):
        """(c) for one link: (its read points in fixed_frame, whether all its geometry was read, max distance)."""
        T = self.link_pose(fixed_frame, name)
        parts, all_checked, worst = [np.zeros((0, 3))], True, 0.0
        for g in link_geometry(self.urdf['links'][name], self.kind):
            if g['kind'] not in CHECKED_KINDS:
                all_checked = False
                continue
            points = transform_points(T, geometry_points(g))
            distance, nearest = tree.query(points)
            k = int(np.argmax(distance))
            sys.stdout.write('%s: body %s, link %s, %s: %d points, max distance %.3g m\n'
                             % (self.robot, body, name, g['text'], len(points), distance[k]))
            self.assertLessEqual(distance[k], TOLERANCE, '%s: body %s, link %s, %s: %d of %d points are farther'
                                 ' than %g m from every served vertex (max %.6g m: read %s, nearest served %s)'
                                 % (self.robot, body, name, g['text'], (distance > TOLERANCE).sum(), len(points),
                                    TOLERANCE, distance[k], points[k], tree.data[nearest[k]]))
            parts.append(points)
            worst = max(worst, distance[k])
        return np.concatenate(parts), all_checked, worst

    def check_converse(self, body, name, points, served):
        """(d) every served vertex of a link with only meshes and boxes lies on that link's read points."""
        where = '%s: body %s, link %s' % (self.robot, body, name)
        self.assertTrue(len(points), '%s: %d vertices served, none read' % (where, len(served)))
        distance = cKDTree(points).query(served)[0]
        sys.stdout.write('%s: %d served vertices, max distance to the read points %.3g m\n'
                         % (where, len(served), distance.max()))
        self.assertLessEqual(distance.max(), TOLERANCE, '%s: %d served vertices are farther than %g m from the'
                             ' link\'s geometry (max %.6g m)' % (where, (distance > TOLERANCE).sum(), TOLERANCE,
                                                                 distance.max()))
        return distance.max()

    def test_e_coordinates(self):
        a, per_body = self.bodies()
        self.assertEqual(len(a.dofs), len(a.names), '%s: dofs is not one per body' % self.robot)
        self.assertEqual(sum(a.joint_counts), len(a.joint_names), '%s: joint_counts do not add up' % self.robot)
        order = [j['name'] for j in self.urdf['joints']]
        joints = {j['name']: j for j in self.urdf['joints']}
        start = 0
        for b, indices in enumerate(per_body):
            names = list(a.joint_names[start:start + a.joint_counts[b]])
            start += a.joint_counts[b]
            links = {a.link_names[i] for i in indices}
            where = '%s: body %s' % (self.robot, a.names[b])
            for name in names:
                self.assertIn(name, joints, '%s: joint %s is not in the URDF' % (where, name))
                j = joints[name]
                self.assertTrue(j['type'] in ('revolute', 'continuous', 'prismatic') and not j['mimic'],
                                '%s: joint %s (%s%s) is not an independent 1-dof joint'
                                % (where, name, j['type'], ', mimic' if j['mimic'] else ''))
                self.assertIn(j['child'], links, '%s: joint %s moves %s, not one of its links' % (where, name,
                                                                                                  j['child']))
            self.assertEqual(names, sorted(names, key=order.index), '%s: joints not in URDF order' % where)
            root_joint = [n for n, j in joints.items() if j['child'] == a.link_names[indices[0]]]
            root_floats = not (root_joint and root_joint[0] in names)
            self.assertEqual(a.dofs[b], len(names) + (6 if root_floats else 0), '%s: dofs %d for joints %s'
                             % (where, a.dofs[b], names))

    def check_counts(self, body, read, served_count, complete):
        """(d) with identical positions joined, the read points are at least as many as the served vertices."""
        unique = len(np.unique(read, axis=0))
        sys.stdout.write('%s: body %s: %d unique read points, %d served vertices%s\n'
                         % (self.robot, body, unique, served_count,
                            '' if complete else ' (not compared: the body has spheres or cylinders)'))
        if complete:
            self.assertGreaterEqual(unique, served_count, '%s: body %s serves %d vertices, its meshes and boxes'
                                    ' have only %d distinct points' % (self.robot, body, served_count, unique))


if __name__ == '__main__':
    rospy.init_node('robot_description_check')
    rostest.rosrun(PKG, 'robot_description_check', RobotDescription)
