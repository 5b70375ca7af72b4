"""`pointhaptics run --surface FILE` (issue 15, item 4): the object's deformed surface written at the end.

- the statically bent cantilever's surface is written as STL, PLY and OBJ, each closed (every edge shared by
  two triangles), the same triangles in all three;
- the surface follows the points: its lowest vertex is within 3% of the tip deflection of the lowest point;
- a file type that is not a mesh is refused before the run, naming the option.
Usage: cli_surface.py CLI SCENES WORK
"""
import json
import os
import struct
import subprocess
import sys
from collections import Counter

cli, scenes, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
scene = os.path.join(scenes, "cantilever_static.toml")


def read_binary_stl(path):
    with open(path, "rb") as f:
        data = f.read()
    (count,) = struct.unpack_from("<I", data, 80)
    assert len(data) == 84 + 50 * count, (path, len(data), count)
    triangles = []
    for t in range(count):
        values = struct.unpack_from("<12f", data, 84 + 50 * t)
        triangles.append([tuple(values[3 + 3 * k: 6 + 3 * k]) for k in range(3)])
    return triangles


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        words = line.split()
        if words and words[0] == "v":
            vertices.append(tuple(float(w) for w in words[1:4]))
        elif words and words[0] == "f":
            faces.append([int(w.split("/")[0]) - 1 for w in words[1:4]])
    return [[vertices[i] for i in f] for f in faces]


def expect_closed(triangles, what):
    edges = Counter()
    for tri in triangles:
        for k in range(3):
            edges[tuple(sorted((tri[k], tri[(k + 1) % 3])))] += 1
    bad = [e for e, n in edges.items() if n != 2]
    assert not bad, f"{what}: {len(bad)} edges not shared by two triangles"


outputs = {ext: os.path.join(work, "cantilever" + ext) for ext in (".stl", ".ply", ".obj")}
result = os.path.join(work, "result.json")
for ext, path in outputs.items():
    p = subprocess.run([cli, "run", scene, "--quiet", "--surface", path, "--json", result], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, (p.returncode, p.stderr)
    assert os.path.getsize(path) > 0, path
stl = read_binary_stl(outputs[".stl"])
obj = read_obj(outputs[".obj"])
expect_closed(stl, "stl")
expect_closed(obj, "obj")
assert len(stl) == len(obj) > 100, (len(stl), len(obj))
with open(outputs[".ply"], "rb") as f:
    header = f.read(400).decode("latin-1")
assert f"element face {len(stl)}" in header, header

doc = json.load(open(result))
lowest_point = min(r[1] + u[1] for r, u in zip(doc["points"]["reference"], doc["points"]["displacement"]))
lowest_vertex = min(v[1] for tri in stl for v in tri)
deflection = -lowest_point
assert deflection > 1e-3, deflection
assert abs(lowest_vertex - lowest_point) < 0.03 * deflection, (lowest_vertex, lowest_point)
print(f"ok: {len(stl)} triangles, lowest vertex {lowest_vertex * 1e3:.3f} mm, lowest point {lowest_point * 1e3:.3f} mm")

p = subprocess.run([cli, "run", scene, "--quiet", "--surface", os.path.join(work, "cantilever.xyz")], capture_output=True, text=True, timeout=60)
assert p.returncode == 1 and "--surface" in p.stderr and ".xyz" in p.stderr, (p.returncode, p.stderr)
print("ok: " + p.stderr.strip())
