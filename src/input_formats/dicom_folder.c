/* SPDX-License-Identifier: BSD-3-Clause */
/* DICOM input: a folder of DICOM files, its subfolders included, read file by file into the
 * slices of its series (dicom_folder.h). Which files count (not hidden ones; DICOM objects
 * that are not images skipped by their SOP class), each file's header checked on its own,
 * the files grouped by Series Instance UID, one series picked, its slices checked alike. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "array.h"
#include "dicom_check.h"
#include "dicom_folder.h"
#include "internal.h"

/* Subfolders deeper than this are not entered (a loop of bind mounts, say). */
#define MAX_DEPTH 16

void ip__dicom_folder_free(dicom_folder *f)
{
    for (uint64_t i = 0; i < f->count; i++)
        free(f->slices[i].name);
    free(f->slices);
    free(f->series);
    memset(f, 0, sizeof *f);
}

/* folder/name into out; a name that does not fit was refused when listed. */
static void file_path(const char *folder, const char *name, char out[IP_PATH_MAX])
{
    snprintf(out, IP_PATH_MAX, "%s/%s", folder, name);
}

/* ---- which files ---- */

static int by_name(const void *a, const void *b)
{
    return strcmp(((const dicom_slice *)a)->name, ((const dicom_slice *)b)->name);
}

static ip_status add_name(dicom_folder *f, const char *name, ip_error *err)
{
    if (ip__array_reserve(&f->slices, &f->capacity, f->count + 1, sizeof *f->slices, 64) != IP_OK)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory listing the folder", f->path);
    dicom_slice *slice = &f->slices[f->count];
    memset(slice, 0, sizeof *slice);
    if (!(slice->name = strdup(name)))
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory listing the folder", f->path);
    f->count++;
    return IP_OK;
}

/* The regular, visible files of the folder `relative` (within f->path; "" the folder itself)
 * and of its subfolders, in any order. Links to files count; links to folders are not
 * followed. */
static ip_status list_folder(dicom_folder *f, const char *relative, int depth, ip_error *err)
{
    char here[IP_PATH_MAX];
    snprintf(here, sizeof here, "%s%s%s", f->path, relative[0] ? "/" : "", relative);
    DIR *dir = opendir(here);
    if (!dir)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open the folder", here);
    ip_status st = IP_OK;
    struct dirent *entry;
    while (st == IP_OK && (entry = readdir(dir)) != NULL) {
        char name[IP_PATH_MAX], full[IP_PATH_MAX];
        struct stat info;
        if (entry->d_name[0] == '.')
            continue;
        if (snprintf(name, sizeof name, "%s%s%s", relative, relative[0] ? "/" : "",
                     entry->d_name) >= (int)sizeof name ||
            snprintf(full, sizeof full, "%s/%s", f->path, name) >= (int)sizeof full) {
            st = ip__fail(err, IP_ERR_INPUT, "%s/%s: path too long", here, entry->d_name);
            break;
        }
        if (lstat(full, &info) != 0)
            continue; /* gone since it was listed */
        if (S_ISDIR(info.st_mode) && depth < MAX_DEPTH)
            st = list_folder(f, name, depth + 1, err);
        else if (S_ISDIR(info.st_mode))
            st = ip__fail(err, IP_ERR_INPUT, "%s: folders nested more than %d deep", full,
                          MAX_DEPTH);
        else if (stat(full, &info) == 0 && S_ISREG(info.st_mode))
            st = add_name(f, name, err);
    }
    closedir(dir);
    return st;
}

/* A file of a series folder must be DICOM Part 10: "DICM" after the 128-byte preamble. */
static ip_status check_magic(const char *path, ip_error *err)
{
    unsigned char head[132];
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return ip__fail_errno(err, IP_ERR_IO, errno, "%s: cannot open", path);
    ssize_t got = pread(fd, head, sizeof head, 0);
    close(fd);
    if (got != (ssize_t)sizeof head || memcmp(head + 128, "DICM", 4) != 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: not a DICOM file (no \"DICM\" at byte 128), in a folder of a DICOM "
                        "series",
                        path);
    return IP_OK;
}

/* The SOP classes of objects that are not images (PS3.4 B.5): a UID, or a prefix ending in
 * '.' that names a family. */
static const char *const non_image_classes[] = {
    "1.2.840.10008.1.3.10",          /* Media Storage Directory (a DICOMDIR, whatever its name) */
    "1.2.840.10008.5.1.4.1.1.88.",   /* structured reports, key object selection */
    "1.2.840.10008.5.1.4.1.1.11.",   /* presentation states */
    "1.2.840.10008.5.1.4.1.1.9.",    /* waveforms */
    "1.2.840.10008.5.1.4.1.1.104.",  /* encapsulated documents (PDF, CDA, STL, ...) */
    "1.2.840.10008.5.1.4.1.1.66",    /* raw data */
    "1.2.840.10008.5.1.4.1.1.66.1",  /* spatial registration */
    "1.2.840.10008.5.1.4.1.1.66.2",  /* spatial fiducials */
    "1.2.840.10008.5.1.4.1.1.66.3",  /* deformable spatial registration */
    "1.2.840.10008.5.1.4.1.1.66.5",  /* surface segmentation */
    "1.2.840.10008.5.1.4.1.1.67",    /* real world value mapping */
    "1.2.840.10008.5.1.4.1.1.481.3", /* RT structure set */
    "1.2.840.10008.5.1.4.1.1.481.4", /* RT beams treatment record */
    "1.2.840.10008.5.1.4.1.1.481.5", /* RT plan */
    "1.2.840.10008.5.1.4.1.1.481.6", /* RT brachy treatment record */
    "1.2.840.10008.5.1.4.1.1.481.7", /* RT treatment summary record */
    "1.2.840.10008.5.1.4.1.1.481.8", /* RT ion plan */
    "1.2.840.10008.5.1.4.1.1.481.9", /* RT ion beams treatment record */
    "1.2.840.10008.5.1.4.38.1",      /* hanging protocol */
    "1.2.840.10008.5.1.4.39.1",      /* color palette */
};

static int is_non_image(const char *sop_class)
{
    for (size_t i = 0; i < sizeof non_image_classes / sizeof non_image_classes[0]; i++) {
        const char *c = non_image_classes[i];
        size_t n = strlen(c);
        if (c[n - 1] == '.' ? strncmp(sop_class, c, n) == 0 : strcmp(sop_class, c) == 0)
            return 1;
    }
    return 0;
}

/* ---- series ---- */

/* The index of the series of `h` in f, added when new. */
static ip_status series_of(dicom_folder *f, const ip_dicom_header *h, uint32_t *out, ip_error *err)
{
    const char *uid = h->value[IP_DICOM_SERIES_UID];
    /* consecutive files mostly share a series: look from the last one back */
    for (uint32_t i = f->series_count; i-- > 0;)
        if (strcmp(f->series[i].uid, uid) == 0) {
            *out = i;
            return IP_OK;
        }
    uint64_t capacity = f->series_capacity;
    if (ip__array_reserve(&f->series, &capacity, (uint64_t)f->series_count + 1, sizeof *f->series,
                          4) != IP_OK ||
        f->series_count == UINT32_MAX)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory grouping the series", f->path);
    f->series_capacity = (uint32_t)(capacity < UINT32_MAX ? capacity : UINT32_MAX);
    dicom_group *g = &f->series[f->series_count];
    memset(g, 0, sizeof *g);
    snprintf(g->uid, sizeof g->uid, "%s", uid);
    snprintf(g->description, sizeof g->description, "%s", h->value[IP_DICOM_SERIES_DESCRIPTION]);
    snprintf(g->modality, sizeof g->modality, "%s", h->value[IP_DICOM_MODALITY]);
    *out = f->series_count++;
    return IP_OK;
}

/* Reads a file of the listing: 1 in *skipped when it is not an image (a DICOMDIR by name or a
 * SOP class of no image), else its series and header into the slice. A file whose series
 * cannot be told fails; one whose fields do not do fails its series (the first by name). */
static ip_status read_file(dicom_folder *f, dicom_slice *slice, ip_dicom_header *h, int *skipped,
                           ip_error *err)
{
    char path[IP_PATH_MAX], why[160], sop_class[65];
    const char *base = strrchr(slice->name, '/');
    ip_status st;
    file_path(f->path, slice->name, path);
    *skipped = strcmp(base ? base + 1 : slice->name, "DICOMDIR") == 0;
    if (*skipped || (st = check_magic(path, err)) != IP_OK)
        return *skipped ? IP_OK : st;
    /* the structure first: the DICOM library stops the process on some malformed files */
    int checked = ip__dicom_check_object(path, sop_class, why, sizeof why);
    if ((*skipped = is_non_image(sop_class)) != 0)
        return IP_OK;
    if (checked != 0 || ip__dicom_read_header(path, h, why, sizeof why) != 0)
        return ip__fail(err, IP_ERR_INPUT, "%s: %s", path, why);
    if (!h->syntax_known) /* the library read no further than the meta header: the fields */
        return ip__dicom_read_slice(path, h, slice, err); /* refuse the syntax, naming it */
    if ((st = series_of(f, h, &slice->series, err)) != IP_OK)
        return st;
    dicom_group *g = &f->series[slice->series];
    g->files++;
    if (g->failed)
        return IP_OK; /* the series is not read: its first failure stands */
    if (ip__dicom_read_slice(path, h, slice, &g->error) != IP_OK)
        g->failed = 1;
    return IP_OK;
}

ip_status ip__dicom_folder_scan(dicom_folder *f, const char *path, ip_error *err)
{
    memset(f, 0, sizeof *f);
    f->path = path;
    if (strlen(path) > IP_PATH_MAX - 2)
        return ip__fail(err, IP_ERR_ARGUMENT, "%s: folder path too long", path);
    ip_status st = list_folder(f, "", 0, err);
    if (st != IP_OK)
        return st;
    qsort(f->slices, (size_t)f->count, sizeof *f->slices, by_name);
    ip_dicom_header *h = malloc(sizeof *h);
    if (!h)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory reading the headers", path);
    uint64_t kept = 0, i = 0;
    for (; i < f->count && st == IP_OK; i++) {
        int skipped = 0;
        dicom_slice slice = f->slices[i];
        st = read_file(f, &slice, h, &skipped, err);
        if (st == IP_OK && skipped) {
            f->skipped++;
            free(slice.name);
        } else {
            f->slices[kept++] = slice;
        }
    }
    for (; i < f->count; i++) /* after a failure: the names left, to be freed */
        f->slices[kept++] = f->slices[i];
    f->count = kept;
    free(h);
    return st;
}

/* ---- picking one ---- */

/* "UID "description" MODALITY N slices" of series i, for the lists of messages. */
static void series_label(const dicom_folder *f, uint32_t i, char *out, size_t size)
{
    const dicom_group *g = &f->series[i];
    char uid[IP_DICOM_VALUE_MAX], text[IP_DICOM_VALUE_MAX];
    snprintf(out, size, "%.64s%s%.64s%s%s%.16s %llu slice%s",
             g->uid[0] ? ip__dicom_shown(g->uid, uid) : "(no UID)", g->description[0] ? " \"" : "",
             ip__dicom_shown(g->description, text), g->description[0] ? "\"" : "",
             g->modality[0] ? " " : "", g->modality, (unsigned long long)g->files,
             g->files == 1 ? "" : "s");
}

/* The series of f whose UID starts with `prefix` (all with NULL), each labelled, into out
 * ("A, B, C" as far as it fits, then "and N more"). Returns how many match. */
static uint32_t list_matches(const dicom_folder *f, const char *prefix, char *out, size_t size)
{
    uint32_t matches = 0, shown = 0;
    size_t used = 0;
    out[0] = '\0';
    for (uint32_t i = 0; i < f->series_count; i++) {
        char label[256];
        if (prefix && strncmp(f->series[i].uid, prefix, strlen(prefix)) != 0)
            continue;
        matches++;
        series_label(f, i, label, sizeof label);
        if (used + strlen(label) + 40 < size) {
            used += (size_t)snprintf(out + used, size - used, "%s%s", shown ? "; " : "", label);
            shown++;
        }
    }
    if (shown < matches)
        snprintf(out + used, size - used, "; and %u more", matches - shown);
    return matches;
}

ip_status ip__dicom_folder_pick(const dicom_folder *f, const char *wanted, uint32_t *out,
                                ip_error *err)
{
    char list[640], text[IP_DICOM_VALUE_MAX];
    if (f->series_count == 0)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the folder holds no DICOM images (%llu DICOM object%s that %s not "
                        "images skipped)",
                        f->path, (unsigned long long)f->skipped, f->skipped == 1 ? "" : "s",
                        f->skipped == 1 ? "is" : "are");
    for (uint32_t i = 0; wanted && i < f->series_count; i++)
        if (strcmp(f->series[i].uid, wanted) == 0) {
            *out = i;
            return IP_OK;
        }
    uint32_t matches = list_matches(f, wanted, list, sizeof list);
    if (matches == 1) {
        for (uint32_t i = 0; i < f->series_count; i++)
            if (!wanted || strncmp(f->series[i].uid, wanted, strlen(wanted)) == 0)
                *out = i;
        return IP_OK;
    }
    if (!wanted)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: the folder holds %u series: pick one by its UID (isobrick --series "
                        "UID): %s",
                        f->path, f->series_count, list);
    if (matches > 1)
        return ip__fail(err, IP_ERR_INPUT,
                        "%s: %u series UIDs start with %.64s: give more of it: %s", f->path,
                        matches, ip__dicom_shown(wanted, text), list);
    list_matches(f, NULL, list, sizeof list);
    return ip__fail(err, IP_ERR_INPUT,
                    "%s: no series UID is or starts with %.64s; the folder holds %s", f->path,
                    ip__dicom_shown(wanted, text), list);
}

/* ---- one series ---- */

ip_status ip__dicom_series_of(const dicom_folder *f, uint32_t index, dicom_series *out,
                              ip_error *err)
{
    const dicom_group *g = &f->series[index];
    memset(out, 0, sizeof *out);
    out->folder = f->path;
    if (g->failed) {
        if (err)
            *err = g->error;
        return g->error.code;
    }
    out->slices = malloc((size_t)g->files * sizeof *out->slices);
    if (!out->slices)
        return ip__fail(err, IP_ERR_NOMEM, "%s: out of memory gathering the series", f->path);
    for (uint64_t i = 0; i < f->count; i++)
        if (f->slices[i].series == index)
            out->slices[out->count++] = f->slices[i];
    return ip__dicom_check_alike(out, err);
}
