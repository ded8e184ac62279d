/*
 * render_surface.c -- a render surface driven by the simulation: SOFA's liver (liver.msh)
 * sagging under gravity, its visual surface (liver-smooth.obj, same frame) bound to it, and a
 * few OBJ frames of the deformed surface written for a renderer.
 *
 *   render_surface [MESH_DIR [OUT_DIR]]
 *
 * MESH_DIR holds liver.msh and liver-smooth.obj (default: $TISSUESIM_MESHES, else
 * data/meshes); frames go to OUT_DIR/liver_surface_K.obj, K = 0..4 (default: the current
 * folder). Both meshes are scaled by 0.03 (about 0.19 m long). TS_STEPS=N sets the number of
 * 1 ms steps (default 400).
 *
 * Build: cc -Iinclude examples_c/render_surface.c -Ltarget/release -ltissuesim -lm -o render_surface
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "tissuesim.h"

static int fail(const char *call, ts_status st) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "render_surface: %s failed: %s\n  %s\n", call, ts_status_string((int)st),
            msg);
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

#define FRAMES 5

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : getenv("TISSUESIM_MESHES");
    if (!dir) dir = "data/meshes";
    const char *out_dir = argc > 2 ? argv[2] : ".";
    long steps = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 400;
    if (steps < 1) steps = 1;
    char msh[1024], obj[1024], frame[1024];
    snprintf(msh, sizeof msh, "%s/liver.msh", dir);
    snprintf(obj, sizeof obj, "%s/liver-smooth.obj", dir);

    int rc = 0;
    ts_world *world = NULL;
    double *x = NULL, *pos = NULL, *nrm = NULL, *pos0 = NULL;

    ts_settings settings;
    TRY(ts_settings_default(&settings));
    TRY(ts_world_new(&settings, &world));
    ts_material material;
    TRY(ts_material_default(&material));
    uint32_t liver, surface;
    TRY(ts_world_add_body_from_file(world, msh, 0.03, &material, NULL, &liver));
    TRY(ts_world_add_render_surface_from_file(world, liver, obj, 0.03, &surface));

    /* Fix the top 15% of the liver (along y; gravity is -y). */
    size_t n;
    TRY(ts_body_particle_count(world, liver, &n));
    x = malloc(3 * n * sizeof *x);
    if (!x) {
        rc = 1;
        goto done;
    }
    TRY(ts_body_positions(world, liver, x, 3 * n));
    double ylo = x[1], yhi = x[1];
    for (size_t i = 0; i < n; i++) {
        if (x[3 * i + 1] < ylo) ylo = x[3 * i + 1];
        if (x[3 * i + 1] > yhi) yhi = x[3 * i + 1];
    }
    double box_min[3] = {-10, yhi - 0.15 * (yhi - ylo), -10}, box_max[3] = {10, 10, 10};
    TRY(ts_body_fix_box(world, liver, box_min, box_max, NULL));

    size_t nv, nt;
    TRY(ts_render_surface_vertex_count(world, surface, &nv));
    TRY(ts_render_surface_triangle_count(world, surface, &nt));
    printf("liver: %zu particles; render surface: %zu vertices, %zu triangles\n", n, nv, nt);
    pos = malloc(3 * nv * sizeof *pos);
    nrm = malloc(3 * nv * sizeof *nrm);
    pos0 = malloc(3 * nv * sizeof *pos0);
    if (!pos || !nrm || !pos0) {
        rc = 1;
        goto done;
    }
    TRY(ts_render_surface_update(world, surface, pos0, nrm, 3 * nv));

    long stepped = 0;
    for (int f = 0; f < FRAMES; f++) {
        for (; stepped < steps * f / (FRAMES - 1); stepped++) TRY(ts_world_step(world, NULL));
        /* Every frame: positions and normals into the renderer's buffers (no allocation). */
        TRY(ts_render_surface_update(world, surface, pos, nrm, 3 * nv));
        double sag = 0, worst_unit = 0;
        for (size_t i = 0; i < nv; i++) {
            double d[3], len = 0;
            for (int k = 0; k < 3; k++) {
                d[k] = pos[3 * i + k] - pos0[3 * i + k];
                len += nrm[3 * i + k] * nrm[3 * i + k];
            }
            double u = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (u > sag) sag = u;
            if (fabs(sqrt(len) - 1) > worst_unit) worst_unit = fabs(sqrt(len) - 1);
        }
        if (worst_unit > 1e-12) {
            fprintf(stderr, "render_surface: a normal is not unit (off by %g)\n", worst_unit);
            rc = 1;
            goto done;
        }
        snprintf(frame, sizeof frame, "%s/liver_surface_%d.obj", out_dir, f);
        TRY(ts_render_surface_write_obj(world, surface, frame));
        double t;
        TRY(ts_world_time(world, &t));
        printf("t = %.3f s: largest vertex displacement %.2f mm -> %s\n", t, 1e3 * sag, frame);
    }

done:
    free(x);
    free(pos);
    free(nrm);
    free(pos0);
    ts_world_free(world);
    return rc;
}
