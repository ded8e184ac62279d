/*
 * test_api.c -- calls every function of tissuesim.h and checks statuses and values.
 * Exits non-zero on any failure; the last line printed is "N passed, M failed".
 *
 * TS_STEPS=N sets the number of steps of the stepping checks (default 20).
 *
 * Build: cc -Iinclude examples_c/test_api.c -Ltarget/release -ltissuesim -lm -o test_api
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "tissuesim.h"

#include "check.h"


/* A lattice of cells^3 cubes of edge h (m), 6 tets each, corner at (OX, 0, 0): away from the
 * default organ (centred on the origin, about 0.2 m across). */
#define OX 0.5
#define CELLS 3
#define NN ((CELLS + 1) * (CELLS + 1) * (CELLS + 1))
#define NT (6 * CELLS * CELLS * CELLS)
static double nodes[3 * NN];
static uint32_t tets[4 * NT];

static uint32_t node_id(int i, int j, int k) {
    return (uint32_t)(i + (CELLS + 1) * (j + (CELLS + 1) * k));
}

static void build_lattice(double h) {
    for (int k = 0; k <= CELLS; k++)
        for (int j = 0; j <= CELLS; j++)
            for (int i = 0; i <= CELLS; i++) {
                uint32_t id = node_id(i, j, k);
                nodes[3 * id] = OX + i * h;
                nodes[3 * id + 1] = j * h;
                nodes[3 * id + 2] = k * h;
            }
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k < CELLS; k++)
        for (int j = 0; j < CELLS; j++)
            for (int i = 0; i < CELLS; i++)
                for (int p = 0; p < 6; p++) {
                    int d[3] = {0, 0, 0};
                    tets[4 * t] = node_id(i, j, k);
                    for (int s = 0; s < 3; s++) {
                        d[perms[p][s]] = 1;
                        tets[4 * t + s + 1] = node_id(i + d[0], j + d[1], k + d[2]);
                    }
                    t++;
                }
}

static void write_file(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* ts_world_settle: a free body cannot settle (nothing changes); once its top layer is fixed it
 * settles to rest under (weak) gravity, and the next step hardly moves it. The 64-node lattice
 * (built by build_lattice) keeps this quick under valgrind. */
static void test_settle(double h) {
    ts_settings settings;
    ts_material material;
    ts_world *world = NULL;
    uint32_t body = 0;
    CHECK_ST(ts_world_settle(NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_settings_default(&settings));
    settings.gravity[1] = -0.5;
    settings.volume_constraints = 0; /* the step then integrates exactly the settled energy */
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_OK(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, &material, NULL, &body));
    CHECK_ST(ts_world_settle(world), TS_STATUS_INVALID_ARGUMENT);
    double x0[3 * NN], x1[3 * NN], v[3 * NN];
    CHECK_OK(ts_body_positions(world, body, x0, 3 * NN));
    double lo[3] = {OX - 1, CELLS * h - 0.25 * h, -1}, hi[3] = {OX + 1, 1, 1};
    CHECK_OK(ts_body_fix_box(world, body, lo, hi, NULL));
    CHECK_OK(ts_world_settle(world));
    CHECK_OK(ts_body_positions(world, body, x1, 3 * NN));
    double sag = 0;
    for (size_t i = 0; i < NN; i++) {
        double d = x0[3 * i + 1] - x1[3 * i + 1];
        if (d > sag) sag = d;
    }
    CHECK(sag > 1e-6); /* it sagged under gravity */
    CHECK_OK(ts_world_step(world, NULL));
    CHECK_OK(ts_body_velocities(world, body, v, 3 * NN));
    double fastest = 0;
    for (size_t i = 0; i < 3 * NN; i++) {
        if (fabs(v[i]) > fastest) fastest = fabs(v[i]);
    }
    CHECK(fastest < 1e-6); /* at rest: < 1 um/s after a step */
    ts_world_free(world);
}

/* ts_world_set_profiling / ts_world_step_profile: no profile while off; on, a step's stages are
 * measured, lie within its total, and change no result (a twin world stepped without profiling
 * ends at the same positions, bit for bit). */
static void test_profile(double h) {
    (void)h;
    ts_settings settings;
    ts_material material;
    ts_world *plain = NULL, *profiled = NULL;
    uint32_t a = 0, b = 0;
    ts_step_profile p;
    CHECK_OK(ts_settings_default(&settings));
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &plain));
    CHECK_OK(ts_world_new(&settings, &profiled));
    CHECK_OK(ts_world_add_body_from_arrays(plain, nodes, NN, tets, NT, &material, NULL, &a));
    CHECK_OK(ts_world_add_body_from_arrays(profiled, nodes, NN, tets, NT, &material, NULL, &b));
    CHECK_ST(ts_world_step_profile(profiled, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_set_profiling(NULL, 1), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_step_profile(profiled, &p));
    CHECK(p.measured == 0 && p.total == 0);
    CHECK_OK(ts_world_set_profiling(profiled, 1));
    for (int k = 0; k < 5; k++) {
        CHECK_OK(ts_world_step(plain, NULL));
        CHECK_OK(ts_world_step(profiled, NULL));
    }
    CHECK_OK(ts_world_step_profile(profiled, &p));
    double stages = p.state_copy + p.prediction + p.volume + p.organ_contact + p.self_contact +
                    p.tool_contact + p.grasp_and_needle + p.update + p.end_of_step;
    CHECK(p.measured == 1 && p.prediction > 0 && p.volume > 0);
    CHECK(stages <= p.total * (1 + 1e-9));
    double xa[3 * NN], xb[3 * NN];
    CHECK_OK(ts_body_positions(plain, a, xa, 3 * NN));
    CHECK_OK(ts_body_positions(profiled, b, xb, 3 * NN));
    CHECK(memcmp(xa, xb, sizeof xa) == 0);
    CHECK_OK(ts_world_set_profiling(profiled, 0));
    CHECK_OK(ts_world_step_profile(profiled, &p));
    CHECK(p.measured == 0);
    ts_world_free(plain);
    ts_world_free(profiled);
}

/* The settled hanging lattice of a world with the given schemes and hourglass stiffness. */
static void settled(double h, uint32_t elastic, uint32_t volume, double hourglass, double *x) {
    ts_settings settings;
    ts_material material;
    ts_world *world = NULL;
    uint32_t body = 0;
    CHECK_OK(ts_settings_default(&settings));
    settings.hourglass_stiffness = hourglass;
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_OK(ts_world_set_schemes(world, elastic, volume));
    CHECK_OK(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, &material, NULL, &body));
    double lo[3] = {OX - 1, CELLS * h - 0.25 * h, -1}, hi[3] = {OX + 1, 1, 1};
    CHECK_OK(ts_body_fix_box(world, body, lo, hi, NULL));
    CHECK_OK(ts_world_settle(world));
    CHECK_OK(ts_body_positions(world, body, x, 3 * NN));
    ts_world_free(world);
}

/* The schemes: the defaults until set, kept by ts_world_set_settings, a bad value refused with
 * nothing changed; and they select what carries the elasticity: the hourglass stiffness acts on
 * the paper's particles only (the default's tetrahedra have no zero-energy modes). */
static void test_schemes(double h) {
    ts_settings settings;
    ts_world *world = NULL;
    ts_schemes s;
    CHECK_OK(ts_settings_default(&settings));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_ST(ts_world_schemes(world, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_set_schemes(NULL, 0, 0), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_schemes(world, &s));
    CHECK(s.elastic == TS_ELASTIC_SCHEME_TETRAHEDRA && s.volume == TS_VOLUME_SCHEME_DUAL_CELLS);
    const uint32_t particles = TS_ELASTIC_SCHEME_POINT_BASED, per_tet = TS_VOLUME_SCHEME_TETRAHEDRA;
    CHECK_OK(ts_world_set_schemes(world, particles, per_tet));
    CHECK_ST(ts_world_set_schemes(world, 7, per_tet), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_world_set_schemes(world, particles, 2), TS_STATUS_INVALID_ARGUMENT);
    settings.iterations = 2;
    CHECK_OK(ts_world_set_settings(world, &settings));
    CHECK_OK(ts_world_schemes(world, &s));
    CHECK(s.elastic == TS_ELASTIC_SCHEME_POINT_BASED && s.volume == TS_VOLUME_SCHEME_TETRAHEDRA);
    ts_world_free(world);
    static double a[3 * NN], b[3 * NN];
    settled(h, TS_ELASTIC_SCHEME_TETRAHEDRA, TS_VOLUME_SCHEME_DUAL_CELLS, 0.25, a);
    settled(h, TS_ELASTIC_SCHEME_TETRAHEDRA, TS_VOLUME_SCHEME_DUAL_CELLS, 1.0, b);
    CHECK(memcmp(a, b, sizeof a) == 0);
    settled(h, TS_ELASTIC_SCHEME_POINT_BASED, TS_VOLUME_SCHEME_TETRAHEDRA, 0.25, a);
    settled(h, TS_ELASTIC_SCHEME_POINT_BASED, TS_VOLUME_SCHEME_TETRAHEDRA, 1.0, b);
    CHECK(memcmp(a, b, sizeof a) != 0);
}

/* The crushed-step substeps: 1 until set, kept by ts_world_set_settings, 0 or more than
 * max_substeps refused with nothing changed. */
static void test_crushed_substeps(void) {
    ts_settings settings;
    ts_world *world = NULL;
    uint32_t n = 0;
    CHECK_OK(ts_settings_default(&settings));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_ST(ts_world_crushed_substeps(world, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_set_crushed_substeps(NULL, 2), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_crushed_substeps(world, &n));
    CHECK(n == 1);
    CHECK_OK(ts_world_set_crushed_substeps(world, 2));
    CHECK_ST(ts_world_set_crushed_substeps(world, 0), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_world_set_crushed_substeps(world, settings.max_substeps + 1),
             TS_STATUS_INVALID_ARGUMENT);
    settings.iterations = 2;
    CHECK_OK(ts_world_set_settings(world, &settings));
    CHECK_OK(ts_world_crushed_substeps(world, &n));
    CHECK(n == 2);
    ts_world_free(world);
}

/* The functions that cover the rest of the Rust API: body state, fixed flags, particle radius,
 * pair and tool friction, convex-hull and triangle-array tools, removing a tool, and a capsule
 * of half-height 0 (a sphere). Uses the lattice of build_lattice (edge CELLS * h). */
static void test_coverage(double h) {
    ts_settings settings;
    ts_material material;
    ts_world *world = NULL;
    uint32_t body = 99, other = 99;
    CHECK_OK(ts_settings_default(&settings));
    settings.gravity[1] = 0; /* only the tool deforms the lattice */
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_OK(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, &material, NULL, &body));
    static double shifted[3 * NN]; /* the lattice 0.2 m further along z */
    for (int i = 0; i < 3 * NN; i++) shifted[i] = nodes[i] + (i % 3 == 2 ? 0.2 : 0.0);
    CHECK_OK(
        ts_world_add_body_from_arrays(world, shifted, NN, tets, NT, &material, NULL, &other));
    double lo[3] = {OX - 1, -1e-9, -1}, hi[3] = {OX + 1, 1e-9, 1};
    size_t fixed = 0;
    CHECK_OK(ts_body_fix_box(world, body, lo, hi, &fixed));
    CHECK(fixed == (CELLS + 1) * (CELLS + 1));

    /* Fixed flags: 1 on the bottom face, 0 elsewhere. */
    uint8_t flags[NN];
    memset(flags, 7, sizeof flags);
    CHECK_OK(ts_body_fixed_flags(world, body, flags, NN));
    size_t ones = 0;
    int flags_right = 1;
    for (int i = 0; i < NN; i++) {
        ones += flags[i] == 1;
        flags_right &= flags[i] == (nodes[3 * i + 1] == 0 ? 1 : 0);
    }
    CHECK(ones == fixed && flags_right);
    CHECK_ST(ts_body_fixed_flags(world, body, flags, NN - 1), TS_STATUS_BUFFER_TOO_SMALL);
    CHECK_ST(ts_body_fixed_flags(world, 9, flags, NN), TS_STATUS_UNKNOWN_BODY);
    double radius = 0;
    CHECK_OK(ts_body_particle_radius(world, body, &radius));
    CHECK(radius > 0 && radius < h);
    CHECK_ST(ts_body_particle_radius(world, body, NULL), TS_STATUS_NULL_PARAMETER);

    /* Set positions and velocities, read them back; fixed particles get zero velocity. */
    static double x[3 * NN], v[3 * NN], got[3 * NN];
    for (int i = 0; i < 3 * NN; i++) {
        x[i] = nodes[i] + 1e-4 * (i % 3);
        v[i] = (i % 3 == 2) ? 0.05 : 0.0;
    }
    CHECK_OK(ts_body_set_state(world, body, x, 3 * NN, v, 3 * NN));
    CHECK_OK(ts_body_positions(world, body, got, 3 * NN));
    CHECK(memcmp(got, x, sizeof x) == 0);
    CHECK_OK(ts_body_velocities(world, body, got, 3 * NN));
    int v_right = 1;
    for (int i = 0; i < NN; i++) v_right &= got[3 * i + 2] == (flags[i] ? 0.0 : 0.05);
    CHECK(v_right);
    CHECK_ST(ts_body_set_state(world, body, x, 3 * NN - 1, v, 3 * NN), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_body_set_state(world, body, x, 3 * NN, v, 3 * NN - 3), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_body_set_state(world, body, x, 3 * NN, NULL, 3 * NN), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_body_set_state(world, 9, x, 3 * NN, v, 3 * NN), TS_STATUS_UNKNOWN_BODY);
    v[4] = NAN;
    CHECK_ST(ts_body_set_state(world, body, x, 3 * NN, v, 3 * NN), TS_STATUS_NON_FINITE);
    CHECK_OK(ts_body_positions(world, body, got, 3 * NN));
    CHECK(memcmp(got, x, sizeof x) == 0); /* unchanged by the failed calls */

    /* Body-pair friction. */
    CHECK_OK(ts_world_set_body_pair_friction(world, body, other, 0.5, 0.4));
    CHECK_OK(ts_world_set_body_pair_friction(world, other, other, 0.2, 0.2));
    CHECK_ST(ts_world_set_body_pair_friction(world, body, 9, 0.5, 0.4), TS_STATUS_UNKNOWN_BODY);
    CHECK_ST(ts_world_set_body_pair_friction(world, body, other, 0.3, 0.4),
             TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_world_set_body_pair_friction(world, body, other, NAN, 0.4), TS_STATUS_NON_FINITE);
    CHECK_ST(ts_world_set_body_pair_friction(NULL, body, other, 0.5, 0.4),
             TS_STATUS_NULL_PARAMETER);

    /* Tools: a convex hull (a tetrahedron), a triangle mesh from arrays, a capsule of
     * half-height 0; friction; removal. */
    ts_pose far = {{2, 2, 2}, {1, 0, 0, 0}};
    const double tetra[12] = {0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01};
    const double flat[12] = {0, 0, 0, 0.01, 0, 0, 0, 0.01, 0, 0.01, 0.01, 0};
    const uint32_t tri[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    uint32_t hull = 99, trimesh = 99, ball = 99, id = 66;
    CHECK_OK(ts_world_add_tool_convex_hull(world, tetra, 4, &far, NULL, &hull));
    CHECK(hull == 0);
    CHECK_ST(ts_world_add_tool_convex_hull(world, flat, 4, &far, NULL, &id),
             TS_STATUS_INVALID_ARGUMENT);
    CHECK(last_error_has("plane"));
    CHECK_ST(ts_world_add_tool_convex_hull(world, tetra, 3, &far, NULL, &id),
             TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_world_add_tool_convex_hull(world, NULL, 4, &far, NULL, &id),
             TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_add_tool_mesh(world, tetra, 4, tri, 4, &far, NULL, &trimesh));
    CHECK(trimesh == 1);
    CHECK_ST(ts_world_add_tool_mesh(world, tetra, 3, tri, 4, &far, NULL, &id),
             TS_STATUS_INVALID_ARGUMENT);
    CHECK(id == 66);
    ts_pose above = {{OX + CELLS * h / 2, CELLS * h + 0.011, CELLS * h / 2}, {1, 0, 0, 0}};
    CHECK_OK(ts_world_add_tool_capsule(world, 0.0, 0.01, &above, NULL, &ball));
    CHECK(ball == 2);
    CHECK_ST(ts_world_add_tool_capsule(world, -0.001, 0.01, &far, NULL, &id),
             TS_STATUS_INVALID_ARGUMENT);
    ts_tool_options opts;
    CHECK_OK(ts_tool_set_friction(world, ball, 0.6, 0.5));
    CHECK_OK(ts_tool_get_options(world, ball, &opts));
    CHECK(opts.friction_static == 0.6 && opts.friction_kinetic == 0.5 && opts.sample_spacing == 0);
    CHECK_ST(ts_tool_set_friction(world, ball, 0.4, 0.5), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_tool_set_friction(world, ball, INFINITY, 0.5), TS_STATUS_NON_FINITE);
    CHECK_ST(ts_tool_set_friction(world, 9, 0.6, 0.5), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_tool_get_options(world, ball, NULL), TS_STATUS_NULL_PARAMETER);

    /* The capsule presses the top face 2.5 mm (0.1 m/s), then is removed: its id goes stale,
     * the next tool gets a new id, and it no longer pushes. */
    static const double rest_v[3 * NN];
    CHECK_OK(ts_body_set_state(world, body, nodes, 3 * NN, rest_v, 3 * NN)); /* back to rest */
    for (int s = 1; s <= 30; s++) {
        ts_pose p = above;
        p.position[1] = CELLS * h + 0.01 + 0.0005 - 1e-4 * s;
        CHECK_OK(ts_tool_set_pose(world, ball, &p));
        CHECK_OK(ts_world_step(world, NULL));
    }
    ts_wrench w;
    CHECK_OK(ts_tool_wrench(world, ball, &w));
    CHECK(w.contact_count > 0 && w.force[1] > 0);
    uint32_t count = 0;
    CHECK_OK(ts_world_tool_count(world, &count));
    CHECK(count == 3);
    CHECK_OK(ts_world_remove_tool(world, ball));
    CHECK_ST(ts_world_remove_tool(world, ball), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_tool_wrench(world, ball, &w), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_tool_set_pose(world, ball, &above), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_world_remove_tool(NULL, 0), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_tool_count(world, &count));
    CHECK(count == 2);
    CHECK_OK(ts_world_add_tool_sphere(world, 0.01, &far, NULL, &id));
    CHECK(id == 3);
    /* The dent (lowest top-face particle below the top face) springs back. */
    double dent_pressed = 0, dent_free = 0;
    CHECK_OK(ts_body_positions(world, body, got, 3 * NN));
    for (int i = 0; i <= CELLS; i++)
        for (int k = 0; k <= CELLS; k++)
            dent_pressed = fmax(dent_pressed, CELLS * h - got[3 * node_id(i, CELLS, k) + 1]);
    for (int s = 0; s < 300; s++) CHECK_OK(ts_world_step(world, NULL));
    CHECK_OK(ts_body_positions(world, body, got, 3 * NN));
    for (int i = 0; i <= CELLS; i++)
        for (int k = 0; k <= CELLS; k++)
            dent_free = fmax(dent_free, CELLS * h - got[3 * node_id(i, CELLS, k) + 1]);
    printf("dent %.3g mm pressed, %.3g mm 0.3 s after the tool was removed\n", 1e3 * dent_pressed,
           1e3 * dent_free);
    CHECK(dent_pressed > 5e-4 && dent_free < 0.75 * dent_pressed);
    ts_world_free(world);
}

/* A world with default settings holding the lattice of build_lattice (default material) as
 * body *out_body; its bottom face fixed when `fix_bottom`. */
static ts_world *lattice_world(int fix_bottom, uint32_t *out_body) {
    ts_settings settings;
    ts_material material;
    ts_world *world = NULL;
    CHECK_OK(ts_settings_default(&settings));
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK_OK(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, &material, NULL, out_body));
    if (fix_bottom) {
        double lo[3] = {OX - 1, -1, -1}, hi[3] = {OX + 1, 1e-9, 1};
        CHECK_OK(ts_body_fix_box(world, *out_body, lo, hi, NULL));
    }
    return world;
}

/* Grasping: a sphere touching the top of a free lattice grasps it (ts_tool_grasp), holds it
 * hanging for 2 s: the pull on the tool equals the lattice's weight (within 5%); release lets
 * it fall away. Bad options and stale ids give their statuses. */
static void test_grasp(double h) {
    uint32_t body = 99, ball = 99, count = 99;
    ts_world *world = lattice_world(0, &body);
    ts_material material;
    CHECK_OK(ts_material_default(&material));
    double radius = 0;
    CHECK_OK(ts_body_particle_radius(world, body, &radius));
    ts_pose top = {{OX + CELLS * h / 2, CELLS * h + 0.01 + 0.5 * radius, CELLS * h / 2},
                   {1, 0, 0, 0}};
    CHECK_OK(ts_world_add_tool_sphere(world, 0.01, &top, NULL, &ball));
    ts_grasp_options g;
    CHECK_OK(ts_grasp_options_default(&g));
    CHECK(g.reach == 0 && g.compliance < 0 && isinf(g.max_force));
    CHECK_ST(ts_grasp_options_default(NULL), TS_STATUS_NULL_PARAMETER);
    g.reach = NAN;
    CHECK_ST(ts_tool_grasp(world, ball, &g, &count), TS_STATUS_NON_FINITE);
    CHECK(count == 99); /* outputs only on success */
    g.reach = 0;
    g.max_force = -1;
    CHECK_ST(ts_tool_grasp(world, ball, &g, &count), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_tool_grasp(world, 9, NULL, &count), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_tool_grasp(NULL, ball, NULL, &count), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_tool_grasp(world, ball, NULL, &count));
    CHECK(count > 0);
    uint32_t held = 0;
    CHECK_OK(ts_tool_grasped_count(world, ball, &held));
    CHECK(held == count);
    CHECK_ST(ts_tool_grasped_count(world, ball, NULL), TS_STATUS_NULL_PARAMETER);
    ts_wrench w;
    double pull = 0;
    for (int s = 0; s < 2000; s++) {
        CHECK_OK(ts_world_step(world, NULL));
        if (s >= 1500) {
            CHECK_OK(ts_tool_wrench(world, ball, &w));
            pull -= w.force[1] / 500;
        }
    }
    double weight = material.density * (CELLS * h) * (CELLS * h) * (CELLS * h) * 9.81;
    printf("grasp: %u particles hold %.4f N of a %.4f N lattice\n", count, pull, weight);
    CHECK(fabs(pull - weight) < 0.05 * weight);
    CHECK_OK(ts_tool_release(world, ball));
    CHECK_OK(ts_tool_grasped_count(world, ball, &held));
    CHECK(held == 0);
    CHECK_ST(ts_tool_release(world, 9), TS_STATUS_UNKNOWN_TOOL);
    for (int s = 0; s < 100; s++) CHECK_OK(ts_world_step(world, NULL));
    CHECK_OK(ts_tool_wrench(world, ball, &w));
    CHECK(w.contact_count == 0 && w.force[1] == 0); /* fell away */
    ts_world_free(world);
}

/* Needle insertion: a 1 mm capsule pushed down into the lattice (bottom face fixed) over a
 * column of particles punctures it when the tissue pushes back with the puncture force, then
 * carries friction x inserted length; options and shapes are checked. */
static void test_needle(double h) {
    uint32_t body = 99, needle = 99, ball = 99;
    ts_world *world = lattice_world(1, &body);
    const double half = 0.05, r = 0.001, x = OX + h, z = h; /* over an interior column */
    double tip = CELLS * h + 0.015;
    /* Pointing down: a half turn about x (w = 0, x = 1). */
    ts_pose pose = {{x, tip + half + r, z}, {0, 1, 0, 0}};
    CHECK_OK(ts_world_add_tool_capsule(world, half, r, &pose, NULL, &needle));
    ts_pose far = {{2, 2, 2}, {1, 0, 0, 0}};
    CHECK_OK(ts_world_add_tool_sphere(world, 0.01, &far, NULL, &ball));
    ts_needle_options o;
    CHECK_OK(ts_needle_options_default(&o));
    CHECK(o.puncture_force > 0 && o.friction_per_length >= 0 && o.reach == 0);
    CHECK_ST(ts_needle_options_default(NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_tool_make_needle(world, ball, &o), TS_STATUS_INVALID_ARGUMENT);
    o.puncture_force = NAN;
    CHECK_ST(ts_tool_make_needle(world, needle, &o), TS_STATUS_NON_FINITE);
    o.puncture_force = 0.1;
    o.friction_per_length = -1;
    CHECK_ST(ts_tool_make_needle(world, needle, &o), TS_STATUS_INVALID_ARGUMENT);
    ts_needle_state st;
    CHECK_ST(ts_tool_needle_state(world, needle, &st), TS_STATUS_INVALID_ARGUMENT);
    o.friction_per_length = 2.0;
    CHECK_OK(ts_tool_make_needle(world, needle, &o));
    CHECK_ST(ts_tool_make_needle(world, 9, &o), TS_STATUS_UNKNOWN_TOOL);
    CHECK_ST(ts_tool_needle_state(world, needle, NULL), TS_STATUS_NULL_PARAMETER);
    double before = 0, at_puncture = -1;
    ts_wrench w;
    for (int s = 0; s < 700; s++) { /* 5 cm/s for 3.5 cm */
        tip -= 5e-5;
        pose.position[1] = tip + half + r;
        CHECK_OK(ts_tool_set_pose(world, needle, &pose));
        CHECK_OK(ts_world_step(world, NULL));
        CHECK_OK(ts_tool_wrench(world, needle, &w));
        CHECK_OK(ts_tool_needle_state(world, needle, &st));
        double axial = w.force[1]; /* the tissue pushes the down-pointing needle up */
        if (st.punctured && at_puncture < 0) {
            at_puncture = axial;
            CHECK(before < o.puncture_force);
        }
        before = axial;
    }
    double friction = o.friction_per_length * st.inserted_length;
    printf("needle: punctured at %.4f N (threshold %.2f N); %.1f mm in, %u held, %.4f N "
           "(friction x length %.4f N)\n",
           at_puncture, o.puncture_force, 1e3 * st.inserted_length, st.held, w.force[1], friction);
    CHECK(at_puncture >= o.puncture_force);
    CHECK(st.punctured == 1 && st.held > 0 && st.inserted_length > 0.01);
    CHECK(fabs(w.force[1] - friction) < 0.25 * friction);
    ts_world_free(world);
}

/* Cutting: a horizontal blade swept through the middle of the lattice (bottom face fixed)
 * cuts it in two; the top half then falls under gravity. A capsule becomes a blade tool. */
static void test_cut(double h) {
    uint32_t body = 99, blade = 99, ball = 99;
    ts_world *world = lattice_world(1, &body);
    double y = 1.5 * h; /* between the second and third layers of nodes */
    double from[6] = {OX - 0.05, y, -0.05, OX - 0.05, y, CELLS * h + 0.05};
    double to[6] = {OX + CELLS * h + 0.05, y, -0.05, OX + CELLS * h + 0.05, y, CELLS * h + 0.05};
    ts_cut_report report = {0, 0, 0};
    uint64_t pairs = 9, removed = 9;
    CHECK_OK(ts_body_cut_counts(world, body, &pairs, &removed));
    CHECK(pairs == 0 && removed == 0);
    from[1] = NAN;
    CHECK_ST(ts_world_cut(world, body, from, to, &report), TS_STATUS_NON_FINITE);
    from[1] = y;
    CHECK_ST(ts_world_cut(world, body, NULL, to, &report), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_cut(world, 9, from, to, &report), TS_STATUS_UNKNOWN_BODY);
    CHECK(report.pairs == 0); /* outputs only on success */
    CHECK_OK(ts_world_cut(world, body, from, to, &report));
    CHECK(report.pairs > 0 && report.tets > 0);
    CHECK_OK(ts_body_cut_counts(world, body, &pairs, &removed));
    CHECK(pairs == report.pairs && removed == report.tets);
    CHECK_ST(ts_body_cut_counts(world, body, NULL, &removed), TS_STATUS_NULL_PARAMETER);
    for (int s = 0; s < 100; s++) CHECK_OK(ts_world_step(world, NULL));
    double x[3 * NN];
    CHECK_OK(ts_body_positions(world, body, x, 3 * NN));
    double fall = 0;
    for (int i = 0; i <= CELLS; i++)
        for (int k = 0; k <= CELLS; k++) fall += (CELLS * h - x[3 * node_id(i, CELLS, k) + 1]) / 16;
    printf("cut: %llu pairs, %llu tets; the top half fell %.1f mm in 0.1 s\n",
           (unsigned long long)report.pairs, (unsigned long long)report.tets, 1e3 * fall);
    CHECK(fall > 0.02); /* free fall: 49 mm in 0.1 s */
    ts_pose far = {{2, 2, 2}, {1, 0, 0, 0}};
    CHECK_OK(ts_world_add_tool_capsule(world, 0.05, 0.0005, &far, NULL, &blade));
    CHECK_OK(ts_tool_make_blade(world, blade));
    CHECK_OK(ts_world_add_tool_sphere(world, 0.01, &far, NULL, &ball));
    CHECK_ST(ts_tool_make_blade(world, ball), TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_tool_make_blade(world, 9), TS_STATUS_UNKNOWN_TOOL);
    ts_world_free(world);
}

/* A body shared into a second world: the same particles, the same motion, and it outlives the
 * world it came from (the model is reference-counted). */
static void test_shared(double h) {
    ts_settings settings;
    ts_material material;
    ts_world *a = NULL, *b = NULL;
    uint32_t body = 99, copy = 99;
    CHECK_OK(ts_settings_default(&settings));
    CHECK_OK(ts_material_default(&material));
    CHECK_OK(ts_world_new(&settings, &a));
    CHECK_OK(ts_world_new(&settings, &b));
    CHECK_OK(ts_world_add_body_from_arrays(a, nodes, NN, tets, NT, &material, NULL, &body));
    CHECK_OK(ts_world_add_body_shared(b, a, body, &copy));
    CHECK(copy == 0);
    CHECK_ST(ts_world_add_body_shared(b, a, 5, &copy), TS_STATUS_UNKNOWN_BODY);
    CHECK_ST(ts_world_add_body_shared(b, NULL, body, &copy), TS_STATUS_NULL_PARAMETER);
    double lo[3] = {OX - 1, -1e-9, -1}, hi[3] = {OX + 1, 1e-9, 1};
    size_t fixed_a = 0, fixed_b = 0;
    CHECK_OK(ts_body_fix_box(a, body, lo, hi, &fixed_a));
    CHECK_OK(ts_body_fix_box(b, copy, lo, hi, &fixed_b));
    CHECK(fixed_a == fixed_b && fixed_a > 0);
    static double xa[3 * NN], xb[3 * NN];
    for (int k = 0; k < 10; k++) {
        CHECK_OK(ts_world_step(a, NULL));
        CHECK_OK(ts_world_step(b, NULL));
    }
    CHECK_OK(ts_body_positions(a, body, xa, 3 * NN));
    CHECK_OK(ts_body_positions(b, copy, xb, 3 * NN));
    CHECK(memcmp(xa, xb, sizeof xa) == 0);
    ts_world_free(a);
    CHECK_OK(ts_world_step(b, NULL));
    CHECK_OK(ts_body_positions(b, copy, xb, 3 * NN));
    CHECK(xb[3 * (NN - 1) + 1] < h * CELLS);
    ts_world_free(b);
}

int main(void) {
    long steps = getenv("TS_STEPS") ? atol(getenv("TS_STEPS")) : 20;
    if (steps < 2) steps = 2;
    const double h = 0.02; /* 6 cm cube */
    build_lattice(h);
    test_settle(h);
    test_profile(h);
    test_schemes(h);
    test_crushed_substeps();
    test_coverage(h);
    test_grasp(h);
    test_needle(h);
    test_cut(h);
    test_shared(h);

    /* ---- version, status strings, last error ---- */
    CHECK(ts_version() == TISSUESIM_VERSION);
    CHECK(ts_version() ==
          TISSUESIM_VERSION_MAJOR * 10000 + TISSUESIM_VERSION_MINOR * 100 + TISSUESIM_VERSION_PATCH);
    CHECK(strcmp(ts_version_string(), TISSUESIM_VERSION_STRING) == 0);
    CHECK(strncmp(ts_status_string(TS_STATUS_OK), "TS_STATUS_OK", 12) == 0);
    CHECK(strncmp(ts_status_string(TS_STATUS_BAD_STATE), "TS_STATUS_BAD_STATE", 19) == 0);
    CHECK(strcmp(ts_status_string(12345), "unknown ts_status value") == 0);
    CHECK(TS_STATUS_OK == 0 && TS_STATUS_NULL_PARAMETER == 1 && TS_STATUS_PANIC == 11);
    ts_last_error_clear();
    CHECK(ts_last_error_message(NULL, 0) == 0);

    /* ---- defaults ---- */
    ts_settings settings;
    ts_material material;
    ts_body_options body_options;
    ts_tool_options tool_options;
    CHECK_OK(ts_settings_default(&settings));
    CHECK(settings.dt == 1e-3 && settings.gravity[1] < 0 && settings.min_substeps >= 1);
    CHECK(settings.contact_mode == TS_CONTACT_MODE_EXACT_SHAPE);
    CHECK(settings.volume_constraints == 1 && settings.self_contact == 0);
    CHECK(settings.mass_scaling == 1 && settings.volumetric_split == 1);
    CHECK(settings.max_depenetration_speed > 0);
    CHECK_OK(ts_material_default(&material));
    CHECK(material.youngs_modulus == 5000 && material.poisson_ratio == 0.45 &&
          material.density == 1060);
    CHECK_OK(ts_body_options_default(&body_options));
    CHECK(body_options.support_radius == 0 && body_options.target_neighbours > 0);
    CHECK_OK(ts_tool_options_default(&tool_options));
    CHECK(tool_options.friction_static == 0 && tool_options.sample_spacing == 0);
    CHECK_ST(ts_settings_default(NULL), TS_STATUS_NULL_PARAMETER);
    CHECK(ts_last_error_message(NULL, 0) > 0);
    {
        char small[4] = {'#', '#', '#', '#'};
        size_t full = ts_last_error_message(small, 3);
        CHECK(full > 3 && small[2] == '\0' && small[3] == '#');
    }
    CHECK_ST(ts_material_default(NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_body_options_default(NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_tool_options_default(NULL), TS_STATUS_NULL_PARAMETER);

    /* ---- world ---- */
    ts_world *world = NULL;
    ts_world_free(NULL);
    CHECK_ST(ts_world_new(NULL, &world), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_new(&settings, NULL), TS_STATUS_NULL_PARAMETER);
    {
        ts_settings bad = settings;
        bad.dt = NAN;
        CHECK_ST(ts_world_new(&bad, &world), TS_STATUS_NON_FINITE);
        CHECK(last_error_has("dt"));
        bad = settings;
        bad.iterations = 0;
        CHECK_ST(ts_world_new(&bad, &world), TS_STATUS_INVALID_ARGUMENT);
        CHECK(world == NULL);
    }
    CHECK_OK(ts_world_new(&settings, &world));
    CHECK(world != NULL);
    {
        ts_settings got;
        CHECK_OK(ts_world_get_settings(world, &got));
        CHECK(got.dt == settings.dt && got.max_substeps == settings.max_substeps);
        got.damping_mass = 1.0;
        CHECK_OK(ts_world_set_settings(world, &got));
        got.gravity[2] = INFINITY;
        CHECK_ST(ts_world_set_settings(world, &got), TS_STATUS_NON_FINITE);
        ts_settings again;
        CHECK_OK(ts_world_get_settings(world, &again));
        CHECK(again.damping_mass == 1.0 && again.gravity[2] == 0);
        CHECK_OK(ts_world_set_settings(world, &settings));
    }
    uint32_t count = 99;
    CHECK_OK(ts_world_body_count(world, &count));
    CHECK(count == 0);
    CHECK_OK(ts_world_tool_count(world, &count));
    CHECK(count == 0);

    /* ---- bodies ---- */
    uint32_t body = 99, organ = 99, from_file = 99;
    CHECK_OK(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, &material, &body_options,
                                           &body));
    CHECK(body == 0);
    CHECK_ST(ts_world_add_body_from_arrays(world, nodes, NN, tets, NT, NULL, NULL, &body),
             TS_STATUS_NULL_PARAMETER);
    {
        double bad_nodes[3 * NN];
        memcpy(bad_nodes, nodes, sizeof bad_nodes);
        bad_nodes[5] = NAN;
        uint32_t id = 77;
        CHECK_ST(ts_world_add_body_from_arrays(world, bad_nodes, NN, tets, NT, &material, NULL, &id),
                 TS_STATUS_NON_FINITE);
        uint32_t bad_tets[4 * NT];
        memcpy(bad_tets, tets, sizeof bad_tets);
        bad_tets[0] = NN + 10;
        CHECK_ST(ts_world_add_body_from_arrays(world, nodes, NN, bad_tets, NT, &material, NULL, &id),
                 TS_STATUS_MESH_ERROR);
        CHECK(id == 77);
    }
    CHECK_OK(ts_world_add_default_organ(world, &material, NULL, &organ));
    CHECK(organ == 1);

    char vtk_path[256], obj_path[256], bad_path[256];
    snprintf(vtk_path, sizeof vtk_path, "/tmp/ts_test_api_%ld.vtk", (long)getpid());
    snprintf(obj_path, sizeof obj_path, "/tmp/ts_test_api_%ld.obj", (long)getpid());
    snprintf(bad_path, sizeof bad_path, "/tmp/ts_test_api_%ld_broken.msh", (long)getpid());
    {
        /* The lattice as legacy VTK, in cm, moved 20 cm further along x. */
        static char text[65536];
        size_t len = 0;
        len += (size_t)snprintf(text + len, sizeof text - len,
                                "# vtk DataFile Version 2.0\nlattice\nASCII\n"
                                "DATASET UNSTRUCTURED_GRID\nPOINTS %d double\n",
                                NN);
        for (int i = 0; i < NN; i++)
            len += (size_t)snprintf(text + len, sizeof text - len, "%g %g %g\n",
                                    100 * (nodes[3 * i] + 0.2), 100 * nodes[3 * i + 1],
                                    100 * nodes[3 * i + 2]);
        len += (size_t)snprintf(text + len, sizeof text - len, "CELLS %d %d\n", NT, 5 * NT);
        for (int t = 0; t < NT; t++)
            len += (size_t)snprintf(text + len, sizeof text - len, "4 %u %u %u %u\n", tets[4 * t],
                                    tets[4 * t + 1], tets[4 * t + 2], tets[4 * t + 3]);
        len += (size_t)snprintf(text + len, sizeof text - len, "CELL_TYPES %d\n", NT);
        for (int t = 0; t < NT; t++) len += (size_t)snprintf(text + len, sizeof text - len, "10\n");
        write_file(vtk_path, text);
        write_file(obj_path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                             "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
        write_file(bad_path, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n");
    }
    CHECK_OK(ts_world_add_body_from_file(world, vtk_path, 0.01, &material, NULL, &from_file));
    CHECK(from_file == 2);
    {
        uint32_t id = 55;
        CHECK_ST(ts_world_add_body_from_file(world, bad_path, 1.0, &material, NULL, &id),
                 TS_STATUS_MESH_ERROR);
        CHECK(last_error_has("_broken.msh"));
        CHECK_ST(ts_world_add_body_from_file(world, "/nonexistent/liver.msh", 1.0, &material, NULL,
                                             &id),
                 TS_STATUS_MESH_ERROR);
        CHECK(last_error_has("/nonexistent/liver.msh"));
        CHECK_ST(ts_world_add_body_from_file(world, vtk_path, -1.0, &material, NULL, &id),
                 TS_STATUS_INVALID_ARGUMENT);
        CHECK(id == 55);
    }
    CHECK_OK(ts_world_body_count(world, &count));
    CHECK(count == 3);

    size_t n = 0, fixed = 0;
    CHECK_OK(ts_body_particle_count(world, body, &n));
    CHECK(n == NN);
    {
        /* Fix the bottom face (y = 0) of the lattice by box and one more particle by index. */
        double lo[3] = {OX - 0.01, -1e-9, -1}, hi[3] = {OX + 0.1, 1e-9, 1};
        CHECK_OK(ts_body_fix_box(world, body, lo, hi, &fixed));
        CHECK(fixed == (CELLS + 1) * (CELLS + 1));
        uint32_t idx[2] = {node_id(0, 1, 0), node_id(CELLS, 1, CELLS)};
        CHECK_OK(ts_body_fix_particles(world, body, idx, 2));
        uint32_t bad_idx[1] = {NN};
        CHECK_ST(ts_body_fix_particles(world, body, bad_idx, 1), TS_STATUS_INVALID_ARGUMENT);
        CHECK_ST(ts_body_fix_particles(world, 42, idx, 2), TS_STATUS_UNKNOWN_BODY);
        double nan_lo[3] = {NAN, 0, 0};
        CHECK_ST(ts_body_fix_box(world, body, nan_lo, hi, NULL), TS_STATUS_NON_FINITE);
        /* Fix the organ's and the file body's lowest 10 % so that they stay put. */
        double olo[3] = {-10, -10, -10}, ohi[3] = {10, -10 + 1e-9, 10};
        double *ox;
        size_t on;
        CHECK_OK(ts_body_particle_count(world, organ, &on));
        ox = malloc(3 * on * sizeof *ox);
        CHECK_OK(ts_body_positions(world, organ, ox, 3 * on));
        double ymin = 1e9, ymax = -1e9;
        for (size_t i = 0; i < on; i++) {
            if (ox[3 * i + 1] < ymin) ymin = ox[3 * i + 1];
            if (ox[3 * i + 1] > ymax) ymax = ox[3 * i + 1];
        }
        ohi[1] = ymin + 0.1 * (ymax - ymin);
        size_t ofixed = 0;
        CHECK_OK(ts_body_fix_box(world, organ, olo, ohi, &ofixed));
        CHECK(ofixed > 0);
        free(ox);
        lo[0] += 0.2;
        hi[0] += 0.2;
        CHECK_OK(ts_body_fix_box(world, from_file, lo, hi, &fixed));
        CHECK(fixed == (CELLS + 1) * (CELLS + 1));
    }

    double *x = malloc(3 * n * sizeof *x), *x_after = malloc(3 * n * sizeof *x);
    double *v = malloc(3 * n * sizeof *v), *x_rest = malloc(3 * n * sizeof *x);
    uint32_t *src = malloc(n * sizeof *src);
    CHECK_OK(ts_body_positions(world, body, x, 3 * n));
    CHECK(x[3 * node_id(1, 2, 3) + 2] == 3 * h);
    CHECK_OK(ts_body_rest_positions(world, body, x_rest, 3 * n));
    CHECK(memcmp(x, x_rest, 3 * n * sizeof *x) == 0);
    CHECK_OK(ts_body_velocities(world, body, v, 3 * n));
    CHECK(v[0] == 0 && v[3 * n - 1] == 0);
    CHECK_OK(ts_body_source_indices(world, body, src, n));
    CHECK(src[0] == 0 && src[n - 1] == n - 1);
    {
        /* Short buffers: status, nothing written. */
        double probe[4] = {-7, -7, -7, -7};
        CHECK_ST(ts_body_positions(world, body, probe, 3), TS_STATUS_BUFFER_TOO_SMALL);
        CHECK(last_error_has("needed"));
        CHECK_ST(ts_body_velocities(world, body, probe, 3 * n - 1), TS_STATUS_BUFFER_TOO_SMALL);
        CHECK_ST(ts_body_rest_positions(world, body, probe, 0), TS_STATUS_BUFFER_TOO_SMALL);
        uint32_t iprobe[2] = {7, 7};
        CHECK_ST(ts_body_source_indices(world, body, iprobe, 1), TS_STATUS_BUFFER_TOO_SMALL);
        CHECK_ST(ts_body_boundary_triangles(world, body, iprobe, 2), TS_STATUS_BUFFER_TOO_SMALL);
        CHECK_ST(ts_body_tets(world, body, iprobe, 2), TS_STATUS_BUFFER_TOO_SMALL);
        CHECK(probe[0] == -7 && probe[3] == -7 && iprobe[0] == 7 && iprobe[1] == 7);
        CHECK_ST(ts_body_positions(world, 7, x, 3 * n), TS_STATUS_UNKNOWN_BODY);
        CHECK_ST(ts_body_positions(world, body, NULL, 3 * n), TS_STATUS_NULL_PARAMETER);
        CHECK_ST(ts_body_positions(NULL, body, x, 3 * n), TS_STATUS_NULL_PARAMETER);
    }
    size_t ntri = 0, ntet = 0;
    CHECK_OK(ts_body_boundary_triangle_count(world, body, &ntri));
    CHECK(ntri == 6 * 2 * CELLS * CELLS);
    CHECK_OK(ts_body_tet_count(world, body, &ntet));
    CHECK(ntet == NT);
    {
        uint32_t *tri = malloc(3 * ntri * sizeof *tri), *tt = malloc(4 * ntet * sizeof *tt);
        CHECK_OK(ts_body_boundary_triangles(world, body, tri, 3 * ntri));
        int in_range = 1;
        for (size_t i = 0; i < 3 * ntri; i++) in_range &= tri[i] < n;
        CHECK(in_range);
        /* Outward normals: the triangles' signed volume about the centroid is positive. */
        double sv = 0, c = 0.5 * CELLS * h, cx = OX + c;
        for (size_t t = 0; t < ntri; t++) {
            const double *a = &x[3 * tri[3 * t]], *b = &x[3 * tri[3 * t + 1]],
                         *d = &x[3 * tri[3 * t + 2]];
            double ax = a[0] - cx, ay = a[1] - c, az = a[2] - c, bx = b[0] - cx, by = b[1] - c,
                   bz = b[2] - c, dx = d[0] - cx, dy = d[1] - c, dz = d[2] - c;
            sv += ax * (by * dz - bz * dy) - ay * (bx * dz - bz * dx) + az * (bx * dy - by * dx);
        }
        CHECK(fabs(sv / 6 - pow(CELLS * h, 3)) < 1e-12);
        CHECK_OK(ts_body_tets(world, body, tt, 4 * ntet));
        in_range = 1;
        for (size_t i = 0; i < 4 * ntet; i++) in_range &= tt[i] < n;
        CHECK(in_range);
        free(tri);
        free(tt);
    }
    double vol = 0, rest = 0, mass = 0, disp = -1;
    CHECK_OK(ts_body_volume(world, body, &vol));
    CHECK_OK(ts_body_rest_volume(world, body, &rest));
    CHECK(fabs(rest - pow(CELLS * h, 3)) < 1e-12 && fabs(vol - rest) < 1e-12);
    CHECK_OK(ts_body_mass(world, body, &mass));
    CHECK(fabs(mass - material.density * rest) < 1e-9);
    double added = -1;
    CHECK_OK(ts_body_added_mass(world, body, &added));
    CHECK(added >= 0);
    CHECK_OK(ts_body_max_displacement(world, body, &disp));
    CHECK(disp == 0);
    CHECK_OK(ts_body_rest_volume(world, from_file, &rest));
    CHECK(fabs(rest - pow(CELLS * h, 3)) < 1e-12);

    /* ---- tools ---- */
    ts_pose above = {{OX + CELLS * h / 2, CELLS * h + 0.011, CELLS * h / 2}, {1, 0, 0, 0}};
    ts_pose far = {{1.0, 1.0, 1.0}, {0.5, 0.5, 0.5, 0.5}};
    uint32_t sphere = 99, capsule = 99, cylinder = 99, box = 99, mesh = 99;
    CHECK_OK(ts_world_add_tool_sphere(world, 0.01, &above, NULL, &sphere));
    CHECK(sphere == 0);
    CHECK_OK(ts_world_add_tool_capsule(world, 0.02, 0.005, &far, &tool_options, &capsule));
    CHECK(capsule == 1);
    CHECK_OK(ts_world_add_tool_cylinder(world, 0.02, 0.005, &far, NULL, &cylinder));
    CHECK(cylinder == 2);
    {
        double half[3] = {0.01, 0.02, 0.03};
        CHECK_OK(ts_world_add_tool_box(world, half, &far, NULL, &box));
        CHECK(box == 3);
        half[1] = -1;
        uint32_t id = 66;
        CHECK_ST(ts_world_add_tool_box(world, half, &far, NULL, &id), TS_STATUS_INVALID_ARGUMENT);
        CHECK_ST(ts_world_add_tool_box(world, NULL, &far, NULL, &id), TS_STATUS_NULL_PARAMETER);
        CHECK_ST(ts_world_add_tool_sphere(world, -0.01, &far, NULL, &id),
                 TS_STATUS_INVALID_ARGUMENT);
        CHECK_ST(ts_world_add_tool_capsule(world, 0.01, NAN, &far, NULL, &id),
                 TS_STATUS_NON_FINITE);
        CHECK_ST(ts_world_add_tool_cylinder(world, 0.01, 0.01, NULL, NULL, &id),
                 TS_STATUS_NULL_PARAMETER);
        CHECK_ST(ts_world_add_tool_mesh_file(world, "/nonexistent/probe.obj", 1, &far, NULL, &id),
                 TS_STATUS_MESH_ERROR);
        CHECK(last_error_has("/nonexistent/probe.obj"));
        CHECK(id == 66);
    }
    CHECK_OK(ts_world_add_tool_mesh_file(world, obj_path, 0.01, &far, NULL, &mesh));
    CHECK(mesh == 4);
    CHECK_OK(ts_world_tool_count(world, &count));
    CHECK(count == 5);
    {
        ts_pose got;
        CHECK_OK(ts_tool_get_pose(world, capsule, &got));
        CHECK(got.position[0] == 1.0 && fabs(got.orientation[0] - 0.5) < 1e-15);
        ts_pose zero = {{0, 0, 0}, {0, 0, 0, 0}}, nan_pose = above;
        nan_pose.orientation[2] = NAN;
        CHECK_ST(ts_tool_set_pose(world, sphere, &zero), TS_STATUS_INVALID_ARGUMENT);
        CHECK_ST(ts_tool_set_pose(world, sphere, &nan_pose), TS_STATUS_NON_FINITE);
        CHECK_ST(ts_tool_set_pose(world, 17, &above), TS_STATUS_UNKNOWN_TOOL);
        CHECK_OK(ts_tool_get_pose(world, sphere, &got));
        CHECK(memcmp(&got, &above, sizeof got) == 0);
    }

    /* ---- stepping: press the sphere gently into the lattice (0.1 m/s, 60 steps, from 0.5 mm
     * above the top face to 5.5 mm into it, while the lattice sags under gravity), then hold
     * it there for TS_STEPS steps ---- */
    ts_step_report report = {0, 0};
    const long press = 60;
    for (long s = 0; s < press + steps; s++) {
        ts_pose p = above;
        long k = s < press ? s + 1 : press;
        p.position[1] = CELLS * h + 0.01 + 0.0005 - 1e-4 * (double)k;
        CHECK_OK(ts_tool_set_pose(world, sphere, &p));
        CHECK_OK(ts_world_step(world, &report));
    }
    CHECK(report.substeps >= 1);
    double t = 0;
    CHECK_OK(ts_world_time(world, &t));
    CHECK(fabs(t - (double)(press + steps) * settings.dt) < 1e-12);
    /* The jump speed: a quarter of the speed bound (250 body sizes per second; the block's size,
     * its diagonal, is between one and two edges). */
    double jump = 0;
    CHECK_OK(ts_world_tool_jump_speed(world, &jump));
    CHECK(jump > 0.25 * 250.0 * CELLS * h && jump < 0.25 * 250.0 * 2.0 * CELLS * h);
    uint64_t diverged = 99;
    CHECK_OK(ts_world_diverged_steps(world, &diverged));
    CHECK(diverged == 0);
    ts_wrench w;
    CHECK_OK(ts_tool_wrench(world, sphere, &w));
    CHECK(w.contact_count > 0 && w.force[1] > 0); /* the tissue pushes the probe up */
    uint32_t contacts = 0;
    CHECK_OK(ts_tool_contact_count(world, sphere, &contacts));
    CHECK(contacts == w.contact_count);
    CHECK_OK(ts_tool_wrench(world, box, &w));
    CHECK(w.contact_count == 0 && w.force[0] == 0 && w.force[1] == 0 && w.force[2] == 0);
    CHECK_ST(ts_tool_wrench(world, 99, &w), TS_STATUS_UNKNOWN_TOOL);
    CHECK_OK(ts_body_max_displacement(world, body, &disp));
    CHECK(disp > 0 && disp < 0.05);
    CHECK_OK(ts_body_volume(world, body, &vol));
    CHECK_OK(ts_body_rest_volume(world, body, &rest));
    CHECK(fabs(vol / rest - 1) < 0.05);

    /* ---- state: save, step, restore, step again: bit-identical ---- */
    size_t size = 0, written = 0;
    CHECK_OK(ts_world_state_size(world, &size));
    CHECK(size > 0);
    unsigned char *state = malloc(size), *junk = malloc(size);
    CHECK_ST(ts_world_save_state(world, state, size - 1, &written), TS_STATUS_BUFFER_TOO_SMALL);
    CHECK(written == 0);
    CHECK_OK(ts_world_save_state(world, state, size, &written));
    CHECK(written == size);
    for (long s = 0; s < steps; s++) CHECK_OK(ts_world_step(world, NULL));
    CHECK_OK(ts_body_positions(world, body, x, 3 * n));
    CHECK_OK(ts_world_restore_state(world, state, size));
    for (long s = 0; s < steps; s++) CHECK_OK(ts_world_step(world, NULL));
    CHECK_OK(ts_body_positions(world, body, x_after, 3 * n));
    CHECK(memcmp(x, x_after, 3 * n * sizeof *x) == 0);
    /* Bad states are rejected and change nothing. */
    for (size_t i = 0; i < size; i++) junk[i] = (unsigned char)(i * 37 + 11);
    CHECK_ST(ts_world_restore_state(world, junk, size), TS_STATUS_BAD_STATE);
    CHECK_ST(ts_world_restore_state(world, state, size / 2), TS_STATUS_BAD_STATE);
    CHECK_ST(ts_world_restore_state(world, state, 0), TS_STATUS_BAD_STATE);
    CHECK_ST(ts_world_restore_state(world, NULL, size), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_body_positions(world, body, x_after, 3 * n));
    CHECK(memcmp(x, x_after, 3 * n * sizeof *x) == 0);
    free(state);
    free(junk);

    ts_world_free(world);
    free(x);
    free(x_after);
    free(v);
    free(x_rest);
    free(src);
    remove(vtk_path);
    remove(obj_path);
    remove(bad_path);

    return check_summary();
}
