#!/usr/bin/env python3
"""End to end: `pointhaptics run --vtk DIR --csv FILE` writes a ParaView time series: a .pvd collection whose frames
exist, each a VTK XML PolyData file with one vertex per point and the point data arrays of the contract,
with finite values; the last frame's displacements are the result JSON's; with levels of detail the
`active` flags count the simulated points; every frame has the object's deformed surface as part 1 (polygons,
with the float arrays carried to its vertices), enclosing the points' current positions."""
import csv
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

exe, scenes, out = sys.argv[1], sys.argv[2], sys.argv[3]
ARRAYS = {"displacement": 3, "cauchy_stress": 9, "von_mises": 1, "strain_energy_density": 1, "active": 1, "fixed": 1}


def read_frame(path):
    piece = ET.parse(path).getroot().find("PolyData/Piece")
    n = int(piece.get("NumberOfPoints"))
    assert int(piece.get("NumberOfVerts")) == n, path
    points = [float(v) for v in piece.find("Points/DataArray").text.split()]
    assert len(points) == 3 * n, path
    arrays = {}
    for a in piece.find("PointData"):
        values = [float(v) for v in a.text.split()]
        comps = int(a.get("NumberOfComponents"))
        assert len(values) == comps * n, (path, a.get("Name"))
        assert all(math.isfinite(v) for v in values), (path, a.get("Name"))
        arrays[a.get("Name")] = (comps, values)
    for name, comps in ARRAYS.items():
        assert name in arrays and arrays[name][0] == comps, (path, name)
    conn = [int(v) for v in piece.find("Verts/DataArray[@Name='connectivity']").text.split()]
    assert conn == list(range(n)), path
    return n, points, arrays


def read_with_vtk(path):
    """VTK's own XML reader (the one ParaView uses for .vtp) on a frame: the points and arrays it finds."""
    import vtk  # python3-vtk9, installed by scripts/setup
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    out = reader.GetOutput()
    pd = out.GetPointData()
    arrays = {pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}
    return out.GetNumberOfPoints(), out.GetNumberOfVerts(), arrays, pd.GetArray("displacement")


def check(scene, extra, name):
    folder = os.path.join(out, name)
    result = os.path.join(out, name + ".json")
    table = os.path.join(out, name + ".csv")
    subprocess.run([exe, "run", os.path.join(scenes, scene), "--quiet", "--vtk", folder, "--json", result, "--csv", table] + extra,
                   check=True)
    every = ET.parse(os.path.join(folder, "frame.pvd")).getroot().findall("Collection/DataSet")
    series = [d for d in every if d.get("part") == "0"]
    surfaces = [d for d in every if d.get("part") == "1"]
    assert len(series) >= 2, len(series)
    assert [d.get("timestep") for d in surfaces] == [d.get("timestep") for d in series], "one surface per frame"
    times = [float(d.get("timestep")) for d in series]
    assert times == sorted(times), times
    for d in series:
        assert os.path.exists(os.path.join(folder, d.get("file"))), d.get("file")
    n, points, arrays = read_frame(os.path.join(folder, series[-1].get("file")))
    vn, verts, varrays, disp = read_with_vtk(os.path.join(folder, series[-1].get("file")))
    assert vn == n and verts == n, (vn, verts, n)
    assert varrays == ARRAYS, varrays
    assert max(abs(disp.GetComponent(i, c) - arrays["displacement"][1][3 * i + c]) for i in range(n) for c in range(3)) < 1e-12
    doc = json.load(open(result))
    u = [c for p in doc["points"]["displacement"] for c in p]
    assert len(u) == 3 * n
    assert max(abs(a - b) for a, b in zip(u, arrays["displacement"][1])) <= 1e-8 * max(1e-12, max(map(abs, u))) + 1e-15
    rows = list(csv.DictReader(open(table)))
    assert len(rows) == n and list(rows[0]) == ["index", "x_ref", "y_ref", "z_ref", "ux", "uy", "uz", "von_mises", "strain_energy_density",
                                                 "active", "fixed"], list(rows[0])
    assert max(abs(float(r[k]) - u[3 * i + c]) for i, r in enumerate(rows) for c, k in enumerate(("ux", "uy", "uz"))) < 1e-8 * max(map(abs, u))
    assert [int(r["active"]) for r in rows] == [int(v) for v in arrays["active"][1]]
    x = [c for p in doc["points"]["reference"] for c in p]
    assert max(abs(p - (a + b)) for p, a, b in zip(points, x, u)) < 1e-9  # points are the current positions
    check_surface(os.path.join(folder, surfaces[-1].get("file")), points)
    return doc, arrays, len(series)


def check_surface(path, points):
    """The last surface: polygons, the float arrays, finite; its bounding box that of the points' current
    positions to within a tenth of the extent (the exact boundary, carried: a box's points lie on its faces, a
    half-sphere's within a spacing of its dome)."""
    import vtk
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    out = reader.GetOutput()
    assert out.GetNumberOfPolys() > 100 and out.GetNumberOfVerts() == 0, (out.GetNumberOfPolys(), out.GetNumberOfVerts())
    pd = out.GetPointData()
    arrays = {pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}
    assert arrays == {k: v for k, v in ARRAYS.items() if k not in ("active", "fixed")}, arrays
    vm = pd.GetArray("von_mises")
    assert all(math.isfinite(vm.GetValue(i)) for i in range(vm.GetNumberOfTuples()))
    lo, hi = [1e300] * 3, [-1e300] * 3
    for i in range(out.GetNumberOfPoints()):
        p = out.GetPoint(i)
        lo = [min(a, b) for a, b in zip(lo, p)]
        hi = [max(a, b) for a, b in zip(hi, p)]
    plo = [min(points[c::3]) for c in range(3)]
    phi = [max(points[c::3]) for c in range(3)]
    extent = max(b - a for a, b in zip(plo, phi))
    # encloses them (to the interpolation's difference from the points' own displacements)
    assert all(a <= b + 0.01 * extent and d >= c - 0.01 * extent for a, b, c, d in zip(lo, plo, phi, hi)), (lo, hi, plo, phi)
    assert max(max(b - a for a, b in zip(lo, plo)), max(d - c for c, d in zip(phi, hi))) < 0.1 * extent, (lo, hi, plo, phi)


doc, arrays, frames = check("beam_fixed_both_ends.toml", ["--vtk-every", "100"], "beam")
assert frames == 1 + (doc["solver"]["steps"] - 1) // 100 + 1, frames  # the start, every 100 steps but the last, the end
assert sum(arrays["fixed"][1]) == sum(doc["points"]["fixed"])
assert max(arrays["von_mises"][1]) > 0
doc, arrays, frames = check("half_sphere_lod.toml", ["--deterministic"], "lod")
assert frames == 2, frames  # interactive runs: the first and the last state
assert sum(arrays["active"][1]) == doc["lod"]["selected"], (sum(arrays["active"][1]), doc["lod"]["selected"])
print("vtk output: ok")
