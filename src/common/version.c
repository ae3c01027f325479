/* The library's version string, built from the numbers in isoprop/version.h. */
#include "isoprop/version.h"

#define IP_STRINGIFY_(x) #x
#define IP_STRINGIFY(x) IP_STRINGIFY_(x)

const char *ip_version(void)
{
    return IP_STRINGIFY(IP_VERSION_MAJOR) "." IP_STRINGIFY(IP_VERSION_MINOR) "." IP_STRINGIFY(
        IP_VERSION_PATCH);
}
