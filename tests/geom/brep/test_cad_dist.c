/* PX_TEST_NEEDS: occt (tests/run.sh skips it in builds without OpenCASCADE) */
/*
 * Distances to the CAD parts of proxima-cadgen (a filleted block with a
 * drilled hole, a plate with holes and a pocket, a bottle with 1 mm
 * walls, a trimmed free-form sheet with a hole, a fused cylinder and
 * sphere) read from STEP and IGES by px_cad and queried as px_brep
 * models, against the tests' reference (tests/support/brep_ref.h: dense
 * samples of each face inside its trimmed domain, of the edges and
 * vertices, polished by Newton) and OpenCASCADE (px_occt_ref.h): its
 * solid classifier gives the sign, its projection and face classifier
 * say that the answer's point lies on the part as it reads it.
 *
 * Random points (in and around the box, near faces on both sides, near
 * edges, far): the distance within 1e-9 of the part size of the
 * reference, both ways; every sign right away from the surface (1e-7 of
 * the size). Paths: smooth paths that slide over the largest faces
 * (on them and just off both sides, past their edges and holes), lines
 * through the holes, the pocket and the bottle's 1 mm walls, and a
 * smooth random path through each part: at every step the answer above,
 * and the signed distance continuous (it moves by no more than the
 * point). A tracked stream (px_model_stream_create()) on the same path
 * is compared with the global answer at every step where the model
 * gives one. No heap calls in queries.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_brep.h"
#include "px_cad.h"
#include "px_features.h"
#include "px_model.h"
#include "px_test.h"
#include "px_test_cad.h"

#if PX_HAVE_OCCT
#include "brep_ref.h"
#include "px_occt_ref.h"

/* Sanitizer builds run a quarter of the points and steps. */
#if defined(__SANITIZE_ADDRESS__)
#define SLOW 4
#else
#define SLOW 1
#endif

/* A part as px_cad reads it (millimetres) and its model (metres). */
struct part {
	char path[512];
	struct px_cad *cad;
	const struct px_brep_desc *d;
	struct px_model *m;
	struct px_occt_ref *occt;
	struct ref r;
	px_aabb box;  /* millimetres */
	double sc;    /* metres per millimetre */
	double size;  /* millimetres */
	int closed;
	/* what was checked */
	long n_answers, n_signs;
	double worst; /* largest |answer - reference| / size */
};

static void part_open(struct part *pt, const char *name, const char *ext)
{
	struct px_brep_error err;
	struct px_brep_info info;
	struct px_brep *b = NULL;
	char msg[512];
	int rc;
	memset(pt, 0, sizeof(*pt));
	px_test_cad_path(pt->path, sizeof pt->path, name, ext);
	rc = px_cad_load(pt->path, NULL, &pt->cad, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", pt->path, msg);
	pt->d = px_cad_desc(pt->cad);
	pt->sc = pt->d->scale;
	rc = px_brep_create(pt->d, NULL, &err, &b);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", pt->path, err.msg);
	PX_CHECK_INT_EQ(px_brep_get_info(b, &info), PX_OK);
	pt->closed = info.closed;
	pt->box.min = px_v3_scale(info.bounds.min, 1.0 / pt->sc);
	pt->box.max = px_v3_scale(info.bounds.max, 1.0 / pt->sc);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &pt->m), PX_OK);
	PX_CHECK_MSG(px_occt_ref_open(pt->path, -1, &pt->occt) == 0, "reference: %s", pt->path);
	PX_CHECK_INT_EQ(px_occt_ref_face_count(pt->occt), pt->d->n_faces);
	ref_init(&pt->r, pt->d);
	pt->size = pt->r.size;
}

static void part_close(struct part *pt)
{
	printf("  %s: %ld answers within %.2g of the size of the reference, %ld signs\n",
	       strrchr(pt->path, '/') + 1, pt->n_answers, pt->worst, pt->n_signs);
	ref_fini(&pt->r);
	px_occt_ref_free(pt->occt);
	px_model_free(pt->m);
	px_cad_free(pt->cad);
}

static px_vec3 to_m(const struct part *pt, px_vec3 q)
{
	return px_v3_scale(q, pt->sc);
}

/* The answer's point lies on the part as OpenCASCADE reads it: on the
 * face it names, inside that face (its own face classifier), or on an
 * edge; elsewhere (a pole) within reach of the part by projection. */
static void check_on_occt(const struct part *pt, const struct px_model_result *a, px_vec3 x)
{
	double p[3] = {x.x, x.y, x.z}, tol = 3e-9 * pt->size, g;
	if (a->feature == PX_FEATURE_SURFACE) {
		g = px_occt_ref_surf_dist(pt->occt, a->index, p);
		PX_CHECK_MSG(g >= 0 && g <= tol, "%s face %d: answer %g off its surface",
			     pt->path, a->index, g);
		PX_CHECK_MSG(px_occt_ref_face_state(pt->occt, a->index, p, 1e-7) != 0,
			     "%s face %d: answer (%g, %g) outside the face for OpenCASCADE",
			     pt->path, a->index, a->u, a->v);
		return;
	}
	g = a->feature == PX_FEATURE_CURVE || a->index >= 0 ? px_occt_ref_edge_dist(pt->occt, p)
							     : px_occt_ref_gap(pt->occt, p, 1e-7);
	PX_CHECK_MSG(g <= tol, "%s: answer (feature %d index %d) %g off the part's edges",
		     pt->path, a->feature, a->index, g);
}

/* One answer a at q (millimetres): distance, point, sign. */
static void check_answer(struct part *pt, px_vec3 q, const struct px_model_result *a)
{
	struct px_model_result mm = *a;
	double got = fabs(a->distance) / pt->sc, want = ref_dist(&pt->r, q);
	double tol = 1e-9 * pt->size;
	int st;
	mm.point = px_v3_scale(a->point, 1.0 / pt->sc);
	PX_CHECK_MSG(fabs(got - want) <= tol,
		     "%s at (%.17g, %.17g, %.17g): %.17g, reference %.17g (feature %d index "
		     "%d at %.9g %.9g %.9g)",
		     pt->path, q.x, q.y, q.z, got, want, a->feature, a->index, mm.point.x,
		     mm.point.y, mm.point.z);
	pt->worst = fmax(pt->worst, fabs(got - want) / pt->size);
	pt->n_answers++;
	PX_CHECK(a->certified);
	check_on_model(&pt->r, &mm);
	check_on_occt(pt, a, mm.point);
	PX_CHECK(fabs(px_v3_dist(q, mm.point) - got) <= 1e-12 * pt->size + 1e-12 * got);
	PX_CHECK_INT_EQ(a->is_signed, pt->closed);
	if (!pt->closed || got <= 1e-7 * pt->size)
		return;
	st = px_occt_ref_solid_state(pt->occt, (double[3]){q.x, q.y, q.z}, 1e-8 * pt->size);
	if (st == 2)
		return;
	PX_CHECK_MSG(a->inside == st && (a->distance < 0) == st,
		     "%s at (%.17g, %.17g, %.17g): inside %d, OpenCASCADE %d (distance %g, "
		     "feature %d index %d)",
		     pt->path, q.x, q.y, q.z, a->inside, st, got, a->feature, a->index);
	pt->n_signs++;
}

static struct px_model_result query(const struct part *pt, px_vec3 q)
{
	struct px_model_result a;
	PX_CHECK_INT_EQ(px_model_query(pt->m, to_m(pt, q), &a), 1);
	return a;
}

/* n random points of every kind; then the same points again counting
 * heap calls. */
static void random_points(struct part *pt, int n)
{
	px_vec3 *q = malloc(sizeof(*q) * (size_t)n);
	struct px_model_result a;
	uint64_t c;
	int i, sum = 0;
	PX_CHECK(q != NULL);
	for (i = 0; i < n; i++) {
		q[i] = ref_rand_point(&pt->r, pt->box);
		a = query(pt, q[i]);
		check_answer(pt, q[i], &a);
	}
	c = px_alloc_region_begin();
	for (i = 0; i < n; i++)
		sum += px_model_query(pt->m, to_m(pt, q[i]), &a);
	PX_CHECK_INT_EQ(px_alloc_region_end(c), 0);
	PX_CHECK_INT_EQ(sum, n);
	free(q);
}

/* ---- paths -------------------------------------------------------------- */

struct path {
	struct part *pt;
	struct px_model_stream *stream; /* NULL: the model tracks nothing */
	px_vec3 prev;
	double prev_d;
	int steps;
};

static void path_begin(struct path *w, struct part *pt)
{
	int rc;
	memset(w, 0, sizeof(*w));
	w->pt = pt;
	rc = px_model_stream_create(pt->m, NULL, &w->stream);
	PX_CHECK_MSG(rc == PX_OK || rc == PX_E_UNSUPPORTED, "stream: %s", px_strerror(rc));
}

static void path_end(struct path *w)
{
	px_model_stream_free(w->stream);
}

/* A tracked stream's answer at the same step equals the global one. */
static void check_tracked(struct path *w, px_vec3 q, const struct px_model_result *a)
{
	struct px_model_result t;
	if (!w->stream)
		return;
	PX_CHECK_INT_EQ(px_model_stream_query(w->stream, to_m(w->pt, q), INFINITY, 0, &t, NULL),
			1);
	PX_CHECK_MSG(fabs(t.distance - a->distance) <= 1e-9 * w->pt->size * w->pt->sc,
		     "%s step %d at (%.17g, %.17g, %.17g): tracked %.17g, global %.17g",
		     w->pt->path, w->steps, q.x, q.y, q.z, t.distance, a->distance);
}

/* One step of a path to q (millimetres). */
static void path_step(struct path *w, px_vec3 q)
{
	struct part *pt = w->pt;
	struct px_model_result a = query(pt, q);
	double d = a.distance / pt->sc;
	check_answer(pt, q, &a);
	check_tracked(w, q, &a);
	if (w->steps > 0)
		PX_CHECK_MSG(fabs(d - w->prev_d) <= px_v3_dist(q, w->prev) + 1e-9 * pt->size,
			     "%s step %d at (%.17g, %.17g, %.17g): distance %.17g after %.17g, "
			     "moved %g",
			     pt->path, w->steps, q.x, q.y, q.z, d, w->prev_d, px_v3_dist(q, w->prev));
	w->prev = q;
	w->prev_d = d;
	w->steps++;
}

/* The straight line a -> b in n steps. */
static void line_path(struct part *pt, px_vec3 a, px_vec3 b, int n)
{
	struct path w;
	int i;
	n /= SLOW;
	path_begin(&w, pt);
	for (i = 0; i <= n; i++)
		path_step(&w, px_v3_lerp(a, b, (double)i / n));
	path_end(&w);
}

/* Along a line through the middle of face f's parameter domain (to its
 * border, so past the face's own edges and through its holes), the
 * surface point moved by h along the outward normal. */
static void slide_path(struct part *pt, int f, double h, int n)
{
	const struct px_brep_face_desc *fd = &pt->d->faces[f];
	double u0, u1, v0, v1, a = px_rand_range(0, 2 * M_PI), du, dv, t;
	px_vec3 nrm = px_v3(0, 0, 0);
	struct path w;
	int i;
	n /= SLOW;
	px_nurbs_surf_domain(&fd->surf, &u0, &u1, &v0, &v1);
	du = cos(a) * (u1 - u0), dv = sin(a) * (v1 - v0);
	t = 0.5 / fmax(fabs(cos(a)), fabs(sin(a)));
	path_begin(&w, pt);
	for (i = 0; i <= n; i++) {
		double s = t * (2.0 * i / n - 1.0);
		double u = fmin(fmax(0.5 * (u0 + u1) + s * du, u0), u1);
		double v = fmin(fmax(0.5 * (v0 + v1) + s * dv, v0), v1);
		struct px_nurbs_surf_derivs dd;
		px_vec3 c;
		px_nurbs_surf_eval(&fd->surf, u, v, 1, &dd);
		c = px_v3_cross(dd.su, dd.sv);
		if (px_v3_norm(c) > 1e-12 * px_v3_norm(dd.su) * px_v3_norm(dd.sv) &&
		    px_v3_norm(c) > 0) /* else a pole: the last normal */
			nrm = px_v3_scale(c, (fd->reversed ? -1.0 : 1.0) / px_v3_norm(c));
		path_step(&w, px_v3_madd(dd.s, nrm, h));
	}
	path_end(&w);
}

/* A smooth random path through and around the part. */
static void wander_path(struct part *pt, int n)
{
	px_vec3 c = px_v3_scale(px_v3_add(pt->box.min, pt->box.max), 0.5);
	px_vec3 e = px_v3_scale(px_v3_sub(pt->box.max, pt->box.min), 0.5);
	double amp[3][3], w[3][3], ph[3][3];
	struct path wk;
	int i, j, k;
	n /= SLOW;
	for (j = 0; j < 3; j++)
		for (k = 0; k < 3; k++) {
			amp[j][k] = px_rand_range(-0.6, 0.6) / (k + 1);
			w[j][k] = (k + 1) * px_rand_range(0.7, 1.3);
			ph[j][k] = px_rand_range(0, 2 * M_PI);
		}
	path_begin(&wk, pt);
	for (i = 0; i <= n; i++) {
		double t = 2 * M_PI * i / n, o[3] = {0, 0, 0};
		for (j = 0; j < 3; j++)
			for (k = 0; k < 3; k++)
				o[j] += amp[j][k] * sin(w[j][k] * t + ph[j][k]);
		path_step(&wk, px_v3(c.x + o[0] * e.x, c.y + o[1] * e.y, c.z + o[2] * e.z));
	}
	path_end(&wk);
}

/* Slides over the k faces with the most samples (the largest in their
 * parameter domain): on them, just outside and just inside. */
static void slide_largest(struct part *pt, int k, int n)
{
	int used[64] = {0}, j, f;
	for (j = 0; j < k; j++) {
		int best = -1;
		for (f = 0; f < pt->d->n_faces && f < 64; f++)
			if (!used[f] && (best < 0 || pt->r.face[f].n_in > pt->r.face[best].n_in))
				best = f;
		if (best < 0)
			best = j % pt->d->n_faces;
		used[best] = 1;
		slide_path(pt, best, 2e-3 * pt->size, n);
		slide_path(pt, best, -2e-3 * pt->size, n);
		slide_path(pt, best, 0.0, n);
	}
}

/* ---- the parts ----------------------------------------------------------- */

static void random_each(const char *name, int n)
{
	struct part pt;
	part_open(&pt, name, "step");
	random_points(&pt, n / SLOW);
	part_close(&pt);
	part_open(&pt, name, "iges");
	random_points(&pt, n / 4 / SLOW);
	part_close(&pt);
}

static void test_random_block(void)
{
	random_each("filleted_block", 240);
}

static void test_random_plate(void)
{
	random_each("plate", 240);
}

static void test_random_bottle(void)
{
	random_each("bottle", 240);
}

static void test_random_sheet(void)
{
	random_each("sheet", 240);
}

static void test_random_cylsphere(void)
{
	random_each("cylsphere", 240);
}

static void test_paths_block(void)
{
	struct part pt;
	part_open(&pt, "filleted_block", "step");
	slide_largest(&pt, 3, 120);
	/* across the block through the drilled hole, then up its axis */
	line_path(&pt, px_v3(-5, 20.3, 10), px_v3(65, 20.3, 10), 400);
	line_path(&pt, px_v3(30.2, 20, -5), px_v3(30.2, 20, 25), 200);
	/* over a filleted corner */
	line_path(&pt, px_v3(-3, -3, 25), px_v3(10, 8, 15), 200);
	wander_path(&pt, 300);
	part_close(&pt);
}

static void test_paths_plate(void)
{
	struct part pt;
	part_open(&pt, "plate", "step");
	slide_largest(&pt, 3, 120);
	/* down a hole's axis, across the pocket and two holes */
	line_path(&pt, px_v3(10.5, 10, -3), px_v3(10.5, 10, 11), 200);
	line_path(&pt, px_v3(-5, 30.5, 6), px_v3(105, 30.5, 6), 500);
	line_path(&pt, px_v3(-5, 10.5, 4), px_v3(105, 10.5, 4), 500);
	wander_path(&pt, 300);
	part_close(&pt);
}

static void test_paths_bottle(void)
{
	struct part pt;
	part_open(&pt, "bottle", "step");
	slide_largest(&pt, 3, 120);
	/* through both walls of the body, the bottom and the neck */
	line_path(&pt, px_v3(-24, 0.3, 30), px_v3(24, 0.3, 30), 1200);
	line_path(&pt, px_v3(0.3, 0.2, -3), px_v3(0.3, 0.2, 8), 400);
	line_path(&pt, px_v3(-12, 0, 70), px_v3(12, 0.5, 66), 600);
	/* through the filleted shoulder, slanted */
	line_path(&pt, px_v3(-10, -3, 64), px_v3(-24, -5, 50), 500);
	wander_path(&pt, 300);
	part_close(&pt);
}

static void test_paths_sheet(void)
{
	struct part pt;
	part_open(&pt, "sheet", "step");
	slide_largest(&pt, 2, 160);
	/* through the hole and past the outer loop */
	line_path(&pt, px_v3(44, 30, -15), px_v3(44, 30, 15), 200);
	line_path(&pt, px_v3(-10, 30, 1), px_v3(90, 30.5, 1), 500);
	wander_path(&pt, 300);
	part_close(&pt);
}

static void test_paths_cylsphere(void)
{
	struct part pt;
	part_open(&pt, "cylsphere", "step");
	slide_largest(&pt, 3, 120);
	/* up the axis through the bottom and the pole; across the seam and
	 * the junction of cylinder and sphere */
	line_path(&pt, px_v3(0, 0, -5), px_v3(0, 0, 60), 400);
	line_path(&pt, px_v3(-20, 0, 30), px_v3(20, 0, 30), 300);
	line_path(&pt, px_v3(-20, 0.1, 28.9), px_v3(20, 0.1, 28.9), 300);
	line_path(&pt, px_v3(15, -8, 20), px_v3(5, 8, 36), 300);
	wander_path(&pt, 300);
	part_close(&pt);
}

static void test_cleanup(void)
{
	px_test_cad_cleanup();
	PX_CHECK(1);
}

static const struct px_test tests[] = {
	PX_T(test_random_block),  PX_T(test_random_plate), PX_T(test_random_bottle),
	PX_T(test_random_sheet),  PX_T(test_random_cylsphere),
	PX_T(test_paths_block),	  PX_T(test_paths_plate),  PX_T(test_paths_bottle),
	PX_T(test_paths_sheet),	  PX_T(test_paths_cylsphere),
	PX_T(test_cleanup)};
#else
static void test_cad_dist_absent(void)
{
	PX_NEEDS(OCCT);
}
static const struct px_test tests[] = {PX_T(test_cad_dist_absent)};
#endif
PX_TEST_MAIN(tests)
