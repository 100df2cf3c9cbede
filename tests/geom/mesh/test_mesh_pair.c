/*
 * Exact mesh-to-mesh distance (geom/mesh/px_mesh_pair.c).
 *
 * References, written independently of the library's routines: the
 * triangle-triangle distance is checked against (1) the nine edge-edge
 * distances by a plain parametric minimisation and the six vertex-face
 * distances, with crossing decided by solving each edge against the
 * other triangle's plane by Cramer's rule, and (2) dense sampling of
 * each triangle measured exactly against the other (an upper bound that
 * the answer may never exceed). Mesh pairs are compared with the
 * minimum over all triangle pairs of reference (1).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_gen.h"
#include "mesh_internal.h"
#include "px_alloc_count.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_vec3 rand_pt(double s)
{
	return px_v3(px_rand_range(-s, s), px_rand_range(-s, s), px_rand_range(-s, s));
}

static px_pose rand_pose(px_vec3 t)
{
	px_pose P;
	double w = px_rand_normal(), x = px_rand_normal(), y = px_rand_normal(),
	       z = px_rand_normal(), n = sqrt(w * w + x * x + y * y + z * z);
	P.q.w = w / n;
	P.q.x = x / n;
	P.q.y = y / n;
	P.q.z = z / n;
	P.t = t;
	return P;
}

/* Segment-segment squared distance: minimum of the interior critical
 * point (when inside the square) and the four boundary sides, each an
 * exact point-segment distance. */
static double ref_pt_seg(px_vec3 p, px_vec3 a, px_vec3 b)
{
	px_vec3 d = px_v3_sub(b, a);
	double l = px_v3_norm2(d), t = l > 0 ? px_v3_dot(px_v3_sub(p, a), d) / l : 0;
	t = t < 0 ? 0 : (t > 1 ? 1 : t);
	return px_v3_dist2(p, px_v3_madd(a, d, t));
}

static double ref_seg_seg(px_vec3 p1, px_vec3 q1, px_vec3 p2, px_vec3 q2)
{
	px_vec3 d1 = px_v3_sub(q1, p1), d2 = px_v3_sub(q2, p2), r = px_v3_sub(p1, p2);
	double a = px_v3_dot(d1, d1), b = px_v3_dot(d1, d2), e = px_v3_dot(d2, d2);
	double c = px_v3_dot(d1, r), f = px_v3_dot(d2, r), den = a * e - b * b;
	double best = fmin(fmin(ref_pt_seg(p1, p2, q2), ref_pt_seg(q1, p2, q2)),
			   fmin(ref_pt_seg(p2, p1, q1), ref_pt_seg(q2, p1, q1)));
	if (den > 1e-300) {
		/* unconstrained minimum of |p1 + s d1 - p2 - t d2|^2 */
		double s = (b * f - c * e) / den, t = (a * f - b * c) / den;
		if (s > 0 && s < 1 && t > 0 && t < 1)
			best = fmin(best, px_v3_dist2(px_v3_madd(p1, d1, s), px_v3_madd(p2, d2, t)));
	}
	return best;
}

/* Does segment pq meet triangle T? Solve p + s (q - p) = T0 + u e1 + v e2
 * by Cramer's rule. */
static int ref_seg_hits(px_vec3 p, px_vec3 q, const px_vec3 T[3])
{
	px_vec3 d = px_v3_sub(q, p), e1 = px_v3_sub(T[1], T[0]), e2 = px_v3_sub(T[2], T[0]);
	px_vec3 r = px_v3_sub(p, T[0]);
	/* columns (e1, e2, -d) */
	px_vec3 md = px_v3_neg(d);
	double det = px_v3_dot(e1, px_v3_cross(e2, md));
	double u, v, s;
	if (fabs(det) < 1e-14 * px_v3_norm(e1) * px_v3_norm(e2) * px_v3_norm(d))
		return 0; /* parallel: left to the distances */
	u = px_v3_dot(r, px_v3_cross(e2, md)) / det;
	v = px_v3_dot(e1, px_v3_cross(r, md)) / det;
	s = px_v3_dot(e1, px_v3_cross(e2, r)) / det;
	return s >= 0 && s <= 1 && u >= 0 && v >= 0 && u + v <= 1;
}

static double ref_tri_tri(const px_vec3 A[3], const px_vec3 B[3], int *cross)
{
	double best = INFINITY;
	int i, j;
	*cross = 0;
	for (i = 0; i < 3; i++)
		if (ref_seg_hits(A[i], A[(i + 1) % 3], B) || ref_seg_hits(B[i], B[(i + 1) % 3], A))
			*cross = 1;
	for (i = 0; i < 3; i++) {
		for (j = 0; j < 3; j++)
			best = fmin(best, ref_seg_seg(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3]));
		best = fmin(best, px_tri_closest(A[i], B[0], B[1], B[2], NULL, NULL, NULL, NULL, NULL));
		best = fmin(best, px_tri_closest(B[i], A[0], A[1], A[2], NULL, NULL, NULL, NULL, NULL));
	}
	return *cross ? 0.0 : best;
}

/* Upper bound by sampling: n x n barycentric grid of each triangle,
 * measured exactly against the other. */
static double sampled_tri_tri(const px_vec3 A[3], const px_vec3 B[3], int n)
{
	double best = INFINITY;
	int i, j, s;
	for (s = 0; s < 2; s++) {
		const px_vec3 *X = s ? B : A, *Y = s ? A : B;
		for (i = 0; i <= n; i++)
			for (j = 0; i + j <= n; j++) {
				double u = (double)i / n, v = (double)j / n;
				px_vec3 p = px_v3_add(px_v3_scale(X[0], 1 - u - v),
						      px_v3_add(px_v3_scale(X[1], u), px_v3_scale(X[2], v)));
				best = fmin(best, px_tri_closest(p, Y[0], Y[1], Y[2], NULL, NULL, NULL, NULL,
								 NULL));
			}
	}
	return best;
}

/* Random triangle pairs of several kinds (see the switch). */
static void make_pair(int kind, px_vec3 A[3], px_vec3 B[3])
{
	int i;
	for (i = 0; i < 3; i++) {
		A[i] = rand_pt(1);
		B[i] = px_v3_add(rand_pt(1), px_v3(px_rand_range(-1.5, 1.5), 0, 0));
	}
	switch (kind) {
	case 0: /* general */
		break;
	case 1: /* A collapsed to a point */
		A[1] = A[2] = A[0];
		break;
	case 2: /* B collapsed to a segment (repeated vertex) */
		B[2] = B[1];
		break;
	case 3: /* needle: third vertex nearly on the first edge */
		A[2] = px_v3_add(px_v3_lerp(A[0], A[1], px_rand_range(-0.5, 1.5)),
				 px_v3_scale(rand_pt(1), px_rand_unit() < 0.5 ? 1e-6 : 1e-13));
		break;
	case 4: { /* coplanar (z = 0), overlapping or not */
		for (i = 0; i < 3; i++) {
			A[i].z = 0;
			B[i].z = 0;
		}
		break;
	}
	case 5: { /* touching: B's vertex placed on A's face */
		double u = px_rand_unit(), v = px_rand_unit() * (1 - u);
		px_vec3 n = px_v3_cross(px_v3_sub(A[1], A[0]), px_v3_sub(A[2], A[0]));
		px_vec3 q = px_v3_add(px_v3_scale(A[0], 1 - u - v),
				      px_v3_add(px_v3_scale(A[1], u), px_v3_scale(A[2], v)));
		px_vec3 off = px_v3_sub(q, B[0]);
		for (i = 0; i < 3; i++)
			B[i] = px_v3_add(B[i], off);
		/* the rest of B on the outer side */
		for (i = 1; i < 3; i++)
			if (px_v3_dot(n, px_v3_sub(B[i], q)) < 0)
				B[i] = px_v3_madd(B[i], n, -2 * px_v3_dot(n, px_v3_sub(B[i], q)) /
							      px_v3_norm2(n));
		break;
	}
	case 6: { /* crossing: B's edge pierces A's interior */
		double u = px_rand_range(0.1, 0.4), v = px_rand_range(0.1, 0.4);
		px_vec3 n = px_v3_cross(px_v3_sub(A[1], A[0]), px_v3_sub(A[2], A[0]));
		px_vec3 q = px_v3_add(px_v3_scale(A[0], 1 - u - v),
				      px_v3_add(px_v3_scale(A[1], u), px_v3_scale(A[2], v)));
		px_vec3 dir = px_v3_add(px_v3_scale(n, 1 / px_v3_norm(n)), px_v3_scale(rand_pt(1), 0.3));
		B[0] = px_v3_madd(q, dir, px_rand_range(0.05, 1));
		B[1] = px_v3_madd(q, dir, -px_rand_range(0.05, 1));
		break;
	}
	case 7: /* nearly parallel edges a little apart */
		B[0] = px_v3_add(A[0], px_v3(0, 0, 1e-3));
		B[1] = px_v3_add(px_v3_madd(A[1], px_v3_sub(A[1], A[0]), 0.3),
				 px_v3(1e-9, 0, 1e-3));
		break;
	default: /* far apart */
		for (i = 0; i < 3; i++)
			B[i] = px_v3_add(B[i], px_v3(10, 3, -2));
		break;
	}
}

static void test_tri_tri_vs_references(void)
{
	int trial, kind, crossings = 0, n = 0;
	for (kind = 0; kind < 9; kind++)
		for (trial = 0; trial < 300; trial++) {
			px_vec3 A[3], B[3], pa, pb;
			double d2, ref, samp;
			int cr, rcr;
			make_pair(kind, A, B);
			d2 = px__tri_tri(A, B, &pa, &pb, &cr);
			ref = ref_tri_tri(A, B, &rcr);
			samp = sampled_tri_tri(A, B, trial % 10 == 0 ? 40 : 12);
			n++;
			crossings += cr;
			/* the points are on the triangles and d2 is their distance
			 * (on a sliver, plane projections are only good to about
			 * eps / its angle: 1e-10 for the 1e-6 slivers here) */
			double on = kind == 3 ? 1e-16 : 1e-22;
			PX_CHECK_NEAR(px_v3_dist2(pa, pb), d2, 1e-12 * (1 + d2));
			PX_CHECK_MSG(px_tri_closest(pa, A[0], A[1], A[2], NULL, NULL, NULL, NULL, NULL) < on,
				     "kind %d: point_a off A by %.3g (cross %d)", kind,
				     sqrt(px_tri_closest(pa, A[0], A[1], A[2], NULL, NULL, NULL, NULL, NULL)), cr);
			PX_CHECK_MSG(px_tri_closest(pb, B[0], B[1], B[2], NULL, NULL, NULL, NULL, NULL) < on,
				     "kind %d: point_b off B by %.3g (cross %d)", kind,
				     sqrt(px_tri_closest(pb, B[0], B[1], B[2], NULL, NULL, NULL, NULL, NULL)), cr);
			/* never above a sampled pair */
			PX_CHECK_MSG(d2 <= samp * (1 + 1e-9) + 1e-28, "kind %d: %.17g above sample %.17g",
				     kind, d2, samp);
			/* equal to the feature reference, 0 when crossing */
			if (rcr && !cr) {
				/* the reference's inclusive tests call a grazing
				 * touch a crossing: then the distance must be ~0 */
				PX_CHECK_MSG(d2 < 1e-24, "kind %d: crossing missed, d2 %.3g", kind, d2);
			} else {
				PX_CHECK_MSG(fabs(sqrt(d2) - sqrt(ref)) <= 1e-9 * sqrt(ref) + 1e-14,
					     "kind %d trial %d: %.17g vs reference %.17g (cross %d/%d)", kind,
					     trial, sqrt(d2), sqrt(ref), cr, rcr);
			}
			if (kind == 6)
				PX_CHECK_MSG(cr && d2 == 0.0, "kind 6 not crossing: %d %.3g", cr, d2);
			if (kind == 5)
				PX_CHECK_MSG(d2 < 1e-24, "touching pair apart: %.3g", d2);
		}
	printf("    %d triangle pairs, %d crossing\n", n, crossings);
}

/* ---- meshes ---------------------------------------------------------------- */

/* Random triangle soup of nt triangles in a cube of half size s. */
static struct px_model *soup(int nt, double s)
{
	double *xyz = malloc(9 * (size_t)nt * sizeof(double));
	uint32_t *tri = malloc(3 * (size_t)nt * sizeof(uint32_t));
	struct px_model *m = NULL;
	int i;
	for (i = 0; i < nt; i++) {
		px_vec3 c = rand_pt(s), p;
		double r = px_rand_range(0.02, 0.4) * s;
		int k;
		for (k = 0; k < 3; k++) {
			p = px_v3_add(c, rand_pt(r));
			xyz[9 * i + 3 * k] = p.x;
			xyz[9 * i + 3 * k + 1] = p.y;
			xyz[9 * i + 3 * k + 2] = p.z;
			tri[3 * i + k] = (uint32_t)(3 * i + k);
		}
	}
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 3 * (size_t)nt, tri, (size_t)nt, NULL, NULL, &m), PX_OK);
	free(xyz);
	free(tri);
	return m;
}

/* Minimum of the reference over all triangle pairs (world frame). */
static double brute(const struct px_model *a, const struct px_model *b)
{
	size_t na = px_mesh_triangle_count(a), nb = px_mesh_triangle_count(b), i, j;
	px_vec3 *A = malloc(3 * na * sizeof(px_vec3)), *B = malloc(3 * nb * sizeof(px_vec3));
	double best = INFINITY;
	int k, cr;
	for (i = 0; i < na; i++) {
		px_mesh_triangle(a, i, A + 3 * i);
		for (k = 0; k < 3; k++)
			A[3 * i + k] = px_pose_transform_point(px_model_pose(a), A[3 * i + k]);
	}
	for (j = 0; j < nb; j++) {
		px_mesh_triangle(b, j, B + 3 * j);
		for (k = 0; k < 3; k++)
			B[3 * j + k] = px_pose_transform_point(px_model_pose(b), B[3 * j + k]);
	}
	for (i = 0; i < na && best > 0; i++)
		for (j = 0; j < nb; j++)
			best = fmin(best, ref_tri_tri(A + 3 * i, B + 3 * j, &cr));
	free(A);
	free(B);
	return sqrt(best);
}

static void check_on_triangle(const struct px_model *m, int t, px_vec3 p)
{
	px_vec3 v[3];
	int k;
	PX_CHECK_INT_EQ(px_mesh_triangle(m, (size_t)t, v), PX_OK);
	for (k = 0; k < 3; k++)
		v[k] = px_pose_transform_point(px_model_pose(m), v[k]);
	PX_CHECK_MSG(sqrt(px_tri_closest(p, v[0], v[1], v[2], NULL, NULL, NULL, NULL, NULL)) <
			     1e-9,
		     "point not on its triangle %d", t);
}

static void test_mesh_pair_vs_brute(void)
{
	int trial, zero = 0, n = 120;
	for (trial = 0; trial < n; trial++) {
		struct px_model *a = trial % 3 == 0 ? soup(px_rand_int(1, 120), 1.0)
						    : px_test_mesh_shape(trial % 4, 2, NULL);
		struct px_model *b = trial % 2 == 0 ? soup(px_rand_int(1, 120), 0.7)
						    : px_test_mesh_shape((trial / 4) % 4, 2, NULL);
		struct px__mesh_pair r, r2;
		double ref;
		px_vec3 dir = rand_pt(1);
		dir = px_v3_scale(dir, 1.0 / px_v3_norm(dir));
		px_model_set_pose(a, rand_pose(rand_pt(0.3)));
		/* from deep overlap to well apart */
		px_model_set_pose(b, rand_pose(px_v3_scale(dir, px_rand_range(0.0, 2.5))));
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, -1, -1, &r), PX_OK);
		ref = brute(a, b);
		zero += ref == 0.0;
		PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9 * ref + 1e-12,
			     "trial %d: %.17g vs brute force %.17g", trial, r.distance, ref);
		PX_CHECK_INT_EQ(r.intersecting, r.distance == 0.0);
		PX_CHECK(r.certified);
		PX_CHECK_NEAR(px_v3_dist(r.point_a, r.point_b), r.distance, 1e-12);
		check_on_triangle(a, r.tri_a, r.point_a);
		check_on_triangle(b, r.tri_b, r.point_b);
		/* any hints, right or wrong, give the same distance */
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, r.tri_a, r.tri_b, &r2), PX_OK);
		PX_CHECK_NEAR(r2.distance, r.distance, 1e-15);
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, 0, (int)px_mesh_triangle_count(b) - 1, &r2), PX_OK);
		PX_CHECK_NEAR(r2.distance, r.distance, 1e-15);
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, 1 << 30, -7, &r2), PX_OK);
		PX_CHECK_NEAR(r2.distance, r.distance, 1e-15);
		px_model_free(a);
		px_model_free(b);
	}
	printf("    %d mesh pairs equal to brute force, %d touching or crossing\n", n, zero);
}

/* Boxes sliding face to face at tiny gaps: many parallel edges and
 * coplanar faces, where rounding decides. */
static void test_mesh_pair_parallel_faces(void)
{
	struct gen_mesh g;
	struct px_model *a, *b;
	double h[3] = {0.5, 0.5, 0.5};
	int k;
	gen_box(h, 3, &g);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &a), PX_OK);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &b), PX_OK);
	gen_free(&g);
	for (k = 0; k < 40; k++) {
		px_pose P = px_pose_identity();
		struct px__mesh_pair r;
		double gap = k < 20 ? pow(10.0, -k * 0.5) : 0.0;
		P.t = px_v3(1.0 + gap, px_rand_range(-0.9, 0.9), px_rand_range(-0.9, 0.9));
		px_model_set_pose(b, P);
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, -1, -1, &r), PX_OK);
		PX_CHECK_MSG(fabs(r.distance - gap) <= 1e-12, "gap %.3g: %.17g", gap, r.distance);
		PX_CHECK_INT_EQ(r.intersecting, gap == 0.0);
	}
	px_model_free(a);
	px_model_free(b);
}

static void test_mesh_pair_errors_and_alloc(void)
{
	struct px_model *a = px_test_mesh_shape(0, 2, NULL), *b = px_test_mesh_shape(1, 2, NULL);
	struct px__mesh_pair r;
	uint64_t reg;
	int i;
	PX_CHECK_INT_EQ(px__mesh_pair(NULL, b, -1, -1, &r), PX_E_INVAL);
	PX_CHECK_INT_EQ(px__mesh_pair(a, b, -1, -1, NULL), PX_E_INVAL);
	reg = px_alloc_region_begin();
	for (i = 0; i < 50; i++) {
		px_model_set_pose(b, rand_pose(rand_pt(1.5)));
		PX_CHECK_INT_EQ(px__mesh_pair(a, b, i, i, &r), PX_OK);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	px_model_free(a);
	px_model_free(b);
}

/* ---- through px_pair_distance ------------------------------------------------ */

/* World-frame triangles of a mesh model (caller frees). */
static px_vec3 *world_tris(const struct px_model *m, size_t *n)
{
	size_t i;
	int k;
	px_vec3 *T;
	*n = px_mesh_triangle_count(m);
	T = malloc(3 * *n * sizeof(px_vec3));
	for (i = 0; i < *n; i++) {
		px_mesh_triangle(m, i, T + 3 * i);
		for (k = 0; k < 3; k++)
			T[3 * i + k] = px_pose_transform_point(px_model_pose(m), T[3 * i + k]);
	}
	return T;
}

/* Reference distance of a mesh to a capsule (segment p q, radius r):
 * triangle to segment (a collapsed triangle) by reference (1), minus r;
 * 0 when that is not positive. */
static double ref_mesh_capsule(const struct px_model *m, px_vec3 p, px_vec3 q, double r)
{
	size_t n, i;
	px_vec3 *T = world_tris(m, &n), S[3] = {p, q, q};
	double best = INFINITY;
	int cr;
	for (i = 0; i < n; i++)
		best = fmin(best, ref_tri_tri(T + 3 * i, S, &cr));
	free(T);
	return fmax(0.0, sqrt(best) - r);
}

/* Reference distance of a mesh to a solid box (pose P, half extents h):
 * 0 when a mesh vertex lies in the box, else the least triangle
 * distance to the box's twelve face triangles by reference (1). */
static double ref_mesh_box(const struct px_model *m, px_pose P, const double h[3])
{
	static const int F[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
				    {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
	size_t n, i;
	px_vec3 *T = world_tris(m, &n), C[8];
	double best = INFINITY;
	int k, f, cr;
	for (k = 0; k < 8; k++)
		C[k] = px_pose_transform_point(P, px_v3(k & 4 ? h[0] : -h[0], k & 2 ? h[1] : -h[1],
							k & 1 ? h[2] : -h[2]));
	for (i = 0; i < 3 * n; i++) {
		px_vec3 l = px_pose_inverse_transform_point(P, T[i]);
		if (fabs(l.x) <= h[0] && fabs(l.y) <= h[1] && fabs(l.z) <= h[2])
			best = 0.0;
	}
	for (i = 0; i < n && best > 0.0; i++)
		for (f = 0; f < 6; f++) {
			px_vec3 U[3] = {C[F[f][0]], C[F[f][1]], C[F[f][2]]};
			px_vec3 W[3] = {C[F[f][0]], C[F[f][2]], C[F[f][3]]};
			best = fmin(best, ref_tri_tri(T + 3 * i, U, &cr));
			best = fmin(best, ref_tri_tri(T + 3 * i, W, &cr));
		}
	free(T);
	return sqrt(best);
}

/* Upper bound for any primitive: dense samples of every triangle,
 * measured by the primitive's exact point query (unsigned: 0 inside). */
static double sampled_mesh_prim(const struct px_model *m, const struct px_model *pr, int g)
{
	size_t n, t;
	px_vec3 *T = world_tris(m, &n);
	double best = INFINITY;
	int i, j;
	for (t = 0; t < n; t++)
		for (i = 0; i <= g; i++)
			for (j = 0; i + j <= g; j++) {
				double u = (double)i / g, v = (double)j / g;
				const px_vec3 *X = T + 3 * t;
				struct px_model_result q;
				px_vec3 p = px_v3_add(px_v3_scale(X[0], 1 - u - v),
						      px_v3_add(px_v3_scale(X[1], u), px_v3_scale(X[2], v)));
				px_model_query(pr, p, &q);
				best = fmin(best, fmax(0.0, q.distance));
			}
	free(T);
	return best;
}

static void test_pair_mesh_vs_convex_primitives(void)
{
	int trial, n = 160, inter = 0, contained = 0;
	for (trial = 0; trial < n; trial++) {
		struct px_model *m = trial % 5 == 4 ? soup(px_rand_int(4, 80), 0.6)
						    : px_test_mesh_shape(trial % 4, 2, NULL);
		struct px_model *pr = NULL;
		struct px_prim P;
		struct px_pair_result r;
		struct px_model_result qa, qb;
		px_pose Pp = rand_pose(px_v3_scale(rand_pt(1), px_rand_range(0.0, 1.4)));
		int kind = trial % 4, swap = (trial / 4) % 2;
		double ref = -1.0, up, h[3];
		memset(&r, 0, sizeof(r));
		px_model_set_pose(m, rand_pose(rand_pt(0.2)));
		P.type = kind == 0 ? PX_PRIM_CAPSULE : kind == 1 ? PX_PRIM_BOX
				  : kind == 2 ? PX_PRIM_CYLINDER : PX_PRIM_CONE;
		P.a = px_rand_range(0.05, 0.4);
		P.b = px_rand_range(0.05, 0.4);
		P.c = kind == 3 ? 0.0 : px_rand_range(0.05, 0.4);
		if (trial % 16 == 5) {
			/* small, deep inside a closed mesh: solids overlap, surfaces apart */
			P.a = P.b = P.c = 0.02;
			px_model_set_pose(m, px_pose_identity());
			Pp.t = px_v3(0.6, 0, 0); /* in the torus tube / inside the others */
			if (trial % 4 != 0)
				Pp.t = px_v3(0, 0, 0);
		}
		PX_CHECK_INT_EQ(px_prim_model(&P, &pr), PX_OK);
		px_model_set_pose(pr, Pp);
		PX_CHECK_INT_EQ(swap ? px_pair_distance(pr, m, NULL, &r) : px_pair_distance(m, pr, NULL, &r),
				PX_OK);
		PX_CHECK_MSG(!r.local_only, "trial %d: mesh / %d flagged", trial, kind);
		h[0] = P.a, h[1] = P.b, h[2] = P.c;
		if (kind == 0)
			ref = ref_mesh_capsule(m, px_pose_transform_point(Pp, px_v3(0, 0, -P.b)),
					       px_pose_transform_point(Pp, px_v3(0, 0, P.b)), P.a);
		else if (kind == 1)
			ref = ref_mesh_box(m, Pp, h);
		up = sampled_mesh_prim(m, pr, kind >= 2 ? 6 : 2);
		{
			/* a closed mesh may hold the primitive whole */
			struct px_model_result qc;
			int held = px_model_query(m, Pp.t, &qc) == 1 && qc.is_signed && qc.distance < 0.0;
			if (ref >= 0)
				PX_CHECK_MSG(r.intersecting == (ref <= 1e-12 || held),
					     "trial %d kind %d: intersecting %d, ref %.9g, held %d", trial, kind,
					     r.intersecting, ref, held);
			if (r.intersecting && !held && r.depth > 0.0 &&
			    !(px_model_caps(m) & PX_MODEL_CAP_CONVEX)) {
				/* penetration witnesses of the depth search: each on
				 * its own surface (convex meshes go through EPA,
				 * tested in test_pair.c) */
				struct px_model_result q1, q2;
				px_model_query_ex(swap ? pr : m, r.point_a, INFINITY, -1, PX_QUERY_UNSIGNED, &q1);
				px_model_query_ex(swap ? m : pr, r.point_b, INFINITY, -1, PX_QUERY_UNSIGNED, &q2);
				PX_CHECK_NEAR(q1.distance, 0.0, 1e-9);
				PX_CHECK_NEAR(q2.distance, 0.0, 1e-9);
			} else if (r.intersecting && !held && r.depth == 0.0) {
				/* the mesh's witness is an overlap point: on the mesh
				 * and inside or on the primitive */
				px_vec3 pm = swap ? r.point_b : r.point_a;
				struct px_model_result q1, q2;
				px_model_query(pr, pm, &q1);
				px_model_query_ex(m, pm, INFINITY, -1, PX_QUERY_UNSIGNED, &q2);
				PX_CHECK_MSG(q1.distance <= 1e-9 && q2.distance <= 1e-9,
					     "trial %d kind %d: intersecting, witness %.3g from the primitive, "
					     "%.3g from the mesh (samples %.3g)",
					     trial, kind, q1.distance, q2.distance, up);
			}
			contained += r.intersecting && held && ref > 1e-12;
		}
		if (r.intersecting) {
			inter++;
		} else {
			const struct px_model *A = swap ? pr : m, *B = swap ? m : pr;
			if (ref >= 0)
				PX_CHECK_MSG(fabs(r.distance - ref) <= 1e-9 * ref + 1e-12,
					     "trial %d kind %d: %.17g vs reference %.17g", trial, kind,
					     r.distance, ref);
			PX_CHECK_MSG(r.distance <= up + 1e-12, "trial %d kind %d: %.17g above samples %.17g",
				     trial, kind, r.distance, up);
			PX_CHECK_NEAR(px_v3_dist(r.point_a, r.point_b), r.distance, 1e-12);
			px_model_query_ex(A, r.point_a, INFINITY, -1, PX_QUERY_UNSIGNED, &qa);
			px_model_query_ex(B, r.point_b, INFINITY, -1, PX_QUERY_UNSIGNED, &qb);
			PX_CHECK_NEAR(qa.distance, 0.0, 1e-9);
			PX_CHECK_NEAR(qb.distance, 0.0, 1e-9);
		}
		px_model_free(m);
		px_model_free(pr);
	}
	printf("    %d mesh / convex primitive pairs exact and certified (%d intersecting, %d of "
	       "them held inside a closed mesh)\n",
	       n, inter, contained);
}

static void test_pair_mesh_in_mesh(void)
{
	/* a small closed mesh inside a big one: surfaces apart, solids
	 * overlap */
	struct gen_mesh g;
	struct px_model *big, *small;
	struct px_pair_result r;
	px_pose P = px_pose_identity();
	gen_sphere(1.0, 12, 16, &g);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &big), PX_OK);
	gen_free(&g);
	gen_sphere(0.1, 6, 8, &g);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &small), PX_OK);
	gen_free(&g);
	P.t = px_v3(0.2, -0.1, 0.3);
	px_model_set_pose(small, P);
	memset(&r, 0, sizeof(r));
	PX_CHECK_INT_EQ(px_pair_distance(big, small, NULL, &r), PX_OK);
	PX_CHECK(r.intersecting && !r.local_only);
	PX_CHECK_MSG(r.depth > 0.5, "depth %.6g", r.depth);
	PX_CHECK_INT_EQ(px_pair_distance(small, big, NULL, &r), PX_OK);
	PX_CHECK(r.intersecting && !r.local_only);
	/* outside: apart, exact */
	P.t = px_v3(3, 0, 0);
	px_model_set_pose(small, P);
	PX_CHECK_INT_EQ(px_pair_distance(small, big, NULL, &r), PX_OK);
	PX_CHECK(!r.intersecting && !r.local_only);
	PX_CHECK_NEAR(r.distance, brute(small, big), 1e-12);
	px_model_free(big);
	px_model_free(small);
}

static void test_pair_exact_paths_alloc(void)
{
	struct px_model *a = px_test_mesh_shape(0, 2, NULL), *b = px_test_mesh_shape(3, 2, NULL);
	struct px_prim bx = {PX_PRIM_BOX, 0.1, 0.2, 0.3}, cy = {PX_PRIM_CYLINDER, 0.1, 0.2, 0};
	struct px_model *p1, *p2;
	struct px_pair_result r;
	struct px_pair_opts co = {1, 64, 1e-12, 1, 0, 0};
	uint64_t reg;
	int i;
	PX_CHECK_INT_EQ(px_prim_model(&bx, &p1), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&cy, &p2), PX_OK);
	memset(&r, 0, sizeof(r));
	reg = px_alloc_region_begin();
	for (i = 0; i < 40; i++) {
		px_pose P = rand_pose(px_v3_scale(rand_pt(1), 1.5));
		px_model_set_pose(b, P);
		px_model_set_pose(p1, P);
		px_model_set_pose(p2, P);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, i % 2 ? &co : NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(a, p1, i % 2 ? &co : NULL, &r), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(p2, a, i % 2 ? &co : NULL, &r), PX_OK);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	px_model_free(a);
	px_model_free(b);
	px_model_free(p1);
	px_model_free(p2);
}

/* Along a smooth path: coherent exact calls equal cold ones at every step;
 * local_ok = 1 takes the projections from last cycle's pair (local_only =
 * 1, an upper bound realised by points on both surfaces) and only in
 * coherent mode with a valid previous result; no allocation. */
static void test_pair_coherent_local_ok(void)
{
	/* b a torus or a (convex) sphere mesh, which local_ok also takes
	 * off the mesh/convex path; centre distance past contact */
	int kb = px_rand_int(0, 1);
	double R = kb ? 1.6 : 2.0;
	struct px_model *a = px_test_mesh_shape(0, 2, NULL);
	struct px_model *b = px_test_mesh_shape(kb, 2, NULL);
	struct px_pair_result rc, rl, r0;
	struct px_pair_opts ex = {1, 64, 1e-12, 1, 0, 0}, lo = {1, 64, 1e-12, 1, 0, 1};
	struct px_model_result qa, qb;
	double ph = px_rand_range(0.0, 6.283), w = px_rand_range(0.5, 2.0);
	uint64_t reg;
	int i, same = 0;
	memset(&rc, 0, sizeof(rc));
	memset(&rl, 0, sizeof(rl));
	/* not coherent yet (res->valid = 0): local_ok is ignored */
	px_model_set_pose(b, rand_pose(px_v3(R, 0.1, 0.2)));
	PX_CHECK_INT_EQ(px_pair_distance(a, b, &lo, &rl), PX_OK);
	PX_CHECK(!rl.local_only);
	PX_CHECK_NEAR(rl.distance, brute(a, b), 1e-12);
	reg = px_alloc_region_begin();
	for (i = 0; i < 60; i++) {
		double t = ph + 0.02 * i;
		px_pose P = rand_pose(px_v3(R * cos(t), R * sin(t), 0.3 * sin(w * t)));
		PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0.3, 1, 0), 2.0 * t, &P.q), PX_OK);
		px_model_set_pose(b, P);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, &ex, &rc), PX_OK);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, NULL, &r0), PX_OK);
		PX_CHECK(!rc.local_only && !r0.local_only);
		PX_CHECK_MSG(fabs(rc.distance - r0.distance) <= 1e-12 * r0.distance,
			     "step %d: coherent %.17g cold %.17g", i, rc.distance, r0.distance);
		PX_CHECK_INT_EQ(px_pair_distance(a, b, &lo, &rl), PX_OK);
		PX_CHECK_MSG(rl.local_only && !rl.intersecting, "step %d: local_only %d intersecting %d d %.6g exact %.6g", i, rl.local_only, rl.intersecting, rl.distance, r0.distance);
		PX_CHECK_MSG(rl.distance >= r0.distance * (1.0 - 1e-12),
			     "step %d: local %.17g below exact %.17g", i, rl.distance, r0.distance);
		PX_CHECK_NEAR(px_v3_dist(rl.point_a, rl.point_b), rl.distance, 1e-12);
		PX_CHECK(px_model_query(a, rl.point_a, &qa) >= 0);
		PX_CHECK(px_model_query(b, rl.point_b, &qb) >= 0);
		PX_CHECK(fabs(qa.distance) < 1e-9 && fabs(qb.distance) < 1e-9);
		same += rl.distance <= r0.distance * (1.0 + 1e-9);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(reg), 0);
	/* a smooth path: the tracked pair is mostly the global one */
	PX_CHECK_MSG(same >= 30, "local tracking global at %d of 60 steps", same);
	px_model_free(a);
	px_model_free(b);
}

/* A generated obstacle (torus, L-prism, sphere or box) against a small
 * link-like mesh (a long box or a coarse sphere), as the arm's pairs:
 * the link moves along a random line through the obstacle, far apart to
 * deep overlap; at every step the cold answer and the coherent one (last
 * step's triangles as the start) equal brute force and each other, and
 * the link moved onto the obstacle by the found gap (touching) gives 0. */
static struct px_model *gen_shape(int kind, struct gen_mesh *g)
{
	static const double hb[3] = {0.08, 0.05, 0.12}, hl[3] = {0.03, 0.035, 0.16};
	struct px_model *m = NULL;
	int rc;
	memset(g, 0, sizeof(*g));
	switch (kind) {
	case 0:
		rc = gen_torus(0.1, 0.03, 32, 16, g);
		break;
	case 1:
		rc = gen_lprism(0.12, 0.08, g);
		break;
	case 2:
		rc = gen_sphere(0.09, 8, 12, g);
		break;
	case 3:
		rc = gen_box(hb, 2, g);
		break;
	default:
		rc = gen_box(hl, 1, g);
		break;
	}
	PX_CHECK_INT_EQ(rc, 0);
	PX_CHECK_INT_EQ(px_mesh_model(g->xyz, g->nv, g->tri, g->nt, NULL, NULL, &m), PX_OK);
	return m;
}

static void test_mesh_pair_paths_coherent_vs_brute(void)
{
	int path, n = 0, apart = 0, over = 0, touch = 0;
	for (path = 0; path < 8; path++) {
		struct gen_mesh ga, gb;
		struct px_model *a = gen_shape(path % 4, &ga);
		struct px_model *b = gen_shape(path % 3 == 2 ? 2 : 4, &gb);
		px_vec3 d0 = rand_pt(1), p0, p1;
		px_pose Pb = rand_pose(px_v3(0, 0, 0));
		px_vec3 ax = rand_pt(1);
		struct px__mesh_pair prev;
		int i, have = 0;
		d0 = px_v3_scale(d0, 1.0 / px_v3_norm(d0));
		p0 = px_v3_scale(d0, 0.6);
		p1 = px_v3_add(px_v3_scale(d0, -0.05), rand_pt(0.05));
		px_model_set_pose(a, rand_pose(rand_pt(0.1)));
		for (i = 0; i <= 24; i++) {
			struct px__mesh_pair r0, r1;
			double ref, t = i / 24.0;
			px_quat dq;
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(ax, 0.05 * i, &dq), PX_OK);
			Pb.t = px_v3_add(px_v3_scale(p0, 1.0 - t), px_v3_scale(p1, t));
			Pb.q = px_quat_mul(dq, rand_pose(p0).q);
			Pb.q = px_quat_mul(dq, Pb.q);
			px_model_set_pose(b, Pb);
			PX_CHECK_INT_EQ(px__mesh_pair(a, b, -1, -1, &r0), PX_OK);
			PX_CHECK_INT_EQ(px__mesh_pair(a, b, have ? prev.tri_a : -1,
						      have ? prev.tri_b : -1, &r1), PX_OK);
			ref = brute(a, b);
			PX_CHECK_MSG(fabs(r0.distance - ref) <= 1e-9 * ref + 1e-12,
				     "path %d step %d: cold %.17g vs brute force %.17g", path, i,
				     r0.distance, ref);
			PX_CHECK_MSG(fabs(r1.distance - r0.distance) <= 1e-12 * r0.distance + 1e-15,
				     "path %d step %d: coherent %.17g vs cold %.17g", path, i,
				     r1.distance, r0.distance);
			PX_CHECK(r0.certified && r1.certified);
			PX_CHECK_NEAR(px_v3_dist(r1.point_a, r1.point_b), r1.distance, 1e-12);
			check_on_triangle(a, r1.tri_a, r1.point_a);
			check_on_triangle(b, r1.tri_b, r1.point_b);
			n++;
			apart += ref > 0.0;
			over += ref == 0.0;
			if (ref > 1e-6) {
				/* moved by the gap onto the obstacle: touching */
				px_pose Pt = Pb;
				struct px__mesh_pair rt;
				Pt.t = px_v3_add(Pb.t, px_v3_sub(r0.point_a, r0.point_b));
				px_model_set_pose(b, Pt);
				PX_CHECK_INT_EQ(px__mesh_pair(a, b, r0.tri_a, r0.tri_b, &rt), PX_OK);
				ref = brute(a, b);
				PX_CHECK_MSG(fabs(rt.distance - ref) <= 1e-9 * ref + 1e-12 &&
						     ref < 1e-12,
					     "path %d step %d touching: %.17g vs brute force %.17g",
					     path, i, rt.distance, ref);
				px_model_set_pose(b, Pb);
				touch++;
			}
			prev = r1;
			have = 1;
		}
		px_model_free(a);
		px_model_free(b);
		gen_free(&ga);
		gen_free(&gb);
	}
	PX_CHECK(apart > 0 && over > 0 && touch > 0);
	printf("    %d poses along 8 paths: %d apart, %d overlapping, %d touching; coherent == cold "
	       "== brute force\n", n, apart, over, touch);
}

static const struct px_test tests[] = {
	PX_T(test_tri_tri_vs_references), PX_T(test_mesh_pair_vs_brute),
	PX_T(test_mesh_pair_parallel_faces), PX_T(test_mesh_pair_errors_and_alloc),
	PX_T(test_pair_mesh_vs_convex_primitives), PX_T(test_pair_mesh_in_mesh),
	PX_T(test_pair_exact_paths_alloc), PX_T(test_pair_coherent_local_ok),
	PX_T(test_mesh_pair_paths_coherent_vs_brute)};
PX_TEST_MAIN(tests)
