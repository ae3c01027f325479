#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""One run of tools/bench/bench_python.sh in this (fresh) process: the isosurface of a raw
volume, read into a numpy array first (not timed), by one of

    isoprop   isoprop.marching_cubes(array, ISO)           (verts, faces, normals, values)
    skimage   skimage.measure.marching_cubes(array, ISO)   (the same four arrays; Lewiner)
    vtk       vtkFlyingEdges3D on the array (Update() with normals, no scalars)
    profile   isoprop's steps one by one: the in-memory store, the welded full extraction
              (ip_extract_full_indexed(), with the values), its copy to numpy in axis order, closing the store

    bench_python.py WHAT RAW ISO    prints one line of JSON: seconds (the call), faces

RAW is named NAME_XxYxZ_TYPE.raw (little-endian), an array of shape (z, y, x). Run it with
/usr/bin/python3 and PYTHONPATH=build/python; skimage needs python3-skimage, vtk python3-vtk9.
"""
import json
import re
import sys
import time

import numpy as np

TYPES = {"uint8": np.uint8, "uint16": "<u2", "int16": "<i2", "float32": "<f4"}


def read(path):
    m = re.search(r"_(\d+)x(\d+)x(\d+)_(uint8|uint16|int16|float32)\.raw$", path)
    if not m:
        sys.exit("bench_python: %s: name is not NAME_XxYxZ_TYPE.raw" % path)
    nx, ny, nz = (int(m.group(i)) for i in (1, 2, 3))
    data = np.fromfile(path, dtype=TYPES[m.group(4)])
    return data.astype(data.dtype.newbyteorder("="), copy=False).reshape(nz, ny, nx)


def run_vtk(a, iso):
    import vtk
    from vtk.util import numpy_support
    image = vtk.vtkImageData()
    image.SetDimensions(a.shape[2], a.shape[1], a.shape[0])
    array = numpy_support.numpy_to_vtk(a.ravel(), deep=False)
    image.GetPointData().SetScalars(array)
    start = time.perf_counter()
    f = vtk.vtkFlyingEdges3D()
    f.SetInputData(image)
    f.SetValue(0, iso)
    f.ComputeNormalsOn()
    f.ComputeScalarsOff()
    f.Update()
    return time.perf_counter() - start, f.GetOutput().GetNumberOfPolys()


def run_profile(a, iso):
    import ctypes
    from isoprop import _structs as S
    from isoprop import mesh as M
    from isoprop._library import lib
    from isoprop.errors import check, new_error
    t = [time.perf_counter()]
    import isoprop
    with isoprop.open_array(a, spacing=(1.0, 1.0, 1.0)) as f:
        t.append(time.perf_counter())
        out, counts, err = S.IndexedMesh(), S.EngineCounts(), new_error()
        values = ctypes.POINTER(ctypes.c_float)()
        check(lib.ip_extract_full_indexed(f._cache_for(None), iso, 0, 0, 1, ctypes.byref(out),
                                          ctypes.byref(values), ctypes.byref(counts),
                                          ctypes.byref(err)), err)
        t.append(time.perf_counter())
        w = M.indexed_arrays(out, reverse=True, take=True)
        M.take_c(values, np.float32, out.vertex_count)
        lib.ip_indexed_mesh_free(ctypes.byref(out))
        t.append(time.perf_counter())
    t.append(time.perf_counter())
    steps = ("volume_file", "extract_welded", "to_numpy", "close")
    return {s: round(t[i + 1] - t[i], 4) for i, s in enumerate(steps)}, len(w.faces)


def main():
    what, path, iso = sys.argv[1], sys.argv[2], float(sys.argv[3])
    a = read(path)
    if what == "isoprop":
        import isoprop
        start = time.perf_counter()
        faces = len(isoprop.marching_cubes(a, iso)[1])
        seconds = time.perf_counter() - start
    elif what == "skimage":
        from skimage.measure import marching_cubes
        start = time.perf_counter()
        faces = len(marching_cubes(a, iso)[1])
        seconds = time.perf_counter() - start
    elif what == "vtk":
        seconds, faces = run_vtk(a, iso)
    elif what == "profile":
        seconds, faces = run_profile(a, iso)
    else:
        sys.exit("bench_python: WHAT is isoprop, skimage, vtk or profile, not %r" % what)
    print(json.dumps({"what": what, "seconds": seconds, "faces": faces}))


if __name__ == "__main__":
    main()
