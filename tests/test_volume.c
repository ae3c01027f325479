/* Sample types, dimension parsing and status messages. */
#include "check.h"
#include "isoprop/volume.h"

int main(void)
{
    ip_type t;
    uint32_t d[3];
    CHECK(ip_type_parse("uint16", &t) == IP_OK && t == IP_UINT16);
    CHECK(ip_type_parse("MET_SHORT", &t) == IP_OK && t == IP_INT16);
    CHECK(ip_type_parse("float", &t) == IP_OK && t == IP_FLOAT32);
    CHECK(ip_type_parse("uint64", &t) == IP_ERR_ARGUMENT);
    CHECK(ip_type_size(IP_UINT8) == 1 && ip_type_size(IP_INT16) == 2 &&
          ip_type_size(IP_FLOAT32) == 4);
    CHECK(ip_dims_parse("512x512x234", d) == IP_OK && d[0] == 512 && d[2] == 234);
    CHECK(ip_dims_parse("512x512", d) == IP_ERR_ARGUMENT);
    CHECK(ip_dims_parse("0x5x5", d) == IP_ERR_ARGUMENT);
    CHECK(ip_dims_parse("5x5x5x", d) == IP_ERR_ARGUMENT);
    CHECK(ip_dims_parse("-1x5x5", d) == IP_ERR_ARGUMENT);
    int16_t s[2] = {-1024, 3071};
    CHECK(ip_sample_get(s, IP_INT16, 0) == -1024.0f && ip_sample_get(s, IP_INT16, 1) == 3071.0f);
    for (int code = 0; code >= -11; code--)
        CHECK(strcmp(ip_status_message(code), "unknown error") != 0);
    return test_summary("test_volume");
}
