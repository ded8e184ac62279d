/*
 * sofa_liver.c -- SOFA's liver demo (examples/Demos/liver.scn) run with tissuesim, for
 * comparison with SOFA's corotational FEM.
 *
 *   sofa_liver PATH/TO/liver.msh [OUT.csv]
 *
 * Scene as in SOFA: E = 3000, nu = 0.3, density 1, mesh units unscaled, nodes 3, 39 and 64
 * (0-based, file order) fixed, gravity 9.81 along -y, dt = 0.02 (tissuesim substeps as its
 * stability limit requires), 2 s (100 steps). SOFA damps with Rayleigh coefficients 0.1 / 0.1
 * and implicit Euler; here the mass-proportional damping is set to 0.1 1/s and the rest of the
 * damping is tissuesim's default (see docs/C_API.md).
 *
 * Writes CSV "time,marker,dx,dy,dz,volume" (marker = 0-based file node index, displacement from
 * the rest position in mesh units, body volume in mesh units^3) for a few marker nodes at every
 * step to OUT.csv, or to stdout. TS_STEPS=N overrides the number of steps.
 *
 * Build: cc -Iinclude examples_c/sofa_liver.c -Ltarget/release -ltissuesim -lm -o sofa_liver
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "tissuesim.h"

static int fail(const char *call, ts_status st) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "sofa_liver: %s failed: %s\n  %s\n", call, ts_status_string((int)st), msg);
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

#define MAX_MARKERS 8

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: %s PATH/TO/liver.msh [OUT.csv]\n", argv[0]);
        return 2;
    }
    int rc = 0;
    ts_world *world = NULL;
    double *x0 = NULL, *x = NULL;
    uint32_t *src = NULL;
    FILE *out = stdout;
    long steps = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 100;

    ts_settings settings;
    TRY(ts_settings_default(&settings));
    settings.dt = 0.02;
    settings.gravity[0] = 0;
    settings.gravity[1] = -9.81;
    settings.gravity[2] = 0;
    settings.max_substeps = 4096;
    settings.damping_mass = 0.1;
    settings.mass_scaling = 0; /* physical masses: this is a dynamics comparison */
    TRY(ts_world_new(&settings, &world));

    ts_material material = {3000.0, 0.3, 1.0};
    uint32_t liver;
    TRY(ts_world_add_body_from_file(world, argv[1], 1.0, &material, NULL, &liver));

    size_t n;
    TRY(ts_body_particle_count(world, liver, &n));
    x0 = malloc(3 * n * sizeof *x0);
    x = malloc(3 * n * sizeof *x);
    src = malloc(n * sizeof *src);
    if (!x0 || !x || !src) {
        rc = 1;
        goto done;
    }
    TRY(ts_body_rest_positions(world, liver, x0, 3 * n));
    TRY(ts_body_source_indices(world, liver, src, n));

    /* File node index -> particle index (unreferenced file nodes were dropped by the loader). */
    const uint32_t fixed_file[3] = {3, 39, 64};
    uint32_t fixed[3];
    double c[3] = {0, 0, 0};
    for (int f = 0; f < 3; f++) {
        size_t i = 0;
        while (i < n && src[i] != fixed_file[f]) i++;
        if (i == n) {
            fprintf(stderr, "sofa_liver: file node %u is not part of the mesh\n", fixed_file[f]);
            rc = 1;
            goto done;
        }
        fixed[f] = (uint32_t)i;
        for (int k = 0; k < 3; k++) c[k] += x0[3 * i + k] / 3;
    }
    TRY(ts_body_fix_particles(world, liver, fixed, 3));

    /* Markers: file nodes 0, 45, 90, 135, 180 (those present) and the node farthest from the
     * fixed ones. */
    uint32_t marker[MAX_MARKERS];
    int nm = 0;
    for (uint32_t f = 0; f <= 180; f += 45)
        for (size_t i = 0; i < n; i++)
            if (src[i] == f) marker[nm++] = (uint32_t)i;
    size_t far = 0;
    double dmax = -1;
    for (size_t i = 0; i < n; i++) {
        double d = 0;
        for (int k = 0; k < 3; k++) d += (x0[3 * i + k] - c[k]) * (x0[3 * i + k] - c[k]);
        if (d > dmax) dmax = d, far = i;
    }
    marker[nm++] = (uint32_t)far;

    if (argc > 2) {
        out = fopen(argv[2], "w");
        if (!out) {
            perror(argv[2]);
            out = NULL;
            rc = 1;
            goto done;
        }
    }
    fprintf(out, "time,marker,dx,dy,dz,volume\n");
    double v0, v, t = 0;
    TRY(ts_body_rest_volume(world, liver, &v0));
    ts_step_report report = {0, 0};
    unsigned max_substeps = 0;
    for (long s = 0; s <= steps; s++) {
        if (s > 0) {
            TRY(ts_world_step(world, &report));
            if (report.substeps > max_substeps) max_substeps = report.substeps;
        }
        TRY(ts_world_time(world, &t));
        TRY(ts_body_positions(world, liver, x, 3 * n));
        TRY(ts_body_volume(world, liver, &v));
        for (int m = 0; m < nm; m++) {
            size_t i = marker[m];
            fprintf(out, "%.4f,%u,%.6e,%.6e,%.6e,%.6e\n", t, src[i], x[3 * i] - x0[3 * i],
                    x[3 * i + 1] - x0[3 * i + 1], x[3 * i + 2] - x0[3 * i + 2], v);
        }
    }
    double sag;
    TRY(ts_body_max_displacement(world, liver, &sag));
    fprintf(stderr,
            "sofa_liver: %zu nodes, fixed file nodes 3 39 64, t = %.2f s, up to %u substeps/step, "
            "max displacement %.4f, volume ratio %.5f\n",
            n, t, max_substeps, sag, v / v0);

done:
    if (out && out != stdout) fclose(out);
    free(src);
    free(x);
    free(x0);
    ts_world_free(world);
    return rc;
}
