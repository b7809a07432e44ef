#!/usr/bin/env python3
"""Generates the default scene's meshes (closed, outward-oriented triangle meshes).

    torus_knot.stl  a (2, 3) torus knot tube: 256 x 16 = 4096 vertices, 8192 triangles
    rock.stl        an icosphere (4 subdivisions) displaced by smooth harmonics:
                    2562 vertices, 5120 triangles

Deterministic: the committed files are this script's output
(`/usr/bin/python3 scripts/generate_demo_meshes.py urdf/meshes`).
Sizes are in metres.
"""
import struct
import sys
from pathlib import Path

import numpy as np


def write_binary_stl(path, vertices, triangles):
    vertices = np.asarray(vertices, dtype=np.float32)
    with open(path, "wb") as out:
        out.write(b"diff_rigid_body demo mesh".ljust(80, b" "))
        out.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            pa, pb, pc = vertices[a], vertices[b], vertices[c]
            normal = np.cross(pb - pa, pc - pa)
            normal /= max(np.linalg.norm(normal), 1e-30)
            out.write(struct.pack("<12fH", *normal, *pa, *pb, *pc, 0))


def torus_knot(p=2, q=3, segments=256, sides=16, radius=0.06, tube=0.012):
    """Tube of radius `tube` around the (p, q) torus knot of scale `radius`."""
    t = np.linspace(0.0, 2.0 * np.pi, segments, endpoint=False)

    def centre(t):
        r = radius * (2.0 + np.cos(q * t)) / 3.0
        return np.stack([r * np.cos(p * t), r * np.sin(p * t), -radius * np.sin(q * t) / 3.0], axis=-1)

    c = centre(t)
    tangent = centre(t + 1e-4) - centre(t - 1e-4)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    normal = np.cross(tangent, [0.0, 0.0, 1.0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    binormal = np.cross(tangent, normal)
    a = np.linspace(0.0, 2.0 * np.pi, sides, endpoint=False)
    vertices = (c[:, None, :] + tube * (np.cos(a)[None, :, None] * normal[:, None, :] +
                                        np.sin(a)[None, :, None] * binormal[:, None, :])).reshape(-1, 3)
    triangles = []
    for i in range(segments):
        for j in range(sides):
            v00 = i * sides + j
            v01 = i * sides + (j + 1) % sides
            v10 = ((i + 1) % segments) * sides + j
            v11 = ((i + 1) % segments) * sides + (j + 1) % sides
            triangles += [(v00, v10, v11), (v00, v11, v01)]
    return vertices, orient_outward(vertices, np.array(triangles))


def icosphere(subdivisions):
    phi = (1.0 + 5.0 ** 0.5) / 2.0
    vertices = [(-1, phi, 0), (1, phi, 0), (-1, -phi, 0), (1, -phi, 0), (0, -1, phi), (0, 1, phi),
                (0, -1, -phi), (0, 1, -phi), (phi, 0, -1), (phi, 0, 1), (-phi, 0, -1), (-phi, 0, 1)]
    vertices = [np.array(v, dtype=float) / np.linalg.norm(v) for v in vertices]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
             (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoint = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                m = vertices[a] + vertices[b]
                vertices.append(m / np.linalg.norm(m))
                midpoint[key] = len(vertices) - 1
            return midpoint[key]

        faces = [f for a, b, c in faces
                 for ab, bc, ca in [(middle(a, b), middle(b, c), middle(c, a))]
                 for f in [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]]
    return np.array(vertices), np.array(faces)


def rock(subdivisions=4, radius=0.07):
    directions, triangles = icosphere(subdivisions)
    x, y, z = directions.T
    bumps = 1.0 + 0.18 * x * y + 0.12 * np.sin(3.0 * z + 1.0) * np.cos(2.0 * x) + 0.08 * np.cos(5.0 * y)
    vertices = radius * directions * bumps[:, None] * np.array([1.3, 1.0, 0.8])
    return vertices, orient_outward(vertices, triangles)


def orient_outward(vertices, triangles):
    """Flips all triangles if the signed volume is negative."""
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    return triangles if volume > 0 else triangles[:, [0, 2, 1]]


def main(folder):
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write_binary_stl(folder / "torus_knot.stl", *torus_knot())
    write_binary_stl(folder / "rock.stl", *rock())


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "urdf/meshes")
