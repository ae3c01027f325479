# SPDX-License-Identifier: BSD-3-Clause
"""Finding and loading libisoprop.so, and the prototypes of the functions the module calls.

Where the library is, first found wins:
1. the environment variable ISOPROP_LIBRARY (a path to libisoprop.so*);
2. the path in _config.py, which CMake writes: absolute in the build tree
   (build/python/isoprop), relative to this folder when installed (cmake --install);
3. the system's loader path (libisoprop.so.MAJOR, then libisoprop.so).
Only libisoprop is loaded: nothing here renders.
"""
import ctypes
import os
from ctypes import (POINTER, c_char_p, c_double, c_float, c_int, c_uint, c_uint32, c_uint64,
                    c_void_p)

from . import _structs as S

try:
    from . import _config
except ImportError:  # the source tree, not configured by CMake
    _config = None

ERR = POINTER(S.Error)
HANDLE = c_void_p

# name: (restype, argtypes); an ip_status return is an int
_PROTOTYPES = {
    "ip_version": (c_char_p, []),
    "ip_status_message": (c_char_p, [c_int]),
    "ip_type_name": (c_char_p, [c_int]),
    "ip_type_parse": (c_int, [c_char_p, POINTER(c_int)]),
    "ip_thread_count": (c_uint, [c_uint]),
    "ip_peak_rss_bytes": (c_uint64, []),
    "ip_now_seconds": (c_double, []),
    "ip_spacing_check": (c_int, [c_double * 3, c_char_p, ERR]),
    "ip_input_describe": (c_int, [c_char_p, POINTER(S.InputOverrides), POINTER(S.InputDesc), ERR]),
    "ip_input_desc_from_planes": (c_int, [POINTER(S.InputDesc), c_char_p, c_uint32 * 3, c_int,
                                          c_double * 3, S.PLANE_SOURCE_FN, c_void_p, ERR]),
    "ip_bricker_options_default": (None, [POINTER(S.BrickerOptions)]),
    "ip_bricker_run": (c_int, [POINTER(S.InputDesc), c_char_p, POINTER(S.BrickerOptions),
                               POINTER(S.BrickerReport), ERR]),
    "ip_store_open": (c_int, [c_char_p, POINTER(HANDLE), ERR]),
    "ip_store_close": (None, [HANDLE]),
    "ip_memory_volume_default": (None, [POINTER(S.MemoryVolume)]),
    "ip_store_open_memory": (c_int, [c_void_p, POINTER(S.MemoryVolume), POINTER(HANDLE), ERR]),
    "ip_store_held_samples": (c_uint64, [HANDLE]),
    "ip_store_layout": (POINTER(S.Layout), [HANDLE]),
    "ip_store_path": (c_char_p, [HANDLE]),
    "ip_store_summary_memory": (c_uint64, [HANDLE]),
    "ip_layout_world_box": (None, [POINTER(S.Layout), c_double * 3, c_double * 3]),
    "ip_rescale_to_stored": (c_double, [POINTER(S.Rescale), c_double]),
    "ip_rescale_to_value": (c_double, [POINTER(S.Rescale), c_double]),
    "ip_rescale_check": (c_int, [POINTER(S.Rescale), c_char_p, ERR]),
    "ip_cache_default_budget": (c_uint64, []),
    "ip_cache_create": (c_int, [HANDLE, c_uint64, POINTER(HANDLE), ERR]),
    "ip_cache_destroy": (None, [HANDLE]),
    "ip_cache_get_stats": (None, [HANDLE, POINTER(S.CacheStats)]),
    "ip_camera_check": (c_int, [POINTER(S.Camera), ERR]),
    "ip_camera_fit_axis": (c_int, [c_double * 3, c_double * 3, c_char_p, c_double, c_uint32,
                                   c_uint32, POINTER(S.Camera), ERR]),
    "ip_camera_parse": (c_int, [c_char_p, POINTER(S.Camera), ERR]),
    "ip_camera_fit_view": (c_int, [POINTER(S.Orientation), c_double * 3, c_double * 3, c_char_p,
                                   c_double, c_uint32, c_uint32, POINTER(S.Camera), ERR]),
    "ip_camera_to_world": (None, [POINTER(S.Orientation), POINTER(S.Camera), POINTER(S.Camera)]),
    "ip_camera_to_physical": (None, [POINTER(S.Orientation), POINTER(S.Camera),
                                     POINTER(S.Camera)]),
    "ip_view_default": (c_char_p, [POINTER(S.Orientation)]),
    "ip_space_name": (c_char_p, [c_int]),
    "ip_engine_options_default": (None, [POINTER(S.EngineOptions)]),
    "ip_engine_create": (c_int, [HANDLE, POINTER(S.EngineOptions), POINTER(HANDLE), ERR]),
    "ip_engine_destroy": (None, [HANDLE]),
    "ip_engine_begin": (c_int, [HANDLE, POINTER(S.Camera), c_float, ERR]),
    "ip_engine_step": (c_int, [HANDLE, c_uint64, c_double, POINTER(S.EngineCounts), ERR]),
    "ip_engine_done": (c_int, [HANDLE]),
    "ip_engine_mesh": (POINTER(S.Mesh), [HANDLE]),
    "ip_engine_totals": (None, [HANDLE, POINTER(S.EngineCounts)]),
    "ip_extract_full": (c_int, [HANDLE, c_float, c_uint32, c_uint, POINTER(S.Mesh),
                                POINTER(S.EngineCounts), ERR]),
    "ip_extract_full_indexed": (c_int, [HANDLE, c_float, c_uint32, c_uint, c_int,
                                        POINTER(S.IndexedMesh), POINTER(POINTER(c_float)),
                                        POINTER(S.EngineCounts), ERR]),
    "ip_extract_full_lod": (c_int, [HANDLE, c_float, POINTER(S.Camera), c_double, c_uint,
                                    c_void_p, c_uint, POINTER(S.Mesh), POINTER(S.EngineCounts),
                                    ERR]),
    "ip_mesh_init": (None, [POINTER(S.Mesh)]),
    "ip_mesh_free": (None, [POINTER(S.Mesh)]),
    "ip_mesh_append_mesh": (c_int, [POINTER(S.Mesh), POINTER(S.Mesh), c_uint64, c_uint64]),
    "ip_mesh_to_physical": (None, [POINTER(S.Mesh), POINTER(S.Orientation)]),
    "ip_mesh_space_of": (c_char_p, [POINTER(S.Orientation)]),
    "ip_orientation_is_identity": (c_int, [POINTER(S.Orientation)]),
    "ip_indexed_mesh_free": (None, [POINTER(S.IndexedMesh)]),
    "ip_mesh_weld": (c_int, [POINTER(S.Mesh), POINTER(S.IndexedMesh)]),
    "ip_mesh_weld_keep_degenerate": (c_int, [POINTER(S.Mesh), POINTER(S.IndexedMesh)]),
    "ip_mesh_format_of": (c_char_p, [c_char_p]),
    "ip_mesh_write_in": (c_int, [POINTER(S.Mesh), c_char_p, c_char_p, c_int, ERR]),
    "ip_indexed_mesh_write_in": (c_int, [POINTER(S.IndexedMesh), c_char_p, c_char_p, c_int,
                                         ERR]),
    "ip_indexed_mesh_decimate": (c_int, [POINTER(S.IndexedMesh), c_double, c_double,
                                         POINTER(c_double), ERR]),
    "ip_extract_cap": (c_int, [HANDLE, c_float, c_uint32, POINTER(S.Mesh), ERR]),
    "ip_indexed_mesh_area": (c_double, [POINTER(S.IndexedMesh)]),
    "ip_indexed_mesh_volume": (c_double, [POINTER(S.IndexedMesh)]),
    "ip_indexed_mesh_bounds": (None, [POINTER(S.IndexedMesh), c_double * 3, c_double * 3]),
    "ip_indexed_mesh_edges": (c_int, [POINTER(S.IndexedMesh), POINTER(c_uint64),
                                      POINTER(c_uint64)]),
    "ip_indexed_mesh_components": (c_int, [POINTER(S.IndexedMesh), POINTER(c_uint32),
                                           POINTER(c_uint64)]),
    "ip_indexed_mesh_component_measures": (None, [POINTER(S.IndexedMesh), POINTER(c_uint32),
                                                  c_uint64, POINTER(c_uint64),
                                                  POINTER(c_double), POINTER(c_double)]),
}


def _candidates():
    env = os.environ.get("ISOPROP_LIBRARY")
    if env:
        return [env]
    found = []
    if _config is not None:
        path = _config.LIBRARY
        if not os.path.isabs(path):
            path = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), path))
        found.append(path)
    if _config is not None and getattr(_config, "SONAME", None):
        found.append(_config.SONAME)
    return found + ["libisoprop.so.0", "libisoprop.so"]


def _load():
    tried = []
    for path in _candidates():
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append(str(e))
            continue
        for name, (restype, argtypes) in _PROTOTYPES.items():
            fn = getattr(lib, name)
            fn.restype = restype
            fn.argtypes = argtypes
        return lib, path
    raise ImportError("isoprop: cannot load libisoprop (set ISOPROP_LIBRARY to its path): " +
                      "; ".join(tried))


lib, path = _load()
