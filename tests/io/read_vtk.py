#!/usr/bin/python3
"""Read the files written by test_io_vtk_write with VTK's own XML readers
(Debian's python3-vtk9) and check counts and exact values.

Usage: /usr/bin/python3 read_vtk.py OUTDIR
Fails (exit 1) with a clear message if VTK cannot be imported: the point of
this test is that a real consumer reads our files, so it is never skipped.
"""
import math
import os
import struct
import sys
import xml.etree.ElementTree as ET

try:
    from vtkmodules.vtkIOXML import (vtkXMLImageDataReader, vtkXMLPolyDataReader,
                                     vtkXMLUnstructuredGridReader)
    from vtkmodules.vtkCommonCore import vtkCommand
except ImportError as e:  # never a skip
    sys.exit("FAIL: %s cannot import vtk (%s). Install Debian's python3-vtk9 "
             "(scripts/deps.sh) -- this test needs a real VTK reader." % (sys.executable, e))

FAILURES = []
CHECKS = [0]


def check(cond, what):
    CHECKS[0] += 1
    if not cond:
        FAILURES.append(what)
        print("check failed:", what, file=sys.stderr)


def f32(x):
    """x rounded to IEEE single precision."""
    return struct.unpack("f", struct.pack("f", x))[0]


def read(reader_cls, path):
    """Read path with a VTK reader; any VTK error or warning is a failure."""
    reader = reader_cls()
    errors = []

    def on_error(obj, event):
        errors.append(event)

    reader.AddObserver(vtkCommand.ErrorEvent, on_error)
    reader.AddObserver(vtkCommand.WarningEvent, on_error)
    reader.SetFileName(path)
    reader.Update()
    check(not errors, "%s: VTK reported %s" % (path, errors))
    check(reader.GetErrorCode() == 0, "%s: reader error code %d" % (path, reader.GetErrorCode()))
    return reader.GetOutput()


def array(data, name, where):
    arr = getattr(data, "Get%sData" % where)().GetAbstractArray(name)
    check(arr is not None, "array %s missing from %s data" % (name, where))
    return arr


def field(data, name):
    arr = data.GetFieldData().GetAbstractArray(name)
    check(arr is not None, "field %s missing" % name)
    return arr.GetTuple1(0) if arr is not None else None


def px_x(i):
    return 0.25 * i - 3.0


def px_y(i):
    return 0.125 * (i % 17) - 1.0


def px_gamma(i):
    return ((i % 11) - 5.0) * 0.0625


def check_particles(path, is32):
    name = os.path.basename(path)
    d = read(vtkXMLPolyDataReader, path)
    n = 1000
    check(d.GetNumberOfPoints() == n, "%s: %d points" % (name, d.GetNumberOfPoints()))
    check(d.GetNumberOfVerts() == n, "%s: %d verts" % (name, d.GetNumberOfVerts()))
    check(d.GetPoints().GetDataType() == (10 if is32 else 11), "%s: points type" % name)
    check(d.GetPoint(17) == (px_x(17), px_y(17), 0.0), "%s: point 17 = %s" % (name, d.GetPoint(17)))
    check(d.GetPoint(999) == (px_x(999), px_y(999), 0.0), "%s: point 999" % name)
    g = array(d, "Gamma", "Point")
    check(g.GetNumberOfComponents() == 1, "%s: Gamma components" % name)
    check(g.GetRange() == (-5 * 0.0625, 5 * 0.0625), "%s: Gamma range %s" % (name, g.GetRange()))
    check(all(g.GetTuple1(i) == px_gamma(i) for i in range(n)), "%s: Gamma values" % name)
    u = array(d, "velocity", "Point")
    check(u.GetNumberOfComponents() == 3, "%s: velocity has 3 components" % name)
    check(u.GetTuple3(17) == (8.5, -4.25, 0.0), "%s: velocity[17] = %s" % (name, u.GetTuple3(17)))
    check(all(u.GetTuple3(i) == (0.5 * i, -0.25 * i, 0.0) for i in range(n)),
          "%s: velocity values" % name)
    f = array(d, "force", "Point")
    check(f.GetTuple3(17) == (8.5, 17.0, 25.5), "%s: force[17] = %s" % (name, f.GetTuple3(17)))
    fxy = array(d, "force_xy", "Point")
    check(fxy.GetNumberOfComponents() == 3, "%s: force_xy padded to 3 components" % name)
    check(all(fxy.GetTuple3(i) == (0.5 * i, 1.0 * i, 0.0) for i in range(n)), "%s: force_xy" % name)
    ids = array(d, "id", "Point")
    check(ids.GetDataTypeAsString() == "int", "%s: id type %s" % (name, ids.GetDataTypeAsString()))
    check(ids.GetTuple1(999) == 999, "%s: id[999]" % name)
    third = array(d, "third", "Point")
    want = f32(17 / 3.0) if is32 else 17 / 3.0
    check(third.GetTuple1(17) == want, "%s: third[17] = %r, want %r" % (name, third.GetTuple1(17), want))
    check(d.GetPointData().GetScalars().GetName() == "Gamma", "%s: active scalars" % name)
    check(d.GetPointData().GetVectors().GetName() == "velocity", "%s: active vectors" % name)
    check(field(d, "TimeValue") == 0.5, "%s: TimeValue" % name)
    check(field(d, "Step") == 10, "%s: Step" % name)
    check(field(d, "Cx") == 0.123456789012345, "%s: Cx" % name)


def check_points_aos(path):
    d = read(vtkXMLPolyDataReader, path)
    check(d.GetNumberOfPoints() == 1000, "points_aos: count")
    check(all(d.GetPoint(i) == (px_x(i), px_y(i), 0.0) for i in range(1000)), "points_aos: coordinates")


def check_big(path):
    d = read(vtkXMLPolyDataReader, path)
    n = 100003
    check(d.GetNumberOfPoints() == n, "big: %d points" % d.GetNumberOfPoints())
    check(d.GetNumberOfVerts() == n, "big: verts")
    for i in (0, 1, 17, 16383, 16384, 65537, n - 1):
        check(d.GetPoint(i) == (0.5 * i, -0.25 * i, float(i % 1000)), "big: point %d = %s" % (i, d.GetPoint(i)))
    g = array(d, "Gamma", "Point")
    u = array(d, "velocity", "Point")
    check(g.GetDataTypeAsString() == "float", "big: Gamma is float")
    check(all(g.GetTuple1(i) == (i % 4096) * 0.25 for i in range(0, n, 7)), "big: Gamma values")
    check(all(u.GetTuple3(i) == (float(i % 8192), -float(i % 8192), 0.0) for i in range(0, n, 7)),
          "big: velocity values")
    check(u.GetTuple3(n - 1) == (float((n - 1) % 8192), -float((n - 1) % 8192), 0.0), "big: last velocity")


def check_body(outdir):
    d = read(vtkXMLPolyDataReader, os.path.join(outdir, "body.vtp"))
    nb = 40
    check(d.GetNumberOfPoints() == nb + 5, "body: points")
    check(d.GetNumberOfLines() == 2, "body: %d lines" % d.GetNumberOfLines())
    check(d.GetNumberOfCells() == 2, "body: cells")
    cell = d.GetCell(0)
    ids = [cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())]
    check(ids == list(range(nb)) + [0], "body: closed polyline ids %s" % ids)
    check(d.GetCellType(0) == 4, "body: cell 0 is a polyline (type %d)" % d.GetCellType(0))
    cell = d.GetCell(1)
    ids = [cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())]
    check(ids == [nb + 4, nb + 3, nb + 2, nb + 1, nb], "body: open line ids %s" % ids)
    p = d.GetPoint(10)
    a = 2.0 * math.pi * 10 / nb
    check(abs(p[0] - 0.5 * math.cos(a)) < 1e-15 and abs(p[1] - 0.5 * math.sin(a)) < 1e-15,
          "body: point 10 = %s" % (p,))
    pr = array(d, "pressure", "Cell")
    check((pr.GetTuple1(0), pr.GetTuple1(1)) == (1.5, -2.5), "body: pressure")

    d = read(vtkXMLPolyDataReader, os.path.join(outdir, "contour_segments.vtp"))
    check(d.GetNumberOfLines() == nb, "segments: %d lines" % d.GetNumberOfLines())
    cell = d.GetCell(nb - 1)
    check((cell.GetPointId(0), cell.GetPointId(1)) == (nb - 1, 0), "segments: closing segment")
    e = array(d, "energy", "Cell")
    check(e.GetTuple1(nb - 1) == 0.5 * (nb - 1), "segments: energy")

    d = read(vtkXMLPolyDataReader, os.path.join(outdir, "surface.vtp"))
    check(d.GetNumberOfPolys() == 4 and d.GetNumberOfLines() == 1, "surface: 4 polys, 1 line")
    check(d.GetCellType(0) == 3 and d.GetCellType(1) == 5, "surface: a line, then triangles")
    cell = d.GetCell(4)
    ids = [cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())]
    check(ids == [1, 2, 3], "surface: last triangle ids %s" % ids)
    h = array(d, "height", "Point")
    check([h.GetTuple1(i) for i in range(4)] == [0, 0, 0, 1], "surface: point data")
    f = array(d, "face", "Cell")
    check([f.GetTuple1(i) for i in range(5)] == [-1, 0, 1, 2, 3], "surface: cell data")


def check_image(path, is32):
    name = os.path.basename(path)
    d = read(vtkXMLImageDataReader, path)
    check(d.GetDimensions() == (5, 4, 3), "%s: dims %s" % (name, d.GetDimensions()))
    check(d.GetOrigin() == (-1.0, 0.5, 2.0), "%s: origin %s" % (name, d.GetOrigin()))
    check(d.GetSpacing() == (0.5, 0.25, 1.0), "%s: spacing %s" % (name, d.GetSpacing()))
    check(d.GetNumberOfPoints() == 60 and d.GetNumberOfCells() == 24, "%s: counts" % name)
    phi = array(d, "phi", "Point")
    check(phi.GetDataTypeAsString() == ("float" if is32 else "double"), "%s: phi type" % name)
    pid = d.ComputePointId([3, 2, 1])
    check(pid == 33 and phi.GetTuple1(pid) == 123.0, "%s: phi(3,2,1) = %s" % (name, phi.GetTuple1(pid)))
    check(d.GetPoint(pid) == (-1.0 + 1.5, 0.5 + 0.5, 3.0), "%s: point (3,2,1)" % name)
    u = array(d, "u", "Point")
    check(u.GetTuple3(pid) == (3.0, 2.0, 0.0), "%s: u(3,2,1)" % name)
    rho = array(d, "rho", "Cell")
    cid = d.ComputeCellId([2, 1, 1])
    check(cid == 18 and rho.GetTuple1(cid) == 112.0, "%s: rho(2,1,1)" % name)
    check(field(d, "TimeValue") == 2.25, "%s: TimeValue" % name)

    d = read(vtkXMLImageDataReader, os.path.join(os.path.dirname(path), "field2d.vti"))
    check(d.GetDimensions() == (6, 3, 1), "field2d: dims")
    check(d.GetNumberOfCells() == 10, "field2d: %d cells" % d.GetNumberOfCells())
    s = array(d, "solid", "Cell")
    check(s.GetDataTypeAsString() == "unsigned char", "field2d: solid is UInt8")
    check([int(s.GetTuple1(c)) for c in range(10)] == [int(c % 3 == 0) for c in range(10)],
          "field2d: solid values")


def check_hex(path, is32):
    name = os.path.basename(path)
    d = read(vtkXMLUnstructuredGridReader, path)
    check(d.GetNumberOfPoints() == 18 and d.GetNumberOfCells() == 4, "%s: counts" % name)
    check(all(d.GetCellType(c) == 12 for c in range(4)), "%s: all hexahedra" % name)
    cell = d.GetCell(1)
    ids = [cell.GetPointId(k) for k in range(8)]
    check(ids == [1, 2, 5, 4, 10, 11, 14, 13], "%s: cell 1 ids %s" % (name, ids))
    check(d.GetPoint(14) == (2.0, 1.0, 1.0), "%s: point 14" % name)
    check(abs(cell.GetBounds()[1] - 2.0) == 0, "%s: cell 1 bounds" % name)
    m = array(d, "material", "Cell")
    e = array(d, "energy", "Cell")
    check([m.GetTuple1(c) for c in range(4)] == [1, 2, 3, 4], "%s: material" % name)
    check([e.GetTuple1(c) for c in range(4)] == [0.5, 1.5, 2.5, 3.5], "%s: energy" % name)
    t = array(d, "T", "Point")
    check(t.GetTuple1(17) == 2 + 2 + 1, "%s: T[17]" % name)
    # The volume of a hexahedron is positive when the node order is right.
    from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
    f = vtkCellSizeFilter()
    f.SetInputData(d)
    f.Update()
    vol = f.GetOutput().GetCellData().GetArray("Volume")
    check(all(abs(vol.GetTuple1(c) - 1.0) < 1e-12 for c in range(4)), "%s: unit volumes" % name)


def check_mixed(path):
    d = read(vtkXMLUnstructuredGridReader, path)
    check([d.GetCellType(c) for c in range(d.GetNumberOfCells())] == [12, 9, 3, 1],
          "mixed: cell types")
    cell = d.GetCell(2)
    check((cell.GetPointId(0), cell.GetPointId(1)) == (2, 5), "mixed: line ids")


def check_series(outdir):
    path = os.path.join(outdir, "series.pvd")
    root = ET.parse(path).getroot()
    check(root.tag == "VTKFile" and root.get("type") == "Collection", "pvd: root element")
    sets = root.findall("./Collection/DataSet")
    times = [float(s.get("timestep")) for s in sets]
    check(times == [0.0, 0.5, 0.75], "pvd: timesteps %s" % times)
    for s in sets:
        f = os.path.join(outdir, s.get("file"))
        d = read(vtkXMLPolyDataReader, f)
        t = float(s.get("timestep"))
        check(field(d, "TimeValue") == t, "pvd: %s TimeValue" % f)
        check(array(d, "t", "Point").GetTuple1(2) == t, "pvd: %s data" % f)


def main():
    outdir = sys.argv[1]
    check_particles(os.path.join(outdir, "particles_f32.vtp"), True)
    check_particles(os.path.join(outdir, "particles_f64.vtp"), False)
    check_points_aos(os.path.join(outdir, "points_aos.vtp"))
    check_big(os.path.join(outdir, "particles_big.vtp"))
    check_body(outdir)
    check_image(os.path.join(outdir, "field_f32.vti"), True)
    check_image(os.path.join(outdir, "field_f64.vti"), False)
    check_hex(os.path.join(outdir, "hex_f32.vtu"), True)
    check_hex(os.path.join(outdir, "hex_f64.vtu"), False)
    check_mixed(os.path.join(outdir, "mixed.vtu"))
    check_series(outdir)
    if FAILURES:
        print("read_vtk.py: %d of %d checks FAILED" % (len(FAILURES), CHECKS[0]), file=sys.stderr)
        return 1
    print("read_vtk.py: all %d checks passed (VTK read every file)" % CHECKS[0])
    return 0


if __name__ == "__main__":
    sys.exit(main())
