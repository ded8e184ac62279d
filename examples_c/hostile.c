/*
 * hostile.c -- a hostile client of tissuesim.h: NaN, Inf, denormal and huge values in every
 * numeric input, stale ids, truncated and crafted states, worlds stepped concurrently on two
 * threads. Every call must return a status (never crash, hang or abort), a refused call must
 * leave the world as it was, and the world must stay usable. Run by run_tests.sh plainly,
 * under valgrind, and built with -fsanitize=address,undefined.
 *
 * Exits non-zero on any failure; the last line printed is "N passed, M failed".
 *
 * Build: cc -std=c11 -Iinclude examples_c/hostile.c -Ltarget/release -ltissuesim -lpthread -lm
 */
#define _POSIX_C_SOURCE 200809L
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tissuesim.h"

#include "check.h"

/* `call` (evaluated once) is refused with a status other than TS_STATUS_PANIC. */
static int refused(ts_status st) { return st != TS_STATUS_OK && st != TS_STATUS_PANIC; }
#define CHECK_REFUSED(call) CHECK(refused(call))

/* Values a hostile host passes where a sane number is expected. */
static double hostile_values[8];
#define N_HOSTILE 8

static void init_hostile(void) {
    double v[N_HOSTILE] = {NAN, INFINITY, -INFINITY, DBL_MIN / 4 /* denormal */, 1e300, -1e300,
                           -1.0, 0.0};
    memcpy(hostile_values, v, sizeof v);
}

/* A 4^3-cell lattice of 1.5 cm cells (125 nodes, 384 tets) whose bottom rests at y = 0. */
#define C 4
#define NN ((C + 1) * (C + 1) * (C + 1))
#define NT (6 * C * C * C)
static double nodes[3 * NN];
static uint32_t tets[4 * NT];

static uint32_t id_of(int i, int j, int k) { return (uint32_t)(i + (C + 1) * (j + (C + 1) * k)); }

static void build_lattice(void) {
    const double h = 0.015;
    for (int k = 0; k <= C; k++)
        for (int j = 0; j <= C; j++)
            for (int i = 0; i <= C; i++) {
                uint32_t n = id_of(i, j, k);
                nodes[3 * n] = i * h;
                nodes[3 * n + 1] = j * h;
                nodes[3 * n + 2] = k * h;
            }
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k < C; k++)
        for (int j = 0; j < C; j++)
            for (int i = 0; i < C; i++)
                for (int p = 0; p < 6; p++) {
                    int d[3] = {0, 0, 0};
                    tets[4 * t] = id_of(i, j, k);
                    for (int s = 0; s < 3; s++) {
                        d[perms[p][s]] = 1;
                        tets[4 * t + s + 1] = id_of(i + d[0], j + d[1], k + d[2]);
                    }
                    t++;
                }
}

/* A world with the lattice (top layer fixed) and a sphere tool above it. */
static ts_world *scene(uint32_t *body, uint32_t *tool) {
    ts_settings s;
    ts_material m;
    ts_world *w = NULL;
    CHECK_OK(ts_settings_default(&s));
    CHECK_OK(ts_material_default(&m));
    CHECK_OK(ts_world_new(&s, &w));
    if (!w) return NULL;
    CHECK_OK(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &m, NULL, body));
    double lo[3] = {-1, C * 0.015 - 0.001, -1}, hi[3] = {1, 1, 1};
    CHECK_OK(ts_body_fix_box(w, *body, lo, hi, NULL));
    ts_pose pose = {{0.03, -0.02, 0.03}, {1, 0, 0, 0}};
    CHECK_OK(ts_world_add_tool_sphere(w, 0.01, &pose, NULL, tool));
    return w;
}

/* The world's whole state, for "nothing changed" checks (caller frees). */
static uint8_t *snapshot(ts_world *w, size_t *len) {
    CHECK_OK(ts_world_state_size(w, len));
    uint8_t *buf = malloc(*len);
    CHECK_OK(ts_world_save_state(w, buf, *len, NULL));
    return buf;
}

static int unchanged(ts_world *w, const uint8_t *before, size_t len) {
    size_t now_len = 0;
    uint8_t *now = snapshot(w, &now_len);
    int same = now_len == len && memcmp(now, before, len) == 0;
    free(now);
    return same;
}

/* Every numeric input of settings, materials, options, tool shapes and poses, one hostile value
 * at a time: refused, and the world unchanged. */
static void hostile_numbers(void) {
    uint32_t body = 0, tool = 0;
    ts_world *w = scene(&body, &tool);
    if (!w) return;
    CHECK_OK(ts_world_step(w, NULL));
    size_t len = 0;
    uint8_t *before = snapshot(w, &len);
    for (int k = 0; k < N_HOSTILE; k++) {
        double v = hostile_values[k];
        /* settings: every double field. */
        ts_settings s;
        CHECK_OK(ts_world_get_settings(w, &s));
        static const size_t fields[] = {offsetof(ts_settings, dt),
                                        offsetof(ts_settings, gravity) + sizeof(double),
                                        offsetof(ts_settings, stability_margin),
                                        offsetof(ts_settings, damping_mass),
                                        offsetof(ts_settings, hourglass_stiffness),
                                        offsetof(ts_settings, max_depenetration_speed),
                                        offsetof(ts_settings, divergence_max_speed),
                                        offsetof(ts_settings, divergence_min_volume_ratio)};
        for (size_t f = 0; f < sizeof fields / sizeof *fields; f++) {
            ts_settings t = s;
            memcpy((char *)&t + fields[f], &v, sizeof v);
            ts_status st = ts_world_set_settings(w, &t);
            CHECK(st != TS_STATUS_PANIC);
            if (st == TS_STATUS_OK) { /* a legal value (e.g. 0 gravity): put the old back */
                CHECK_OK(ts_world_set_settings(w, &s));
            }
        }
        /* materials. */
        ts_material m;
        CHECK_OK(ts_material_default(&m));
        ts_material bad = m;
        bad.youngs_modulus = v;
        uint32_t id = 0;
        CHECK_REFUSED(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &bad, NULL, &id));
        bad = m;
        bad.poisson_ratio = (v == 0.0 || fpclassify(v) == FP_SUBNORMAL) ? 0.5 : v; /* tiny nu is legal */
        CHECK_REFUSED(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &bad, NULL, &id));
        /* body options: radii. */
        ts_body_options o;
        CHECK_OK(ts_body_options_default(&o));
        o.particle_radius = v == 0.0 ? 1e-12 : v;
        CHECK_REFUSED(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &m, &o, &id));
        CHECK_OK(ts_body_options_default(&o));
        o.support_radius = v == 0.0 ? 1e3 : v;
        CHECK_REFUSED(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &m, &o, &id));
        /* a node position. */
        double saved = nodes[7];
        nodes[7] = v == 0.0 ? NAN : v;
        ts_status st = ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &m, NULL, &id);
        CHECK(st != TS_STATUS_PANIC);
        nodes[7] = saved;
        if (st == TS_STATUS_OK) { /* a finite far node gives a (strange) body: start again */
            free(before);
            ts_world_free(w);
            w = scene(&body, &tool);
            CHECK_OK(ts_world_step(w, NULL));
            before = snapshot(w, &len);
        }
        /* tool shapes and poses. */
        ts_pose pose = {{0.03, 0.2, 0.03}, {1, 0, 0, 0}};
        CHECK_REFUSED(ts_world_add_tool_sphere(w, v, &pose, NULL, &id));
        CHECK_REFUSED(ts_world_add_tool_cylinder(w, v, v, &pose, NULL, &id));
        double he[3] = {0.01, v, 0.01};
        CHECK_REFUSED(ts_world_add_tool_box(w, he, &pose, NULL, &id));
        ts_tool_options to;
        CHECK_OK(ts_tool_options_default(&to));
        to.friction_static = v;
        to.friction_kinetic = v;
        st = ts_world_add_tool_sphere(w, 0.01, &pose, &to, &id);
        CHECK(st != TS_STATUS_PANIC);
        if (st == TS_STATUS_OK) { /* zero friction is legal: start again */
            free(before);
            ts_world_free(w);
            w = scene(&body, &tool);
            CHECK_OK(ts_world_step(w, NULL));
            before = snapshot(w, &len);
        }
        for (int c = 0; c < 7; c++) {
            ts_pose p = {{0.03, -0.02, 0.03}, {1, 0, 0, 0}};
            if (c < 3) p.position[c] = v; else p.orientation[c - 3] = v;
            st = ts_tool_set_pose(w, tool, &p);
            CHECK(st != TS_STATUS_PANIC);
            if (st == TS_STATUS_OK) { /* a legal pose (finite, or a non-unit quaternion) */
                CHECK(ts_world_step(w, NULL) != TS_STATUS_PANIC);
                free(before);
                ts_world_free(w);
                w = scene(&body, &tool);
                CHECK_OK(ts_world_step(w, NULL));
                before = snapshot(w, &len);
            }
        }
        /* grasp options: refused, or legal (0 = automatic, negative compliance = automatic,
         * a huge reach grasps everything) and released again. */
        for (int f = 0; f < 3; f++) {
            ts_grasp_options g;
            CHECK_OK(ts_grasp_options_default(&g));
            if (f == 0) g.reach = v; else if (f == 1) g.compliance = v; else g.max_force = v;
            uint32_t held = 0;
            st = ts_tool_grasp(w, tool, &g, &held);
            CHECK(st != TS_STATUS_PANIC);
            if (st == TS_STATUS_OK) CHECK_OK(ts_tool_release(w, tool));
        }
        /* a blade edge with one hostile coordinate: refused (or, finite, cuts nothing this
         * far from the body), the world unchanged. */
        for (int c = 0; c < 12; c++) {
            double from[6] = {5, 5, 5, 5, 5, 6}, to[6] = {6, 5, 5, 6, 5, 6};
            if (c < 6) from[c] = v; else to[c - 6] = v;
            ts_cut_report report;
            st = ts_world_cut(w, body, from, to, &report);
            CHECK(st != TS_STATUS_PANIC);
            if (st == TS_STATUS_OK) CHECK(report.pairs == 0 && report.tets == 0);
        }
        /* needle options with a hostile puncture force: refused (never a panic). */
        ts_needle_options no;
        CHECK_OK(ts_needle_options_default(&no));
        no.puncture_force = v;
        CHECK_REFUSED(ts_tool_make_needle(w, tool, &no));
        CHECK(unchanged(w, before, len));
    }
    /* stale ids. */
    double x[3 * NN];
    CHECK(ts_body_positions(w, body + 1, x, 3 * NN) == TS_STATUS_UNKNOWN_BODY);
    CHECK(ts_body_positions(w, UINT32_MAX, x, 3 * NN) == TS_STATUS_UNKNOWN_BODY);
    ts_pose p = {{0, 0, 0}, {1, 0, 0, 0}};
    CHECK(ts_tool_set_pose(w, tool + 1, &p) == TS_STATUS_UNKNOWN_TOOL);
    CHECK(ts_tool_set_pose(w, UINT32_MAX, &p) == TS_STATUS_UNKNOWN_TOOL);
    CHECK(ts_tool_grasp(w, tool + 1, NULL, NULL) == TS_STATUS_UNKNOWN_TOOL);
    CHECK(ts_tool_release(w, UINT32_MAX) == TS_STATUS_UNKNOWN_TOOL);
    /* short and huge lengths. */
    CHECK(ts_body_positions(w, body, x, 3 * NN - 1) == TS_STATUS_BUFFER_TOO_SMALL);
    CHECK(ts_world_add_body_from_arrays(w, nodes, SIZE_MAX, tets, NT, NULL, NULL, NULL) !=
          TS_STATUS_OK);
    CHECK(unchanged(w, before, len));
    /* still usable. */
    CHECK_OK(ts_world_step(w, NULL));
    free(before);
    ts_world_free(w);
}

/* Every truncation and every single-byte corruption of a state is refused at restore and
 * leaves the world as it was; the good state still restores. */
static void hostile_states(void) {
    uint32_t body = 0, tool = 0;
    ts_world *w = scene(&body, &tool);
    if (!w) return;
    for (int k = 0; k < 5; k++) CHECK_OK(ts_world_step(w, NULL));
    size_t len = 0;
    uint8_t *good = snapshot(w, &len);
    CHECK_OK(ts_world_step(w, NULL));
    size_t now_len = 0;
    uint8_t *now = snapshot(w, &now_len);
    int refused = 0, tried = 0;
    for (size_t cut = 0; cut < len; cut += 1 + cut / 3) {
        tried++;
        refused += ts_world_restore_state(w, good, cut) == TS_STATUS_BAD_STATE;
    }
    uint8_t *bad = malloc(len);
    for (size_t at = 0; at < len; at += 1 + at / 5) {
        memcpy(bad, good, len);
        bad[at] ^= 0x5a;
        tried++;
        refused += ts_world_restore_state(w, bad, len) == TS_STATUS_BAD_STATE;
    }
    CHECK(refused == tried);
    CHECK(unchanged(w, now, now_len));
    CHECK(ts_world_restore_state(w, NULL, len) == TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_restore_state(w, good, len));
    CHECK_OK(ts_world_step(w, NULL));
    free(bad);
    free(now);
    free(good);
    ts_world_free(w);
}

/* Two worlds stepped at once on two threads (each its own world: a world is not shared) give
 * the same, deterministic result. */
typedef struct {
    double final_y;
    int ok;
} run_result;

static void *run_world(void *arg) {
    run_result *r = arg;
    uint32_t body = 0, tool = 0;
    ts_world *w = scene(&body, &tool);
    r->ok = w != NULL;
    if (!w) return NULL;
    for (int k = 0; k < 30; k++) {
        ts_pose p = {{0.03, -0.02 + 0.0005 * k, 0.03}, {1, 0, 0, 0}};
        r->ok &= ts_tool_set_pose(w, tool, &p) == TS_STATUS_OK;
        r->ok &= ts_world_step(w, NULL) == TS_STATUS_OK;
    }
    double x[3 * NN];
    r->ok &= ts_body_positions(w, body, x, 3 * NN) == TS_STATUS_OK;
    r->final_y = x[3 * id_of(2, 0, 2) + 1];
    ts_world_free(w);
    return NULL;
}

static void concurrent_worlds(void) {
    pthread_t a, b;
    run_result ra = {0, 0}, rb = {0, 0};
    CHECK(pthread_create(&a, NULL, run_world, &ra) == 0);
    CHECK(pthread_create(&b, NULL, run_world, &rb) == 0);
    pthread_join(a, NULL);
    pthread_join(b, NULL);
    CHECK(ra.ok && rb.ok);
    CHECK(ra.final_y == rb.final_y);
    CHECK(ra.final_y > 0.0); /* the probe pushed the bottom up */
}

int main(void) {
    init_hostile();
    build_lattice();
    hostile_numbers();
    hostile_states();
    concurrent_worlds();
    return check_summary();
}
