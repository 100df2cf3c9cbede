/*
 * Primitives and the model interface.
 *
 * The reference is independent of the closed forms under test: each
 * primitive gets an implicit function f (negative inside, zero exactly on
 * the surface, written as a max of slabs or a plain radius test) and a
 * dense sampling of its surface by rings and grids. For random shapes,
 * poses and query points the answer must lie on the surface (f = 0), be
 * at the reported distance from the query, carry the sign of f, satisfy
 * query = point + distance * direction with a unit direction, and be no
 * farther than the nearest of the surface samples (a wrong local minimum
 * shows up as a sample that beats it).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "px_alloc_count.h"
#include "px_model.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

/* ---- independent references ------------------------------------------- */

static double ref_f(const struct px_prim *p, px_vec3 x)
{
	double rho = sqrt(x.x * x.x + x.y * x.y);
	switch (p->type) {
	case PX_PRIM_SPHERE:
		return sqrt(x.x * x.x + x.y * x.y + x.z * x.z) - p->a;
	case PX_PRIM_BOX:
		return fmax(fabs(x.x) - p->a,
			    fmax(fabs(x.y) - p->b, fabs(x.z) - p->c));
	case PX_PRIM_CAPSULE: {
		double z = x.z > p->b ? x.z - p->b : (x.z < -p->b ? x.z + p->b : 0);
		return sqrt(rho * rho + z * z) - p->a;
	}
	case PX_PRIM_CYLINDER:
		return fmax(rho - p->a, fabs(x.z) - p->b);
	case PX_PRIM_CONE: {
		double rz = p->a + (p->c - p->a) * (x.z + p->b) / (2 * p->b);
		return fmax(rho - rz, fabs(x.z) - p->b);
	}
	case PX_PRIM_TORUS:
		return sqrt((rho - p->a) * (rho - p->a) + x.z * x.z) - p->b;
	case PX_PRIM_HALFSPACE:
		return x.z;
	}
	return NAN;
}

struct samples {
	px_vec3 *p;
	size_t n, cap;
};

static void add(struct samples *s, px_vec3 x)
{
	if (s->n == s->cap) {
		s->cap = s->cap ? 2 * s->cap : 4096;
		s->p = realloc(s->p, s->cap * sizeof(px_vec3));
		PX_CHECK(s->p != NULL);
	}
	s->p[s->n++] = x;
}

/* Circle of radius r at height z, arc spacing <= d. */
static void ring(struct samples *s, double r, double z, double d)
{
	int n = r > 0 ? (int)ceil(2 * M_PI * r / d) : 1, i;
	for (i = 0; i < n; i++) {
		double a = 2 * M_PI * i / n;
		add(s, px_v3(r * cos(a), r * sin(a), z));
	}
}

/* Rings along the segment (r0, z0)-(r1, z1) of a profile. */
static void profile_seg(struct samples *s, double r0, double z0, double r1,
			double z1, double d)
{
	double L = hypot(r1 - r0, z1 - z0);
	int n = (int)ceil(L / d), i;
	for (i = 0; i <= n; i++) {
		double t = (double)i / n;
		ring(s, r0 + t * (r1 - r0), z0 + t * (z1 - z0), d);
	}
}

static void sample(const struct px_prim *p, double d, struct samples *s)
{
	int i, j, k, n;
	s->n = 0;
	switch (p->type) {
	case PX_PRIM_SPHERE:
		n = (int)ceil(M_PI * p->a / d);
		for (i = 0; i <= n; i++) {
			double th = M_PI * i / n;
			ring(s, p->a * sin(th), p->a * cos(th), d);
		}
		break;
	case PX_PRIM_BOX: {
		double h[3] = {p->a, p->b, p->c};
		for (k = 0; k < 3; k++) {
			int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
			int n1 = (int)ceil(2 * h[k1] / d), n2 = (int)ceil(2 * h[k2] / d);
			int sg;
			for (sg = -1; sg <= 1; sg += 2)
				for (i = 0; i <= n1; i++)
					for (j = 0; j <= n2; j++) {
						double x[3];
						x[k] = sg * h[k];
						x[k1] = -h[k1] + 2 * h[k1] * i / n1;
						x[k2] = -h[k2] + 2 * h[k2] * j / n2;
						add(s, px_v3(x[0], x[1], x[2]));
					}
		}
		break;
	}
	case PX_PRIM_CAPSULE:
		profile_seg(s, p->a, -p->b, p->a, p->b, d);
		n = (int)ceil(M_PI * p->a / 2 / d);
		for (i = 0; i <= n; i++) {
			double th = M_PI / 2 * i / n;
			ring(s, p->a * sin(th), p->b + p->a * cos(th), d);
			ring(s, p->a * sin(th), -p->b - p->a * cos(th), d);
		}
		break;
	case PX_PRIM_CYLINDER:
	case PX_PRIM_CONE: {
		double r0 = p->a, r1 = p->type == PX_PRIM_CONE ? p->c : p->a;
		profile_seg(s, 0, -p->b, r0, -p->b, d);
		profile_seg(s, r0, -p->b, r1, p->b, d);
		profile_seg(s, r1, p->b, 0, p->b, d);
		break;
	}
	case PX_PRIM_TORUS:
		n = (int)ceil(2 * M_PI * p->b / d);
		for (i = 0; i < n; i++) {
			double ps = 2 * M_PI * i / n;
			ring(s, p->a + p->b * cos(ps), p->b * sin(ps), d);
		}
		break;
	case PX_PRIM_HALFSPACE:
		n = (int)ceil(8.0 / d);
		for (i = 0; i <= n; i++)
			for (j = 0; j <= n; j++)
				add(s, px_v3(-4 + 8.0 * i / n, -4 + 8.0 * j / n, 0));
		break;
	}
}

static struct px_prim rand_prim(enum px_prim_type t)
{
	struct px_prim p = {t, 0, 0, 0};
	switch (t) {
	case PX_PRIM_SPHERE:
		p.a = px_rand_range(0.2, 1.5);
		break;
	case PX_PRIM_BOX:
		p.a = px_rand_range(0.1, 1.2);
		p.b = px_rand_range(0.1, 1.2);
		p.c = px_rand_range(0.1, 1.2);
		break;
	case PX_PRIM_CAPSULE:
	case PX_PRIM_CYLINDER:
		p.a = px_rand_range(0.1, 0.9);
		p.b = px_rand_range(0.1, 1.2);
		break;
	case PX_PRIM_CONE:
		p.a = px_rand_range(0.0, 1.0);
		p.b = px_rand_range(0.1, 1.2);
		p.c = px_rand_range(0.0, 1.0);
		switch (px_rand_int(0, 2)) {
		case 0: p.c = 0; break;
		case 1: p.a = 0; break;
		default: break;
		}
		break;
	case PX_PRIM_TORUS:
		p.a = px_rand_range(0.5, 1.5);
		p.b = px_rand_range(0.1, 0.9) * p.a;
		break;
	case PX_PRIM_HALFSPACE:
		break;
	}
	return p;
}

/* ---- tests ---------------------------------------------------------------- */

static void check_type(enum px_prim_type t)
{
	const double d = 0.02;
	struct samples s = {0};
	int shape, i;

	for (shape = 0; shape < 3; shape++) {
		struct px_prim p = rand_prim(t);
		struct px_model *m = NULL;
		px_pose P = px_test_rand_pose(2);
		px_aabb box = px_prim_aabb(&p);
		double ext = t == PX_PRIM_HALFSPACE ? 1.5 : 0.0;

		PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_set_pose(m, P), PX_OK);
		PX_CHECK(px_model_caps(m) & PX_MODEL_CAP_SIGNED);
		sample(&p, d, &s);
		for (i = 0; i < 120; i++) {
			struct px_model_result r;
			px_vec3 xl, xw, cl;
			double fq, fc, best = INFINITY;
			size_t k;

			if (t == PX_PRIM_HALFSPACE) {
				xl = px_v3(px_rand_range(-ext, ext),
					   px_rand_range(-ext, ext),
					   px_rand_range(-ext, ext));
			} else {
				px_vec3 lo = box.min, hi = box.max;
				xl = px_v3(px_rand_range(1.4 * lo.x - 0.3, 1.4 * hi.x + 0.3),
					   px_rand_range(1.4 * lo.y - 0.3, 1.4 * hi.y + 0.3),
					   px_rand_range(1.4 * lo.z - 0.3, 1.4 * hi.z + 0.3));
			}
			/* edge cases: on the axis, at the centre */
			if (i == 0)
				xl = px_v3(0, 0, 0);
			if (i == 1 || i == 2)
				xl.x = xl.y = 0.0;
			xw = px_pose_transform_point(P, xl);
			PX_CHECK_INT_EQ(px_model_query(m, xw, &r), 1);
			cl = px_pose_inverse_transform_point(P, r.point);
			fc = ref_f(&p, cl);
			fq = ref_f(&p, xl);
			PX_CHECK_MSG(fabs(fc) < 1e-9, "type %d: closest point off the surface (f = %g)",
				     t, fc);
			PX_CHECK_NEAR(fabs(r.distance), px_v3_dist(xw, r.point), 1e-9);
			PX_CHECK_NEAR(px_v3_norm(r.direction), 1.0, 1e-12);
			PX_CHECK_NEAR(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance), xw), 0.0, 1e-9);
			PX_CHECK(r.is_signed);
			if (fabs(fq) > 1e-9) {
				PX_CHECK_MSG((r.distance < 0) == (fq < 0),
					     "type %d: sign %g vs reference %g", t, r.distance, fq);
				PX_CHECK_INT_EQ(r.inside, fq < 0);
			}
			for (k = 0; k < s.n; k++) {
				double e = px_v3_dist2(xl, s.p[k]);
				if (e < best)
					best = e;
			}
			best = sqrt(best);
			PX_CHECK_MSG(fabs(r.distance) <= best + 1e-9,
				     "type %d shape %d query %d: |d| = %.12g but a surface sample is at %.12g",
				     t, shape, i, fabs(r.distance), best);
			PX_CHECK_MSG(best <= fabs(r.distance) + d, "sampling too coarse: %g vs %g",
				     best, fabs(r.distance));
			PX_CHECK(r.certified == 1);
			PX_CHECK(r.feature >= PX_FEATURE_FACE && r.feature <= PX_FEATURE_VERTEX);
		}
		px_model_free(m);
	}
	free(s.p);
}

static void test_sphere(void) { check_type(PX_PRIM_SPHERE); }
static void test_box(void) { check_type(PX_PRIM_BOX); }
static void test_capsule(void) { check_type(PX_PRIM_CAPSULE); }
static void test_cylinder(void) { check_type(PX_PRIM_CYLINDER); }
static void test_cone(void) { check_type(PX_PRIM_CONE); }
static void test_torus(void) { check_type(PX_PRIM_TORUS); }
static void test_halfspace(void) { check_type(PX_PRIM_HALFSPACE); }

static void test_features(void)
{
	struct px_prim box = {PX_PRIM_BOX, 1, 2, 3};
	struct px_prim cone = {PX_PRIM_CONE, 1, 1, 0};
	struct px_prim cyl = {PX_PRIM_CYLINDER, 1, 1, 0};
	struct px_model_result r;

	PX_CHECK_INT_EQ(px_prim_closest(&box, px_v3(5, 0, 0), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_FACE);
	PX_CHECK_INT_EQ(r.index, 1);
	PX_CHECK_INT_EQ(px_prim_closest(&box, px_v3(5, 5, 0), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_EDGE);
	PX_CHECK_INT_EQ(px_prim_closest(&box, px_v3(-5, -5, -5), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_VERTEX);
	PX_CHECK_NEAR(r.distance, sqrt(16 + 9 + 4), 1e-12);
	/* inside: depth to the nearest face, direction out of it */
	PX_CHECK_INT_EQ(px_prim_closest(&box, px_v3(0.5, 0, 0), 0, &r), PX_OK);
	PX_CHECK_NEAR(r.distance, -0.5, 1e-15);
	PX_CHECK_NEAR(r.direction.x, 1.0, 0);
	PX_CHECK_INT_EQ(r.index, 1);
	/* unsigned: same point, positive distance, direction towards query */
	PX_CHECK_INT_EQ(px_prim_closest(&box, px_v3(0.5, 0, 0), 1, &r), PX_OK);
	PX_CHECK_NEAR(r.distance, 0.5, 1e-15);
	PX_CHECK_NEAR(r.direction.x, -1.0, 0);
	PX_CHECK(!r.is_signed && !r.inside);
	/* cone apex and rims */
	PX_CHECK_INT_EQ(px_prim_closest(&cone, px_v3(0, 0, 3), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_VERTEX);
	PX_CHECK_NEAR(r.distance, 2.0, 1e-15);
	PX_CHECK_INT_EQ(px_prim_closest(&cyl, px_v3(2, 0, 2), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_EDGE);
	PX_CHECK_NEAR(r.distance, sqrt(2.0), 1e-15);
	/* below the centre of the cylinder's cap: a face, not an apex */
	PX_CHECK_INT_EQ(px_prim_closest(&cyl, px_v3(0, 0, -3), 0, &r), PX_OK);
	PX_CHECK_INT_EQ(r.feature, PX_FEATURE_FACE);
	PX_CHECK_INT_EQ(r.index, 0);
	/* on the surface: distance 0, the outward normal as direction */
	PX_CHECK_INT_EQ(px_prim_closest(&cyl, px_v3(0, 1, 0), 0, &r), PX_OK);
	PX_CHECK(r.distance == 0.0 && !signbit(r.distance));
	PX_CHECK_NEAR(r.direction.y, 1.0, 1e-15);
}

static void test_invalid(void)
{
	struct px_prim bad[] = {
		{PX_PRIM_SPHERE, 0, 0, 0},     {PX_PRIM_SPHERE, NAN, 0, 0},
		{PX_PRIM_BOX, 1, -1, 1},       {PX_PRIM_CAPSULE, 1, 0, 0},
		{PX_PRIM_CONE, 0, 1, 0},       {PX_PRIM_CONE, -1, 1, 1},
		{PX_PRIM_TORUS, 1, 1, 0},      {PX_PRIM_TORUS, 1, INFINITY, 0},
		{(enum px_prim_type)99, 1, 1, 1}};
	int expect[] = {PX_E_RANGE, PX_E_NAN, PX_E_RANGE, PX_E_RANGE, PX_E_RANGE,
			PX_E_RANGE, PX_E_RANGE, PX_E_NAN, PX_E_INVAL};
	size_t i;
	struct px_model *m = (struct px_model *)1;
	struct px_prim ok = {PX_PRIM_SPHERE, 1, 0, 0};
	struct px_model_result r;
	px_pose bp = px_pose_identity();

	for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
		PX_CHECK_INT_EQ(px_prim_check(&bad[i]), expect[i]);
		PX_CHECK_INT_EQ(px_prim_model(&bad[i], &m), expect[i]);
		PX_CHECK(m == NULL);
	}
	PX_CHECK_INT_EQ(px_prim_model(&ok, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(NAN, 0, 0), &r), PX_E_NAN);
	PX_CHECK_INT_EQ(px_model_query_ex(m, px_v3(0, 0, 0), -1, -1, 0, &r), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_model_query(NULL, px_v3(0, 0, 0), &r), PX_E_INVAL);
	bp.q.w = 2.0;
	PX_CHECK_INT_EQ(px_model_set_pose(m, bp), PX_E_RANGE);
	bp.q.w = NAN;
	PX_CHECK_INT_EQ(px_model_set_pose(m, bp), PX_E_NAN);
	PX_CHECK_NEAR(px_model_pose(m).q.w, 1.0, 0);
	px_model_free(m);
	PX_CHECK_INT_EQ(px_model_create(NULL, NULL, 0, &m), PX_E_INVAL);
	px_model_free(NULL);
}

static void test_interface(void)
{
	struct px_prim sp = {PX_PRIM_SPHERE, 0.5, 0, 0};
	struct px_model *m;
	struct px_model_result r;
	px_pose P = px_test_rand_pose(2);
	px_aabb wb;
	px_obb ob;
	uint64_t a;
	int i, rc;

	PX_CHECK_INT_EQ(px_prim_model(&sp, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_PRIMITIVE);
	PX_CHECK(px_model_memory_bytes(m) > sizeof(struct px_prim));
	PX_CHECK_INT_EQ(px_model_set_pose(m, P), PX_OK);
	wb = px_model_world_aabb(m);
	ob = px_model_world_obb(m);
	PX_CHECK(px_aabb_contains(&wb, P.t));
	PX_CHECK_NEAR(px_v3_dist(ob.center, P.t), 0, 1e-12);
	/* bounded query: nothing within 0.1 of a point 1 from the surface */
	rc = px_model_query_ex(m, px_v3_add(P.t, px_v3(1.5, 0, 0)), 0.1, -1, 0, &r);
	PX_CHECK_INT_EQ(rc, 0);
	PX_CHECK(isinf(r.distance) && r.index == -1);
	rc = px_model_query_ex(m, px_v3_add(P.t, px_v3(1.5, 0, 0)), 1.0 + 1e-9, -1, 0, &r);
	PX_CHECK_INT_EQ(rc, 1);
	PX_CHECK_NEAR(r.distance, 1.0, 1e-12);
	rc = px_model_query_ex(m, P.t, INFINITY, -1, PX_QUERY_UNSIGNED, &r);
	PX_CHECK_INT_EQ(rc, 1);
	PX_CHECK(!r.is_signed && r.distance == 0.5);
	/* the pose changes every cycle, queries never allocate */
	a = px_alloc_region_begin();
	for (i = 0; i < 1000; i++) {
		px_pose Q = P;
		Q.t.x += 1e-3 * i;
		px_model_set_pose(m, Q);
		px_model_query(m, px_v3(0.1 * i, 0, 0), &r);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
}

static const struct px_test tests[] = {
	PX_T(test_sphere),   PX_T(test_box),      PX_T(test_capsule),
	PX_T(test_cylinder), PX_T(test_cone),     PX_T(test_torus),
	PX_T(test_halfspace), PX_T(test_features), PX_T(test_invalid),
	PX_T(test_interface)};
PX_TEST_MAIN(tests)
