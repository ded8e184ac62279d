/*
 * header_check.c -- compiled by run_tests.sh as C99, C11 (-pedantic) and as C++11 and C++17
 * (-x c++), each with -Wall -Wextra -Werror: the header must compile cleanly in every one of
 * them. It touches every type and a few functions, links and runs: exit 0 when the header and the
 * library agree on the version.
 */
#include "tissuesim.h"

#include <stdio.h>

int main(void) {
    ts_settings settings;
    ts_material material;
    ts_body_options body_options;
    ts_tool_options tool_options;
    ts_pose pose = {{0, 0, 0}, {1, 0, 0, 0}};
    ts_wrench wrench;
    ts_step_report report;
    ts_world *world = NULL;
    ts_status status = TS_STATUS_OK;
    ts_contact_mode mode = TS_CONTACT_MODE_EXACT_SHAPE;
    size_t sizes = sizeof settings + sizeof material + sizeof body_options + sizeof tool_options +
                   sizeof pose + sizeof wrench + sizeof report;

    ts_world_free(world);
    if (ts_settings_default(&settings) != status || (int)settings.contact_mode != (int)mode) {
        fprintf(stderr, "header_check: unexpected default settings\n");
        return 1;
    }
    printf("header %s, library %s, %u bytes of plain structs\n", TISSUESIM_VERSION_STRING,
           ts_version_string(), (unsigned)sizes);
    return ts_version() == TISSUESIM_VERSION ? 0 : 1;
}
