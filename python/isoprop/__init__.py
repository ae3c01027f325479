# SPDX-License-Identifier: BSD-3-Clause
"""isoprop: isosurfaces of volumes far larger than memory, from Python.

    import isoprop
    isoprop.brick(array_zyx, "head.ibv", spacing=(0.3, 0.3, 0.5))   # or a raw/NRRD/MHD path
    with isoprop.open("head.ibv") as f:
        mesh = f.extract(600.5, view="-y", size=(800, 600))          # progressive
        mesh = f.extract(600.5, full=True)                            # every active cell
        for step in f.extract_steps(600.5, rays_per_step=4096):       # step by step
            ...
    with isoprop.open_array(array_zyx, (0.3, 0.3, 0.5)) as f:          # no file at all
        mesh = f.extract(600.5, full=True)

A thin layer (ctypes) over the shared library libisoprop; docs/python.md describes it.
"""
from ._library import lib as _lib
from ._library import path as library_path
from .array import open_array
from .bricking import brick
from .errors import ArgumentError, Error
from .mesh import Mesh, Step, Welded
from .surface import contour, marching_cubes
from .volume import File, Level, Rescale, open

__version__ = _lib.ip_version().decode()
__all__ = ["brick", "open", "open_array", "marching_cubes", "contour", "File", "Level", "Rescale",
           "Mesh", "Step", "Welded", "Error", "ArgumentError", "library_path", "__version__"]
