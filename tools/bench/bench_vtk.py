#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""The VTK side of tools/bench/bench_engine.sh: isosurface extraction of a raw volume with VTK's
vtkFlyingEdges3D and vtkMarchingCubes (only the filter's Update() is timed), VTK's own rendering
of the result offscreen, and the peak memory of Flying Edges on a large volume.

    bench_vtk.py extract RAW ISO [ISO...]          one line of JSON per filter call and isovalue
                                                   (Flying Edges twice: first call, then again)
    bench_vtk.py render  RAW ISO VIEW WxH          Flying Edges, then two timed Render() calls
    bench_vtk.py memory  RAW ISO                   Flying Edges only; prints its peak RSS

RAW is named NAME_XxYxZ_TYPE.raw (little-endian). Needs Debian's python3-vtk9 (run it with
/usr/bin/python3); `render` needs an X display (run it under xvfb-run).
"""
import json
import re
import resource
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

TYPES = {"uint8": np.uint8, "uint16": "<u2", "int16": "<i2", "float32": "<f4"}


def read_raw(path):
    m = re.search(r"_(\d+)x(\d+)x(\d+)_(uint8|uint16|int16|float32)\.raw$", path)
    if not m:
        sys.exit(f"bench_vtk: {path}: name is not NAME_XxYxZ_TYPE.raw")
    nx, ny, nz = (int(m.group(i)) for i in (1, 2, 3))
    start = time.perf_counter()
    data = np.fromfile(path, dtype=TYPES[m.group(4)])
    if data.size != nx * ny * nz:
        sys.exit(f"bench_vtk: {path}: {data.size} samples, expected {nx * ny * nz}")
    data = data.astype(data.dtype.newbyteorder("="), copy=False)
    read_s = time.perf_counter() - start
    image = vtk.vtkImageData()
    image.SetDimensions(nx, ny, nz)
    image.SetSpacing(1.0, 1.0, 1.0)
    image.SetOrigin(0.0, 0.0, 0.0)
    array = numpy_support.numpy_to_vtk(data, deep=False)  # x fastest, as in the file
    array.SetName("scalars")
    image.GetPointData().SetScalars(array)
    image._keep = data  # the VTK array borrows numpy's memory
    return image, read_s, (nx, ny, nz)


def run_filter(kind, image, iso):
    f = vtk.vtkFlyingEdges3D() if kind == "flying_edges" else vtk.vtkMarchingCubes()
    f.SetInputData(image)
    f.SetValue(0, iso)
    f.ComputeNormalsOn()   # the engine computes gradient normals too
    f.ComputeScalarsOff()
    start = time.perf_counter()
    f.Update()
    seconds = time.perf_counter() - start
    out = f.GetOutput()
    return f, out, seconds


def peak_rss_bytes():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def cmd_extract(path, isos):
    image, read_s, dims = read_raw(path)
    threads = vtk.vtkSMPTools.GetEstimatedNumberOfThreads()
    backend = vtk.vtkSMPTools.GetBackend() if hasattr(vtk.vtkSMPTools, "GetBackend") else "?"
    for iso in isos:
        # Flying Edges twice: the first call in a process also starts TBB's threads
        for kind, call in (("flying_edges", 1), ("flying_edges", 2), ("marching_cubes", 1)):
            f, out, seconds = run_filter(kind, image, iso)
            print(json.dumps({"filter": kind, "call": call, "iso": iso,
                              "update_s": round(seconds, 6),
                              "triangles": out.GetNumberOfPolys(),
                              "points": out.GetNumberOfPoints(), "read_s": round(read_s, 3),
                              "smp_backend": backend, "smp_threads": threads,
                              "vtk": vtk.vtkVersion.GetVTKVersion()}), flush=True)
            del f, out


def cmd_render(path, iso, view, size):
    w, h = (int(v) for v in size.lower().split("x"))
    image, _, dims = read_raw(path)
    f, poly, seconds = run_filter("flying_edges", image, iso)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(poly)
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    ren = vtk.vtkRenderer()
    ren.AddActor(actor)
    ren.SetBackground(1, 1, 1)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(w, h)
    win.AddRenderer(ren)
    # the engine's framing: eye on the VIEW side of the volume, fov 30 degrees, up +z
    centre = [(d - 1) / 2.0 for d in dims]
    axis = {"x": 0, "y": 1, "z": 2}[view[1]]
    sign = -1.0 if view[0] == "-" else 1.0
    cam = ren.GetActiveCamera()
    cam.SetFocalPoint(*centre)
    pos = list(centre)
    pos[axis] += sign * 3.0 * max(dims)
    cam.SetPosition(*pos)
    cam.SetViewUp(*((0, 1, 0) if axis == 2 else (0, 0, 1)))
    cam.SetViewAngle(30.0)
    ren.ResetCamera()
    times = []
    for _ in range(2):
        start = time.perf_counter()
        win.Render()
        if hasattr(win, "WaitForCompletion"):
            win.WaitForCompletion()  # glFinish: the frame is really drawn
        times.append(time.perf_counter() - start)
    print(json.dumps({"iso": iso, "view": view, "width": w, "height": h,
                      "triangles": poly.GetNumberOfPolys(), "update_s": round(seconds, 6),
                      "first_render_s": round(times[0], 6), "second_render_s": round(times[1], 6),
                      "opengl": [line.split(":", 1)[1].strip()
                                 for line in win.ReportCapabilities().splitlines()
                                 if line.startswith("OpenGL renderer string")]}), flush=True)


def cmd_memory(path, iso):
    image, read_s, dims = read_raw(path)
    after_read = peak_rss_bytes()
    f, out, seconds = run_filter("flying_edges", image, iso)
    print(json.dumps({"filter": "flying_edges", "iso": iso, "update_s": round(seconds, 6),
                      "read_s": round(read_s, 3), "triangles": out.GetNumberOfPolys(),
                      "rss_after_read_bytes": after_read, "peak_rss_bytes": peak_rss_bytes()}),
          flush=True)


def main(argv):
    if len(argv) < 3 or argv[0] not in ("extract", "render", "memory"):
        sys.exit(__doc__)
    if argv[0] == "extract":
        cmd_extract(argv[1], [float(v) for v in argv[2:]])
    elif argv[0] == "render":
        cmd_render(argv[1], float(argv[2]), argv[3], argv[4])
    else:
        cmd_memory(argv[1], float(argv[2]))


if __name__ == "__main__":
    main(sys.argv[1:])
