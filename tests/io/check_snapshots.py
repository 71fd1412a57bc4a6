#!/usr/bin/env python3
"""Snapshots open in a real VTK reader (Debian's python3-vtk9) with the expected points, cells and fields.

    check_snapshots.py HILLDEM SOURCE_DIR WORK_DIR

1. The 27-grain assembly (examples/assembly_27.toml), binary and ASCII: every snapshot listed in the
   .pvd index reads with vtkXMLPolyDataReader without an error; 27 points with every ball field; the
   contacts are one line per contact with their force fields; the floor contacts carry the assembly's
   weight (memo A1, 0.368 N); 12 wall triangles; both encodings give the same numbers.
2. The wet restart bed (tests/data/restart/wet_servo_box.toml): the moisture fields show wet and dry
   contacts (wet flag, mois_state, moisture force < 0 exactly where wet, per-ball wet counts).
"""
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import vtk
from vtk.util.numpy_support import vtk_to_numpy

hilldem, source, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


# Every message VTK prints (errors of the reader and of its internal XML parser) lands here.
vtk_messages = vtk.vtkStringOutputWindow()
vtk.vtkOutputWindow.SetInstance(vtk_messages)
seen = [0]


def read(path):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    text = vtk_messages.GetOutput()[seen[0]:]
    seen[0] += len(text)
    check(text.strip() == "" and reader.GetErrorCode() == 0, f"{path}: VTK reported: {text.strip()[:300]}")
    return reader.GetOutput()


def array(data, name, components=1):
    a = data.GetArray(name)
    check(a is not None, f"field '{name}' is missing")
    if a is None:
        return None
    check(a.GetNumberOfComponents() == components, f"field '{name}' has {a.GetNumberOfComponents()} components, expected {components}")
    return vtk_to_numpy(a)


def strings(data, name):
    a = data.GetAbstractArray(name)
    check(a is not None, f"string field '{name}' is missing")
    return [a.GetValue(i) for i in range(a.GetNumberOfValues())] if a else []


def series(folder, kind):
    """(time, file) of every snapshot in <kind>.pvd; each file must exist."""
    root = ET.parse(folder / f"{kind}.pvd").getroot()
    check(root.get("type") == "Collection", f"{kind}.pvd is not a VTK Collection")
    entries = [(float(d.get("timestep")), folder / d.get("file")) for d in root.iter("DataSet")]
    check(len(entries) >= 2, f"{kind}.pvd lists {len(entries)} snapshots")
    check(all(a[0] <= b[0] for a, b in zip(entries, entries[1:])), f"{kind}.pvd times are not increasing")
    for _, f in entries:
        check(f.is_file(), f"{f} listed in {kind}.pvd does not exist")
    return entries


def run(scenario, out, *extra):
    subprocess.run([hilldem, "run", "-q", str(scenario), "-o", str(out), *extra], check=True, stdout=subprocess.DEVNULL)
    return out / "snapshots"


BALL_FIELDS = {"id": 1, "radius": 1, "mass": 1, "velocity": 3, "spin": 3, "contact_force": 3, "contact_moment": 3,
               "fixity": 1, "groups": 1, "group": 1, "coordination": 1, "wet_contacts": 1, "moisture_force": 1, "clump_id": 1}
CONTACT_FIELDS = {"ball1": 1, "ball2": 1, "wall": 1, "kind": 1, "model": 1, "mois_state": 1, "wet": 1, "active": 1,
                  "gap": 1, "normal": 3, "normal_force": 1, "moisture_force": 1, "shear_force": 3, "shear_force_mag": 1,
                  "force": 3, "contact_point": 3, "suction": 1}


def assembly(encoding):
    snaps = run(source / "examples/assembly_27.toml", work / f"a27_{encoding}", "--snapshots-every", "100",
                "--snapshot-format", encoding)
    balls, contacts, walls = series(snaps, "balls"), series(snaps, "contacts"), series(snaps, "walls")
    check(len(balls) == len(contacts) == len(walls), "the three series differ in length")
    for t, f in balls:
        b = read(f)
        check(b.GetNumberOfPoints() == 27, f"{f.name}: {b.GetNumberOfPoints()} points, expected 27")
        check(b.GetNumberOfVerts() == 27, f"{f.name}: {b.GetNumberOfVerts()} vertices, expected 27")
        for name, comps in BALL_FIELDS.items():
            array(b.GetPointData(), name, comps)
        tv = array(b.GetFieldData(), "TimeValue")
        check(tv is not None and abs(tv[0] - t) <= 1e-12 * max(1.0, t), f"{f.name}: TimeValue differs from the .pvd")
        check(sorted(array(b.GetPointData(), "id")) == list(range(1, 28)), f"{f.name}: ball ids are not 1..27")
        check(abs(array(b.GetPointData(), "radius") - 5e-3).max() == 0.0, f"{f.name}: radii are not 5 mm")
        check("grains" in strings(b.GetFieldData(), "group_names"), f"{f.name}: group_names lacks 'grains'")
    final_b = read(balls[-1][1])
    final_c = read(contacts[-1][1])
    final_w = read(walls[-1][1])
    n = final_c.GetNumberOfLines()
    # One line per contact: as many as the run's final checkpoint holds.
    ckpt = sorted((work / f"a27_{encoding}" / "checkpoints").glob("ckpt-*.hdc"))[-1]
    info = subprocess.run([hilldem, "inspect", str(ckpt)], check=True, capture_output=True, text=True).stdout
    expected = int(info.split("contacts: ")[1].split()[0])
    check(n == expected and final_c.GetNumberOfCells() == n, f"contacts: {n} lines, the checkpoint has {expected} contacts")
    check(final_c.GetNumberOfPoints() == 2 * n, "contacts: two points per line")
    cd = final_c.GetCellData()
    for name, comps in CONTACT_FIELDS.items():
        array(cd, name, comps)
    kind, model, fn = array(cd, "kind"), array(cd, "model"), array(cd, "normal_force")
    check(((kind == 0) == (model == 1)).all(), "ball-ball contacts are hill, ball-wall contacts linear")
    check((fn >= 0).all(), "no contact of the settled (dry) assembly is in tension")
    # Simple cubic 3x3x3: at least the 18 vertical contacts carry the weight down to the floor.
    check(int(((kind == 0) & (fn > 0)).sum()) >= 18, f"{int(((kind == 0) & (fn > 0)).sum())} loaded ball-ball contacts, expected >= 18")
    # Memo A1: the floor (box.zmin, two facets) carries the weight, 0.368 N (computed 0.36752 N).
    names = strings(final_w.GetFieldData(), "wall_names")
    check(len(names) == 12 and final_w.GetNumberOfPolys() == 12, f"walls: {final_w.GetNumberOfPolys()} triangles, {len(names)} names")
    floor = [i for i, s in enumerate(names) if s.startswith("box.zmin.")]
    wall, force = array(cd, "wall"), array(cd, "force", 3)
    on_floor = sum(force[k, 2] for k in range(n) if wall[k] in floor)
    check(abs(-on_floor - 0.36752) < 2e-4, f"floor contacts carry {-on_floor} N, expected the weight 0.36752 N")
    wf = array(final_w.GetCellData(), "force", 3)
    check(abs(sum(wf[i, 2] for i in floor) - on_floor) < 1e-12, "wall force sums differ from their contacts")
    return final_b, final_c


def same(a, b, what):
    for data in ("GetPointData", "GetCellData"):
        da, db = getattr(a, data)(), getattr(b, data)()
        for i in range(da.GetNumberOfArrays()):
            name = da.GetArrayName(i)
            x, y = vtk_to_numpy(da.GetArray(name)), vtk_to_numpy(db.GetArray(name))
            check(x.shape == y.shape and (x == y).all(), f"{what}: '{name}' differs between binary and ASCII")


def wet_bed():
    snaps = run(source / "tests/data/restart/wet_servo_box.toml", work / "wet")
    final_b = read(series(snaps, "balls")[-1][1])
    final_c = read(series(snaps, "contacts")[-1][1])
    check(final_b.GetNumberOfPoints() == 36, "wet bed: 36 balls")
    cd = final_c.GetCellData()
    wet, state, fm, model = array(cd, "wet"), array(cd, "mois_state"), array(cd, "moisture_force"), array(cd, "model")
    check(wet.sum() > 10, f"wet bed: {wet.sum()} wet contacts")
    check(((model == 1) & (wet == 0)).sum() > 0, "wet bed: no dry hill contact")
    check(((wet == 1) == (state == 2)).all(), "wet flag and mois_state disagree")
    check((fm[wet == 1] < 0).all() and (fm[wet == 0] == 0).all(), "moisture force < 0 exactly on wet contacts")
    check((array(cd, "suction")[wet == 1] == 20e3).all(), "wet contacts carry the 20 kPa suction")
    wb = array(final_b.GetPointData(), "wet_contacts")
    check(wb.sum() == 2 * wet.sum(), "per-ball wet counts do not add up to twice the wet contacts")


def clumps_box():
    """examples/clumps_box.toml: 7 clumps of 3 pebbles; each pebble is a point with its clump's index."""
    snaps = run(source / "examples/clumps_box.toml", work / "clumps", "--snapshots-every", "20000")
    final_b = read(series(snaps, "balls")[-1][1])
    check(final_b.GetNumberOfPoints() == 21, f"clumps: {final_b.GetNumberOfPoints()} pebbles, expected 21")
    cid = array(final_b.GetPointData(), "clump_id")
    check(sorted(cid.tolist()) == [k for k in range(7) for _ in range(3)], f"clumps: clump_id {cid.tolist()}")
    ids = array(final_b.GetPointData(), "id")
    check(all(cid[i] == (ids[i] - 1) // 3 for i in range(21)), "clumps: pebbles 3k+1..3k+3 are clump k's")
    # At rest in the box: every pebble above the floor by less than the box is high, none outside.
    pts = vtk_to_numpy(final_b.GetPoints().GetData())
    check((abs(pts[:, 0]) < 18e-3).all() and (abs(pts[:, 1]) < 18e-3).all() and (pts[:, 2] > 0).all(),
          "clumps: a pebble outside the box")
    check(pts[:, 2].max() < 20e-3, f"clumps: not settled (highest pebble at z = {pts[:, 2].max()} m)")


b_bin, c_bin = assembly("binary")
b_asc, c_asc = assembly("ascii")
same(b_bin, b_asc, "balls")
same(c_bin, c_asc, "contacts")
wet_bed()
clumps_box()
if failures:
    print(f"{len(failures)} failures")
    sys.exit(1)
print("ok: snapshots read by VTK", vtk.vtkVersion.GetVTKVersion())
