/*
 * test_render_surface.c -- calls every render-surface function of tissuesim.h with NULL
 * pointers, unknown ids, short buffers, bad files and valid arguments, and checks statuses and
 * values. Exits non-zero on any failure; the last line printed is "N passed, M failed".
 *
 *   test_render_surface [SCRATCH_DIR]      (default: the current folder; OBJ/VTU files go there)
 *
 * Build: cc -Iinclude examples_c/test_render_surface.c -Ltarget/release -ltissuesim -lm
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tissuesim.h"

#include "check.h"


/* A cube [0, 0.1]^3 m of 2 x 2 x 2 cells, 6 tetrahedra each (Kuhn split). */
#define C 2
#define NN ((C + 1) * (C + 1) * (C + 1))
#define NT (6 * C * C * C)
static double nodes[3 * NN];
static uint32_t tets[4 * NT];

static uint32_t id3(int i, int j, int k) {
    return (uint32_t)(i + (C + 1) * (j + (C + 1) * k));
}

static void build_cube(void) {
    const double h = 0.1 / C;
    for (int k = 0; k <= C; k++)
        for (int j = 0; j <= C; j++)
            for (int i = 0; i <= C; i++) {
                uint32_t n = id3(i, j, k);
                nodes[3 * n] = i * h;
                nodes[3 * n + 1] = j * h;
                nodes[3 * n + 2] = k * h;
            }
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    int t = 0;
    for (int k = 0; k < C; k++)
        for (int j = 0; j < C; j++)
            for (int i = 0; i < C; i++)
                for (int p = 0; p < 6; p++) {
                    int c[3] = {i, j, k};
                    tets[4 * t] = id3(c[0], c[1], c[2]);
                    for (int s = 0; s < 3; s++) {
                        c[perm[p][s]]++;
                        tets[4 * t + 1 + s] = id3(c[0], c[1], c[2]);
                    }
                    t++;
                }
}

static int write_text(const char *path, const char *text) {
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

/* A textured quad on the cube's top face, seen from +z counter-clockwise (normal +z). */
static const char *QUAD = "# quad\n"
                          "v 0.02 0.02 0.1\nv 0.08 0.02 0.1\nv 0.08 0.08 0.1\nv 0.02 0.08 0.1\n"
                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
                          "f 1/1/1 2/2/1 3/3/1 4/4/1\n";

int main(int argc, char **argv) {
    const char *dir = argc > 1 ? argv[1] : ".";
    char quad[1024], bad[1024], out_obj[1024], out_vtu[1024], nowhere[1024];
    snprintf(quad, sizeof quad, "%s/rs_quad.obj", dir);
    snprintf(bad, sizeof bad, "%s/rs_bad.obj", dir);
    snprintf(out_obj, sizeof out_obj, "%s/rs_out.obj", dir);
    snprintf(out_vtu, sizeof out_vtu, "%s/rs_out.vtu", dir);
    snprintf(nowhere, sizeof nowhere, "%s/no/such/folder/x.obj", dir);
    CHECK(write_text(quad, QUAD));
    CHECK(write_text(bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"));

    CHECK(strncmp(ts_status_string(TS_STATUS_UNKNOWN_RENDER_SURFACE),
                  "TS_STATUS_UNKNOWN_RENDER_SURFACE", 32) == 0);

    ts_settings s;
    CHECK_OK(ts_settings_default(&s));
    ts_world *w = NULL;
    CHECK_OK(ts_world_new(&s, &w));
    ts_material m;
    CHECK_OK(ts_material_default(&m));
    build_cube();
    uint32_t body = 99;
    CHECK_OK(ts_world_add_body_from_arrays(w, nodes, NN, tets, NT, &m, NULL, &body));

    /* Adding: NULL, unknown body, bad scale, missing and malformed files. */
    uint32_t id = 77;
    CHECK_ST(ts_world_add_render_surface_from_file(NULL, body, quad, 1, &id),
             TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, NULL, 1, &id),
             TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, quad, 1, NULL),
             TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body + 1, quad, 1, &id),
             TS_STATUS_UNKNOWN_BODY);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, quad, 0, &id),
             TS_STATUS_INVALID_ARGUMENT);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, quad, NAN, &id),
             TS_STATUS_NON_FINITE);
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, nowhere, 1, &id),
             TS_STATUS_MESH_ERROR);
    CHECK(last_error_has("x.obj"));
    CHECK_ST(ts_world_add_render_surface_from_file(w, body, bad, 1, &id), TS_STATUS_MESH_ERROR);
    CHECK(last_error_has("rs_bad.obj:4:"));
    CHECK_ST(ts_world_add_render_surface_from_boundary(NULL, body, &id),
             TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_add_render_surface_from_boundary(w, body, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_add_render_surface_from_boundary(w, body + 1, &id), TS_STATUS_UNKNOWN_BODY);
    CHECK(id == 77); /* nothing written on failure */
    size_t count = 5;
    CHECK_ST(ts_world_render_surface_count(NULL, &count), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_world_render_surface_count(w, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_OK(ts_world_render_surface_count(w, &count));
    CHECK(count == 0);

    /* Success. */
    uint32_t quad_id = 77, hull_id = 77;
    CHECK_OK(ts_world_add_render_surface_from_file(w, body, quad, 1, &quad_id));
    CHECK_OK(ts_world_add_render_surface_from_boundary(w, body, &hull_id));
    CHECK(quad_id == 0 && hull_id == 1);
    CHECK_OK(ts_world_render_surface_count(w, &count));
    CHECK(count == 2);

    /* Counts. */
    size_t nv = 0, nt = 0;
    CHECK_ST(ts_render_surface_vertex_count(NULL, quad_id, &nv), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_vertex_count(w, quad_id, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_vertex_count(w, 2, &nv), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK(last_error_has("render surface id 2"));
    CHECK_ST(ts_render_surface_triangle_count(NULL, quad_id, &nt), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_triangle_count(w, quad_id, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_triangle_count(w, 9, &nt), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_OK(ts_render_surface_vertex_count(w, quad_id, &nv));
    CHECK_OK(ts_render_surface_triangle_count(w, quad_id, &nt));
    CHECK(nv == 4 && nt == 2);
    size_t hv = 0, ht = 0;
    CHECK_OK(ts_render_surface_vertex_count(w, hull_id, &hv));
    CHECK_OK(ts_render_surface_triangle_count(w, hull_id, &ht));
    CHECK(hv == 26 && ht == 6 * 2 * C * C); /* the 26 boundary nodes, 48 boundary triangles */

    /* Triangles. */
    uint32_t tri[6], tri_short[5];
    for (int i = 0; i < 5; i++) tri_short[i] = 12345;
    CHECK_ST(ts_render_surface_triangles(NULL, quad_id, tri, 6), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_triangles(w, quad_id, NULL, 6), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_triangles(w, 5, tri, 6), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_ST(ts_render_surface_triangles(w, quad_id, tri_short, 5), TS_STATUS_BUFFER_TOO_SMALL);
    CHECK(last_error_has("6 needed"));
    CHECK(tri_short[0] == 12345 && tri_short[4] == 12345);
    CHECK_OK(ts_render_surface_triangles(w, quad_id, tri, 6));
    CHECK(tri[0] == 0 && tri[1] == 1 && tri[2] == 2 && tri[3] == 0 && tri[4] == 2 && tri[5] == 3);

    /* Texture coordinates. */
    double uv[8], uv_short[7];
    for (int i = 0; i < 7; i++) uv_short[i] = -7;
    CHECK_ST(ts_render_surface_texcoords(NULL, quad_id, uv, 8), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_texcoords(w, quad_id, NULL, 8), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_texcoords(w, 3, uv, 8), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_ST(ts_render_surface_texcoords(w, quad_id, uv_short, 7), TS_STATUS_BUFFER_TOO_SMALL);
    CHECK(uv_short[0] == -7 && uv_short[6] == -7);
    CHECK_OK(ts_render_surface_texcoords(w, quad_id, uv, 8));
    CHECK(uv[0] == 0 && uv[1] == 0 && uv[2] == 1 && uv[3] == 0 && uv[4] == 1 && uv[5] == 1 &&
          uv[6] == 0 && uv[7] == 1);

    /* Update: at rest the quad is where the file put it, normal +z. */
    double p[12], n[12], p_short[11];
    for (int i = 0; i < 11; i++) p_short[i] = -3;
    CHECK_ST(ts_render_surface_update(NULL, quad_id, p, n, 12), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_update(w, quad_id, NULL, n, 12), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_update(w, quad_id, p, NULL, 12), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_update(w, 4, p, n, 12), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_ST(ts_render_surface_update(w, quad_id, p_short, n, 11), TS_STATUS_BUFFER_TOO_SMALL);
    CHECK(p_short[0] == -3 && p_short[10] == -3);
    CHECK_OK(ts_render_surface_update(w, quad_id, p, n, 12));
    CHECK(fabs(p[0] - 0.02) < 1e-15 && fabs(p[1] - 0.02) < 1e-15 && fabs(p[2] - 0.1) < 1e-15);
    CHECK(fabs(p[6] - 0.08) < 1e-15 && fabs(p[7] - 0.08) < 1e-15 && fabs(p[8] - 0.1) < 1e-15);
    for (int v = 0; v < 4; v++)
        CHECK(fabs(n[3 * v]) < 1e-12 && fabs(n[3 * v + 1]) < 1e-12 &&
              fabs(n[3 * v + 2] - 1) < 1e-12);

    /* After a few free-falling steps (gravity -y): the quad falls with the cube, its normals
     * stay unit +z. */
    double p0[12];
    memcpy(p0, p, sizeof p);
    for (int k = 0; k < 5; k++) CHECK_OK(ts_world_step(w, NULL));
    CHECK_OK(ts_render_surface_update(w, quad_id, p, n, 12));
    CHECK(p[1] < p0[1] - 1e-5);
    for (int v = 0; v < 4; v++)
        CHECK(fabs(sqrt(n[3 * v] * n[3 * v] + n[3 * v + 1] * n[3 * v + 1] +
                        n[3 * v + 2] * n[3 * v + 2]) -
                   1) < 1e-12 &&
              n[3 * v + 2] > 0.999);
    double hp[3 * 26], hn[3 * 26];
    CHECK_OK(ts_render_surface_update(w, hull_id, hp, hn, 3 * 26));

    /* Export. */
    CHECK_ST(ts_render_surface_write_obj(NULL, quad_id, out_obj), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_write_obj(w, quad_id, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_write_obj(w, 6, out_obj), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_ST(ts_render_surface_write_obj(w, quad_id, nowhere), TS_STATUS_IO_ERROR);
    CHECK(last_error_has("x.obj"));
    CHECK_OK(ts_render_surface_write_obj(w, quad_id, out_obj));
    CHECK_ST(ts_render_surface_write_vtu(NULL, hull_id, out_vtu), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_write_vtu(w, hull_id, NULL), TS_STATUS_NULL_PARAMETER);
    CHECK_ST(ts_render_surface_write_vtu(w, 6, out_vtu), TS_STATUS_UNKNOWN_RENDER_SURFACE);
    CHECK_ST(ts_render_surface_write_vtu(w, hull_id, nowhere), TS_STATUS_IO_ERROR);
    CHECK_OK(ts_render_surface_write_vtu(w, hull_id, out_vtu));

    /* The written OBJ (the fallen quad) reads back as a render surface with the same counts;
     * bound at rest and updated from the fallen cube, it has fallen twice: bp = 2 p - p0. */
    uint32_t back = 77;
    CHECK_OK(ts_world_add_render_surface_from_file(w, body, out_obj, 1, &back));
    size_t bv = 0;
    CHECK_OK(ts_render_surface_vertex_count(w, back, &bv));
    CHECK(back == 2 && bv == 4);
    double bp[12], bn[12];
    CHECK_OK(ts_render_surface_update(w, back, bp, bn, 12));
    for (int i = 0; i < 12; i++) CHECK(fabs(bp[i] - (2 * p[i] - p0[i])) < 1e-9);

    ts_world_free(w);
    remove(quad);
    remove(bad);
    remove(out_obj);
    remove(out_vtu);
    return check_summary();
}
