/* SPDX-License-Identifier: BSD-3-Clause */
/* Finding the readers of TIFF and DICOM, which live in the input component libisoprop_input
 * (src/input_formats/, include/isoprop/input_formats.h): linked in where the build put them
 * in the same library (IP_INPUT_FORMATS_LINKED: the static library, the component itself),
 * else loaded the first time an input needs them, so that libisoprop.so links neither libtiff
 * nor GDCM and a program that only opens brick files never loads them. */
#include <stdio.h>
#include <string.h>

#include "input_source.h"
#include "internal.h"
#include "isoprop/input_formats.h"

#ifdef IP_INPUT_FORMATS_LINKED

ip_status ip__input_formats_load(const char *path, const ip__input_formats **out, ip_error *err)
{
    *out = ip_input_formats_table(IP__INPUT_FORMATS_ABI);
    if (!*out)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: the linked TIFF and DICOM readers are of "
                        "another build",
                        path);
    return IP_OK;
}

#else

#include <dlfcn.h>

#define COMPONENT "libisoprop_input.so." IP__STRINGIFY(IP_VERSION_MAJOR)

typedef const void *(*table_fn)(uint32_t abi);
typedef const char *(*version_fn)(void);

/* The component beside this library's own file, else wherever the loader finds it; NULL with
 * the loader's message in why. The handle is never unloaded (RTLD_NODELETE): the readers'
 * table stays valid for the life of the process, with no state kept here. */
static void *open_component(char *why, size_t size)
{
    Dl_info self;
    void *handle = NULL;
    if (dladdr((const void *)&ip__input_formats_load, &self) && self.dli_fname) {
        const char *slash = strrchr(self.dli_fname, '/');
        char beside[IP_PATH_MAX];
        if (slash && snprintf(beside, sizeof beside, "%.*s/%s", (int)(slash - self.dli_fname),
                              self.dli_fname, COMPONENT) < (int)sizeof beside)
            handle = dlopen(beside, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    }
    if (!handle)
        handle = dlopen(COMPONENT, RTLD_NOW | RTLD_LOCAL | RTLD_NODELETE);
    if (!handle) {
        const char *message = dlerror();
        snprintf(why, size, "%s", message ? message : "not found");
    }
    return handle;
}

ip_status ip__input_formats_load(const char *path, const ip__input_formats **out, ip_error *err)
{
    char why[512];
    *out = NULL;
    void *handle = open_component(why, sizeof why);
    if (!handle)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: TIFF, DICOM, HDF5 and Zarr need the input component " COMPONENT
                        ", which cannot be loaded (%s)",
                        path, why);
    table_fn table;
    version_fn version;
    *(void **)&table = dlsym(handle, "ip_input_formats_table");
    *(void **)&version = dlsym(handle, "ip_input_formats_version");
    *out = table ? table(IP__INPUT_FORMATS_ABI) : NULL;
    const char *theirs = version ? version() : "unknown";
    dlclose(handle); /* RTLD_NODELETE: stays loaded */
    if (!*out)
        return ip__fail(err, IP_ERR_UNSUPPORTED,
                        "%s: the input component " COMPONENT " is version %s, not %s", path, theirs,
                        IP__VERSION_STRING);
    return IP_OK;
}

#endif
