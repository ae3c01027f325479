/* SPDX-License-Identifier: BSD-3-Clause */
/* isorender: extract an isosurface progressively (or fully) and render it to PNG, headless. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "isorender.h"

/* The view and the clipping planes, given in the file's physical space, in world units. */
static int setup_camera(run *r, ip_error *err)
{
    tool_space_of(r->store, &r->space);
    memcpy(r->lo, r->space.lo, sizeof r->lo);
    memcpy(r->hi, r->space.hi, sizeof r->hi);
    tool_space_clip(&r->space, &r->o.common);
    if (tool_space_camera(&r->space, r->o.common.camera, r->o.common.view, r->o.common.width,
                          r->o.common.height, &r->camera, err) != 0)
        return -1;
    r->view_camera = r->camera;
    tool_apply_orbit(&r->o.orbit, &r->space, &r->camera);
    return 0;
}

/* Frees the decoded bricks once extraction is over: the image needs only the mesh, and
 * rendering a large one needs memory of its own. The statistics are taken before. */
static void drop_bricks(run *r)
{
    ip_cache_trim(r->cache, 0);
#ifdef __GLIBC__
    malloc_trim(0); /* give the freed bricks back to the system now */
#endif
}

/* Records the output just written at `path` into the run's set; a signal caught since the
 * last output stops the run there (the set is then removed). Returns 0 or 1. */
static int wrote(run *r, const char *path)
{
    if (tool_outputs_add(&r->outputs, path) != 0) {
        fprintf(stderr, "isorender: %s: out of memory\n", path);
        return 1;
    }
    return tool_signal_caught() ? 1 : 0;
}

/* Renders, then writes every output, as a set (tool_outputs.h): a failure or a signal before
 * the last one is written leaves none of them. */
static int finish(run *r, ip_error *err)
{
    ip_cache_stats st;
    ip_cache_get_stats(r->cache, &st);
    drop_bricks(r);
    size_t n = (size_t)r->camera.width * r->camera.height;
    uint8_t *rgba = malloc(n * 4);
    if (!rgba) {
        fprintf(stderr, "isorender: out of memory for a %ux%u image\n", r->camera.width,
                r->camera.height);
        return 1;
    }
    int rc = render_image(r, rgba, NULL, err);
    uint8_t *strip = NULL;
    uint32_t strip_width = 0, strip_height = 0;
    if (rc == 0 && r->o.strip && strip_compose(r, &strip, &strip_width, &strip_height, err) != 0)
        rc = -1;
    for (size_t i = 0; i <= r->other_count; i++)
        if (rc == 0 && ((r->o.progress && !r->o.full) || r->o.common.stats) &&
            final_pixels(surface_run(r, i), err) != 0)
            rc = -1;
    if (rc != 0 || tool_signal_caught()) {
        free(rgba);
        free(strip);
        return rc != 0 ? tool_fail("isorender", err) : 1;
    }
    if (ip_png_write(r->o.out, rgba, r->camera.width, r->camera.height, r->o.common.force, err) !=
        IP_OK)
        rc = -1;
    free(rgba);
    if (rc == 0 && wrote(r, r->o.out) != 0)
        rc = 1;
    if (rc == 0 && strip &&
        ip_png_write(r->o.strip, strip, strip_width, strip_height, r->o.common.force, err) != IP_OK)
        rc = -1;
    if (rc == 0 && strip && wrote(r, r->o.strip) != 0)
        rc = 1;
    free(strip);
    if (rc != 0)
        return rc < 0 ? tool_fail("isorender", err) : 1;
    for (size_t i = 0; i <= r->other_count; i++) {
        run *s = surface_run(r, i);
        if (write_mesh(s, err) != 0 || (s->o.mesh && wrote(r, s->o.mesh) != 0))
            return 1;
    }
    if (r->o.progress && !r->o.full &&
        (tool_write_text_file("isorender", r->o.progress, r->o.common.force, progress_csv, r) !=
             0 ||
         wrote(r, r->o.progress) != 0))
        return 1;
    uint64_t summary = ip_store_summary_memory(r->store);
    /* with --stats - or --progress -, stdout holds that output alone: the summary goes to
     * stderr */
    FILE *report =
        tool_is_stdout(r->o.common.stats) || tool_is_stdout(r->o.progress) ? stderr : stdout;
    if (!r->o.common.quiet) {
        print_summary(report, r);
        if (r->o.strip)
            strip_print(report, r);
        tool_print_cache_table(report, &st, summary);
    }
    if (r->o.common.stats &&
        (tool_write_stats_file("isorender", r->o.common.stats, r->o.common.force, &st, summary,
                               json_counts, r) != 0 ||
         wrote(r, r->o.common.stats) != 0))
        return 1;
    tool_outputs_complete(&r->outputs);
    return 0;
}

int main(int argc, char **argv)
{
    run r;
    memset(&r, 0, sizeof r);
    int rc = parse_args(argc, argv, &r.o);
    const char *mesh_option = r.o.mesh; /* as given: setup_surfaces() may name it per surface */
    if (!rc)
        rc = setup_surfaces(&r);
    if (rc) {
        free_surfaces(&r);
        return rc;
    }
    const char *inputs[] = {r.o.file};
    const char *outputs[5 + TOOL_MAX_ISOS - 1] = {r.o.turntable ? r.o.mp4 : r.o.out, r.o.mesh,
                                                  r.o.common.stats, r.o.full ? NULL : r.o.progress,
                                                  r.o.strip};
    for (size_t i = 0; i < r.other_count; i++)
        outputs[5 + i] = r.others[i].o.mesh;
    if (tool_check_paths("isorender", inputs, 1, outputs, 5 + r.other_count, r.o.common.force) !=
        0) {
        free_surfaces(&r);
        return 1;
    }
    if (r.o.mesh && !ip_mesh_format_of(r.o.mesh)) { /* before any work, after the paths' checks */
        free_surfaces(&r);
        return tool_usage_error(
            "isorender", "--mesh %s: the name must end in .ply, .stl, .obj or .glb", mesh_option);
    }
    tool_signals_catch();
    ip_error err;
    ip_error_clear(&err);
    if (ip_store_open(r.o.file, &r.store, &err) != IP_OK) {
        rc = tool_fail("isorender", &err);
        free_surfaces(&r);
        tool_signals_reraise();
        return rc;
    }
    rc = 1;
    if (ip_cache_create(r.store, r.o.common.cache_bytes, &r.cache, &err) != IP_OK ||
        setup_camera(&r, &err) != 0) {
        rc = tool_fail("isorender", &err);
    } else {
        /* the errors above come first: a bad command line is one line, not a warning too */
        for (size_t i = 0; i <= r.other_count; i++) {
            run *s = surface_run(&r, i);
            tool_settle_iso(&s->o.common, ip_store_layout(r.store));
            tool_warn_iso_range("isorender", r.store, &s->o.common, s->warning, sizeof s->warning);
        }
        if (r.o.turntable)
            rc = turntable_run(&r, &err);
        else if (extract_surfaces(&r, &err) == 0)
            rc = finish(&r, &err);
        else if (!(err.code == IP_ERR_CANCELLED && tool_signal_caught()))
            rc = tool_fail("isorender", &err); /* a cancel by a signal is reported below */
    }
    tool_signals_cancel_engine(NULL);
    free_surfaces(&r);
    ip_engine_destroy(r.engine);
    ip_mesh_free(&r.full_mesh);
    free(r.checkpoints);
    ip_cache_destroy(r.cache);
    ip_store_close(r.store);
    return tool_outputs_end(&r.outputs, "isorender", r.o.file, rc);
}
