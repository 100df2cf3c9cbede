/*
 * Triangle meshes: point-triangle distance, hierarchy, sign, validation,
 * files.
 *
 * References: the point-triangle routine against dense barycentric
 * sampling; the hierarchy against a linear scan over every triangle; the
 * sign against the analytic solid the mesh approximates (and, for a box
 * mesh, the exact box primitive, which must agree to rounding); files
 * against the arrays they were written from.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_mesh.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_pose rand_pose(void)
{
	return px_test_rand_pose(2);
}

static px_vec3 rand_v(double s)
{
	return px_v3(px_rand_range(-s, s), px_rand_range(-s, s),
		     px_rand_range(-s, s));
}

/* ---- point-triangle ---------------------------------------------------------- */

static void test_tri_closest(void)
{
	int it;
	for (it = 0; it < 400; it++) {
		px_vec3 a = rand_v(1), b = rand_v(1), c = rand_v(1), p = rand_v(2), q;
		double d2, best = INFINITY, u, v;
		int f, s, i, j, n = 120;
		int kind = it % 5;
		if (kind == 1) /* needle: c almost on ab */
			c = px_v3_add(px_v3_lerp(a, b, px_rand_range(-0.5, 1.5)),
				      px_v3_scale(rand_v(1), 1e-11));
		if (kind == 2) /* collapsed to a segment */
			c = b;
		if (kind == 3) /* collapsed to a point */
			b = c = a;
		if (kind == 4) /* thin but a real triangle */
			c = px_v3_add(px_v3_lerp(a, b, 0.3), px_v3_scale(rand_v(1), 1e-4));
		d2 = px_tri_closest(p, a, b, c, &q, &f, &s, &u, &v);
		/* q is the point of the triangle at (u, v) and at distance d */
		PX_CHECK(u >= -1e-12 && v >= -1e-12 && u + v <= 1 + 1e-12);
		PX_CHECK_NEAR(px_v3_dist(q, px_v3_add(px_v3_add(px_v3_scale(a, 1 - u - v),
							       px_v3_scale(b, u)),
						    px_v3_scale(c, v))),
			      0.0, 1e-9);
		PX_CHECK_NEAR(d2, px_v3_dist2(p, q), 1e-12);
		for (i = 0; i <= n; i++)
			for (j = 0; i + j <= n; j++) {
				double x = (double)i / n, y = (double)j / n;
				px_vec3 w = px_v3_add(px_v3_add(px_v3_scale(a, 1 - x - y),
								px_v3_scale(b, x)),
						      px_v3_scale(c, y));
				double e = px_v3_dist2(p, w);
				if (e < best)
					best = e;
			}
		PX_CHECK_MSG(sqrt(d2) <= sqrt(best) + 1e-9,
			     "kind %d: %.15g > sample %.15g", kind, sqrt(d2), sqrt(best));
		PX_CHECK(f >= PX_FEATURE_FACE && f <= PX_FEATURE_VERTEX);
	}
}

static void test_tri_regions(void)
{
	px_vec3 a = px_v3(0, 0, 0), b = px_v3(1, 0, 0), c = px_v3(0, 1, 0), q;
	int f, s;
	double u, v, d2;
	d2 = px_tri_closest(px_v3(0.2, 0.2, 1), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK_INT_EQ(f, PX_FEATURE_FACE);
	PX_CHECK_NEAR(d2, 1.0, 1e-15);
	PX_CHECK_NEAR(u, 0.2, 1e-15);
	PX_CHECK_NEAR(v, 0.2, 1e-15);
	px_tri_closest(px_v3(-1, -1, 0), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_VERTEX && s == 0);
	px_tri_closest(px_v3(2, -0.5, 0), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_VERTEX && s == 1);
	px_tri_closest(px_v3(0, 3, 1), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_VERTEX && s == 2);
	px_tri_closest(px_v3(0.5, -1, 0), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_EDGE && s == 0);
	px_tri_closest(px_v3(1, 1, 0), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_EDGE && s == 1);
	PX_CHECK_NEAR(u, 0.5, 1e-15);
	px_tri_closest(px_v3(-1, 0.5, 0), a, b, c, &q, &f, &s, &u, &v);
	PX_CHECK(f == PX_FEATURE_EDGE && s == 2);
	PX_CHECK_NEAR(v, 0.5, 1e-15);
}

/* ---- hierarchy against a linear scan -------------------------------------- */

static double brute(const struct px_model *m, px_vec3 p)
{
	return px_test_mesh_brute(m, p);
}

static void check_against_brute(struct px_model *m, int nq, double spread)
{
	int i;
	for (i = 0; i < nq; i++) {
		px_pose P = px_model_pose(m);
		px_aabb b = px_model_local_aabb(m);
		px_vec3 c = px_aabb_center(&b), h = px_aabb_half_extents(&b);
		px_vec3 pl = px_v3(c.x + spread * h.x * px_rand_range(-1, 1),
				   c.y + spread * h.y * px_rand_range(-1, 1),
				   c.z + spread * h.z * px_rand_range(-1, 1));
		px_vec3 pw = px_pose_transform_point(P, pl);
		struct px_model_result r;
		px_vec3 v[3];
		double ref = brute(m, pl), dt;
		/* tolerances scale with the mesh and its place (rounding of the
		 * pose transform) */
		double L = 1.0 + px_v3_norm(c) + px_v3_norm(h) + px_v3_norm(P.t);

		PX_CHECK_INT_EQ(px_model_query(m, pw, &r), 1);
		PX_CHECK_MSG(fabs(fabs(r.distance) - ref) <= 1e-12 * (1 + ref) + 1e-14 * L,
			     "query %d: %.17g vs linear scan %.17g", i, fabs(r.distance), ref);
		PX_CHECK_NEAR(px_v3_dist(pw, r.point), fabs(r.distance), 1e-12 * L);
		PX_CHECK_NEAR(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance), pw), 0, 1e-9 * L);
		/* the reported triangle holds the reported point */
		PX_CHECK(r.index >= 0 && (size_t)r.index < px_mesh_triangle_count(m));
		px_mesh_triangle(m, (size_t)r.index, v);
		dt = px_tri_closest(px_pose_inverse_transform_point(P, r.point), v[0], v[1],
				    v[2], NULL, NULL, NULL, NULL, NULL);
		PX_CHECK_NEAR(sqrt(dt), 0.0, 1e-9 * L);
		PX_CHECK(r.certified);
	}
}

static void test_soup_vs_brute(void)
{
	int rep;
	for (rep = 0; rep < 4; rep++) {
		size_t nt = (size_t)px_rand_int(1, 400), nv = 3 * nt, i;
		double *xyz = malloc(3 * nv * sizeof(double));
		uint32_t *tri = malloc(3 * nt * sizeof(uint32_t));
		struct px_model *m;
		struct px_mesh_report rp;
		for (i = 0; i < nt; i++) {
			px_vec3 c = rand_v(2), a = px_v3_add(c, rand_v(0.3)),
				b = px_v3_add(c, rand_v(0.3)), d = px_v3_add(c, rand_v(0.3));
			if (i % 17 == 3)
				d = b; /* collapsed */
			if (i % 23 == 5)
				d = px_v3_lerp(a, b, 0.7); /* collinear */
			memcpy(xyz + 9 * i, &a, sizeof(a));
			memcpy(xyz + 9 * i + 3, &b, sizeof(b));
			memcpy(xyz + 9 * i + 6, &d, sizeof(d));
			tri[3 * i] = (uint32_t)(3 * i);
			tri[3 * i + 1] = (uint32_t)(3 * i + 1);
			tri[3 * i + 2] = (uint32_t)(3 * i + 2);
		}
		PX_CHECK_INT_EQ(px_mesh_model(xyz, nv, tri, nt, NULL, &rp, &m), PX_OK);
		PX_CHECK(!rp.closed);
		PX_CHECK(!px_mesh_is_closed(m));
		PX_CHECK(rp.n_degenerate >= (nt > 5 ? 1u : 0u));
		PX_CHECK_INT_EQ(px_model_set_pose(m, rand_pose()), PX_OK);
		check_against_brute(m, 150, 1.5);
		{
			struct px_model_result r;
			px_model_query(m, px_v3(0, 0, 0), &r);
			PX_CHECK(!r.is_signed && r.distance >= 0);
		}
		px_model_free(m);
		free(xyz);
		free(tri);
	}
}

static void test_closed_vs_brute(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct px_mesh_report rp;
	struct px_mesh_opts o = {0, 1, 0};
	int leaf;

	PX_CHECK_INT_EQ(gen_torus(1.0, 0.35, 40, 24, &g), 0);
	for (leaf = 1; leaf <= 8; leaf += 7) {
		o.leaf_size = leaf;
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, &rp, &m), PX_OK);
		PX_CHECK_MSG(rp.closed, "torus not closed: %s", rp.message);
		PX_CHECK(!rp.flipped);
		PX_CHECK(rp.volume > 0);
		PX_CHECK(rp.depth <= PX_MESH_MAX_DEPTH);
		PX_CHECK_INT_EQ(px_model_set_pose(m, rand_pose()), PX_OK);
		check_against_brute(m, 200, 1.4);
		px_model_free(m);
	}
	gen_free(&g);
}

/* The single-precision bounds must stay lower bounds at every scale:
 * tiny meshes far from the origin (float spacing larger than the mesh),
 * huge meshes, query points beyond the float range (exact path only),
 * and two sheets 1e-7 apart, where the bounds of both are nearly equal. */
static void test_scales_vs_brute(void)
{
	static const double sc[4][2] = {{1e-5, 1e3}, {1e4, 0.0}, {1.0, 50.0}, {1e-3, 0.0}};
	struct gen_mesh g;
	int k, i;
	PX_CHECK_INT_EQ(gen_torus(1.0, 0.35, 24, 12, &g), 0);
	for (k = 0; k < 4; k++) {
		double *xyz = malloc(3 * g.nv * sizeof(double));
		struct px_model *m;
		size_t j;
		for (j = 0; j < 3 * g.nv; j++)
			xyz[j] = g.xyz[j] * sc[k][0] + sc[k][1];
		PX_CHECK_INT_EQ(px_mesh_model(xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
		check_against_brute(m, 150, 1.5);
		PX_CHECK_INT_EQ(px_model_set_pose(m, rand_pose()), PX_OK);
		check_against_brute(m, 100, 1.2);
		PX_CHECK_INT_EQ(px_model_set_pose(m, px_pose_identity()), PX_OK);
		for (i = 0; i < 20; i++) {
			/* beyond the float range: the exact path alone */
			px_vec3 p = px_v3_scale(rand_v(1.0), 1e35 / fmax(sc[k][0], 1e-3));
			struct px_model_result r;
			double ref = brute(m, p);
			PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
			PX_CHECK_MSG(fabs(fabs(r.distance) - ref) <= 1e-12 * ref, "far %.17g vs %.17g",
				     fabs(r.distance), ref);
		}
		px_model_free(m);
		free(xyz);
	}
	gen_free(&g);
	{
		/* two parallel 20 x 20 sheets 1e-7 apart, one shifted by half
		 * a cell */
		enum { N = 20 };
		double *xyz = malloc(2 * (N + 1) * (N + 1) * 3 * sizeof(double));
		uint32_t *tri = malloc(2 * 2 * N * N * 3 * sizeof(uint32_t));
		struct px_model *m;
		size_t nv = 0, nt = 0;
		int sh, a, b;
		for (sh = 0; sh < 2; sh++) {
			size_t base = nv;
			for (b = 0; b <= N; b++)
				for (a = 0; a <= N; a++) {
					xyz[3 * nv] = a * 0.05 + sh * 0.025;
					xyz[3 * nv + 1] = b * 0.05 + sh * 0.025;
					xyz[3 * nv + 2] = 0.3 + sh * 1e-7;
					nv++;
				}
			for (b = 0; b < N; b++)
				for (a = 0; a < N; a++) {
					uint32_t v0 = (uint32_t)(base + (size_t)b * (N + 1) + (size_t)a);
					uint32_t q[6] = {v0, v0 + 1, v0 + N + 2, v0, v0 + N + 2, v0 + N + 1};
					memcpy(tri + 3 * nt, q, sizeof(q));
					nt += 2;
				}
		}
		PX_CHECK_INT_EQ(px_mesh_model(xyz, nv, tri, nt, NULL, NULL, &m), PX_OK);
		for (i = 0; i < 300; i++) {
			px_vec3 p = px_v3(px_rand_range(-0.1, 1.1), px_rand_range(-0.1, 1.1),
					  0.3 + px_rand_range(-1, 1) * (i % 2 ? 1e-6 : 0.2));
			struct px_model_result r;
			double ref = brute(m, p);
			PX_CHECK_INT_EQ(px_model_query(m, p, &r), 1);
			PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-12 * (1 + ref),
				     "sheets: %.17g vs %.17g", r.distance, ref);
		}
		px_model_free(m);
		free(xyz);
		free(tri);
	}
}

/* ---- coherence -------------------------------------------------------------- */

static void test_coherent(void)
{
	struct gen_mesh g;
	struct px_model *m;
	int i, hint = -1;
	px_vec3 p = px_v3(1.2, 0, 0.5);

	PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 60, 30, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
	for (i = 0; i < 500; i++) {
		struct px_model_result rc, rh, rw;
		int wrong = px_rand_int(-10, (int)g.nt + 10);
		p = px_v3_add(p, rand_v(0.02));
		if (i % 100 == 99)
			p = rand_v(1.5); /* a jump: the hint is now far off */
		PX_CHECK_INT_EQ(px_model_query(m, p, &rc), 1);
		PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, hint, PX_QUERY_COHERENT, &rh), 1);
		PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, wrong, PX_QUERY_COHERENT, &rw), 1);
		PX_CHECK_NEAR(rh.distance, rc.distance, 1e-15);
		PX_CHECK_NEAR(rw.distance, rc.distance, 1e-15);
		PX_CHECK(rh.inside == rc.inside);
		hint = rh.index;
	}
	px_model_free(m);
	gen_free(&g);
}

static void test_cache(void)
{
	/* The cache must give exactly the distances of full queries, with
	 * any margin (tiny: refills every cycle; huge: more triangles than it
	 * holds, so it falls back), across jumps and model switches. */
	struct gen_mesh g, g2;
	struct px_model *m, *m2;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.5, 0, 0};
	struct px_model *pm;
	const double margins[4] = {0.0, 1e-6, 0.01, 10.0};
	int k, i;
	uint64_t a;

	PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 60, 30, &g), 0);
	PX_CHECK_INT_EQ(gen_sphere(0.7, 10, 16, &g2), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_mesh_model(g2.xyz, g2.nv, g2.tri, g2.nt, NULL, NULL, &m2), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&sp, &pm), PX_OK);
	for (k = 0; k < 4; k++) {
		struct px_model_cache c;
		px_vec3 p = px_v3(1.3, 0, 0.1);
		px_model_cache_init(&c, margins[k]);
		px_model_set_pose(m, rand_pose());
		a = px_alloc_region_begin();
		for (i = 0; i < 3000; i++) {
			struct px_model_result rc, rf;
			const struct px_model *mm = (i / 500) % 3 == 2 ? m2 : m;
			p = px_v3_add(p, rand_v(0.003));
			if (i % 700 == 699)
				p = rand_v(2.0);
			if (i % 100 == 50) /* the model moves too */
				px_model_set_pose(m, rand_pose());
			PX_CHECK_INT_EQ(px_model_query_cached(mm, p, &c, &rc), 1);
			PX_CHECK_INT_EQ(px_model_query(mm, p, &rf), 1);
			PX_CHECK_MSG(rc.distance == rf.distance,
				     "margin %g, step %d: cached %.17g vs full %.17g", margins[k], i,
				     rc.distance, rf.distance);
			PX_CHECK(rc.inside == rf.inside);
			PX_CHECK_NEAR(px_v3_dist(rc.point, rf.point), 0.0,
				      1e-9 + (rc.index != rf.index ? INFINITY : 0));
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		PX_CHECK_INT_EQ(px_model_cache_queries(&c), 3000);
		if (k == 2)
			PX_CHECK_MSG(px_model_cache_refills(&c) < 1500, "%lu refills",
				     px_model_cache_refills(&c));
		if (k == 1)
			PX_CHECK(px_model_cache_refills(&c) > 2000);
	}
	{
		/* a model without cache operations: coherent queries instead */
		struct px_model_cache c;
		struct px_model_result rc, rf;
		px_model_cache_init(&c, 0.0);
		PX_CHECK_INT_EQ(px_model_query_cached(pm, px_v3(1, 2, 3), &c, &rc), 1);
		PX_CHECK_INT_EQ(px_model_query(pm, px_v3(1, 2, 3), &rf), 1);
		PX_CHECK(rc.distance == rf.distance);
		PX_CHECK_INT_EQ(px_model_query_cached(pm, px_v3(NAN, 2, 3), &c, &rc), PX_E_NAN);
	}
	px_model_free(m);
	px_model_free(m2);
	px_model_free(pm);
	gen_free(&g);
	gen_free(&g2);
}

static void test_convex_support(void)
{
	/* The support point of convex meshes (hill climbing on larger ones)
	 * against a scan of all vertices, including axis directions, where a
	 * subdivided box has whole faces of ties. */
	struct gen_mesh g[3];
	double h[3] = {0.3, 0.5, 0.2};
	int k, i;
	PX_CHECK_INT_EQ(gen_sphere(0.5, 20, 40, &g[0]), 0);
	PX_CHECK_INT_EQ(gen_box(h, 6, &g[1]), 0);
	PX_CHECK_INT_EQ(gen_sphere(0.5, 3, 4, &g[2]), 0); /* small: plain scan */
	for (k = 0; k < 3; k++) {
		struct px_model *m;
		struct px_mesh_report rp;
		PX_CHECK_INT_EQ(px_mesh_model(g[k].xyz, g[k].nv, g[k].tri, g[k].nt, NULL, &rp, &m), PX_OK);
		PX_CHECK_MSG(rp.convex, "mesh %d not convex: %s", k, rp.message);
		px_model_set_pose(m, rand_pose());
		for (i = 0; i < 600; i++) {
			px_vec3 d = i < 6 ? px_v3(i / 2 == 0 ? (i % 2 ? 1 : -1) : 0,
						  i / 2 == 1 ? (i % 2 ? 1 : -1) : 0,
						  i / 2 == 2 ? (i % 2 ? 1 : -1) : 0)
				    : rand_v(1), s, dl;
			double best = -INFINITY;
			size_t t;
			int c;
			if (i < 6) /* axis directions of the mesh's own frame */
				d = px_pose_transform_vector(px_model_pose(m), d);
			PX_CHECK_INT_EQ(px_model_support(m, d, &s), PX_OK);
			dl = px_pose_inverse_transform_vector(px_model_pose(m), d);
			for (t = 0; t < px_mesh_triangle_count(m); t++) {
				px_vec3 v[3];
				px_mesh_triangle(m, t, v);
				for (c = 0; c < 3; c++)
					best = fmax(best, px_v3_dot(v[c], dl));
			}
			PX_CHECK_NEAR(px_v3_dot(px_pose_inverse_transform_point(px_model_pose(m), s), dl),
				      best, 1e-12);
		}
		px_model_free(m);
		gen_free(&g[k]);
	}
	{
		/* a flat double-sided sheet is closed but not a convex solid */
		double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
		uint32_t t2[] = {0, 1, 2, 0, 2, 1};
		struct px_model *m;
		struct px_mesh_report rp;
		px_vec3 out;
		PX_CHECK_INT_EQ(px_mesh_model(xyz, 3, t2, 2, NULL, &rp, &m), PX_OK);
		PX_CHECK(!rp.convex);
		PX_CHECK_INT_EQ(px_model_support(m, px_v3(1, 0, 0), &out), PX_E_UNSUPPORTED);
		px_model_free(m);
	}
}

/* ---- sign -------------------------------------------------------------------- */

static void test_sign_box_exact(void)
{
	/* The mesh of a box is the box: signed distances must agree with the
	 * primitive to rounding, including points near edges and corners,
	 * where pseudo-normals matter. */
	int rep, i;
	for (rep = 0; rep < 3; rep++) {
		double h[3] = {px_rand_range(0.2, 1), px_rand_range(0.2, 1), px_rand_range(0.2, 1)};
		struct px_prim pb = {PX_PRIM_BOX, h[0], h[1], h[2]};
		struct gen_mesh g;
		struct px_model *m, *pm;
		struct px_mesh_report rp;
		px_pose P = rand_pose();
		PX_CHECK_INT_EQ(gen_box(h, 1 + rep * 2, &g), 0);
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rp, &m), PX_OK);
		PX_CHECK_MSG(rp.closed, "box not closed: %s", rp.message);
		PX_CHECK_NEAR(rp.volume, 8 * h[0] * h[1] * h[2], 1e-12);
		PX_CHECK(rp.n_welded == (size_t)(6 * (1 + rep * 2) * (1 + rep * 2) + 2));
		PX_CHECK_INT_EQ(px_prim_model(&pb, &pm), PX_OK);
		px_model_set_pose(m, P);
		px_model_set_pose(pm, P);
		for (i = 0; i < 400; i++) {
			struct px_model_result a, b;
			px_vec3 pl = px_v3(px_rand_range(-1.6, 1.6) * h[0],
					   px_rand_range(-1.6, 1.6) * h[1],
					   px_rand_range(-1.6, 1.6) * h[2]);
			px_vec3 pw;
			if (i % 4 == 0) /* near a corner or an edge */
				pl = px_v3(copysign(h[0], pl.x) + px_rand_range(-0.05, 0.05),
					   copysign(h[1], pl.y) + px_rand_range(-0.05, 0.05),
					   i % 8 ? pl.z : copysign(h[2], pl.z) + px_rand_range(-0.05, 0.05));
			pw = px_pose_transform_point(P, pl);
			px_model_query(m, pw, &a);
			px_model_query(pm, pw, &b);
			PX_CHECK(a.is_signed);
			PX_CHECK_MSG(fabs(a.distance - b.distance) <= 1e-12,
				     "mesh %.17g vs box %.17g at (%g %g %g)", a.distance,
				     b.distance, pl.x, pl.y, pl.z);
		}
		px_model_free(m);
		px_model_free(pm);
		gen_free(&g);
	}
}

static void check_sign_shape(struct gen_mesh *g, const struct px_prim *shape,
			     double margin, int flip)
{
	struct px_model *m;
	struct px_mesh_report rp;
	px_pose P = rand_pose();
	px_aabb box = px_prim_aabb(shape);
	int i, tested = 0;

	if (flip) {
		size_t t;
		for (t = 0; t < g->nt; t++) {
			uint32_t x = g->tri[3 * t + 1];
			g->tri[3 * t + 1] = g->tri[3 * t + 2];
			g->tri[3 * t + 2] = x;
		}
	}
	PX_CHECK_INT_EQ(px_mesh_model(g->xyz, g->nv, g->tri, g->nt, NULL, &rp, &m), PX_OK);
	PX_CHECK_MSG(rp.closed, "not closed: %s", rp.message);
	PX_CHECK_INT_EQ(rp.flipped, flip);
	px_model_set_pose(m, P);
	for (i = 0; i < 3000; i++) {
		struct px_model_result r, a;
		px_vec3 pl = px_v3(px_rand_range(1.3 * box.min.x, 1.3 * box.max.x),
				   px_rand_range(1.3 * box.min.y, 1.3 * box.max.y),
				   px_rand_range(1.3 * box.min.z, 1.3 * box.max.z));
		px_prim_closest(shape, pl, 0, &a);
		if (fabs(a.distance) <= margin)
			continue;
		tested++;
		px_model_query(m, px_pose_transform_point(P, pl), &r);
		PX_CHECK(r.is_signed);
		PX_CHECK_MSG(r.inside == a.inside,
			     "sign: mesh %g vs analytic %g at (%g %g %g)", r.distance,
			     a.distance, pl.x, pl.y, pl.z);
		PX_CHECK_NEAR(r.distance, a.distance, margin);
	}
	PX_CHECK(tested > 1000);
	px_model_free(m);
}

static void test_sign_sphere_torus(void)
{
	struct gen_mesh g;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.8, 0, 0};
	struct px_prim to = {PX_PRIM_TORUS, 1.0, 0.4, 0};
	int flip;
	for (flip = 0; flip < 2; flip++) {
		/* chord sagitta r (1 - cos(step / 2)) < r step^2 / 8 */
		PX_CHECK_INT_EQ(gen_sphere(0.8, 24, 48, &g), 0);
		check_sign_shape(&g, &sp, 0.8 * pow(M_PI / 24, 2), flip);
		gen_free(&g);
		PX_CHECK_INT_EQ(gen_torus(1.0, 0.4, 64, 32, &g), 0);
		check_sign_shape(&g, &to, 1.4 * pow(2 * M_PI / 32, 2), flip);
		gen_free(&g);
	}
}

/* Inside test of the L prism (scale s, half height hz). */
static int in_l(px_vec3 p, double s, double hz)
{
	double x = p.x / s, y = p.y / s;
	if (fabs(p.z) > hz || x < 0 || y < 0 || x > 2 || y > 2)
		return 0;
	return x <= 1 || y <= 1;
}

static void test_sign_concave(void)
{
	/* Reflex edge and vertices: inside points whose closest point is on
	 * the reflex edge are where a face normal alone gives the wrong sign. */
	struct gen_mesh g;
	struct px_model *m;
	struct px_mesh_report rp;
	double s = px_rand_range(0.3, 1.0), hz = px_rand_range(0.2, 1.0);
	px_pose P = rand_pose();
	int i, tested = 0;

	PX_CHECK_INT_EQ(gen_lprism(s, hz, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, &rp, &m), PX_OK);
	PX_CHECK_MSG(rp.closed && !rp.flipped, "%s", rp.message);
	PX_CHECK_NEAR(rp.volume, 3 * s * s * 2 * hz, 1e-12);
	px_model_set_pose(m, P);
	for (i = 0; i < 3000; i++) {
		struct px_model_result r;
		px_vec3 pl;
		if (i % 2)
			pl = px_v3(px_rand_range(-0.3, 2.3) * s, px_rand_range(-0.3, 2.3) * s,
				   px_rand_range(-1.3, 1.3) * hz);
		else /* around the reflex edge, often near its ends */
			pl = px_v3(s + px_rand_range(-0.2, 0.2) * s, s + px_rand_range(-0.2, 0.2) * s,
				   (i % 4 ? px_rand_range(-1, 1) : copysign(1, px_rand_range(-1, 1)) *
						   px_rand_range(0.8, 1.2)) * hz);
		px_model_query(m, px_pose_transform_point(P, pl), &r);
		if (fabs(r.distance) < 1e-9)
			continue;
		tested++;
		PX_CHECK_MSG(r.inside == in_l(pl, s, hz),
			     "sign at (%g %g %g): distance %g, feature %d", pl.x, pl.y, pl.z,
			     r.distance, r.feature);
	}
	PX_CHECK(tested > 2500);
	px_model_free(m);
	gen_free(&g);
}

static double vol6(px_vec3 a, px_vec3 b, px_vec3 c, px_vec3 d)
{
	return px_v3_dot(px_v3_sub(b, a), px_v3_cross(px_v3_sub(c, a), px_v3_sub(d, a)));
}

static void test_sign_tetra(void)
{
	/* Random tetrahedra have sharp edges and vertices (normals more than
	 * 90 degrees apart), where the sign needs the edge and vertex
	 * pseudo-normals; either orientation of the input is accepted. */
	int rep, i, tested = 0;
	for (rep = 0; rep < 30; rep++) {
		px_vec3 V[4];
		double xyz[12];
		uint32_t tri[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
		struct px_model *m;
		struct px_mesh_report rp;
		double v6;
		int k;
		do {
			for (k = 0; k < 4; k++)
				V[k] = rand_v(1);
			v6 = vol6(V[0], V[1], V[2], V[3]);
		} while (fabs(v6) < 0.05);
		for (k = 0; k < 4; k++)
			memcpy(xyz + 3 * k, &V[k], sizeof(V[k]));
		PX_CHECK_INT_EQ(px_mesh_model(xyz, 4, tri, 4, NULL, &rp, &m), PX_OK);
		PX_CHECK_MSG(rp.closed, "%s", rp.message);
		PX_CHECK_INT_EQ(rp.flipped, v6 < 0);
		PX_CHECK_NEAR(rp.volume, fabs(v6) / 6, 1e-12);
		for (i = 0; i < 300; i++) {
			struct px_model_result r;
			/* near a vertex or an edge, or anywhere around */
			int a = px_rand_int(0, 3), b = px_rand_int(0, 3);
			px_vec3 p = i % 3 == 0 ? px_v3_add(V[a], rand_v(0.3))
				  : i % 3 == 1 ? px_v3_add(px_v3_lerp(V[a], V[b], px_rand_unit()), rand_v(0.2))
					       : rand_v(1.3);
			double s0 = vol6(p, V[1], V[2], V[3]), s1 = vol6(V[0], p, V[2], V[3]);
			double s2 = vol6(V[0], V[1], p, V[3]), s3 = vol6(V[0], V[1], V[2], p);
			int in = v6 > 0 ? (s0 > 0 && s1 > 0 && s2 > 0 && s3 > 0)
					: (s0 < 0 && s1 < 0 && s2 < 0 && s3 < 0);
			px_model_query(m, p, &r);
			if (fabs(r.distance) < 1e-9)
				continue;
			tested++;
			PX_CHECK_MSG(r.inside == in, "tet %d: sign at (%g %g %g): %g, feature %d",
				     rep, p.x, p.y, p.z, r.distance, r.feature);
		}
		px_model_free(m);
	}
	PX_CHECK(tested > 8000);
}

/* ---- topology and validation -------------------------------------------------- */

static void test_open_and_bad_topology(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct px_mesh_report rp;
	struct px_mesh_opts strict = {PX_MESH_REQUIRE_CLOSED, 0, 0};
	struct px_model_result r;
	uint32_t *t2;
	size_t nt;

	PX_CHECK_INT_EQ(gen_sphere(1.0, 8, 12, &g), 0);
	nt = g.nt;
	/* open: one triangle missing */
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, nt - 1, NULL, &rp, &m), PX_OK);
	PX_CHECK(!rp.closed);
	PX_CHECK_INT_EQ(rp.n_boundary_edges, 3);
	PX_CHECK(strstr(rp.message, "boundary") != NULL);
	PX_CHECK(!(px_model_caps(m) & PX_MODEL_CAP_SIGNED));
	px_model_query(m, px_v3(0, 0, 0), &r);
	PX_CHECK(!r.is_signed && r.distance > 0.5);
	px_model_free(m);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, nt - 1, &strict, &rp, &m),
			PX_E_DEGENERATE);
	PX_CHECK(m == NULL);
	/* non-manifold: a triangle repeated (an edge used by 3 and more) */
	t2 = malloc((nt + 1) * 3 * sizeof(uint32_t));
	memcpy(t2, g.tri, nt * 3 * sizeof(uint32_t));
	t2[3 * nt] = g.tri[0], t2[3 * nt + 1] = g.tri[2], t2[3 * nt + 2] = g.tri[1];
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, t2, nt + 1, NULL, &rp, &m), PX_OK);
	PX_CHECK(!rp.closed && rp.n_nonmanifold_edges == 3);
	PX_CHECK(strstr(rp.message, "non-manifold") != NULL);
	px_model_free(m);
	/* one triangle flipped: inconsistent orientation */
	memcpy(t2, g.tri, nt * 3 * sizeof(uint32_t));
	t2[4] = g.tri[5], t2[5] = g.tri[4];
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, t2, nt, NULL, &rp, &m), PX_OK);
	PX_CHECK(!rp.closed && rp.n_misoriented_edges == 3);
	PX_CHECK(rp.first_bad_edge_triangle >= 0);
	px_model_free(m);
	free(t2);
	gen_free(&g);
}

static void test_validation(void)
{
	double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, NAN, 1, 1, 0};
	uint32_t t_ok[] = {0, 1, 2}, t_nan[] = {0, 1, 2, 1, 3, 2},
		 t_range[] = {0, 1, 2, 0, 1, 7}, t_deg[] = {0, 1, 2, 0, 1, 1};
	struct px_mesh_opts strict = {PX_MESH_REJECT_DEGENERATE, 0, 0};
	struct px_mesh_report rp;
	struct px_model *m = (struct px_model *)1;

	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_nan, 2, NULL, &rp, &m), PX_E_NAN);
	PX_CHECK(m == NULL);
	PX_CHECK_MSG(strstr(rp.message, "vertex 3") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_range, 2, NULL, &rp, &m), PX_E_RANGE);
	PX_CHECK_MSG(strstr(rp.message, "triangle 1") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_deg, 2, &strict, &rp, &m), PX_E_DEGENERATE);
	PX_CHECK_MSG(strstr(rp.message, "triangle 1") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_deg, 2, NULL, &rp, &m), PX_OK);
	PX_CHECK_INT_EQ(rp.n_degenerate, 1);
	PX_CHECK_INT_EQ(rp.first_degenerate, 1);
	px_model_free(m);
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_ok, 0, NULL, &rp, &m), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_mesh_model(NULL, 5, t_ok, 1, NULL, &rp, &m), PX_E_INVAL);
	/* the unused NaN vertex is no problem */
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 5, t_ok, 1, NULL, &rp, &m), PX_OK);
	PX_CHECK_INT_EQ(px_mesh_triangle_count(m), 1);
	PX_CHECK_INT_EQ(px_mesh_triangle_count(NULL), 0);
	px_model_free(m);
}

/* ---- files ------------------------------------------------------------------- */

static char tmpdir[64];

static const char *tpath(const char *name)
{
	static char buf[4][160];
	static int k;
	k = (k + 1) % 4;
	snprintf(buf[k], sizeof(buf[k]), "%s/%s", tmpdir, name);
	return buf[k];
}

static void write_files(const struct gen_mesh *g)
{
	FILE *f;
	size_t i;
	int k;
	/* ASCII STL */
	f = fopen(tpath("box_a.stl"), "w");
	PX_CHECK(f != NULL);
	fprintf(f, "solid box\n");
	for (i = 0; i < g->nt; i++) {
		fprintf(f, " facet normal 0 0 0\n  outer loop\n");
		for (k = 0; k < 3; k++) {
			const double *v = g->xyz + 3 * g->tri[3 * i + k];
			fprintf(f, "   vertex %.9g %.9g %.9g\n", v[0], v[1], v[2]);
		}
		fprintf(f, "  endloop\n endfacet\n");
	}
	fprintf(f, "endsolid box\n");
	fclose(f);
	/* binary STL */
	f = fopen(tpath("box_b.stl"), "wb");
	PX_CHECK(f != NULL);
	{
		char hdr[80] = "binary box";
		uint32_t n = (uint32_t)g->nt;
		uint16_t attr = 0;
		fwrite(hdr, 1, 80, f);
		fwrite(&n, 4, 1, f);
		for (i = 0; i < g->nt; i++) {
			float x[12] = {0};
			for (k = 0; k < 9; k++)
				x[3 + k] = (float)g->xyz[3 * g->tri[3 * i + k / 3] + k % 3];
			fwrite(x, 4, 12, f);
			fwrite(&attr, 2, 1, f);
		}
	}
	fclose(f);
	/* OBJ with quads split by the importer and 1-based indices */
	f = fopen(tpath("box.obj"), "w");
	PX_CHECK(f != NULL);
	fprintf(f, "# box\no box\n");
	for (i = 0; i < g->nv; i++)
		fprintf(f, "v %.9g %.9g %.9g\n", g->xyz[3 * i], g->xyz[3 * i + 1], g->xyz[3 * i + 2]);
	for (i = 0; i + 1 < g->nt; i += 2) /* gen_quad pairs: (a b c) (a c d) */
		fprintf(f, "f %u %u %u %u\n", g->tri[3 * i] + 1, g->tri[3 * i + 1] + 1,
			g->tri[3 * i + 2] + 1, g->tri[3 * i + 5] + 1);
	fclose(f);
	/* ASCII PLY */
	f = fopen(tpath("box.ply"), "w");
	PX_CHECK(f != NULL);
	fprintf(f, "ply\nformat ascii 1.0\nelement vertex %zu\nproperty float x\n"
		   "property float y\nproperty float z\nelement face %zu\n"
		   "property list uchar int vertex_indices\nend_header\n", g->nv, g->nt);
	for (i = 0; i < g->nv; i++)
		fprintf(f, "%.9g %.9g %.9g\n", g->xyz[3 * i], g->xyz[3 * i + 1], g->xyz[3 * i + 2]);
	for (i = 0; i < g->nt; i++)
		fprintf(f, "3 %u %u %u\n", g->tri[3 * i], g->tri[3 * i + 1], g->tri[3 * i + 2]);
	fclose(f);
	/* bad files */
	f = fopen(tpath("garbage.stl"), "w");
	fprintf(f, "this is not a mesh\n");
	fclose(f);
	f = fopen(tpath("nan.stl"), "w");
	fprintf(f, "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
		   "vertex 1 0 0\nvertex 0 1 nan\nendloop\nendfacet\nendsolid x\n");
	fclose(f);
	/* PLY whose last face lost its last index */
	f = fopen(tpath("trunc.ply"), "w");
	fprintf(f, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
		   "property float y\nproperty float z\nelement face 1\n"
		   "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
	fclose(f);
	f = fopen(tpath("points.obj"), "w");
	fprintf(f, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n");
	fclose(f);
}

static void test_load_files(void)
{
	PX_NEEDS(ASSIMP);
	/* coordinates in eighths: exact in the importer's floats */
	double h[3] = {0.5, 0.25, 0.75};
	struct gen_mesh g;
	struct px_model *ref, *m;
	struct px_mesh_report rp;
	const char *good[] = {"box_a.stl", "box_b.stl", "box.obj", "box.ply"};
	size_t k;
	int i;

	snprintf(tmpdir, sizeof(tmpdir), "/tmp/px_mesh_XXXXXX");
	PX_CHECK(mkdtemp(tmpdir) != NULL);
	PX_CHECK_INT_EQ(gen_box(h, 2, &g), 0);
	write_files(&g);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &ref), PX_OK);
	for (k = 0; k < 4; k++) {
		int rc = px_mesh_load(tpath(good[k]), NULL, &rp, &m);
		PX_CHECK_MSG(rc == PX_OK, "%s: %s (%s)", good[k], px_strerror(rc), rp.message);
		PX_CHECK_MSG(rp.closed, "%s: not closed: %s", good[k], rp.message);
		PX_CHECK_INT_EQ(rp.n_triangles, g.nt);
		PX_CHECK_NEAR(rp.volume, 8 * h[0] * h[1] * h[2], 1e-12);
		for (i = 0; i < 50; i++) {
			struct px_model_result a, b;
			px_vec3 p = rand_v(1.2);
			px_model_query(m, p, &a);
			px_model_query(ref, p, &b);
			PX_CHECK_NEAR(a.distance, b.distance, 1e-12);
		}
		px_model_free(m);
	}
	{
		/* scaled (a URDF <mesh scale>): mirrored keeps outside outside */
		const double sc[2][3] = {{2.0, 0.5, 3.0}, {-2.0, 0.5, 3.0}};
		const double zero[3] = {1.0, 0.0, 1.0};
		int s;
		for (s = 0; s < 2; s++) {
			int rc = px_mesh_load_scaled(tpath("box.obj"), sc[s], NULL, &rp, &m);
			PX_CHECK_MSG(rc == PX_OK, "%s", rp.message);
			if (rc)
				continue;
			PX_CHECK_MSG(rp.closed && !rp.flipped, "scale %d: %s", s, rp.message);
			PX_CHECK_NEAR(rp.volume, 8 * h[0] * h[1] * h[2] * 3.0, 1e-12);
			for (i = 0; i < 50; i++) {
				struct px_model_result a, b;
				px_vec3 p = rand_v(1.2), q;
				q.x = p.x / sc[s][0];
				q.y = p.y / sc[s][1];
				q.z = p.z / sc[s][2];
				px_model_query(m, p, &a);
				px_model_query(ref, q, &b);
				/* the sign of a point is the sign of its preimage */
				PX_CHECK((a.distance < 0) == (b.distance < 0));
			}
			px_model_free(m);
		}
		m = (struct px_model *)1;
		PX_CHECK_INT_EQ(px_mesh_load_scaled(tpath("box.obj"), zero, NULL, &rp, &m),
				PX_E_RANGE);
		PX_CHECK(m == NULL && strstr(rp.message, "box.obj") != NULL);
	}
	m = (struct px_model *)1;
	PX_CHECK_INT_EQ(px_mesh_load(tpath("missing.stl"), NULL, &rp, &m), PX_E_NOTFOUND);
	PX_CHECK(m == NULL);
	PX_CHECK(strstr(rp.message, "missing.stl") != NULL);
	PX_CHECK_INT_EQ(px_mesh_load(tpath("garbage.stl"), NULL, &rp, &m), PX_E_PARSE);
	PX_CHECK_MSG(strstr(rp.message, "garbage.stl") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_load(tpath("nan.stl"), NULL, &rp, &m), PX_E_NAN);
	PX_CHECK_MSG(strstr(rp.message, "nan.stl") && strstr(rp.message, "non-finite"),
		     "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_load(tpath("points.obj"), NULL, &rp, &m), PX_E_PARSE);
	PX_CHECK_MSG(strstr(rp.message, "no triangles") != NULL, "%s", rp.message);
	PX_CHECK_INT_EQ(px_mesh_load(tmpdir, NULL, &rp, &m), PX_E_IO);
	PX_CHECK_INT_EQ(px_mesh_load(tpath("trunc.ply"), NULL, &rp, &m), PX_E_PARSE);
	PX_CHECK_MSG(strstr(rp.message, "ends early") != NULL, "%s", rp.message);
	px_model_free(ref);
	gen_free(&g);
	{
		const char *all[] = {"box_a.stl", "box_b.stl", "box.obj", "box.ply",
				     "garbage.stl", "nan.stl", "points.obj", "trunc.ply"};
		for (k = 0; k < sizeof(all) / sizeof(all[0]); k++)
			unlink(tpath(all[k]));
		rmdir(tmpdir);
	}
}

/* ---- real-time ------------------------------------------------------------------ */

static void test_no_alloc(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct px_model_result r;
	uint64_t a;
	int i, hint = -1;

	PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 80, 40, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
	a = px_alloc_region_begin();
	for (i = 0; i < 2000; i++) {
		px_vec3 p = px_v3(1.5 * cos(0.01 * i), 1.5 * sin(0.01 * i), 0.2);
		px_model_query(m, p, &r);
		px_model_query_ex(m, p, INFINITY, hint, PX_QUERY_COHERENT, &r);
		px_model_query_ex(m, p, 0.01, hint, PX_QUERY_COHERENT, &r);
		hint = r.index;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	gen_free(&g);
}

static const struct px_test tests[] = {
	PX_T(test_tri_closest),      PX_T(test_tri_regions),
	PX_T(test_soup_vs_brute),    PX_T(test_closed_vs_brute),
	PX_T(test_scales_vs_brute),
	PX_T(test_coherent),         PX_T(test_cache), PX_T(test_convex_support),         PX_T(test_sign_box_exact),
	PX_T(test_sign_sphere_torus), PX_T(test_sign_concave), PX_T(test_sign_tetra),
	PX_T(test_open_and_bad_topology),
	PX_T(test_validation),       PX_T(test_load_files),
	PX_T(test_no_alloc)};
PX_TEST_MAIN(tests)
