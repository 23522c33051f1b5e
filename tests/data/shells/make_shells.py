#!/usr/bin/env python3
"""Writes the multi-shell OBJ files of this folder (tests/data/README.md): spheres (cubes of
n x n quads per side pushed onto a sphere) and tori, each a closed shell of quads, some written
inside out. Run from anywhere; the files land next to this script."""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def sphere(center, radius, n=3):
    """Quads counter-clockwise seen from outside; vertices shared along the cube's edges."""
    index, points, faces = {}, [], []

    def vertex(g):  # g: integer cube coordinates in [0, n]^3 on the cube's surface
        if g not in index:
            c = [2.0 * x / n - 1.0 for x in g]
            length = math.sqrt(sum(x * x for x in c))
            index[g] = len(points)
            points.append(tuple(center[k] + radius * c[k] / length for k in range(3)))
        return index[g]

    for axis in range(3):
        u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3  # e_u x e_v = e_axis
        for side in (0, n):
            for i in range(n):
                for j in range(n):
                    corners = []
                    for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        g = [0, 0, 0]
                        g[axis], g[u_axis], g[v_axis] = side, i + du, j + dv
                        corners.append(vertex(tuple(g)))
                    faces.append(corners if side == n else corners[::-1])
    return points, faces


def torus(center, major, minor, nu=8, nv=4):
    """Around the z axis; (theta, phi) quads counter-clockwise seen from outside."""
    points, faces = [], []
    for i in range(nu):
        t = 2 * math.pi * i / nu
        for j in range(nv):
            p = 2 * math.pi * j / nv
            r = major + minor * math.cos(p)
            points.append((center[0] + r * math.cos(t), center[1] + r * math.sin(t), center[2] + minor * math.sin(p)))
    for i in range(nu):
        for j in range(nv):
            a, b = i * nv + j, ((i + 1) % nu) * nv + j
            c, d = ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv
            faces.append([a, b, c, d])
    return points, faces


def write(name, comment, shells):
    """shells: (points, faces, reversed) in order; one OBJ, 1-based indices."""
    lines = ["# " + c for c in comment] + []
    offset = 0
    for points, faces, reverse in shells:
        lines += ["v %.9g %.9g %.9g" % p for p in points]
    for points, faces, reverse in shells:
        for f in faces:
            f = f[::-1] if reverse else f
            lines.append("f " + " ".join(str(v + 1 + offset) for v in f))
        offset += len(points)
    with open(os.path.join(HERE, name), "w") as out:
        out.write("\n".join(lines) + "\n")


def main():
    write("two_spheres.obj", ["Two unit spheres side by side, both outward."],
          [(*sphere((-1.5, 0, 0), 1), False), (*sphere((1.5, 0, 0), 1), False)])
    write("two_spheres_one_reversed.obj",
          ["two_spheres.obj with the second sphere's faces reversed (inside out)."],
          [(*sphere((-1.5, 0, 0), 1), False), (*sphere((1.5, 0, 0), 1), True)])
    write("hollow_sphere.obj",
          ["A hollow solid: a sphere of radius 2 with a spherical cavity of radius 1, both shells",
           "written outward (the cavity's wall must face into the cavity)."],
          [(*sphere((0, 0, 0), 2), False), (*sphere((0.2, 0.1, 0), 1), False)])
    write("nested_spheres.obj",
          ["Three nested spheres (radii 3, 2, 1): the outer written inside out, the middle",
           "(a cavity's wall) and the inner (an island in the cavity) outward."],
          [(*sphere((0, 0, 0), 3), True), (*sphere((0, 0, 0.1), 2), False), (*sphere((0.1, 0, 0), 1), False)])
    write("two_tori_one_reversed.obj",
          ["Two tori side by side, the second inside out."],
          [(*torus((-2.5, 0, 0), 1.5, 0.5), False), (*torus((2.5, 0, 0), 1.5, 0.5), True)])


if __name__ == "__main__":
    main()
