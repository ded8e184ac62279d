/*
 * hello.c -- the smallest tissuesim program: load an organ, fix its top, let it sag, print
 * its volume.
 *
 *   hello                      use the embedded default organ (about 0.2 m across)
 *   hello MESH [SCALE]         load a tetrahedral mesh (.msh, .node/.ele, .vtk), node
 *                              coordinates times SCALE (default 1) in metres
 *
 * TS_STEPS=N in the environment sets the number of 1 ms steps (default 500).
 *
 * Build: cc -Iinclude examples_c/hello.c -Ltarget/release -ltissuesim -lm -o hello
 * Run:   LD_LIBRARY_PATH=target/release ./hello
 */
#include <stdio.h>
#include <stdlib.h>

#include "tissuesim.h"

/* Print the failing call, its status and the thread's last error message. */
static int fail(const char *call, ts_status st) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "hello: %s failed: %s\n  %s\n", call, ts_status_string((int)st), msg);
    return 1;
}

#define TRY(call)                                                                                  \
    do {                                                                                           \
        ts_status st_ = (call);                                                                    \
        if (st_ != TS_STATUS_OK) {                                                                 \
            rc = fail(#call, st_);                                                                 \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

int main(int argc, char **argv) {
    int rc = 0;
    ts_world *world = NULL;
    double *x = NULL;
    long steps = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 500;

    if (ts_version() != TISSUESIM_VERSION) {
        fprintf(stderr, "hello: header %s but library %s\n", TISSUESIM_VERSION_STRING,
                ts_version_string());
        return 1;
    }
    printf("tissuesim %s\n", ts_version_string());

    ts_settings settings;
    TRY(ts_settings_default(&settings));
    TRY(ts_world_new(&settings, &world));

    ts_material material;
    TRY(ts_material_default(&material));
    uint32_t body;
    if (argc > 1) {
        double scale = argc > 2 ? atof(argv[2]) : 1.0;
        TRY(ts_world_add_body_from_file(world, argv[1], scale, &material, NULL, &body));
        printf("mesh %s (scale %g)\n", argv[1], scale);
    } else {
        TRY(ts_world_add_default_organ(world, &material, NULL, &body));
        printf("default organ\n");
    }

    /* Fix the top 10% of the organ (along y, gravity is -y). */
    size_t n;
    TRY(ts_body_particle_count(world, body, &n));
    x = malloc(3 * n * sizeof *x);
    if (!x) {
        rc = 1;
        goto done;
    }
    TRY(ts_body_positions(world, body, x, 3 * n));
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (x[3 * i + k] < lo[k]) lo[k] = x[3 * i + k];
            if (x[3 * i + k] > hi[k]) hi[k] = x[3 * i + k];
        }
    double box_min[3] = {lo[0] - 1, hi[1] - 0.1 * (hi[1] - lo[1]), lo[2] - 1};
    double box_max[3] = {hi[0] + 1, hi[1] + 1, hi[2] + 1};
    size_t fixed;
    TRY(ts_body_fix_box(world, body, box_min, box_max, &fixed));

    double v0, v;
    TRY(ts_body_rest_volume(world, body, &v0));
    printf("%zu particles, %zu fixed, rest volume %.6e m^3\n", n, fixed, v0);

    ts_step_report report = {0, 0};
    for (long s = 0; s < steps; s++) TRY(ts_world_step(world, &report));

    double t, sag;
    TRY(ts_world_time(world, &t));
    TRY(ts_body_volume(world, body, &v));
    TRY(ts_body_max_displacement(world, body, &sag));
    printf("t = %.3f s (%u substeps/step): volume %.6e m^3 (ratio %.5f), max displacement %.2f mm\n",
           t, report.substeps, v, v / v0, 1e3 * sag);

done:
    free(x);
    ts_world_free(world);
    return rc;
}
