/*
 * B-rep models (px_brep.h) built in C (tests/support/brep_gen.h): every
 * answer against the tests' reference (tests/support/brep_ref.h: dense
 * sampling of each face restricted to its trimmed domain, of every edge
 * and the vertices, polished by Newton), never worse by more than 1e-9
 * of the part size and always a point of the trimmed model (so never
 * better than the true minimum); signs against the parts' exact inside tests, thin walls
 * included; the refusals with their messages; no heap calls in queries.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_gen.h"
#include "brep_ref.h"
#include "px_alloc_count.h"
#include "px_brep.h"
#include "px_cad.h"
#include "px_features.h"
#include "px_model.h"
#include "px_test.h"
#include "px_trim.h"

/* n random points against the reference; inside() (NULL: open part)
 * gives the exact side. */
static void run_part(struct brep_gen *g, int n, int (*inside)(px_vec3), int want_closed)
{
	struct px_brep_error err;
	struct px_brep *b;
	struct px_brep_info info;
	struct px_model *m;
	struct ref r;
	int i, rc;

	rc = px_brep_create(&g->d, NULL, &err, &b);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", g->d.name, err.msg);
	PX_CHECK(px_brep_get_info(b, &info) == PX_OK);
	PX_CHECK_MSG(info.closed == want_closed, "%s: closed %d: %s", g->d.name, info.closed,
		     info.why);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_BREP);
	PX_CHECK(strcmp(px_model_name(m), g->d.name) == 0);
	PX_CHECK(px_model_brep(m) == b);
	PX_CHECK_INT_EQ(!!(px_model_caps(m) & PX_MODEL_CAP_SIGNED), want_closed);
	ref_init(&r, &g->d);
	for (i = 0; i < n; i++) {
		px_vec3 p = ref_rand_point(&r, info.bounds);
		struct px_model_result a;
		double want, got;
		PX_CHECK_INT_EQ(px_model_query(m, p, &a), 1);
		got = fabs(a.distance);
		want = ref_dist(&r, p);
		PX_CHECK_MSG(got <= want + 1e-9 * r.size,
			     "%s point %d (%.17g, %.17g, %.17g): %.17g, reference %.17g "
			     "(feature %d index %d)",
			     g->d.name, i, p.x, p.y, p.z, got, want, a.feature, a.index);
		PX_CHECK(a.certified);
		check_on_model(&r, &a);
		PX_CHECK(fabs(px_v3_dist(p, a.point) - got) <= 1e-12 * r.size + 1e-12 * got);
		PX_CHECK_INT_EQ(a.is_signed, want_closed);
		if (inside && got > 1e-12 * r.size)
			PX_CHECK_MSG(a.inside == inside(p) && (a.distance < 0.0) == inside(p),
				     "%s point %d (%.17g, %.17g, %.17g): inside %d, want %d "
				     "(distance %g, feature %d index %d)",
				     g->d.name, i, p.x, p.y, p.z, a.inside, inside(p), a.distance,
				     a.feature, a.index);
	}
	ref_fini(&r);
	px_model_free(m);
}

static void test_sheet_hole(void)
{
	struct brep_gen *g = brep_gen_sheet_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_model_result a;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	/* Above the hole's middle: the circle edge (a ring of minima). */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.5, 0.5, 0.3), &a), 1);
	PX_CHECK_CLOSE(a.distance, hypot(0.25, 0.3), 1e-12, 0);
	PX_CHECK(a.feature == PX_FEATURE_CURVE || a.feature == PX_FEATURE_VERTEX);
	/* Above the sheet: the face, straight below. */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.1, 0.2, -0.3), &a), 1);
	PX_CHECK_CLOSE(a.distance, 0.3, 1e-14, 0);
	PX_CHECK_INT_EQ(a.feature, PX_FEATURE_SURFACE);
	PX_CHECK_INT_EQ(a.index, 0);
	PX_CHECK_CLOSE(a.u, 0.1, 1e-12, 0);
	PX_CHECK_CLOSE(a.v, 0.2, 1e-12, 0);
	/* Beside a corner: the vertex. */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(-0.1, -0.1, 0.0), &a), 1);
	PX_CHECK_CLOSE(a.distance, sqrt(0.02), 1e-14, 0);
	PX_CHECK_INT_EQ(a.feature, PX_FEATURE_VERTEX);
	px_model_free(m);
	run_part(g, 300, NULL, 0);
	free(g);
}

/* A hole across a C0 crease: the crease's curve pieces are crossed by
 * the hole and must not answer from inside it. */
static void test_roof_hole(void)
{
	struct brep_gen *g = brep_gen_roof_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_model_result a;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	/* Above the ridge in the hole's middle: the ridge point (0.5, 0.5,
	 * 0.2) is in the hole; the hole's rim is nearest. */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.5, 0.5, 0.5), &a), 1);
	PX_CHECK(a.distance > 0.3 + 1e-3);
	PX_CHECK(a.feature != PX_FEATURE_SURFACE);
	/* Above the ridge outside the hole: on the crease. */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.5, 0.1, 0.5), &a), 1);
	PX_CHECK_CLOSE(a.distance, 0.3, 1e-12, 0);
	PX_CHECK_INT_EQ(a.feature, PX_FEATURE_SURFACE);
	px_model_free(m);
	run_part(g, 250, NULL, 0);
	free(g);
}

static int cube_hole_inside(px_vec3 p)
{
	return p.x > 0 && p.x < 1 && p.y > 0 && p.y < 1 && p.z > 0 && p.z < 1 &&
	       hypot(p.x - 0.5, p.y - 0.5) > 0.2;
}

static void test_cube_hole(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	run_part(g, 400, cube_hole_inside, 1);
	free(g);
}

static void test_freeform(void)
{
	struct brep_gen *g = brep_gen_freeform();
	run_part(g, 250, NULL, 0);
	free(g);
}

static int thin_inside(px_vec3 p)
{
	int in_outer = p.x > 0 && p.x < 0.1 && p.y > 0 && p.y < 0.1 && p.z > 0 && p.z < 0.1;
	int in_void = p.x > 0.001 && p.x < 0.099 && p.y > 0.001 && p.y < 0.099 &&
		      p.z > 0.001 && p.z < 0.099;
	return in_outer && !in_void;
}

static void test_thin_box(void)
{
	struct brep_gen *g = brep_gen_thin_box();
	struct px_brep *b;
	struct px_model *m;
	struct px_model_result a;
	int i;
	run_part(g, 300, thin_inside, 1);
	/* Through a wall along x at mid height: outside, in the wall,
	 * in the void, in the far wall, outside. */
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	for (i = 0; i <= 1040; i++) {
		double x = -0.002 + 0.0001 * i + 0.000037;
		px_vec3 p = px_v3(x, 0.0431, 0.0573);
		PX_CHECK_INT_EQ(px_model_query(m, p, &a), 1);
		PX_CHECK_MSG(a.inside == thin_inside(p), "x = %.17g: inside %d", x, a.inside);
	}
	px_model_free(m);
	free(g);
}

/* The shipped STEP part (a filleted block with a drilled hole, read by
 * px_cad): closed and signed (its fillet corners have collapsed loop
 * curves); distances against the reference in the file's millimetres;
 * along random lines the sign changes only where the distance passes
 * through zero (a wrong side anywhere would be a jump). */
static void test_step_block(void)
{
	struct px_cad *c;
	struct px_brep *b;
	struct px_brep_info info;
	struct px_model *m;
	struct px_brep_error err;
	const struct px_brep_desc *d;
	struct ref r;
	char path[512], msg[256];
	double sc;
	int i, k, flips = 0;

	PX_NEEDS(OCCT);
	px_test_data_path(path, sizeof(path), "../../config/examples/parts/filleted_block.step");
	PX_CHECK_MSG(px_cad_load(path, NULL, &c, msg, sizeof(msg)) == PX_OK, "%s", msg);
	d = px_cad_desc(c);
	sc = d->scale;
	PX_CHECK_MSG(px_brep_create(d, NULL, &err, &b) == PX_OK, "%s", err.msg);
	px_brep_get_info(b, &info);
	PX_CHECK_MSG(info.closed, "%s", info.why);
	PX_CHECK(info.n_point_cands > 0);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	ref_init(&r, d);
	for (i = 0; i < 60; i++) {
		px_vec3 p = ref_rand_point(&r, (px_aabb){px_v3_scale(info.bounds.min, 1.0 / sc),
						     px_v3_scale(info.bounds.max, 1.0 / sc)});
		struct px_model_result a;
		double want;
		PX_CHECK_INT_EQ(px_model_query(m, px_v3_scale(p, sc), &a), 1);
		want = ref_dist(&r, p) * sc;
		PX_CHECK_MSG(fabs(a.distance) <= want + 1e-9 * r.size * sc,
			     "point %d: %.17g, reference %.17g (feature %d index %d)", i,
			     fabs(a.distance), want, a.feature, a.index);
		PX_CHECK(a.certified);
		PX_CHECK(a.is_signed);
	}
	for (i = 0; i < 60; i++) {
		px_vec3 lo = info.bounds.min, e = px_v3_sub(info.bounds.max, lo), o, dir;
		double h = 2e-4 * px_v3_norm(e), prev = 0.0;
		o = px_v3(lo.x + e.x * px_rand_range(-0.1, 1.1), lo.y + e.y * px_rand_range(-0.1, 1.1),
			  lo.z + e.z * px_rand_range(-0.1, 1.1));
		dir = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1), px_rand_range(-1, 1));
		dir = px_v3_scale(dir, h / px_v3_norm(dir));
		for (k = 0; k < 400; k++) {
			struct px_model_result a;
			PX_CHECK_INT_EQ(px_model_query(m, px_v3_madd(o, dir, k), &a), 1);
			if (k > 0 && (a.distance < 0.0) != (prev < 0.0)) {
				flips++;
				PX_CHECK_MSG(fabs(a.distance) + fabs(prev) <= 1.001 * h,
					     "line %d step %d: %g then %g", i, k, prev, a.distance);
			}
			prev = a.distance;
		}
	}
	PX_CHECK(flips > 0);
	ref_fini(&r);
	px_model_free(m);
	px_cad_free(c);
}

/* ---- refusals ------------------------------------------------------------------- */

static void expect_refusal(const struct px_brep_desc *d, int code, const char *part)
{
	struct px_brep_error err;
	struct px_brep *b = (struct px_brep *)(void *)&err;
	int rc = px_brep_create(d, NULL, &err, &b);
	PX_CHECK_MSG(rc == code, "code %d, want %d: %s", rc, code, err.msg);
	PX_CHECK(b == NULL);
	PX_CHECK_INT_EQ(err.code, code);
	PX_CHECK_MSG(strstr(err.msg, part) != NULL, "message \"%s\" lacks \"%s\"", err.msg,
		     part);
}

static void test_refusals(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	struct px_brep_desc d = g->d;
	struct px_brep_face_desc faces[BG_MAXF];
	struct px_brep_edge_desc edges[BG_MAXE];
	struct px_brep_coedge co[4];
	const struct px_brep_coedge *cop[BG_MAXL];
	struct px_trim_loop loops[BG_MAXL];
	struct px_nurbs_curve lc[4];
	struct px_brep_shell_desc sh[2];

	d.scale = 0.0;
	expect_refusal(&d, PX_E_INVAL, "scale");
	d.scale = NAN;
	expect_refusal(&d, PX_E_INVAL, "scale");
	d.scale = 1.0;

	/* A coedge naming an edge that does not exist. */
	memcpy(faces, g->faces, sizeof(faces));
	memcpy(co, g->co[2][0], sizeof(co));
	co[1].edge = 99;
	memcpy(cop, g->cop[2], sizeof(cop));
	cop[0] = co;
	faces[2].coedges = cop;
	d.faces = faces;
	expect_refusal(&d, PX_E_INVAL, "face 2 (id 102): loop 0 curve 1: edge 99 out of range");
	d = g->d;

	/* An edge's vertex out of range. */
	memcpy(edges, g->edges, sizeof(edges));
	edges[3].v1 = 40;
	d.edges = edges;
	expect_refusal(&d, PX_E_INVAL, "edge 3");
	d = g->d;

	/* An open loop: one side of face 3 moved off its corner. */
	memcpy(faces, g->faces, sizeof(faces));
	memcpy(loops, g->loops[3], sizeof(loops));
	memcpy(lc, g->lc[3][0], sizeof(lc));
	lc[2] = bg_line(g, px_v3(1, 1, 0), px_v3(0.2, 1, 0));
	loops[0].curves = lc;
	faces[3].loops = loops;
	d.faces = faces;
	expect_refusal(&d, PX_E_INVAL, "face 3 (id 103)");
	d = g->d;

	/* A face whose loop encloses no area. */
	memcpy(faces, g->faces, sizeof(faces));
	memcpy(loops, g->loops[4], sizeof(loops));
	lc[0] = bg_line(g, px_v3(0, 0, 0), px_v3(1, 0, 0));
	lc[1] = bg_line(g, px_v3(1, 0, 0), px_v3(0, 0, 0));
	loops[0].curves = lc;
	loops[0].n_curves = 2;
	loops[0].reversed = NULL;
	faces[4].loops = loops;
	faces[4].n_loops = 1;
	d.faces = faces;
	expect_refusal(&d, PX_E_DEGENERATE, "face 4 (id 104)");
	d = g->d;

	/* A loop curve without a 3D edge that is not a point. */
	memcpy(faces, g->faces, sizeof(faces));
	memcpy(co, g->co[5][0], sizeof(co));
	co[0].edge = -1;
	memcpy(cop, g->cop[5], sizeof(cop));
	cop[0] = co;
	faces[5].coedges = cop;
	d.faces = faces;
	expect_refusal(&d, PX_E_INVAL, "face 5 (id 105): loop 0 curve 0 has no 3D edge");
	d = g->d;

	/* A shell in a solid that does not exist; a face in no shell. */
	sh[0] = g->shells[0];
	sh[0].solid = 3;
	d.shells = sh;
	expect_refusal(&d, PX_E_INVAL, "shell 0");
	d = g->d;
	memcpy(faces, g->faces, sizeof(faces));
	faces[1].shell = 5;
	d.faces = faces;
	expect_refusal(&d, PX_E_INVAL, "face 1 (id 101): shell 5");
	d = g->d;

	/* A bad surface: the kernel's message, with the face. */
	memcpy(faces, g->faces, sizeof(faces));
	faces[0].surf.n_knots[0] = 3;
	d.faces = faces;
	expect_refusal(&d, PX_E_INVAL, "face 0 (id 100): surface");
	d = g->d;

	d.n_faces = 0;
	expect_refusal(&d, PX_E_INVAL, "no faces");
	free(g);
}

/* An open box (a face left out) and a box with one face turned are
 * answered unsigned, saying why. */
static void test_unsigned_why(void)
{
	struct brep_gen *g = brep_gen_thin_box();
	struct px_brep_desc d = g->d;
	struct px_brep_face_desc faces[BG_MAXF];
	struct px_brep *b;
	struct px_brep_info info;

	memcpy(faces, g->faces, sizeof(faces));
	faces[2].reversed = !faces[2].reversed;
	d.faces = faces;
	PX_CHECK_INT_EQ(px_brep_create(&d, NULL, NULL, &b), PX_OK);
	px_brep_get_info(b, &info);
	PX_CHECK(!info.closed);
	PX_CHECK_MSG(strstr(info.why, "disagree") != NULL, "%s", info.why);
	px_brep_free(b);

	d = g->d;
	d.n_faces = 5; /* the outer box without its y sides' last face */
	PX_CHECK_INT_EQ(px_brep_create(&d, NULL, NULL, &b), PX_OK);
	px_brep_get_info(b, &info);
	PX_CHECK(!info.closed);
	PX_CHECK_MSG(strstr(info.why, "edge") != NULL, "%s", info.why);
	px_brep_free(b);

	d = g->d;
	d.scale = 1000.0; /* millimetres in, metres out: scaled, still closed */
	PX_CHECK_INT_EQ(px_brep_create(&d, NULL, NULL, &b), PX_OK);
	px_brep_get_info(b, &info);
	PX_CHECK(info.closed);
	PX_CHECK_CLOSE(info.bounds.max.x, 100.0, 1e-9, 0);
	px_brep_free(b);
	free(g);
}

/* Queries make no heap calls. */
static void test_no_alloc(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	struct px_brep *b;
	struct px_model *m;
	uint64_t a;
	int i, sum = 0;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	a = px_alloc_region_begin();
	for (i = 0; i < 3000; i++) {
		struct px_model_result r;
		px_vec3 p = px_v3(px_rand_range(-0.5, 1.5), px_rand_range(-0.5, 1.5),
				  px_rand_range(-0.5, 1.5));
		sum += px_model_query(m, p, &r);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	PX_CHECK_INT_EQ(sum, 3000);
	px_model_free(m);
	free(g);
}

static const struct px_test tests[] = {
	PX_T(test_sheet_hole), PX_T(test_roof_hole),	PX_T(test_cube_hole),
	PX_T(test_freeform),
	PX_T(test_thin_box),   PX_T(test_step_block),	PX_T(test_refusals),
	PX_T(test_unsigned_why), PX_T(test_no_alloc)};
PX_TEST_MAIN(tests)
