#!/usr/bin/python3
"""Writes the project meshes in assets/ (metres, y up), and checks each one before writing.

    /usr/bin/python3 scripts/make_assets.py [output_dir]    (default: assets/ next to scripts/)

bridge_pier.stl   rounded-nose pier (semicircular nose and tail), closed
mound.obj         rounded earth mound (surface of revolution), closed
v_deflector.stl   V-shaped deflector (two walls meeting at 90 degrees, apex upstream), closed
terrain_patch.obj open height field (gentle slope with a bump), one-sided, normals up
square_column.obj 1.5 x 1.5 m square column, 8.5 m tall from y = -0.5 (the seed's §7.5 column,
                  sunk 0.5 m into the bed), centred on x = z = 0, closed; rotate it with rotate_deg
thin_plate.obj    plate 1 cm thick (x in [-0.005, 0.005]), 1 m wide (z in [-0.5, 0.5]), y from 0 to
                  1 m, closed: the stability suite's thin mesh obstacle (scenes/stress/)

Checks: closed meshes have every edge used exactly twice, in opposite directions (consistent
orientation) and a positive volume (outward); no triangle has an area below 1e-6 * diagonal^2.
Standard library only; the output is deterministic (fixed formatting).
"""
import math
import os
import sys


def prism(polygon, y0, y1):
    """Closed prism over the (x, z) polygon for y in [y0, y1]. The polygon must be star-shaped
    from its vertex 0 (the caps are fans from it); either winding is accepted."""
    # Signed area in the (x, z) plane; the caps below need it clockwise there (see top cap).
    area = sum(a[0] * b[1] - b[0] * a[1] for a, b in zip(polygon, polygon[1:] + polygon[:1]))
    if area > 0:
        polygon = [polygon[0]] + polygon[:0:-1]
    n = len(polygon)
    vertices = [(x, y0, z) for x, z in polygon] + [(x, y1, z) for x, z in polygon]
    triangles = []
    for i in range(1, n - 1):
        # (p_i - p_0) x (p_{i+1} - p_0) has y component a_z b_x - a_x b_z, > 0 for a clockwise
        # (x, z) polygon: the top cap faces +y and the reversed bottom cap faces -y.
        triangles.append((n, n + i, n + i + 1))
        triangles.append((0, i + 1, i))
    for i in range(n):
        j = (i + 1) % n
        triangles.append((i, j, n + j))
        triangles.append((i, n + j, n + i))
    return vertices, triangles


def bridge_pier(length=4.0, width=1.5, height=6.0, segments=16):
    """Straight sides and semicircular nose (x-) and tail (x+), centred on x = z = 0, base y = 0."""
    r = width / 2
    c = length / 2 - r  # centres of the semicircles at x = -c, +c
    polygon = []
    for k in range(segments + 1):  # tail: from (c, -r) round to (c, r) through (length/2, 0)
        a = -math.pi / 2 + math.pi * k / segments
        polygon.append((c + r * math.cos(a), r * math.sin(a)))
    for k in range(segments + 1):  # nose: from (-c, r) round to (-c, -r) through (-length/2, 0)
        a = math.pi / 2 + math.pi * k / segments
        polygon.append((-c + r * math.cos(a), r * math.sin(a)))
    return prism(polygon, 0.0, height)  # convex: the caps' fans from vertex 0 are valid


def mound(radius=3.0, height=3.0, rings=12, sectors=48):
    """y = height * cos(pi r / (2 radius)) for r <= radius: rounded top, 57 degree toe; flat base."""
    vertices = [(0.0, height, 0.0)]  # apex
    for i in range(1, rings + 1):
        r = radius * i / rings
        y = 0.0 if i == rings else height * math.cos(math.pi * r / (2 * radius))
        for k in range(sectors):
            a = 2 * math.pi * k / sectors
            vertices.append((r * math.cos(a), y, r * math.sin(a)))
    base_centre = len(vertices)
    vertices.append((0.0, 0.0, 0.0))

    def ring(i, k):
        return 1 + (i - 1) * sectors + k % sectors

    triangles = []
    for k in range(sectors):  # ring vertices go from +x towards +z: (x, z) counter-clockwise
        triangles.append((0, ring(1, k + 1), ring(1, k)))
        for i in range(1, rings):
            triangles.append((ring(i, k), ring(i, k + 1), ring(i + 1, k + 1)))
            triangles.append((ring(i, k), ring(i + 1, k + 1), ring(i + 1, k)))
        triangles.append((base_centre, ring(rings, k), ring(rings, k + 1)))
    return vertices, triangles


def v_deflector(arm_length=4.0, thickness=0.5, height=2.0):
    """Two walls at +-45 degrees to the flow (x), meeting at 90 degrees; the outer apex points
    upstream at the origin, the arms open downstream (+x). Outer arm length arm_length."""
    s = math.sqrt(0.5)
    apex = (0.0, 0.0)
    inner_apex = (thickness / s, 0.0)  # where the two inner faces meet
    outer_left = (arm_length * s, arm_length * s)
    inner_left = (outer_left[0] + thickness * s, outer_left[1] - thickness * s)
    outer_right = (outer_left[0], -outer_left[1])
    inner_right = (inner_left[0], -inner_left[1])
    # Star-shaped from the apex (vertex 0): the fan covers both arms.
    polygon = [apex, outer_left, inner_left, inner_apex, inner_right, outer_right]
    return prism(polygon, 0.0, height)


def terrain_patch(length=20.0, width=10.0, spacing=0.5, slope=0.05, bump=0.8, bump_at=(12.0, 1.0),
                  bump_sigma=1.5):
    """Height field y = slope x + bump exp(-|(x, z) - bump_at|^2 / (2 sigma^2)) over
    x in [0, length], z in [-width/2, width/2]; triangles face +y."""
    nx = int(round(length / spacing))
    nz = int(round(width / spacing))
    vertices = []
    for j in range(nz + 1):
        z = -width / 2 + spacing * j
        for i in range(nx + 1):
            x = spacing * i
            d2 = (x - bump_at[0]) ** 2 + (z - bump_at[1]) ** 2
            vertices.append((x, slope * x + bump * math.exp(-d2 / (2 * bump_sigma ** 2)), z))

    def v(i, j):
        return j * (nx + 1) + i

    triangles = []
    for j in range(nz):
        for i in range(nx):
            triangles.append((v(i, j), v(i, j + 1), v(i + 1, j + 1)))
            triangles.append((v(i, j), v(i + 1, j + 1), v(i + 1, j)))
    return vertices, triangles


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def check(name, vertices, triangles, closed):
    lo = [min(v[k] for v in vertices) for k in range(3)]
    hi = [max(v[k] for v in vertices) for k in range(3)]
    diagonal2 = sum((h - l) ** 2 for l, h in zip(lo, hi))
    directed = {}
    volume = 0.0
    for t, (a, b, c) in enumerate(triangles):
        n = cross(sub(vertices[b], vertices[a]), sub(vertices[c], vertices[a]))
        area = 0.5 * math.sqrt(sum(x * x for x in n))
        if area < 1e-6 * diagonal2:
            raise SystemExit(f"{name}: triangle {t} is degenerate (area {area:g})")
        volume += sum(vertices[a][k] * cross(vertices[b], vertices[c])[k] for k in range(3)) / 6
        for i, j in ((a, b), (b, c), (c, a)):
            if (i, j) in directed:
                raise SystemExit(f"{name}: edge {i}-{j} used twice in the same direction")
            directed[(i, j)] = t
    open_edges = sum(1 for (i, j) in directed if (j, i) not in directed)
    if closed and (open_edges or volume <= 0):
        raise SystemExit(f"{name}: not closed and outward ({open_edges} open edges, "
                         f"volume {volume:g})")
    if not closed:
        for t, (a, b, c) in enumerate(triangles):
            if cross(sub(vertices[b], vertices[a]), sub(vertices[c], vertices[a]))[1] <= 0:
                raise SystemExit(f"{name}: triangle {t} does not face +y")
    size = " x ".join(f"{h - l:.3f}" for l, h in zip(lo, hi))
    kind = f"closed, volume {volume:.3f} m^3" if closed else f"one-sided, {open_edges} open edges"
    print(f"{name}: {len(vertices)} vertices, {len(triangles)} triangles, "
          f"extent (x y z) {size} m, {kind}")


def fmt(x):
    return f"{x:.9g}" if x != 0 else "0"  # no "-0"


def write_stl(path, name, vertices, triangles):
    with open(path, "w") as f:
        f.write(f"solid {name}\n")
        for a, b, c in triangles:
            n = cross(sub(vertices[b], vertices[a]), sub(vertices[c], vertices[a]))
            length = math.sqrt(sum(x * x for x in n))
            f.write("  facet normal " + " ".join(fmt(x / length) for x in n) + "\n")
            f.write("    outer loop\n")
            for v in (a, b, c):
                f.write("      vertex " + " ".join(fmt(x) for x in vertices[v]) + "\n")
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")


def write_obj(path, name, comment, vertices, triangles):
    with open(path, "w") as f:
        f.write(f"# {comment}\n# written by scripts/make_assets.py; metres, y up\n")
        f.write(f"o {name}\n")
        for v in vertices:
            f.write("v " + " ".join(fmt(x) for x in v) + "\n")
        for t in triangles:
            f.write("f " + " ".join(str(i + 1) for i in t) + "\n")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "assets")
    os.makedirs(out, exist_ok=True)
    meshes = [
        ("bridge_pier", "stl", bridge_pier(), True, ""),
        ("mound", "obj", mound(), True, "rounded earth mound, 6 m base, 3 m tall, closed"),
        ("v_deflector", "stl", v_deflector(), True, ""),
        ("terrain_patch", "obj", terrain_patch(), False,
         "terrain patch 20 m x 10 m, slope 0.05 with a 0.8 m bump, open (one-sided, normals up)"),
        ("square_column", "obj",
         prism([(-0.75, -0.75), (0.75, -0.75), (0.75, 0.75), (-0.75, 0.75)], -0.5, 8.0), True,
         "square column 1.5 m x 1.5 m, y from -0.5 to 8 m, centred on x = z = 0, closed"),
        ("thin_plate", "obj",
         prism([(-0.005, -0.5), (0.005, -0.5), (0.005, 0.5), (-0.005, 0.5)], 0.0, 1.0), True,
         "thin plate 0.01 m x 1 m x 1 m (x, y, z), x in [-0.005, 0.005], z in [-0.5, 0.5], closed"),
    ]
    for name, ext, (vertices, triangles), closed, comment in meshes:
        check(name, vertices, triangles, closed)
        path = os.path.join(out, f"{name}.{ext}")
        if ext == "stl":
            write_stl(path, name, vertices, triangles)
        else:
            write_obj(path, name, comment, vertices, triangles)
        print(f"  wrote {os.path.relpath(path)} ({os.path.getsize(path) / 1024:.1f} KiB)")


if __name__ == "__main__":
    main()
