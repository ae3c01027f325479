# SPDX-License-Identifier: BSD-3-Clause
"""The statistics of an extraction, as a dict with the keys of isorender's --stats JSON
(tools/isorender/stats.c, tools/common/report.c). Left out, since they need the run's image:
the renderer's work (final_pixel_pct, visible_triangles, overdraw); "renderer" is "none" and the
rendering times are 0."""
import ctypes
from typing import Any, Dict, Optional

from . import _structs as S
from ._library import lib

# ip_cache_stats members that --stats writes as they are, in its order
_CACHE_COUNTERS_1 = ("budget_bytes", "resident_bytes", "resident_peak_bytes", "resident_bricks",
                     "hits", "misses", "evictions", "waits")
_CACHE_COUNTERS_2 = ("bytes_decompressed", "bytes_read", "decode_seconds", "over_budget_pins",
                     "pinned_bytes", "errors", "prefetched", "prefetch_hits", "bytes_read_disk",
                     "wait_seconds", "bricks_touched", "bricks_total")


def cache_stats(cache: Optional[int], summary_bytes: int) -> Dict[str, Any]:
    """The "cache" object of --stats for the cache handle `cache`."""
    s = S.CacheStats()
    lib.ip_cache_get_stats(cache, ctypes.byref(s))
    out = {k: getattr(s, k) for k in _CACHE_COUNTERS_1}
    lookups = s.hits + s.misses
    out["hit_rate"] = s.hits / lookups if lookups else 0.0
    out.update({k: getattr(s, k) for k in _CACHE_COUNTERS_2})
    out["levels"] = [{"level": k, "bricks_touched": s.level[k].bricks_touched,
                      "bricks_total": s.level[k].bricks_total, "misses": s.level[k].misses}
                     for k in range(s.levels)]
    out["summary_bytes"] = summary_bytes
    out["peak_rss_bytes"] = lib.ip_peak_rss_bytes()
    return out


def run_stats(run: Any, counts: Any, cache: Optional[int]) -> Dict[str, Any]:
    """The whole dict for `run` (a volume._Run) with totals `counts` (ip_engine_counts)."""
    c = run.physical  # the camera in the file's physical space, as isorender reports it
    mode = "full-lod" if run.full == "lod" else "full" if run.full else "progressive"
    out = {"cache": cache_stats(cache, run.summary_bytes), "file": run.path, "iso": run.iso}
    if run.rescale:  # as isorender's: the stored value and the rescale beside the value
        out["iso_stored"] = run.iso_stored
        out["rescale"] = run.rescale._asdict()
    out.update({"mode": mode, "width": c.width, "height": c.height,
                "renderer": "none",
                "camera": {"eye": list(c.eye), "target": list(c.target), "up": list(c.up),
                           "fov": c.fov_y},
                "lod": bool(run.options.lod), "pixel_error": run.options.pixel_error,
                "warm": False, "threads": lib.ip_thread_count(run.options.threads),
                "cutoff_degrees": run.options.cutoff_degrees,
                "foldback_degrees": run.options.foldback_degrees,
                "clip": [list(p.normal) + [p.offset]
                         for p in run.options.clip[:run.options.clip_count]],
                "rays": counts.rays, "rays_total": c.width * c.height, "done": run.done(),
                "seeds": counts.seeds, "cells": counts.cells, "triangles": counts.triangles,
                "time": {"intersection_s": counts.intersection_seconds,
                         "propagation_s": counts.propagation_seconds,
                         "extraction_s": counts.extraction_seconds,
                         "rendering_s": counts.rendering_seconds,
                         "extraction_wall_s": run.wall_seconds, "progress_render_s": 0.0}})
    if not run.full:
        out.update({"occlusion": bool(run.options.occlusion), "deferred_cells": counts.deferred,
                    "retired_rays": counts.retired, "ray_nodes": counts.nodes,
                    "prefetch": bool(run.options.prefetch),
                    "prefetch_mode": S.PREFETCH_NAMES[run.options.prefetch],
                    "cull": bool(run.options.occlusion and run.options.cull),
                    "culled_triangles": counts.culled})
    out["warnings"] = list(run.warnings)
    return out


def counts_dict(counts: Any) -> Dict[str, int]:
    """One step's ip_engine_counts as a dict."""
    return {"rays": counts.rays, "seeds": counts.seeds, "cells": counts.cells,
            "triangles": counts.triangles, "deferred": counts.deferred,
            "retired": counts.retired, "nodes": counts.nodes, "culled": counts.culled}
