#!/usr/bin/python3
"""Builds the seed corpus of the fuzz targets (tests/fuzz/corpus/<target>/seed_*).

Usage: make_corpus.py SURGE_BINARY

scene: every scene of scenes/ and tests/data/{scenes,bad_scenes} (mesh paths made relative to
       tests/data/scenes, where fuzz_scene runs), plus one with --set override lines.
mesh:  byte 0 = extension selector ('0' .stl, '1' .obj, '2' .ply, '3' .gltf), then the file:
       the test meshes, the small assets, a binary STL, ASCII and binary PLY and a glTF cube.
io:    byte 0 = reader ('0' checkpoint, '1' result forces, '2' result status), then a checkpoint
       and a result of a tiny run (4 particles, one obstacle, a dynamic box) written by SURGE.
Inputs of fixed findings live beside the seeds as corpus/<target>/regress_* and are kept.
The io seeds have no .h5 extension (git ignores *.h5).
"""
import base64
import glob
import os
import shutil
import struct
import subprocess
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
root = os.path.dirname(os.path.dirname(here))
corpus = os.path.join(here, "corpus")


def put(target, name, data):
    d = os.path.join(corpus, target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "seed_" + name), "wb") as f:
        f.write(data)


def cube():
    v = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    # 12 outward triangles of the unit cube (vertex index = 4x + 2y + z)
    t = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
         (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return v, t


def scenes():
    files = sorted(glob.glob(os.path.join(root, "scenes", "*.yaml")) +
                   glob.glob(os.path.join(root, "tests/data/scenes/*.yaml")) +
                   glob.glob(os.path.join(root, "tests/data/bad_scenes/*.yaml")))
    for p in files:
        text = open(p, "rb").read()
        if os.path.dirname(p) == os.path.join(root, "scenes"):
            text = text.replace(b"../assets/", b"../../../assets/")
        put("scene", os.path.relpath(p, root).replace("/", "_"), text)
    base = open(os.path.join(root, "tests/data/scenes/dam_barrier_small_2d.yaml"), "rb").read()
    put("scene", "with_set", b"--set time.end=0.01\n--set bodies.0.particles_per_cell=1\n" + base)


def meshes():
    for p in sorted(glob.glob(os.path.join(root, "tests/data/meshes/*")) +
                    [os.path.join(root, "assets", a) for a in ("square_column.obj", "v_deflector.stl")]):
        sel = {".stl": b"0", ".obj": b"1", ".ply": b"2", ".gltf": b"3"}[os.path.splitext(p)[1]]
        put("mesh", os.path.basename(p), sel + open(p, "rb").read())
    v, t = cube()
    stl = b"binary cube".ljust(80, b" ") + struct.pack("<I", len(t))
    for a, b, c in t:
        stl += struct.pack("<3f", 0, 0, 0)
        for i in (a, b, c):
            stl += struct.pack("<3f", *v[i])
        stl += b"\0\0"
    put("mesh", "cube_binary.stl", b"0" + stl)
    head = "ply\nformat {}\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n" \
           "element face 12\nproperty list uchar int vertex_indices\nend_header\n"
    ascii_ply = head.format("ascii 1.0") + "".join("%d %d %d\n" % p for p in v) + \
        "".join("3 %d %d %d\n" % f for f in t)
    put("mesh", "cube_ascii.ply", b"2" + ascii_ply.encode())
    bin_ply = head.format("binary_little_endian 1.0").encode() + \
        b"".join(struct.pack("<3f", *p) for p in v) + \
        b"".join(struct.pack("<B3i", 3, *f) for f in t)
    put("mesh", "cube_binary.ply", b"2" + bin_ply)
    pos = b"".join(struct.pack("<3f", *p) for p in v)
    idx = b"".join(struct.pack("<3H", *f) for f in t)
    buf = base64.b64encode(pos + idx).decode()
    gltf = ('{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],'
            '"nodes":[{"mesh":0,"name":"cube"}],"meshes":[{"name":"cube","primitives":[{"attributes":'
            '{"POSITION":0},"indices":1}]}],"buffers":[{"byteLength":%d,"uri":'
            '"data:application/octet-stream;base64,%s"}],"bufferViews":[{"buffer":0,"byteOffset":0,'
            '"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":72}],"accessors":[{"bufferView":0,'
            '"componentType":5126,"count":8,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,'
            '"componentType":5123,"count":36,"type":"SCALAR"}]}') % (len(pos) + len(idx), buf)
    put("mesh", "cube.gltf", b"3" + gltf.encode())


TINY = """name: tiny
dimension: 3
time: {end: 0.05}
gravity: [0, -9.81, 0]
grid: {cell_size: 0.1}
domain: {min: [0, 0, 0], max: [0.6, 0.4, 0.1], walls: {y-: slip}}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e4, viscosity: 0.001, bulk_viscosity: {}}
bodies:
  - {name: column, material: water, region: {box: {min: [0, 0, 0], max: [0.2, 0.2, 0.1]}}, particles_per_cell: 1}
obstacles:
  - {name: wall, shape: {box: {min: [0.4, 0, 0], max: [0.45, 0.1, 0.1]}}}
  - {name: box, shape: {box: {min: [0.2, 0.25, 0.02], max: [0.3, 0.35, 0.08]}}, motion: {dynamic: {density: 500}}}
output: {every: 0.02, checkpoint_every: 0.02}
"""


def shrink(src, dst):
    """Copies an HDF5 file with every dataset contiguous instead of chunked (the writer's
    4096-row chunks and their B-trees make a 4 MB file of a 5-step run); /snapshots and /energy,
    which the readers skip, are left out. Types, shapes and attributes stay; the file format
    stays the default (no metadata checksums, so mutations reach the readers)."""
    import h5py

    with h5py.File(src, "r") as a, h5py.File(dst, "w") as b:
        def copy(ga, gb):
            for k, v in ga.attrs.items():
                gb.attrs.create(k, v, dtype=ga.attrs.get_id(k).dtype)
            for key, obj in ga.items():
                if ga.name == "/" and key in ("snapshots", "energy"):
                    continue
                if isinstance(obj, h5py.Group):
                    copy(obj, gb.create_group(key))
                    continue
                d = gb.create_dataset(key, data=obj[()], dtype=obj.dtype)
                for k, v in obj.attrs.items():
                    d.attrs.create(k, v, dtype=obj.attrs.get_id(k).dtype)
        copy(a, b)


def io(surge):
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(tmp, "tiny.yaml")
        open(scene, "w").write(TINY)
        # Relative paths and a bare program name: the result stores the command line and the
        # scene path, and the committed seeds must not carry this machine's paths.
        subprocess.run(["surge", "run", "tiny.yaml", "--out", "out", "--progress", "quiet",
                        "--threads", "1"], executable=surge, cwd=tmp, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        ck = sorted(glob.glob(os.path.join(tmp, "out/checkpoints/*.h5")))[-1]
        res = os.path.join(tmp, "small.h5")
        shrink(os.path.join(tmp, "out/tiny.h5"), res)
        put("io", "checkpoint", b"0" + open(ck, "rb").read())
        put("io", "result_forces", b"1" + open(res, "rb").read())
        put("io", "result_status", b"2" + open(res, "rb").read())


def main():
    for t in ("scene", "mesh", "io"):
        for p in glob.glob(os.path.join(corpus, t, "seed_*")):
            os.remove(p)
    scenes()
    meshes()
    io(os.path.abspath(sys.argv[1]))
    for t in ("scene", "mesh", "io"):
        files = glob.glob(os.path.join(corpus, t, "*"))
        print(t, len(files), "files,", sum(os.path.getsize(f) for f in files), "bytes")


if __name__ == "__main__":
    main()
