/*
 * surgery.c -- grasping and cutting from C on the default organ, hanging from its top 15 %:
 *
 * 1. a 5 mm grasper touches the organ's front face, grasps (ts_tool_grasp), retracts 2 cm at
 *    2 cm/s and holds; the tissue's pull on it is printed; then it lets go (ts_tool_release);
 * 2. a blade (a thin capsule made a blade with ts_tool_make_blade) sweeps horizontally through
 *    the organ 3 cm above its lowest point; the part below the cut falls away.
 *
 * Exits 1 if the grasp holds nothing, pulls less than 0.05 N, or the cut piece does not fall.
 * TS_STEPS=N scales the run down (valgrind): N steps per phase instead of the defaults.
 *
 * Build: cc -Iinclude examples_c/surgery.c -Ltarget/release -ltissuesim -lm -o surgery
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "tissuesim.h"

#define PI 3.14159265358979323846

static int fail(const char *call, ts_status st) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "surgery: %s failed: %s\n  %s\n", call, ts_status_string((int)st), msg);
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

/* Mean y (m) of the particles whose y at the cut was below `cut_y`. */
static double mean_y_below(const double *x, const double *before, size_t n, double cut_y) {
    double sum = 0;
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (before[3 * i + 1] < cut_y) {
            sum += x[3 * i + 1];
            k++;
        }
    return k ? sum / (double)k : 0;
}

int main(void) {
    int rc = 0;
    ts_world *world = NULL;
    double *x = NULL, *before = NULL;
    long scale = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 0;

    ts_settings settings;
    TRY(ts_settings_default(&settings));
    TRY(ts_world_new(&settings, &world));
    ts_material material;
    TRY(ts_material_default(&material));
    uint32_t organ;
    TRY(ts_world_add_default_organ(world, &material, NULL, &organ));
    size_t n;
    TRY(ts_body_particle_count(world, organ, &n));
    x = malloc(3 * n * sizeof *x);
    before = malloc(3 * n * sizeof *before);
    if (!x || !before) {
        rc = 1;
        goto done;
    }
    TRY(ts_body_positions(world, organ, x, 3 * n));
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            lo[k] = fmin(lo[k], x[3 * i + k]);
            hi[k] = fmax(hi[k], x[3 * i + k]);
        }
    double fix_min[3] = {lo[0] - 1, hi[1] - 0.15 * (hi[1] - lo[1]), lo[2] - 1};
    double fix_max[3] = {hi[0] + 1, hi[1] + 1, hi[2] + 1};
    TRY(ts_body_fix_box(world, organ, fix_min, fix_max, NULL));
    if (scale == 0) TRY(ts_world_settle(world)); /* hanging at rest (skipped under valgrind) */
    TRY(ts_body_positions(world, organ, x, 3 * n));

    /* 1. Grasp: the front face (largest z) near (x, y) = (0.035, 0). */
    double face = lo[2];
    for (size_t i = 0; i < n; i++)
        if (fabs(x[3 * i] - 0.035) < 0.01 && fabs(x[3 * i + 1]) < 0.01) face = fmax(face, x[3 * i + 2]);
    double r = 0;
    TRY(ts_body_particle_radius(world, organ, &r));
    ts_pose grasper = {{0.035, 0.0, face + r + 0.004}, {1, 0, 0, 0}};
    uint32_t jaws;
    TRY(ts_world_add_tool_sphere(world, 0.005, &grasper, NULL, &jaws));
    uint32_t held = 0;
    TRY(ts_tool_grasp(world, jaws, NULL, &held));
    long pull_steps = scale ? scale : 1000; /* 2 cm at 2 cm/s */
    ts_wrench w = {{0, 0, 0}, {0, 0, 0}, 0, 0};
    for (long s = 0; s < pull_steps; s++) {
        grasper.position[2] += 0.02 / (double)pull_steps;
        TRY(ts_tool_set_pose(world, jaws, &grasper));
        TRY(ts_world_step(world, NULL));
    }
    TRY(ts_tool_wrench(world, jaws, &w));
    printf("grasp: %u particles held; after a 20 mm retraction the tissue pulls with %.3f N "
           "(towards the organ: %s)\n",
           held, -w.force[2], w.force[2] < 0 ? "yes" : "no");
    if (held == 0 || -w.force[2] < (scale ? 0.0 : 0.05)) rc = 1;
    TRY(ts_tool_release(world, jaws));
    TRY(ts_world_remove_tool(world, jaws));

    /* 2. Cut: a blade along x swept along -z through the organ, 3 cm above its lowest point. */
    TRY(ts_body_positions(world, organ, before, 3 * n));
    double low = before[1];
    for (size_t i = 0; i < n; i++) low = fmin(low, before[3 * i + 1]);
    double cut_y = low + 0.03;
    double half = 0.5 * (hi[0] - lo[0]) + 0.05;
    /* A capsule's edge is its local y axis: a quarter turn about z lays it along x. */
    ts_pose blade_pose = {{0.5 * (lo[0] + hi[0]), cut_y, hi[2] + 0.03},
                          {cos(PI / 4), 0, 0, sin(PI / 4)}};
    uint32_t blade;
    TRY(ts_world_add_tool_capsule(world, half, 0.0005, &blade_pose, NULL, &blade));
    TRY(ts_tool_make_blade(world, blade));
    long cut_steps = scale ? scale : 40; /* a fast stroke (40 ms): a slow one lets the cut part sag below the blade before it is severed */
    double sweep = (hi[2] - lo[2]) + 0.06;
    for (long s = 0; s < cut_steps; s++) {
        blade_pose.position[2] -= sweep / (double)cut_steps;
        TRY(ts_tool_set_pose(world, blade, &blade_pose));
        TRY(ts_world_step(world, NULL));
    }
    uint64_t pairs = 0, tets = 0;
    TRY(ts_body_cut_counts(world, organ, &pairs, &tets));
    double y0 = mean_y_below(before, before, n, cut_y);
    for (long s = 0; s < (scale ? scale : 300); s++) TRY(ts_world_step(world, NULL));
    TRY(ts_body_positions(world, organ, x, 3 * n));
    double drop = y0 - mean_y_below(x, before, n, cut_y);
    /* Mass scaling (the default) slows a free fall: gravity acts on the physical mass m, the
     * inertia is m + added. */
    double m = 0, added = 0;
    TRY(ts_body_mass(world, organ, &m));
    TRY(ts_body_added_mass(world, organ, &added));
    double t = 0.3, damped_fall = 0.5 * 9.81 * (m / (m + added)) * t * t;
    printf("cut: %llu neighbour pairs and %llu tetrahedra cut; the part below fell %.1f mm in "
           "0.3 s (free fall with the inertia of mass scaling, %.0f%% added: %.1f mm)\n",
           (unsigned long long)pairs, (unsigned long long)tets, 1e3 * drop, 100 * added / m,
           1e3 * damped_fall);
    if (pairs == 0 || (scale == 0 && drop < 0.3 * damped_fall)) rc = 1;

done:
    free(x);
    free(before);
    ts_world_free(world);
    return rc;
}
