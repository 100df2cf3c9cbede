/* Signed distance to closed NURBS surface shells through the point-to-model
 * interface: sphere, torus, box and pillow shells (and their mirror
 * orientations) against analytic inside tests and ray parity on a fine
 * tessellation; poles, seams, creases and corners; open and inconsistently
 * oriented shells stay unsigned and say why. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_arena.h"
#include "px_dist.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "px_test.h"

static unsigned char arena_mem[1 << 22];
static struct px_arena arena;

static void arena_reset(void)
{
	px_arena_init(&arena, arena_mem, sizeof(arena_mem));
}

static const double circ[9][3] = {{1, 0, 1}, {1, 1, 0}, {0, 1, 1}, {-1, 1, 0},
				  {-1, 0, 1}, {-1, -1, 0}, {0, -1, 1},
				  {1, -1, 0}, {1, 0, 1}};

/* Surface of revolution about z: the profile (rho, z, weight) rows j,
 * revolved by the rational quadratic circle along u. flip reverses u. */
static void revolve(struct px_nurbs_surf *s, int nv, const double (*prof)[3],
		    const double *kv, int nkv, int flip)
{
	static const double ku[12] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
	double xyz[3 * 81], w[81];
	const double r2 = sqrt(0.5);
	int i, j;
	for (j = 0; j < nv; j++)
		for (i = 0; i < 9; i++) {
			int k = j * 9 + i, ci = flip ? 8 - i : i;
			xyz[3 * k] = prof[j][0] * circ[ci][0];
			xyz[3 * k + 1] = prof[j][0] * circ[ci][1];
			xyz[3 * k + 2] = prof[j][1];
			w[k] = (circ[ci][2] ? 1.0 : r2) * prof[j][2];
		}
	PX_CHECK_INT_EQ(px_nurbs_surf_init(s, &arena, 2, 2, 9, nv, ku, 12, kv, nkv,
					   xyz, w, NULL),
			PX_OK);
}

static void sphere(struct px_nurbs_surf *s, double R, int flip)
{
	static const double kv[8] = {0, 0, 0, 0.5, 0.5, 1, 1, 1};
	const double r2 = sqrt(0.5);
	const double prof[5][3] = {{0, -R, 1}, {R, -R, r2}, {R, 0, 1}, {R, R, r2}, {0, R, 1}};
	revolve(s, 5, prof, kv, 8, flip);
}

static void torus(struct px_nurbs_surf *s, double R, double r)
{
	static const double kv[12] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
	const double r2 = sqrt(0.5);
	double prof[9][3];
	int j;
	for (j = 0; j < 9; j++) {
		prof[j][0] = R + r * circ[j][0];
		prof[j][1] = r * circ[j][1];
		prof[j][2] = circ[j][2] ? 1.0 : r2;
	}
	revolve(s, 9, (const double (*)[3])prof, kv, 12, 0);
}

/* Six faces of the box [-h, h] as degree-d Bezier patches (d = 1:
 * bilinear, 3: bicubic) with straight edges; bulge pushes the interior
 * control points of bicubic faces outwards (a pillow). Face f has
 * outward normal along axis f / 2, sign by f % 2, and Su x Sv outward
 * unless reversed (bit f of flip_mask). */
struct box_face {
	px_vec3 c, e1, e2, n;
};

static struct box_face box_face(px_vec3 h, int f, int flip)
{
	struct box_face b;
	int a = f / 2, pos = f % 2 == 0;
	double hv[3] = {h.x, h.y, h.z};
	int a1 = pos ? (a + 1) % 3 : (a + 2) % 3, a2 = pos ? (a + 2) % 3 : (a + 1) % 3;
	double c[3] = {-hv[0], -hv[1], -hv[2]}, e1[3] = {0, 0, 0}, e2[3] = {0, 0, 0},
	       n[3] = {0, 0, 0};
	if (pos)
		c[a] = hv[a];
	e1[a1] = 2 * hv[a1];
	e2[a2] = 2 * hv[a2];
	n[a] = pos ? 1 : -1;
	b.c = px_v3(c[0], c[1], c[2]);
	b.e1 = px_v3(e1[0], e1[1], e1[2]);
	b.e2 = px_v3(e2[0], e2[1], e2[2]);
	b.n = px_v3(n[0], n[1], n[2]);
	if (flip) {
		px_vec3 t = b.e1;
		b.e1 = b.e2;
		b.e2 = t;
	}
	return b;
}

static void box_shell(struct px_nurbs_surf *s, px_vec3 h, int deg, double bulge,
		      int nfaces, unsigned flip_mask)
{
	static const double k1[4] = {0, 0, 1, 1};
	static const double k3[8] = {0, 0, 0, 0, 1, 1, 1, 1};
	int f, i, j;
	for (f = 0; f < nfaces; f++) {
		struct box_face b = box_face(h, f, (flip_mask >> f) & 1u);
		double xyz[3 * 16];
		for (j = 0; j <= deg; j++)
			for (i = 0; i <= deg; i++) {
				px_vec3 p = px_v3_add(b.c, px_v3_add(px_v3_scale(b.e1, (double)i / deg),
								     px_v3_scale(b.e2, (double)j / deg)));
				if (i > 0 && i < deg && j > 0 && j < deg)
					p = px_v3_madd(p, b.n, bulge);
				xyz[3 * (j * (deg + 1) + i)] = p.x;
				xyz[3 * (j * (deg + 1) + i) + 1] = p.y;
				xyz[3 * (j * (deg + 1) + i) + 2] = p.z;
			}
		PX_CHECK_INT_EQ(px_nurbs_surf_init(&s[f], &arena, deg, deg, deg + 1, deg + 1,
						   deg == 1 ? k1 : k3, 2 * deg + 2,
						   deg == 1 ? k1 : k3, 2 * deg + 2, xyz, NULL,
						   NULL),
				PX_OK);
	}
}

/* ---- independent inside test: ray parity on a tessellation ---------------- */

#define TESS 48
#define MAX_TRI (12 * 2 * TESS * TESS) /* up to twelve surfaces */
static px_vec3 tri[MAX_TRI][3];
static int n_tri;

static void tessellate(const struct px_nurbs_surf *s, int ns)
{
	int f, i, j;
	n_tri = 0;
	for (f = 0; f < ns; f++) {
		double u0, u1, v0, v1;
		px_nurbs_surf_domain(&s[f], &u0, &u1, &v0, &v1);
		for (j = 0; j < TESS; j++)
			for (i = 0; i < TESS; i++) {
				double ua = u0 + (u1 - u0) * i / TESS, ub = u0 + (u1 - u0) * (i + 1) / TESS;
				double va = v0 + (v1 - v0) * j / TESS, vb = v0 + (v1 - v0) * (j + 1) / TESS;
				px_vec3 a = px_nurbs_surf_point(&s[f], ua, va);
				px_vec3 b = px_nurbs_surf_point(&s[f], ub, va);
				px_vec3 c = px_nurbs_surf_point(&s[f], ub, vb);
				px_vec3 d = px_nurbs_surf_point(&s[f], ua, vb);
				tri[n_tri][0] = a; tri[n_tri][1] = b; tri[n_tri][2] = c; n_tri++;
				tri[n_tri][0] = a; tri[n_tri][1] = c; tri[n_tri][2] = d; n_tri++;
			}
	}
}

/* Crossings of the ray p + t dir (t > 0) with the tessellation. */
static int ray_crossings(px_vec3 p, px_vec3 dir)
{
	int k, n = 0;
	for (k = 0; k < n_tri; k++) {
		px_vec3 e1 = px_v3_sub(tri[k][1], tri[k][0]), e2 = px_v3_sub(tri[k][2], tri[k][0]);
		px_vec3 pv = px_v3_cross(dir, e2), tv, qv;
		double det = px_v3_dot(e1, pv), inv, u, v, t;
		if (fabs(det) < 1e-300)
			continue;
		inv = 1.0 / det;
		tv = px_v3_sub(p, tri[k][0]);
		u = px_v3_dot(tv, pv) * inv;
		if (u < 0.0 || u > 1.0)
			continue;
		qv = px_v3_cross(tv, e1);
		v = px_v3_dot(dir, qv) * inv;
		if (v < 0.0 || u + v > 1.0)
			continue;
		t = px_v3_dot(e2, qv) * inv;
		if (t > 0.0)
			n++;
	}
	return n;
}

/* Inside by parity, agreed on by three random rays (-1 when they disagree:
 * a ray grazing a tessellation edge). */
static int parity_inside(px_vec3 p)
{
	int k, votes = 0;
	for (k = 0; k < 3; k++) {
		px_vec3 d = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
		votes += ray_crossings(p, d) & 1;
	}
	return votes == 0 ? 0 : votes == 3 ? 1 : -1;
}

/* ---- checks ------------------------------------------------------------- */

struct stats {
	int inside, outside;
};

/* One query against the expected side (1 inside, 0 outside) and the
 * unsigned distance from an unsigned query of the same model. */
static void check_point(const struct px_model *m, px_vec3 x, int want_inside,
			struct stats *st)
{
	struct px_model_result r, ru;
	PX_CHECK_INT_EQ(px_model_query(m, x, &r), 1);
	PX_CHECK_INT_EQ(px_model_query_ex(m, x, INFINITY, -1, PX_QUERY_UNSIGNED, &ru), 1);
	PX_CHECK(r.is_signed && !ru.is_signed);
	PX_CHECK_MSG(r.inside == want_inside,
		     "(%.17g, %.17g, %.17g): inside %d, expected %d (d %g, entity %d, u %g v %g)",
		     x.x, x.y, x.z, r.inside, want_inside, r.distance, r.index, r.u, r.v);
	PX_CHECK(want_inside ? r.distance < 0.0 : r.distance >= 0.0);
	PX_CHECK_CLOSE(fabs(r.distance), ru.distance, 1e-12, 1e-12);
	PX_CHECK_CLOSE(px_v3_norm(r.direction), 1.0, 1e-9, 0);
	PX_CHECK_CLOSE(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance), x), 0.0,
		       1e-9, 0);
	if (st) {
		if (want_inside)
			st->inside++;
		else
			st->outside++;
	}
}

static void check_closed(const struct px_model *m, double volume, double tol)
{
	struct px_nurbs_sign_info info;
	PX_CHECK_INT_EQ(px_nurbs_model_sign_info(m, &info), PX_OK);
	PX_CHECK_MSG(info.closed, "not closed: %s", info.why);
	PX_CHECK(px_model_caps(m) & PX_MODEL_CAP_SIGNED);
	PX_CHECK_CLOSE(info.volume, volume, tol, tol);
}

static void check_open(const struct px_model *m, const char *why_part)
{
	struct px_nurbs_sign_info info;
	struct px_model_result r;
	int i;
	PX_CHECK_INT_EQ(px_nurbs_model_sign_info(m, &info), PX_OK);
	PX_CHECK(!info.closed);
	PX_CHECK(!(px_model_caps(m) & PX_MODEL_CAP_SIGNED));
	PX_CHECK_MSG(strstr(info.why, why_part) != NULL, "why: %s", info.why);
	for (i = 0; i < 20; i++) {
		px_vec3 x = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1), px_rand_range(-1, 1));
		PX_CHECK_INT_EQ(px_model_query(m, x, &r), 1);
		PX_CHECK(!r.is_signed && !r.inside && r.distance >= 0.0);
	}
}

static void test_sphere(void)
{
	struct px_nurbs_surf s;
	struct px_model *m;
	struct stats st = {0, 0};
	const double R = 1.3;
	int flip, i;
	for (flip = 0; flip < 2; flip++) {
		uint64_t a;
		arena_reset();
		sphere(&s, R, flip);
		PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
		check_closed(m, 4.0 / 3.0 * M_PI * R * R * R, 1e-9);
		a = px_alloc_region_begin();
		for (i = 0; i < 400; i++) {
			px_vec3 x = px_v3(px_rand_range(-2, 2), px_rand_range(-2, 2),
					  px_rand_range(-2, 2));
			if (fabs(px_v3_norm(x) - R) < 1e-9)
				continue;
			check_point(m, x, px_v3_norm(x) < R, &st);
		}
		/* Poles (on and just off the axis), the seam half-plane. */
		for (i = 0; i < 8; i++) {
			double e = i % 2 ? 1e-3 : 0.4, side = i / 4 ? -1.0 : 1.0;
			double off = (i / 2) % 2 ? 1e-9 : 0.0;
			check_point(m, px_v3(off, 0, side * R * (1 + e)), 0, &st);
			check_point(m, px_v3(off, 0, side * R * (1 - e)), 1, &st);
			check_point(m, px_v3_scale(px_v3(cos(0.3 * i - 1), off, sin(0.3 * i - 1)),
						   R * (1 + e)), 0, &st);
			check_point(m, px_v3_scale(px_v3(cos(0.3 * i - 1), -off, sin(0.3 * i - 1)),
						   R * (1 - e)), 1, &st);
		}
		check_point(m, px_v3(0, 0, 0), 1, &st);
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		px_model_free(m);
	}
	printf("    sphere: %d inside, %d outside\n", st.inside, st.outside);
	PX_CHECK(st.inside > 100 && st.outside > 100);
}

static void test_torus(void)
{
	struct px_nurbs_surf s;
	struct px_model *m;
	struct stats st = {0, 0};
	const double R = 1.0, r = 0.35;
	uint64_t a;
	int i;
	arena_reset();
	torus(&s, R, r);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
	check_closed(m, 2.0 * M_PI * M_PI * R * r * r, 1e-9);
	a = px_alloc_region_begin();
	for (i = 0; i < 400; i++) {
		px_vec3 x = px_v3(px_rand_range(-1.5, 1.5), px_rand_range(-1.5, 1.5),
				  px_rand_range(-0.5, 0.5));
		double rho = hypot(x.x, x.y), t = hypot(rho - R, x.z);
		if (fabs(t - r) < 1e-9 || rho < 1e-9)
			continue;
		check_point(m, x, t < r, &st);
	}
	/* Both seams: the u seam is the half-plane y = 0, x > 0, the v seam
	 * the outer equator. */
	for (i = 0; i < 6; i++) {
		double e = i % 2 ? 1e-4 : 0.2;
		check_point(m, px_v3(R + r * (1 + e), 0, 0), 0, &st);
		check_point(m, px_v3(R + r * (1 - e), 0, 0), 1, &st);
		check_point(m, px_v3(R + r * (1 - e) * cos(0.5 * i), 0, r * (1 - e) * sin(0.5 * i)), 1, &st);
		check_point(m, px_v3((R + r * (1 + e)) * cos(0.7 * i), (R + r * (1 + e)) * sin(0.7 * i), 0), 0, &st);
	}
	check_point(m, px_v3(0, 0, 0), 0, &st);
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	printf("    torus: %d inside, %d outside\n", st.inside, st.outside);
	PX_CHECK(st.inside > 20 && st.outside > 100);
}

static int box_inside(px_vec3 x, px_vec3 h)
{
	return fabs(x.x) < h.x && fabs(x.y) < h.y && fabs(x.z) < h.z;
}

/* Box shells (bilinear and flat bicubic, both orientations): random
 * points, and points around every corner and along every edge. */
static void test_box(void)
{
	struct px_nurbs_surf s[6];
	struct px_model *m;
	struct stats st = {0, 0};
	const px_vec3 h = px_v3(0.7, 0.5, 0.9);
	int variant, i, c;
	for (variant = 0; variant < 3; variant++) {
		uint64_t a;
		arena_reset();
		box_shell(s, h, variant == 1 ? 3 : 1, 0.0, 6, variant == 2 ? 0x3fu : 0u);
		PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 6, NULL, &m), PX_OK);
		check_closed(m, 8 * h.x * h.y * h.z, 1e-9);
		a = px_alloc_region_begin();
		for (i = 0; i < 300; i++) {
			px_vec3 x = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1),
					  px_rand_range(-1.2, 1.2));
			check_point(m, x, box_inside(x, h), &st);
		}
		for (c = 0; c < 8; c++) {
			px_vec3 k = px_v3(c & 1 ? h.x : -h.x, c & 2 ? h.y : -h.y, c & 4 ? h.z : -h.z);
			for (i = 0; i < 30; i++) {
				double sc = i % 3 == 0 ? 1e-6 : i % 3 == 1 ? 1e-3 : 0.1;
				px_vec3 d = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
				px_vec3 x = px_v3_madd(k, d, sc);
				/* corner, then the middle of an edge */
				check_point(m, x, box_inside(x, h), &st);
				x.z -= k.z;
				check_point(m, x, box_inside(x, h), &st);
			}
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		px_model_free(m);
	}
	printf("    box: %d inside, %d outside\n", st.inside, st.outside);
	PX_CHECK(st.inside > 200 && st.outside > 200);
}

/* Pillow: six bicubic patches bulging out (and a dented one), compared
 * with ray parity on a fine tessellation away from the surface. */
static void test_pillow(void)
{
	struct px_nurbs_surf s[6];
	struct px_model *m;
	struct stats st = {0, 0};
	const px_vec3 h = px_v3(0.6, 0.6, 0.5);
	int variant, i, skipped = 0;
	for (variant = 0; variant < 2; variant++) {
		double bulge = variant ? -0.25 : 0.35;
		struct px_nurbs_sign_info info;
		arena_reset();
		box_shell(s, h, 3, bulge, 6, 0u);
		PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 6, NULL, &m), PX_OK);
		PX_CHECK_INT_EQ(px_nurbs_model_sign_info(m, &info), PX_OK);
		PX_CHECK_MSG(info.closed, "%s", info.why);
		/* Each face is displaced by bulge * 3s(1-s) * 3t(1-t) along its
		 * normal (the interior control points' Bernstein weights), which
		 * adds bulge * area / 4. */
		PX_CHECK_CLOSE(info.volume,
			       8 * h.x * h.y * h.z + 2.0 * bulge *
						      (h.x * h.y + h.y * h.z + h.z * h.x),
			       1e-9, 1e-9);
		tessellate(s, 6);
		for (i = 0; i < 250; i++) {
			px_vec3 x = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1),
					  px_rand_range(-1, 1));
			struct px_model_result ru;
			int in;
			PX_CHECK_INT_EQ(px_model_query_ex(m, x, INFINITY, -1, PX_QUERY_UNSIGNED, &ru), 1);
			if (ru.distance < 2e-3) {
				skipped++;
				continue; /* the tessellation differs from the surface here */
			}
			in = parity_inside(x);
			if (in < 0) {
				skipped++;
				continue;
			}
			check_point(m, x, in, &st);
		}
		/* Along the creases of the pillow, both sides. */
		for (i = 0; i < 40; i++) {
			double t = px_rand_range(-0.9, 0.9), e = i % 2 ? 1e-3 : 0.05;
			px_vec3 x = px_v3(h.x + e, t * h.y, h.z + e);
			int in = parity_inside(x);
			if (in >= 0)
				check_point(m, x, in, &st);
			x = px_v3(h.x - e * 2, t * h.y, h.z - e * 2);
			in = parity_inside(x);
			if (in >= 0)
				check_point(m, x, in, &st);
		}
		px_model_free(m);
	}
	printf("    pillow: %d inside, %d outside, %d skipped\n", st.inside, st.outside,
	       skipped);
	PX_CHECK(st.inside > 100 && st.outside > 100);
}

/* Quarter q (0..3) of the surface of revolution of a straight profile
 * from (rho0, z0) to (rho1, z1): a rational quadratic arc along u (90
 * degrees from q * 90), linear along v. */
static void quarter(struct px_nurbs_surf *s, int q, double rho0, double z0,
		    double rho1, double z1)
{
	static const double ku[6] = {0, 0, 0, 1, 1, 1}, kv[4] = {0, 0, 1, 1};
	const double r2 = sqrt(0.5), prof[2][2] = {{rho0, z0}, {rho1, z1}};
	double xyz[3 * 6], w[6];
	int i, j;
	for (j = 0; j < 2; j++)
		for (i = 0; i < 3; i++) {
			int k = j * 3 + i, ci = 2 * q + i;
			xyz[3 * k] = prof[j][0] * circ[ci][0];
			xyz[3 * k + 1] = prof[j][0] * circ[ci][1];
			xyz[3 * k + 2] = prof[j][1];
			w[k] = circ[ci][2] ? 1.0 : r2;
		}
	PX_CHECK_INT_EQ(px_nurbs_surf_init(s, &arena, 2, 1, 3, 2, ku, 6, kv, 4, xyz, w, NULL),
			PX_OK);
}

/* A capped cylinder of twelve patches (four quarters each for the side
 * and the two caps): four patches meet at each of the eight rim
 * vertices, the rims are curved edges between a side and a cap patch,
 * four cap patches share the centre. Random points around the rim
 * vertices, along the rims and the side seams at several scales, against
 * the exact inside test, and a sample checked against ray parity on a
 * dense tessellation as well. */
static void test_capped_cylinder(void)
{
	struct px_nurbs_surf s[12];
	struct px_model *m;
	struct stats st = {0, 0};
	const double r = 0.4, h = 0.6;
	int q, i, agree = 0, compared = 0;
	uint64_t a;
	arena_reset();
	for (q = 0; q < 4; q++) {
		quarter(&s[q], q, r, -h, r, h);     /* side, outward */
		quarter(&s[4 + q], q, r, h, 0, h);  /* top, +z */
		quarter(&s[8 + q], q, 0, -h, r, -h); /* bottom, -z */
	}
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 12, NULL, &m), PX_OK);
	check_closed(m, M_PI * r * r * 2 * h, 1e-9);
	tessellate(s, 12);
	a = px_alloc_region_begin();
	for (i = 0; i < 480; i++) {
		double sc = i % 4 == 0 ? 1e-7 : i % 4 == 1 ? 1e-4 : i % 4 == 2 ? 1e-2 : 0.1;
		double ang = i % 8 < 4 ? 0.5 * M_PI * (i % 8) : px_rand_range(0, 2 * M_PI);
		double z = (i / 8) % 3 == 2 ? px_rand_range(-h, h) : ((i / 8) % 3 ? h : -h);
		px_vec3 base = px_v3(r * cos(ang), r * sin(ang), z);
		px_vec3 x = px_v3_madd(base, px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal()), sc);
		double rho = hypot(x.x, x.y);
		int in = rho < r && fabs(x.z) < h;
		/* (i / 8) % 3 == 2: along a side seam at a quarter angle, or
		 * anywhere on the side; else a rim vertex or a rim point */
		check_point(m, x, in, &st);
		if (sc >= 1e-2 && px_model_query(m, x, &(struct px_model_result){0}) == 1) {
			struct px_model_result ru;
			px_model_query_ex(m, x, INFINITY, -1, PX_QUERY_UNSIGNED, &ru);
			/* the tessellation's chords cut inside the curved side
			 * by r (1 - cos(pi / 4 / TESS)): compare beyond that */
			if (ru.distance > 2.0 * r * (1.0 - cos(M_PI / 4 / TESS)) + 1e-6) {
				int pin = parity_inside(x);
				if (pin >= 0) {
					compared++;
					agree += pin == in;
				}
			}
		}
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	printf("    capped cylinder: %d inside, %d outside; ray parity agrees on %d of %d\n",
	       st.inside, st.outside, agree, compared);
	PX_CHECK(st.inside > 100 && st.outside > 100);
	PX_CHECK(compared > 50 && agree == compared);
}

/* Bilinear quad with corners c0..c3 counterclockwise seen from the side
 * Su x Sv points to. */
static void quad(struct px_nurbs_surf *s, px_vec3 c0, px_vec3 c1, px_vec3 c2, px_vec3 c3)
{
	static const double k1[4] = {0, 0, 1, 1};
	double xyz[12] = {c0.x, c0.y, c0.z, c1.x, c1.y, c1.z,
			  c3.x, c3.y, c3.z, c2.x, c2.y, c2.z};
	PX_CHECK_INT_EQ(px_nurbs_surf_init(s, &arena, 1, 1, 2, 2, k1, 4, k1, 4, xyz, NULL,
					   NULL),
			PX_OK);
}

static int l_inside(px_vec3 x, double h)
{
	if (x.z <= 0.0 || x.z >= h || x.x <= 0.0 || x.y <= 0.0)
		return 0;
	return (x.x < 2.0 && x.y < 1.0) || (x.x < 1.0 && x.y < 2.0);
}

/* An L-shaped prism: a reflex (concave) edge, T-junctions between the
 * caps (two rectangles each) and the long side faces. */
static void test_l_prism(void)
{
	static const double poly[6][2] = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
	struct px_nurbs_surf s[10];
	struct px_model *m;
	struct stats st = {0, 0};
	const double h = 0.8;
	uint64_t a;
	int i, n = 0;
	arena_reset();
	for (i = 0; i < 6; i++) {
		const double *p0 = poly[i], *p1 = poly[(i + 1) % 6];
		quad(&s[n++], px_v3(p0[0], p0[1], 0), px_v3(p1[0], p1[1], 0),
		     px_v3(p1[0], p1[1], h), px_v3(p0[0], p0[1], h));
	}
	/* caps: [0,2]x[0,1] and [0,1]x[1,2], top facing +z, bottom -z */
	quad(&s[n++], px_v3(0, 0, h), px_v3(2, 0, h), px_v3(2, 1, h), px_v3(0, 1, h));
	quad(&s[n++], px_v3(0, 1, h), px_v3(1, 1, h), px_v3(1, 2, h), px_v3(0, 2, h));
	quad(&s[n++], px_v3(0, 0, 0), px_v3(0, 1, 0), px_v3(2, 1, 0), px_v3(2, 0, 0));
	quad(&s[n++], px_v3(0, 1, 0), px_v3(0, 2, 0), px_v3(1, 2, 0), px_v3(1, 1, 0));
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, n, NULL, &m), PX_OK);
	check_closed(m, 3.0 * h, 1e-9);
	a = px_alloc_region_begin();
	for (i = 0; i < 400; i++) {
		px_vec3 x = px_v3(px_rand_range(-0.5, 2.5), px_rand_range(-0.5, 2.5),
				  px_rand_range(-0.4, 1.2));
		check_point(m, x, l_inside(x, h), &st);
	}
	/* Around the reflex edge x = y = 1 and its two end corners, and
	 * around the T-junction points (0, 1, z) and (1, 1, 0). */
	for (i = 0; i < 300; i++) {
		static const double anchors[5][3] = {{1, 1, 0.4}, {1, 1, 0}, {1, 1, 0.8},
						     {0, 1, 0.3}, {1.5, 1, 0}};
		const double *k = anchors[i % 5];
		double sc = (i / 5) % 3 == 0 ? 1e-6 : (i / 5) % 3 == 1 ? 1e-3 : 0.1;
		px_vec3 x = px_v3_madd(px_v3(k[0], k[1], k[2]),
				       px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal()),
				       sc);
		check_point(m, x, l_inside(x, h), &st);
	}
	/* The bisector of the reflex edge, inside and outside. */
	for (i = 1; i <= 10; i++) {
		double e = pow(10.0, -i * 0.6);
		check_point(m, px_v3(1 + e, 1 + e, 0.4), 0, &st);
		check_point(m, px_v3(1 - e, 1 - e, 0.4), 1, &st);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	printf("    L prism: %d inside, %d outside\n", st.inside, st.outside);
	PX_CHECK(st.inside > 100 && st.outside > 200);
}

static void test_unsigned_cases(void)
{
	struct px_nurbs_surf s[6];
	struct px_model *m;
	const px_vec3 h = px_v3(0.5, 0.5, 0.5);
	struct px_nurbs_curve cv;
	static const double ck[4] = {0, 0, 1, 1};
	static const double cx[6] = {0, 0, 0, 1, 1, 1};

	/* Open box: five faces. */
	arena_reset();
	box_shell(s, h, 1, 0.0, 5, 0u);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 5, NULL, &m), PX_OK);
	check_open(m, "not shared");
	px_model_free(m);
	/* One face flipped: not consistently oriented. */
	arena_reset();
	box_shell(s, h, 1, 0.0, 6, 0x4u);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 6, NULL, &m), PX_OK);
	check_open(m, "oppositely");
	px_model_free(m);
	/* A single open patch. */
	arena_reset();
	box_shell(s, h, 3, 0.3, 1, 0u);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, s, 1, NULL, &m), PX_OK);
	check_open(m, "not shared");
	px_model_free(m);
	/* Sphere with a curve: curves make the model unsigned. */
	arena_reset();
	sphere(&s[0], 1.0, 0);
	PX_CHECK_INT_EQ(px_nurbs_curve_init(&cv, &arena, 1, 2, ck, 4, cx, NULL, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_nurbs_model_create(&cv, 1, s, 1, NULL, &m), PX_OK);
	check_open(m, "curves");
	px_model_free(m);
	/* Not a NURBS model. */
	PX_CHECK_INT_EQ(px_nurbs_model_sign_info(NULL, NULL), PX_E_INVAL);
}

/* Points on the surface are outside, with a unit direction; max_dist and
 * the unsigned flag work on signed models; a posed model signs in the
 * world frame. */
static void test_on_surface_and_pose(void)
{
	struct px_nurbs_surf s;
	struct px_model *m;
	struct px_model_result r;
	px_pose pose;
	int i;
	arena_reset();
	sphere(&s, 1.0, 0);
	PX_CHECK_INT_EQ(px_nurbs_model_create(NULL, 0, &s, 1, NULL, &m), PX_OK);
	for (i = 0; i < 10; i++) {
		px_vec3 x = px_nurbs_surf_point(&s, 0.1 * i, 0.37);
		PX_CHECK_INT_EQ(px_model_query(m, x, &r), 1);
		PX_CHECK(r.is_signed && !r.inside && r.distance >= 0.0 && r.distance < 1e-12);
		PX_CHECK_CLOSE(px_v3_norm(r.direction), 1.0, 1e-9, 0);
	}
	PX_CHECK_INT_EQ(px_model_query_ex(m, px_v3(0, 0, 0.5), 0.4, -1, 0, &r), 0);
	PX_CHECK_INT_EQ(px_model_query_ex(m, px_v3(0, 0, 0.5), 0.6, -1, 0, &r), 1);
	PX_CHECK_CLOSE(r.distance, -0.5, 1e-12, 0);
	PX_CHECK_CLOSE(r.direction.z, 1.0, 1e-12, 0);
	PX_CHECK(px_quat_from_axis_angle(px_v3(1, 2, 3), 0.7, &pose.q) == PX_OK);
	pose.t = px_v3(3, -1, 2);
	PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
	for (i = 0; i < 100; i++) {
		px_vec3 x = px_v3_add(pose.t, px_v3(px_rand_range(-1.5, 1.5), px_rand_range(-1.5, 1.5),
						    px_rand_range(-1.5, 1.5)));
		double want = px_v3_dist(x, pose.t) - 1.0;
		PX_CHECK_INT_EQ(px_model_query(m, x, &r), 1);
		PX_CHECK_CLOSE(r.distance, want, 1e-10, 1e-10);
		PX_CHECK(r.inside == (want < 0));
		PX_CHECK_CLOSE(px_v3_dist(px_v3_madd(r.point, r.direction, r.distance), x), 0.0,
			       1e-9, 0);
	}
	px_model_free(m);
}

static const struct px_test tests[] = {
	PX_T(test_sphere),
	PX_T(test_torus),
	PX_T(test_box),
	PX_T(test_pillow),
	PX_T(test_l_prism),
	PX_T(test_capped_cylinder),
	PX_T(test_unsigned_cases),
	PX_T(test_on_surface_and_pose),
};

PX_TEST_MAIN(tests)
