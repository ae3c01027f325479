/* SPDX-License-Identifier: BSD-3-Clause */
/* Prints the size and every field's offset of the public structs that the Python module
 * mirrors with ctypes (python/isoprop/_structs.py), one "STRUCT SIZE" line per struct and one
 * "STRUCT.FIELD OFFSET" line per field, and the value of every constant it mirrors, one
 * "#NAME VALUE" line each; tests/python/test_layouts.py compares them. Built against the
 * public headers alone. */
#include <stddef.h>
#include <stdio.h>

#include "isoprop/isoprop.h"

#define SIZE(type) printf("%s %zu\n", #type, sizeof(type))
#define FIELD(type, field) printf("%s.%s %zu\n", #type, #field, offsetof(type, field))
#define CONSTANT(name) printf("#%s %lld\n", #name, (long long)(name))

static void error_and_input(void)
{
    SIZE(ip_error);
    FIELD(ip_error, code);
    FIELD(ip_error, message);
    SIZE(ip_input_desc);
    FIELD(ip_input_desc, path);
    FIELD(ip_input_desc, data_path);
    FIELD(ip_input_desc, data_offset);
    FIELD(ip_input_desc, dims);
    FIELD(ip_input_desc, type);
    FIELD(ip_input_desc, big_endian);
    FIELD(ip_input_desc, spacing);
    FIELD(ip_input_desc, encoding);
    FIELD(ip_input_desc, stream_skip);
    FIELD(ip_input_desc, has_rescale);
    FIELD(ip_input_desc, rescale_slope);
    FIELD(ip_input_desc, rescale_intercept);
    FIELD(ip_input_desc, orientation);
    FIELD(ip_input_desc, series_uid);
    FIELD(ip_input_desc, series_count);
    FIELD(ip_input_desc, skipped_objects);
    FIELD(ip_input_desc, source_slices);
    FIELD(ip_input_desc, resampled);
    FIELD(ip_input_desc, tilt_degrees);
    FIELD(ip_input_desc, rescale_unit);
    FIELD(ip_input_desc, plane_source);
    FIELD(ip_input_desc, plane_user);
    FIELD(ip_input_desc, dataset);
    FIELD(ip_input_desc, reader_bytes);
    FIELD(ip_input_desc, zarr_time);
    FIELD(ip_input_desc, zarr_channel);
    FIELD(ip_input_desc, zarr_scale);
    FIELD(ip_input_desc, zarr_scales);
    FIELD(ip_input_desc, space_unit);
    FIELD(ip_input_desc, reserved);
    SIZE(ip_rescale);
    FIELD(ip_rescale, present);
    FIELD(ip_rescale, slope);
    FIELD(ip_rescale, intercept);
    FIELD(ip_rescale, unit);
    SIZE(ip_orientation);
    FIELD(ip_orientation, origin);
    FIELD(ip_orientation, directions);
    FIELD(ip_orientation, space);
    SIZE(ip_input_overrides);
    FIELD(ip_input_overrides, size);
    FIELD(ip_input_overrides, has_dims);
    FIELD(ip_input_overrides, dims);
    FIELD(ip_input_overrides, has_type);
    FIELD(ip_input_overrides, type);
    FIELD(ip_input_overrides, has_endian);
    FIELD(ip_input_overrides, big_endian);
    FIELD(ip_input_overrides, has_spacing);
    FIELD(ip_input_overrides, spacing);
    FIELD(ip_input_overrides, series);
    FIELD(ip_input_overrides, tilt);
    FIELD(ip_input_overrides, uneven);
    FIELD(ip_input_overrides, dataset);
    FIELD(ip_input_overrides, has_scale);
    FIELD(ip_input_overrides, scale);
    FIELD(ip_input_overrides, has_time);
    FIELD(ip_input_overrides, time);
    FIELD(ip_input_overrides, has_channel);
    FIELD(ip_input_overrides, channel);
}

static void memory_volume(void)
{
    SIZE(ip_memory_volume);
    FIELD(ip_memory_volume, size);
    FIELD(ip_memory_volume, dims);
    FIELD(ip_memory_volume, type);
    FIELD(ip_memory_volume, strides);
    FIELD(ip_memory_volume, spacing);
    FIELD(ip_memory_volume, orientation);
    FIELD(ip_memory_volume, rescale);
    FIELD(ip_memory_volume, brick_edge);
    FIELD(ip_memory_volume, subblock_edge);
    FIELD(ip_memory_volume, threads);
    FIELD(ip_memory_volume, name);
}

static void bricker(void)
{
    SIZE(ip_bricker_options);
    FIELD(ip_bricker_options, size);
    FIELD(ip_bricker_options, brick_edge);
    FIELD(ip_bricker_options, subblock_edge);
    FIELD(ip_bricker_options, lz4_level);
    FIELD(ip_bricker_options, threads);
    FIELD(ip_bricker_options, memory_limit);
    FIELD(ip_bricker_options, force);
    FIELD(ip_bricker_options, progress);
    FIELD(ip_bricker_options, progress_user);
    SIZE(ip_bricker_report);
    FIELD(ip_bricker_report, input_bytes);
    FIELD(ip_bricker_report, file_bytes);
    FIELD(ip_bricker_report, bricks);
    FIELD(ip_bricker_report, bricks_constant);
    FIELD(ip_bricker_report, bricks_compressed);
    FIELD(ip_bricker_report, bricks_raw);
    FIELD(ip_bricker_report, levels);
    FIELD(ip_bricker_report, threads);
    FIELD(ip_bricker_report, seconds);
    FIELD(ip_bricker_report, memory_planned);
    FIELD(ip_bricker_report, peak_rss);
    FIELD(ip_bricker_report, seconds_read);
    FIELD(ip_bricker_report, seconds_encode);
    FIELD(ip_bricker_report, seconds_write);
    FIELD(ip_bricker_report, bytes_direct);
    FIELD(ip_bricker_report, read_overlap);
    FIELD(ip_bricker_report, reserved);
}

static void layout(void)
{
    SIZE(ip_level_layout);
    FIELD(ip_level_layout, dims);
    FIELD(ip_level_layout, bricks);
    FIELD(ip_level_layout, first_brick);
    FIELD(ip_level_layout, brick_count);
    FIELD(ip_level_layout, octree_depth);
    FIELD(ip_level_layout, first_node);
    FIELD(ip_level_layout, node_count);
    FIELD(ip_level_layout, value_min);
    FIELD(ip_level_layout, value_max);
    SIZE(ip_layout);
    FIELD(ip_layout, dims);
    FIELD(ip_layout, type);
    FIELD(ip_layout, spacing);
    FIELD(ip_layout, orientation);
    FIELD(ip_layout, brick_edge);
    FIELD(ip_layout, subblock_edge);
    FIELD(ip_layout, level_count);
    FIELD(ip_layout, value_min);
    FIELD(ip_layout, value_max);
    FIELD(ip_layout, brick_count);
    FIELD(ip_layout, node_count);
    FIELD(ip_layout, data_offset);
    FIELD(ip_layout, data_size);
    FIELD(ip_layout, summary_offset);
    FIELD(ip_layout, summary_size);
    FIELD(ip_layout, summary_checksum);
    FIELD(ip_layout, file_size);
    FIELD(ip_layout, levels);
    FIELD(ip_layout, format_version);
    FIELD(ip_layout, rescale);
}

static void cache(void)
{
    SIZE(ip_cache_level_stats);
    FIELD(ip_cache_level_stats, bricks_total);
    FIELD(ip_cache_level_stats, bricks_touched);
    FIELD(ip_cache_level_stats, misses);
    SIZE(ip_cache_stats);
    FIELD(ip_cache_stats, budget_bytes);
    FIELD(ip_cache_stats, resident_bytes);
    FIELD(ip_cache_stats, resident_peak_bytes);
    FIELD(ip_cache_stats, resident_bricks);
    FIELD(ip_cache_stats, hits);
    FIELD(ip_cache_stats, misses);
    FIELD(ip_cache_stats, evictions);
    FIELD(ip_cache_stats, waits);
    FIELD(ip_cache_stats, bytes_decompressed);
    FIELD(ip_cache_stats, bytes_read);
    FIELD(ip_cache_stats, decode_seconds);
    FIELD(ip_cache_stats, over_budget_pins);
    FIELD(ip_cache_stats, pinned_bytes);
    FIELD(ip_cache_stats, errors);
    FIELD(ip_cache_stats, prefetched);
    FIELD(ip_cache_stats, prefetch_hits);
    FIELD(ip_cache_stats, bytes_read_disk);
    FIELD(ip_cache_stats, wait_seconds);
    FIELD(ip_cache_stats, bricks_touched);
    FIELD(ip_cache_stats, bricks_total);
    FIELD(ip_cache_stats, levels);
    FIELD(ip_cache_stats, level);
    FIELD(ip_cache_stats, reserved);
}

static void engine(void)
{
    SIZE(ip_camera);
    FIELD(ip_camera, eye);
    FIELD(ip_camera, target);
    FIELD(ip_camera, up);
    FIELD(ip_camera, fov_y);
    FIELD(ip_camera, width);
    FIELD(ip_camera, height);
    SIZE(ip_engine_options);
    FIELD(ip_engine_options, size);
    FIELD(ip_engine_options, cutoff_degrees);
    FIELD(ip_engine_options, foldback_degrees);
    FIELD(ip_engine_options, threads);
    FIELD(ip_engine_options, lod);
    FIELD(ip_engine_options, pixel_error);
    FIELD(ip_engine_options, cell_ids);
    FIELD(ip_engine_options, occlusion);
    FIELD(ip_engine_options, prefetch);
    FIELD(ip_engine_options, cull);
    FIELD(ip_engine_options, clip_count);
    FIELD(ip_engine_options, clip);
    FIELD(ip_engine_options, reuse);
    SIZE(ip_clip_plane);
    FIELD(ip_clip_plane, normal);
    FIELD(ip_clip_plane, offset);
    SIZE(ip_engine_counts);
    FIELD(ip_engine_counts, rays);
    FIELD(ip_engine_counts, seeds);
    FIELD(ip_engine_counts, cells);
    FIELD(ip_engine_counts, triangles);
    FIELD(ip_engine_counts, intersection_seconds);
    FIELD(ip_engine_counts, propagation_seconds);
    FIELD(ip_engine_counts, extraction_seconds);
    FIELD(ip_engine_counts, rendering_seconds);
    FIELD(ip_engine_counts, deferred);
    FIELD(ip_engine_counts, retired);
    FIELD(ip_engine_counts, nodes);
    FIELD(ip_engine_counts, culled);
    FIELD(ip_engine_counts, kept);
    FIELD(ip_engine_counts, reserved);
    SIZE(ip_mesh);
    FIELD(ip_mesh, positions);
    FIELD(ip_mesh, normals);
    FIELD(ip_mesh, cells);
    FIELD(ip_mesh, triangle_count);
    FIELD(ip_mesh, capacity);
    FIELD(ip_mesh, populated);
    FIELD(ip_mesh, with_cells);
    SIZE(ip_indexed_mesh);
    FIELD(ip_indexed_mesh, positions);
    FIELD(ip_indexed_mesh, normals);
    FIELD(ip_indexed_mesh, indices);
    FIELD(ip_indexed_mesh, vertex_count);
    FIELD(ip_indexed_mesh, triangle_count);
    FIELD(ip_indexed_mesh, dropped_triangles);
}

static void constants(void)
{
    CONSTANT(IP_PATH_MAX);
    CONSTANT(IP_MAX_LEVELS);
    CONSTANT(IP_MAX_CLIP_PLANES);
    CONSTANT(IP_PREFETCH_OFF);
    CONSTANT(IP_PREFETCH_ON);
    CONSTANT(IP_PREFETCH_ALWAYS);
    CONSTANT(IP_RESCALE_UNIT_MAX);
}

int main(void)
{
    error_and_input();
    bricker();
    memory_volume();
    layout();
    cache();
    engine();
    constants();
    return 0;
}
