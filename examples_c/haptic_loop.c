/*
 * haptic_loop.c -- a 1 kHz haptic loop: a spherical probe (radius 1 cm) follows a scripted path
 * pressing the default organ (press 15 mm, slide sideways, release) while the loop reads the
 * contact force every step, as a haptic device driver would.
 *
 *   haptic_loop [FORCE.csv]
 *
 * Prints the per-step latency (set pose + step + read wrench) min / median / p99 / max in
 * microseconds and the number of missed 1 ms deadlines. The force trace goes as CSV
 * (step,time_s,probe_x,probe_y,probe_z,fx_N,fy_N,fz_N,contacts,latency_us) to FORCE.csv, or
 * every 100th row to stdout when no file is given.
 *
 * TS_STEPS=N sets the number of steps (default 2000 = 2 s); TS_THREADS=N the solver threads
 * (default 2: the calling thread and one worker; results are bit-identical for any count);
 * TS_NO_SLEEP=1 runs flat out without waiting for the 1 ms deadlines (used under valgrind).
 *
 * Build: cc -Iinclude examples_c/haptic_loop.c -Ltarget/release -ltissuesim -lm -o haptic_loop
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "tissuesim.h"

#define PERIOD_NS 1000000L /* 1 kHz */
#define PI 3.14159265358979323846

static int fail(const char *call, ts_status st) {
    char msg[512];
    ts_last_error_message(msg, sizeof msg);
    fprintf(stderr, "haptic_loop: %s failed: %s\n  %s\n", call, ts_status_string((int)st), msg);
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

static int64_t now_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static void sleep_until(int64_t t_ns) {
    struct timespec ts = {(time_t)(t_ns / 1000000000LL), (long)(t_ns % 1000000000LL)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) != 0) {
    }
}

static int cmp_i64(const void *a, const void *b) {
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Smooth 0 -> 1 ramp over [0, 1]. */
static double ease(double u) {
    if (u <= 0) return 0;
    if (u >= 1) return 1;
    return 0.5 - 0.5 * cos(PI * u);
}

/* The scripted probe path at time t of a run lasting T (s): descend by `depth` in the first
 * quarter, slide +-2 cm along x in the middle half, come back up in the last quarter. */
static void probe_path(double t, double T, const double start[3], double depth, double out[3]) {
    double down = ease(t / (0.25 * T)) - ease((t - 0.75 * T) / (0.25 * T));
    double slide = (t > 0.25 * T && t < 0.75 * T) ? sin(2 * PI * (t - 0.25 * T) / (0.5 * T)) : 0;
    out[0] = start[0] + 0.02 * slide;
    out[1] = start[1] - depth * down;
    out[2] = start[2];
}

int main(int argc, char **argv) {
    int rc = 0;
    ts_world *world = NULL;
    double *x = NULL;
    int64_t *lat = NULL;
    FILE *csv = NULL;
    long steps = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 2000;
    int no_sleep = getenv("TS_NO_SLEEP") != NULL;
    if (steps < 1) steps = 1;

    ts_settings settings;
    TRY(ts_settings_default(&settings)); /* dt = 1 ms */
    settings.threads = getenv("TS_THREADS") ? (uint32_t)atol(getenv("TS_THREADS")) : 2;
    TRY(ts_world_new(&settings, &world));
    ts_material material;
    TRY(ts_material_default(&material)); /* E = 5 kPa, nu = 0.45, rho = 1060 */
    uint32_t organ;
    TRY(ts_world_add_default_organ(world, &material, NULL, &organ));

    /* Bounding box; fix the bottom 10 % (the organ rests on it). */
    size_t n;
    TRY(ts_body_particle_count(world, organ, &n));
    x = malloc(3 * n * sizeof *x);
    lat = malloc((size_t)steps * sizeof *lat);
    if (!x || !lat) {
        rc = 1;
        goto done;
    }
    TRY(ts_body_positions(world, organ, x, 3 * n));
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            if (x[3 * i + k] < lo[k]) lo[k] = x[3 * i + k];
            if (x[3 * i + k] > hi[k]) hi[k] = x[3 * i + k];
        }
    double fix_min[3] = {lo[0] - 1, lo[1] - 1, lo[2] - 1};
    double fix_max[3] = {hi[0] + 1, lo[1] + 0.1 * (hi[1] - lo[1]), hi[2] + 1};
    TRY(ts_body_fix_box(world, organ, fix_min, fix_max, NULL));

    /* Surface height above the centre of the organ: highest particle within 1.5 cm in x-z. */
    double cx = 0.5 * (lo[0] + hi[0]), cz = 0.5 * (lo[2] + hi[2]), top = lo[1];
    for (size_t i = 0; i < n; i++) {
        double dx = x[3 * i] - cx, dz = x[3 * i + 2] - cz;
        if (dx * dx + dz * dz < 0.015 * 0.015 && x[3 * i + 1] > top) top = x[3 * i + 1];
    }
    const double radius = 0.01, depth = 0.015;
    double start[3] = {cx, top + radius + 0.003, cz};
    ts_pose pose = {{start[0], start[1], start[2]}, {1, 0, 0, 0}};
    uint32_t probe;
    TRY(ts_world_add_tool_sphere(world, radius, &pose, NULL, &probe));

    if (argc > 1) {
        csv = fopen(argv[1], "w");
        if (!csv) {
            perror(argv[1]);
            rc = 1;
            goto done;
        }
    }
    const char *header = "step,time_s,probe_x,probe_y,probe_z,fx_N,fy_N,fz_N,contacts,latency_us\n";
    if (csv)
        fputs(header, csv);
    else
        fputs(header, stdout);

    printf("# %zu particles, probe r = %.0f mm pressing %.0f mm, %ld steps at 1 kHz on %u "
           "thread(s)%s\n",
           n, 1e3 * radius, 1e3 * depth, steps, settings.threads, no_sleep ? " (no sleeping)" : "");

    long missed = 0;
    double max_force = 0;
    const double T = steps * settings.dt;
    int64_t deadline = now_ns() + PERIOD_NS;
    for (long s = 0; s < steps; s++) {
        probe_path((s + 1) * settings.dt, T, start, depth, pose.position);

        int64_t t0 = now_ns();
        TRY(ts_tool_set_pose(world, probe, &pose));
        TRY(ts_world_step(world, NULL));
        ts_wrench w;
        TRY(ts_tool_wrench(world, probe, &w));
        int64_t t1 = now_ns();

        lat[s] = t1 - t0;
        double f = sqrt(w.force[0] * w.force[0] + w.force[1] * w.force[1] + w.force[2] * w.force[2]);
        if (f > max_force) max_force = f;
        FILE *out = csv ? csv : ((s + 1) % 100 == 0 ? stdout : NULL);
        if (out)
            fprintf(out, "%ld,%.4f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%u,%.1f\n", s + 1,
                    (s + 1) * settings.dt, pose.position[0], pose.position[1], pose.position[2],
                    w.force[0], w.force[1], w.force[2], w.contact_count, 1e-3 * (double)lat[s]);

        if (t1 > deadline) {
            missed++;
            deadline = t1 + PERIOD_NS; /* resynchronise after an overrun */
        } else {
            if (!no_sleep) sleep_until(deadline);
            deadline += PERIOD_NS;
        }
    }

    qsort(lat, (size_t)steps, sizeof *lat, cmp_i64);
    size_t p99 = (size_t)ceil(0.99 * (double)steps) - 1;
    printf("latency_us min %.1f median %.1f p99 %.1f max %.1f\n", 1e-3 * (double)lat[0],
           1e-3 * (double)lat[steps / 2], 1e-3 * (double)lat[p99], 1e-3 * (double)lat[steps - 1]);
    printf("missed 1 ms deadlines: %ld of %ld\n", missed, steps);
    printf("peak contact force %.3f N\n", max_force);
    if (csv) printf("force trace written to %s\n", argv[1]);

done:
    if (csv) fclose(csv);
    free(lat);
    free(x);
    ts_world_free(world);
    return rc;
}
