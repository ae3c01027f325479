# SPDX-License-Identifier: BSD-3-Clause
"""ctypes mirrors of the public C structs that the module passes to libisoprop.

Each class copies a struct of include/isoprop/*.h field by field, in order. The test
tests/python/test_layouts.py compares every size and field offset here with the C compiler's
(tests/helpers/struct_layouts.c), so a change to a header that is not made here too fails the
tests instead of corrupting memory.
"""
import ctypes
from ctypes import c_char, c_char_p, c_double, c_float, c_int, c_int16, c_uint, c_uint32, c_uint64, c_void_p

PATH_MAX = 4096  # IP_PATH_MAX, include/isoprop/volume.h
MAX_LEVELS = 32  # IP_MAX_LEVELS, include/isoprop/layout.h


class Error(ctypes.Structure):
    """ip_error (status.h)"""
    _fields_ = [("code", c_int), ("message", c_char * 1024)]


class Orientation(ctypes.Structure):
    """ip_orientation (orientation.h)"""
    _fields_ = [("origin", c_double * 3), ("directions", (c_double * 3) * 3), ("space", c_int)]


RESCALE_UNIT_MAX = 16  # IP_RESCALE_UNIT_MAX, include/isoprop/volume.h


class Rescale(ctypes.Structure):
    """ip_rescale (volume.h)"""
    _fields_ = [("present", c_int), ("slope", c_double), ("intercept", c_double),
                ("unit", c_char * RESCALE_UNIT_MAX)]


class MemoryVolume(ctypes.Structure):
    """ip_memory_volume (store.h)"""
    _fields_ = [("size", c_uint32), ("dims", c_uint32 * 3), ("type", c_int),
                ("strides", ctypes.c_int64 * 3), ("spacing", c_double * 3),
                ("orientation", Orientation), ("rescale", Rescale), ("brick_edge", c_uint32),
                ("subblock_edge", c_uint32), ("threads", c_uint32), ("name", ctypes.c_char_p)]


# ip_plane_source_fn (input.h): fills `count` z-planes from z into dst; an ip_status
PLANE_SOURCE_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_uint32, c_uint32, c_void_p,
                                   ctypes.POINTER(Error))


class InputDesc(ctypes.Structure):
    """ip_input_desc (input.h)"""
    _fields_ = [("path", c_char * PATH_MAX), ("data_path", c_char * PATH_MAX),
                ("data_offset", c_uint64), ("dims", c_uint32 * 3), ("type", c_int),
                ("big_endian", c_int), ("spacing", c_double * 3), ("encoding", c_int),
                ("stream_skip", c_uint64), ("has_rescale", c_int), ("rescale_slope", c_double),
                ("rescale_intercept", c_double), ("orientation", Orientation),
                ("series_uid", c_char * 72), ("series_count", c_uint32),
                ("skipped_objects", c_uint32), ("source_slices", c_uint32), ("resampled", c_uint32),
                ("tilt_degrees", c_double), ("rescale_unit", c_char * RESCALE_UNIT_MAX),
                ("plane_source", PLANE_SOURCE_FN), ("plane_user", c_void_p),
                ("dataset", c_char * 96),
                ("reader_bytes", c_uint64), ("zarr_time", c_uint32),
                ("zarr_channel", ctypes.c_uint16), ("zarr_scale", ctypes.c_uint8),
                ("zarr_scales", ctypes.c_uint8), ("space_unit", c_char * 8),
                ("reserved", c_uint64 * 1)]


class InputOverrides(ctypes.Structure):
    """ip_input_overrides (input.h)"""
    _fields_ = [("size", c_uint32), ("has_dims", c_int), ("dims", c_uint32 * 3), ("has_type", c_int),
                ("type", c_int), ("has_endian", c_int), ("big_endian", c_int),
                ("has_spacing", c_int), ("spacing", c_double * 3), ("series", c_char_p),
                ("tilt", c_int), ("uneven", c_int), ("dataset", c_char_p),
                ("has_scale", c_int), ("scale", c_uint32),
                ("has_time", c_int), ("time", c_uint32), ("has_channel", c_int),
                ("channel", c_uint32)]


# ip_progress_fn (bricker.h): nonzero cancels the run
PROGRESS_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_uint64, c_uint64)


class BrickerOptions(ctypes.Structure):
    """ip_bricker_options (bricker.h)"""
    _fields_ = [("size", c_uint32), ("brick_edge", c_uint32), ("subblock_edge", c_uint32), ("lz4_level", c_int),
                ("threads", c_uint), ("memory_limit", c_uint64), ("force", c_int),
                ("progress", PROGRESS_FN), ("progress_user", c_void_p)]


class BrickerReport(ctypes.Structure):
    """ip_bricker_report (bricker.h)"""
    _fields_ = [("input_bytes", c_uint64), ("file_bytes", c_uint64), ("bricks", c_uint64),
                ("bricks_constant", c_uint64), ("bricks_compressed", c_uint64),
                ("bricks_raw", c_uint64), ("levels", c_uint32), ("threads", c_uint),
                ("seconds", c_double), ("memory_planned", c_uint64), ("peak_rss", c_uint64),
                ("seconds_read", c_double), ("seconds_encode", c_double),
                ("seconds_write", c_double), ("bytes_direct", c_uint64), ("read_overlap", c_int), ("reserved", c_uint64 * 8)]


class LevelLayout(ctypes.Structure):
    """ip_level_layout (layout.h)"""
    _fields_ = [("dims", c_uint32 * 3), ("bricks", c_uint32 * 3), ("first_brick", c_uint64),
                ("brick_count", c_uint64), ("octree_depth", c_uint32), ("first_node", c_uint64),
                ("node_count", c_uint64), ("value_min", c_float), ("value_max", c_float)]


class Layout(ctypes.Structure):
    """ip_layout (layout.h)"""
    _fields_ = [("dims", c_uint32 * 3), ("type", c_int), ("spacing", c_double * 3),
                ("orientation", Orientation), ("brick_edge", c_uint32), ("subblock_edge", c_uint32), ("level_count", c_uint32),
                ("value_min", c_float), ("value_max", c_float), ("brick_count", c_uint64),
                ("node_count", c_uint64), ("data_offset", c_uint64), ("data_size", c_uint64),
                ("summary_offset", c_uint64), ("summary_size", c_uint64),
                ("summary_checksum", c_uint64), ("file_size", c_uint64),
                ("levels", LevelLayout * MAX_LEVELS), ("format_version", c_uint32),
                ("rescale", Rescale)]


class CacheLevelStats(ctypes.Structure):
    """ip_cache_level_stats (cache.h)"""
    _fields_ = [("bricks_total", c_uint64), ("bricks_touched", c_uint64), ("misses", c_uint64)]


class CacheStats(ctypes.Structure):
    """ip_cache_stats (cache.h)"""
    _fields_ = [("budget_bytes", c_uint64), ("resident_bytes", c_uint64),
                ("resident_peak_bytes", c_uint64), ("resident_bricks", c_uint64),
                ("hits", c_uint64), ("misses", c_uint64), ("evictions", c_uint64),
                ("waits", c_uint64), ("bytes_decompressed", c_uint64), ("bytes_read", c_uint64),
                ("decode_seconds", c_double), ("over_budget_pins", c_uint64),
                ("pinned_bytes", c_uint64), ("errors", c_uint64), ("prefetched", c_uint64),
                ("prefetch_hits", c_uint64), ("bytes_read_disk", c_uint64),
                ("wait_seconds", c_double), ("bricks_touched", c_uint64),
                ("bricks_total", c_uint64), ("levels", c_uint32),
                ("level", CacheLevelStats * 32), ("reserved", c_uint64 * 8)]


class Camera(ctypes.Structure):
    """ip_camera (camera.h)"""
    _fields_ = [("eye", c_double * 3), ("target", c_double * 3), ("up", c_double * 3),
                ("fov_y", c_double), ("width", c_uint32), ("height", c_uint32)]


IP_MAX_CLIP_PLANES = 6  # engine.h
# ip_engine_options.prefetch (engine.h)
PREFETCH_OFF = 0  # IP_PREFETCH_OFF: no reader
PREFETCH_ON = 1  # IP_PREFETCH_ON: the default
PREFETCH_ALWAYS = 2  # IP_PREFETCH_ALWAYS: every planned brick read ahead
# each mode's name, as isorender's --prefetch takes it and --stats writes it ("prefetch_mode")
PREFETCH_NAMES = {PREFETCH_OFF: "off", PREFETCH_ON: "on", PREFETCH_ALWAYS: "always"}


class ClipPlane(ctypes.Structure):
    """ip_clip_plane (engine.h)"""
    _fields_ = [("normal", c_double * 3), ("offset", c_double)]


class EngineOptions(ctypes.Structure):
    """ip_engine_options (engine.h)"""
    _fields_ = [("size", c_uint32), ("cutoff_degrees", c_double), ("foldback_degrees", c_double),
                ("threads", c_uint), ("lod", c_int), ("pixel_error", c_double),
                ("cell_ids", c_int), ("occlusion", c_int), ("prefetch", c_int),
                ("cull", c_int), ("clip_count", c_uint), ("clip", ClipPlane * IP_MAX_CLIP_PLANES),
                ("reuse", c_int)]


class EngineCounts(ctypes.Structure):
    """ip_engine_counts (engine.h)"""
    _fields_ = [("rays", c_uint64), ("seeds", c_uint64), ("cells", c_uint64),
                ("triangles", c_uint64), ("intersection_seconds", c_double),
                ("propagation_seconds", c_double), ("extraction_seconds", c_double),
                ("rendering_seconds", c_double), ("deferred", c_uint64),
                ("retired", c_uint64), ("nodes", c_uint64), ("culled", c_uint64),
                ("kept", c_uint64), ("reserved", c_uint64 * 8)]


class Mesh(ctypes.Structure):
    """ip_mesh (mesh.h)"""
    _fields_ = [("positions", ctypes.POINTER(c_float)), ("normals", ctypes.POINTER(c_int16)),
                ("cells", ctypes.POINTER(c_uint64)), ("triangle_count", c_uint64),
                ("capacity", c_uint64), ("populated", c_uint64), ("with_cells", c_int)]


class IndexedMesh(ctypes.Structure):
    """ip_indexed_mesh (mesh.h)"""
    _fields_ = [("positions", ctypes.POINTER(c_float)), ("normals", ctypes.POINTER(c_int16)),
                ("indices", ctypes.POINTER(c_uint32)), ("vertex_count", c_uint64),
                ("triangle_count", c_uint64), ("dropped_triangles", c_uint64)]


# Every mirror, by its C name: what the layout test checks.
MIRRORS = {
    "ip_error": Error,
    "ip_orientation": Orientation,
    "ip_rescale": Rescale,
    "ip_input_desc": InputDesc,
    "ip_memory_volume": MemoryVolume,
    "ip_input_overrides": InputOverrides,
    "ip_bricker_options": BrickerOptions,
    "ip_bricker_report": BrickerReport,
    "ip_level_layout": LevelLayout,
    "ip_layout": Layout,
    "ip_cache_level_stats": CacheLevelStats,
    "ip_cache_stats": CacheStats,
    "ip_camera": Camera,
    "ip_clip_plane": ClipPlane,
    "ip_engine_options": EngineOptions,
    "ip_engine_counts": EngineCounts,
    "ip_mesh": Mesh,
    "ip_indexed_mesh": IndexedMesh,
}

# Every mirrored constant, by its C name: what the layout test checks.
CONSTANTS = {
    "IP_PATH_MAX": PATH_MAX,
    "IP_MAX_LEVELS": MAX_LEVELS,
    "IP_MAX_CLIP_PLANES": IP_MAX_CLIP_PLANES,
    "IP_PREFETCH_OFF": PREFETCH_OFF,
    "IP_PREFETCH_ON": PREFETCH_ON,
    "IP_PREFETCH_ALWAYS": PREFETCH_ALWAYS,
    "IP_RESCALE_UNIT_MAX": RESCALE_UNIT_MAX,
}
