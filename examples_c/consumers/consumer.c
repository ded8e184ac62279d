/*
 * consumer.c -- the program of the install test (examples_c/test_install.sh): built against an
 * installed tissuesim, once through CMake (consumers/cmake: find_package(tissuesim CONFIG
 * REQUIRED) and tissuesim::tissuesim) and once with pkg-config (cc consumer.c $(pkg-config
 * --cflags --libs tissuesim)). It creates a world with the default organ, fixes the organ's top,
 * steps it, prints what it did and returns 1 on any failure status.
 */
#include <stdio.h>

#include "tissuesim.h"

#define STEPS 20

static int failed(const char *call, ts_status status) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "consumer: %s failed: %s: %s\n", call, ts_status_string((int)status), msg);
    return 1;
}

#define CHECK(call)                                                                                \
    do {                                                                                           \
        ts_status status_ = (call);                                                                \
        if (status_ != TS_STATUS_OK) {                                                             \
            rc = failed(#call, status_);                                                           \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

int main(void) {
    int rc = 0;
    ts_world *world = NULL;
    ts_settings settings;
    ts_material material;
    uint32_t organ;
    size_t particles, fixed;
    double lo[3] = {-1, 0.05, -1}, hi[3] = {1, 1, 1};
    double t, volume, rest_volume, sag;
    int s;

    if (ts_version() != TISSUESIM_VERSION) {
        fprintf(stderr, "consumer: header %s but library %s\n", TISSUESIM_VERSION_STRING,
                ts_version_string());
        return 1;
    }
    CHECK(ts_settings_default(&settings));
    CHECK(ts_world_new(&settings, &world));
    CHECK(ts_material_default(&material));
    CHECK(ts_world_add_default_organ(world, &material, NULL, &organ));
    CHECK(ts_body_particle_count(world, organ, &particles));
    CHECK(ts_body_fix_box(world, organ, lo, hi, &fixed));
    for (s = 0; s < STEPS; s++) CHECK(ts_world_step(world, NULL));
    CHECK(ts_world_time(world, &t));
    CHECK(ts_body_volume(world, organ, &volume));
    CHECK(ts_body_rest_volume(world, organ, &rest_volume));
    CHECK(ts_body_max_displacement(world, organ, &sag));
    if (fixed == 0 || !(sag > 0)) {
        fprintf(stderr, "consumer: %zu particles fixed, max displacement %g m\n", fixed, sag);
        rc = 1;
        goto done;
    }
    printf("tissuesim %s: %zu particles (%zu fixed), t = %.3f s, volume ratio %.5f, "
           "max displacement %.3f mm\n",
           ts_version_string(), particles, fixed, t, volume / rest_volume, 1e3 * sag);
done:
    ts_world_free(world);
    return rc;
}
