/*
 * B-rep models (px_brep.h) built in C (tests/support/brep_gen.h): every
 * answer against a reference written here (dense sampling of each face
 * restricted to its trimmed domain, of every edge and the vertices,
 * polished by Newton), never worse by more than 1e-9 of the part size
 * and always a point of the trimmed model (so never better than the true
 * minimum); signs against the parts' exact inside tests, thin walls
 * included; the refusals with their messages; no heap calls in queries.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_gen.h"
#include "px_alloc_count.h"
#include "px_brep.h"
#include "px_cad.h"
#include "px_features.h"
#include "px_model.h"
#include "px_test.h"
#include "px_trim.h"

/* ---- the reference ----------------------------------------------------------- */

struct ref {
	const struct px_brep_desc *d;
	struct px_trim **trim; /* per face */
	double size;
};

static void ref_init(struct ref *r, const struct px_brep_desc *d)
{
	px_aabb b = px_aabb_empty();
	int f, i;
	memset(r, 0, sizeof(*r));
	r->d = d;
	r->trim = calloc((size_t)d->n_faces, sizeof(*r->trim));
	PX_CHECK(r->trim != NULL);
	for (f = 0; f < d->n_faces; f++) {
		px_aabb sb;
		PX_CHECK(px_trim_create(d->faces[f].loops, d->faces[f].n_loops, NULL, NULL,
					&r->trim[f]) == PX_OK);
		sb = px_nurbs_surf_aabb(&d->faces[f].surf);
		b = px_aabb_union(&b, &sb);
	}
	for (i = 0; i < d->n_vertices; i++)
		px_aabb_extend(&b, d->vertices[i]);
	r->size = px_aabb_diagonal(&b);
}

static void ref_fini(struct ref *r)
{
	int f;
	for (f = 0; f < r->d->n_faces; f++)
		px_trim_free(r->trim[f]);
	free(r->trim);
}

/* Newton on |S(u, v) - p|^2 from (u, v), inside the domain; the best
 * point met that lies inside the trimmed domain lowers *best. */
static void polish_face(const struct ref *r, int f, px_vec3 p, double u, double v,
			double *best)
{
	const struct px_nurbs_surf *s = &r->d->faces[f].surf;
	double u0, u1, v0, v1;
	int it;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (it = 0; it < 30; it++) {
		struct px_nurbs_surf_derivs dd;
		px_vec3 e;
		double g0, g1, h00, h01, h11, det, du, dv;
		px_nurbs_surf_eval(s, u, v, 2, &dd);
		e = px_v3_sub(dd.s, p);
		if (px_trim_contains(r->trim[f], u, v, NULL) == PX_TRIM_INSIDE &&
		    px_v3_dot(e, e) < *best)
			*best = px_v3_dot(e, e);
		g0 = px_v3_dot(e, dd.su);
		g1 = px_v3_dot(e, dd.sv);
		h00 = px_v3_dot(dd.su, dd.su) + px_v3_dot(e, dd.suu);
		h01 = px_v3_dot(dd.su, dd.sv) + px_v3_dot(e, dd.suv);
		h11 = px_v3_dot(dd.sv, dd.sv) + px_v3_dot(e, dd.svv);
		det = h00 * h11 - h01 * h01;
		if (!(det > 0.0 && h00 > 0.0)) {
			h00 = px_v3_dot(dd.su, dd.su);
			h01 = px_v3_dot(dd.su, dd.sv);
			h11 = px_v3_dot(dd.sv, dd.sv);
			det = h00 * h11 - h01 * h01;
			if (!(det > 0.0))
				break;
		}
		du = -(h11 * g0 - h01 * g1) / det;
		dv = -(h00 * g1 - h01 * g0) / det;
		u = fmin(fmax(u + du, u0), u1);
		v = fmin(fmax(v + dv, v0), v1);
		if (fabs(du) + fabs(dv) < 1e-15)
			break;
	}
}

static void polish_curve(const struct px_nurbs_curve *c, px_vec3 p, double t, double *best)
{
	double t0, t1;
	int it;
	px_nurbs_curve_domain(c, &t0, &t1);
	for (it = 0; it < 30; it++) {
		px_vec3 d[3], e;
		double g, h, dt;
		px_nurbs_curve_eval(c, t, 2, d);
		e = px_v3_sub(d[0], p);
		if (px_v3_dot(e, e) < *best)
			*best = px_v3_dot(e, e);
		g = px_v3_dot(e, d[1]);
		h = px_v3_dot(d[1], d[1]) + px_v3_dot(e, d[2]);
		if (!(h > 0.0))
			h = px_v3_dot(d[1], d[1]);
		if (!(h > 0.0))
			break;
		dt = -g / h;
		t = fmin(fmax(t + dt, t0), t1);
		if (fabs(dt) < 1e-15)
			break;
	}
}

/* Reference distance from p to the trimmed model. */
static double ref_dist(const struct ref *r, px_vec3 p)
{
	const struct px_brep_desc *d = r->d;
	const int N = 64, K = 4;
	double best = INFINITY;
	int f, e, i, j, k;
	for (f = 0; f < d->n_faces; f++) {
		const struct px_nurbs_surf *s = &d->faces[f].surf;
		double u0, u1, v0, v1, kd[4], ku[4], kv[4];
		px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
		for (k = 0; k < K; k++)
			kd[k] = INFINITY, ku[k] = kv[k] = 0.0;
		for (i = 0; i <= N; i++)
			for (j = 0; j <= N; j++) {
				double u = u0 + (u1 - u0) * i / N, v = v0 + (v1 - v0) * j / N, d2;
				if (px_trim_contains(r->trim[f], u, v, NULL) != PX_TRIM_INSIDE)
					continue;
				d2 = px_v3_dist2(px_nurbs_surf_point(s, u, v), p);
				for (k = 0; k < K; k++)
					if (d2 < kd[k]) {
						int m;
						for (m = K - 1; m > k; m--)
							kd[m] = kd[m - 1], ku[m] = ku[m - 1],
							kv[m] = kv[m - 1];
						kd[k] = d2, ku[k] = u, kv[k] = v;
						break;
					}
			}
		for (k = 0; k < K; k++)
			if (isfinite(kd[k])) {
				best = fmin(best, kd[k]);
				polish_face(r, f, p, ku[k], kv[k], &best);
			}
	}
	for (e = 0; e < d->n_edges; e++) {
		const struct px_nurbs_curve *c = &d->edges[e].curve;
		double t0, t1, bt = 0.0, bd = INFINITY;
		px_nurbs_curve_domain(c, &t0, &t1);
		for (i = 0; i <= 400; i++) {
			double t = t0 + (t1 - t0) * i / 400.0;
			double d2 = px_v3_dist2(px_nurbs_curve_point(c, t), p);
			if (d2 < bd)
				bd = d2, bt = t;
		}
		best = fmin(best, bd);
		polish_curve(c, p, bt, &best);
	}
	for (i = 0; i < d->n_vertices; i++)
		best = fmin(best, px_v3_dist2(d->vertices[i], p));
	return sqrt(best);
}

/* The answer's point lies on the trimmed model where it says. */
static void check_on_model(const struct ref *r, const struct px_model_result *a)
{
	const struct px_brep_desc *d = r->d;
	double tol = 1e-9 * r->size;
	px_vec3 q;
	if (a->feature == PX_FEATURE_SURFACE) {
		PX_CHECK(a->index >= 0 && a->index < d->n_faces);
		q = px_nurbs_surf_point(&d->faces[a->index].surf, a->u, a->v);
		PX_CHECK_MSG(px_trim_contains(r->trim[a->index], a->u, a->v, NULL) !=
				     PX_TRIM_OUTSIDE,
			     "face %d answer (%g, %g) outside its domain", a->index, a->u, a->v);
	} else if (a->feature == PX_FEATURE_CURVE) {
		PX_CHECK(a->index >= 0 && a->index < d->n_edges);
		q = px_nurbs_curve_point(&d->edges[a->index].curve, a->u);
	} else {
		PX_CHECK_INT_EQ(a->feature, PX_FEATURE_VERTEX);
		PX_CHECK(a->index >= 0 && a->index < d->n_vertices);
		q = d->vertices[a->index];
	}
	PX_CHECK_MSG(px_v3_dist(q, a->point) <= tol, "answer point %g off its feature",
		     px_v3_dist(q, a->point));
}

/* A random query point: in the enlarged box, near a face (both sides),
 * near an edge, or far. */
static px_vec3 rand_point(const struct ref *r, px_aabb box)
{
	const struct px_brep_desc *d = r->d;
	int kind = (int)(px_rand_u64() % 5);
	px_vec3 c = px_v3_scale(px_v3_add(box.min, box.max), 0.5);
	double s = r->size;
	if (kind == 0 || kind == 4) {
		double k = kind == 4 ? 10.0 : 0.8;
		return px_v3(c.x + px_rand_range(-k, k) * s, c.y + px_rand_range(-k, k) * s,
			     c.z + px_rand_range(-k, k) * s);
	}
	if (kind == 1) {
		int f = (int)(px_rand_u64() % (uint64_t)d->n_faces), tries;
		const struct px_nurbs_surf *sf = &d->faces[f].surf;
		double u0, u1, v0, v1;
		px_nurbs_surf_domain(sf, &u0, &u1, &v0, &v1);
		for (tries = 0; tries < 100; tries++) {
			double u = px_rand_range(u0, u1), v = px_rand_range(v0, v1);
			struct px_nurbs_surf_derivs dd;
			px_vec3 n;
			double h;
			if (px_trim_contains(r->trim[f], u, v, NULL) != PX_TRIM_INSIDE)
				continue;
			px_nurbs_surf_eval(sf, u, v, 1, &dd);
			n = px_v3_cross(dd.su, dd.sv);
			n = px_v3_scale(n, 1.0 / px_v3_norm(n));
			h = s * pow(10.0, px_rand_range(-7.0, -1.5)) * (px_rand_u64() & 1 ? 1 : -1);
			return px_v3_madd(dd.s, n, h);
		}
	}
	if (d->n_edges > 0) {
		int e = (int)(px_rand_u64() % (uint64_t)d->n_edges);
		double t0, t1;
		px_vec3 q;
		px_nurbs_curve_domain(&d->edges[e].curve, &t0, &t1);
		q = px_nurbs_curve_point(&d->edges[e].curve, px_rand_range(t0, t1));
		return px_v3(q.x + s * px_rand_range(-0.05, 0.05), q.y + s * px_rand_range(-0.05, 0.05),
			     q.z + s * px_rand_range(-0.05, 0.05));
	}
	return c;
}

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
		px_vec3 p = rand_point(&r, info.bounds);
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
#ifdef __SANITIZE_ADDRESS__
	/* OpenCASCADE's reader keeps global allocations that the leak
	 * checker reports at exit; the B-rep's own memory is checked by the
	 * other tests. */
	PX_SKIP("OpenCASCADE's global allocations show as leaks under ASan");
#endif
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
		px_vec3 p = rand_point(&r, (px_aabb){px_v3_scale(info.bounds.min, 1.0 / sc),
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
