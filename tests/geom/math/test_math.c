/*
 * Math core: vec3, quaternions, poses, boxes.
 *
 * References are computed independently here: rotations by the explicit
 * Hamilton product q v q* and by Rodrigues' formula, box distances by
 * clamping in local coordinates and by dense sampling, box overlap by
 * enumerating the vertices of the intersection of the two boxes' 12
 * half-spaces (an exact feasibility test, unlike the separating axes).
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_math.h"
#include "px_test.h"

/* Tolerances. Everything is O(1) in size unless scaled explicitly. */
#define TOL_ULP 1e-15   /* a handful of roundings on unit quantities */
#define TOL_REL 1e-12   /* round trips through several operations */

/* ---- independent references ------------------------------------------ */

/* Hamilton product written out from the definition with 4-vectors
 * (s1 s2 - v1.v2, s1 v2 + s2 v1 + v1 x v2). */
static px_quat ref_qmul(px_quat a, px_quat b)
{
	double s = a.w * b.w - (a.x * b.x + a.y * b.y + a.z * b.z);
	px_quat r;
	r.w = s;
	r.x = a.w * b.x + b.w * a.x + (a.y * b.z - a.z * b.y);
	r.y = a.w * b.y + b.w * a.y + (a.z * b.x - a.x * b.z);
	r.z = a.w * b.z + b.w * a.z + (a.x * b.y - a.y * b.x);
	return r;
}

static px_vec3 ref_rotate(px_quat q, px_vec3 v)
{
	px_quat p = {0.0, v.x, v.y, v.z};
	px_quat c = {q.w, -q.x, -q.y, -q.z};
	px_quat r = ref_qmul(ref_qmul(q, p), c);
	return px_v3(r.x, r.y, r.z);
}

/* Rodrigues: rotation matrix of angle th about unit k. */
static px_mat3 ref_rodrigues(px_vec3 k, double th)
{
	double c = cos(th), s = sin(th), C = 1.0 - c;
	px_mat3 m;
	m.m[0][0] = c + k.x * k.x * C;
	m.m[0][1] = k.x * k.y * C - k.z * s;
	m.m[0][2] = k.x * k.z * C + k.y * s;
	m.m[1][0] = k.y * k.x * C + k.z * s;
	m.m[1][1] = c + k.y * k.y * C;
	m.m[1][2] = k.y * k.z * C - k.x * s;
	m.m[2][0] = k.z * k.x * C - k.y * s;
	m.m[2][1] = k.z * k.y * C + k.x * s;
	m.m[2][2] = c + k.z * k.z * C;
	return m;
}

static px_vec3 ref_unit(px_vec3 v)
{
	double n = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
	return px_v3(v.x / n, v.y / n, v.z / n);
}

static px_vec3 rand_dir(void)
{
	px_vec3 v;
	do
		v = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	while (px_v3_norm(v) < 1e-3);
	return ref_unit(v);
}

static px_quat rand_quat(void)
{
	px_quat q;
	double n;
	do {
		q.w = px_rand_normal();
		q.x = px_rand_normal();
		q.y = px_rand_normal();
		q.z = px_rand_normal();
		n = sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
	} while (n < 1e-3);
	q.w /= n;
	q.x /= n;
	q.y /= n;
	q.z /= n;
	return q;
}

static px_vec3 rand_box_point(double r)
{
	return px_v3(px_rand_range(-r, r), px_rand_range(-r, r),
		     px_rand_range(-r, r));
}

static px_pose rand_pose(double r)
{
	px_pose p;
	p.q = rand_quat();
	p.t = rand_box_point(r);
	return p;
}

/* Max componentwise difference between q and +-r (same rotation). */
static double qdiff_sign(px_quat q, px_quat r)
{
	double dp = fmax(fmax(fabs(q.w - r.w), fabs(q.x - r.x)),
			 fmax(fabs(q.y - r.y), fabs(q.z - r.z)));
	double dm = fmax(fmax(fabs(q.w + r.w), fabs(q.x + r.x)),
			 fmax(fabs(q.y + r.y), fabs(q.z + r.z)));
	return fmin(dp, dm);
}

static double vdiff(px_vec3 a, px_vec3 b)
{
	return fmax(fmax(fabs(a.x - b.x), fabs(a.y - b.y)), fabs(a.z - b.z));
}

static double mdiff(const px_mat3 *a, const px_mat3 *b)
{
	double d = 0.0;
	int i, j;
	for (i = 0; i < 3; i++)
		for (j = 0; j < 3; j++)
			d = fmax(d, fabs(a->m[i][j] - b->m[i][j]));
	return d;
}

static double qnorm(px_quat q)
{
	return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}

static int qfinite(px_quat q)
{
	return isfinite(q.w) && isfinite(q.x) && isfinite(q.y) &&
	       isfinite(q.z);
}

#define CHECK_VEC_NEAR(a, b, tol)                                           \
	do {                                                                \
		px_vec3 a_ = (a), b_ = (b);                                 \
		PX_CHECK_MSG(vdiff(a_, b_) <= (tol),                        \
			     "%s ~ %s: (%.17g %.17g %.17g) vs (%.17g %.17g " \
			     "%.17g), tol %.3g",                            \
			     #a, #b, a_.x, a_.y, a_.z, b_.x, b_.y, b_.z,    \
			     (double)(tol));                                \
	} while (0)

/* ---- identities -------------------------------------------------------- */

static void test_identities(void)
{
	int n;
	for (n = 0; n < 2000; n++) {
		px_pose p = rand_pose(10.0), id = px_pose_identity(), c, inv;
		px_quat qc;
		px_vec3 x = rand_box_point(10.0);

		c = px_pose_compose(id, p);
		PX_CHECK(qdiff_sign(c.q, p.q) <= TOL_ULP);
		CHECK_VEC_NEAR(c.t, p.t, 0.0);
		c = px_pose_compose(p, id);
		PX_CHECK(qdiff_sign(c.q, p.q) <= TOL_ULP);
		CHECK_VEC_NEAR(c.t, p.t, 0.0);

		inv = px_pose_inverse(p);
		c = px_pose_compose(p, inv);
		PX_CHECK(qdiff_sign(c.q, px_quat_identity()) <= 4 * TOL_ULP);
		CHECK_VEC_NEAR(c.t, px_v3(0, 0, 0), 1e-13);
		c = px_pose_compose(inv, p);
		PX_CHECK(qdiff_sign(c.q, px_quat_identity()) <= 4 * TOL_ULP);
		CHECK_VEC_NEAR(c.t, px_v3(0, 0, 0), 1e-13);
		c = px_pose_inverse(inv);
		PX_CHECK(qdiff_sign(c.q, p.q) <= 0.0);
		CHECK_VEC_NEAR(c.t, p.t, 1e-13);

		qc = px_quat_mul(p.q, px_quat_conj(p.q));
		PX_CHECK(qdiff_sign(qc, px_quat_identity()) <= 4 * TOL_ULP);
		/* Hamilton product against the independent definition. */
		{
			px_quat a = rand_quat(), b = rand_quat();
			PX_CHECK(qdiff_sign(px_quat_mul(a, b), ref_qmul(a, b)) <=
				 4 * TOL_ULP);
		}

		/* Rotation against q v q*, and a transform of a transform
		 * against the composed pose. */
		CHECK_VEC_NEAR(px_quat_rotate(p.q, x), ref_rotate(p.q, x),
			       1e-13);
		{
			px_pose a = rand_pose(10.0);
			px_vec3 y1 = px_pose_transform_point(
				px_pose_compose(a, p), x);
			px_vec3 y2 = px_pose_transform_point(
				a, px_pose_transform_point(p, x));
			px_vec3 y3 = px_v3_add(
				ref_rotate(a.q, px_v3_add(ref_rotate(p.q, x),
							  p.t)),
				a.t);
			CHECK_VEC_NEAR(y1, y2, 1e-12);
			CHECK_VEC_NEAR(y1, y3, 1e-12);
		}
	}
	/* Exact basics. */
	{
		px_quat q;
		PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, 0, 1), M_PI / 2,
							&q),
				PX_OK);
		CHECK_VEC_NEAR(px_quat_rotate(q, px_v3(1, 0, 0)),
			       px_v3(0, 1, 0), TOL_ULP);
		CHECK_VEC_NEAR(px_v3_cross(px_v3(1, 0, 0), px_v3(0, 1, 0)),
			       px_v3(0, 0, 1), 0.0);
		PX_CHECK_NEAR(px_mat3_det(&(px_mat3){{{2, 0, 0}, {0, 3, 0},
						      {0, 0, 4}}}),
			      24.0, 0.0);
	}
}

/* ---- random round trips ------------------------------------------------ */

static void test_round_trips(void)
{
	int n, i, j;
	for (n = 0; n < 5000; n++) {
		px_pose p = rand_pose(100.0);
		px_vec3 x = rand_box_point(100.0), y, v;
		px_mat3 r, rt, rtr, r2;
		px_quat q2;
		double scale = px_v3_norm(x) + px_v3_norm(p.t);

		y = px_pose_transform_point(p, x);
		CHECK_VEC_NEAR(px_pose_inverse_transform_point(p, y), x,
			       TOL_REL * scale);
		v = px_pose_transform_vector(p, x);
		PX_CHECK_REL(px_v3_norm(v), px_v3_norm(x), TOL_REL);
		CHECK_VEC_NEAR(px_pose_inverse_transform_vector(p, v), x,
			       TOL_REL * scale);
		/* inverse(p) applied = inverse transform */
		CHECK_VEC_NEAR(px_pose_transform_point(px_pose_inverse(p), y),
			       x, TOL_REL * scale);

		/* quat -> mat3: orthonormal, det +1, acts like q */
		r = px_quat_to_mat3(p.q);
		rt = px_mat3_transpose(&r);
		rtr = px_mat3_mul(&rt, &r);
		for (i = 0; i < 3; i++)
			for (j = 0; j < 3; j++)
				PX_CHECK_NEAR(rtr.m[i][j], i == j ? 1.0 : 0.0,
					      1e-14);
		PX_CHECK_NEAR(px_mat3_det(&r), 1.0, 1e-14);
		PX_CHECK(px_mat3_is_rotation(&r, 1e-12));
		CHECK_VEC_NEAR(px_mat3_mul_v3(&r, x), ref_rotate(p.q, x),
			       TOL_REL * scale);
		/* mat3 -> quat recovers q up to sign, w >= 0 */
		q2 = px_quat_from_mat3(&r);
		PX_CHECK(q2.w >= 0.0);
		PX_CHECK_MSG(qdiff_sign(q2, p.q) <= 1e-14, "diff %.3g",
			     qdiff_sign(q2, p.q));
		PX_CHECK_NEAR(qnorm(q2), 1.0, TOL_ULP);
		/* composition of poses = product of matrices */
		{
			px_pose a = rand_pose(1.0);
			px_mat3 ra = px_quat_to_mat3(a.q);
			px_mat3 rab = px_mat3_mul(&ra, &r);
			r2 = px_quat_to_mat3(px_pose_compose(a, p).q);
			PX_CHECK(mdiff(&r2, &rab) <= 1e-14);
		}
		/* pose from matrix + t */
		{
			px_pose pp;
			PX_CHECK_INT_EQ(px_pose_from_mat3_t(&r, p.t, &pp),
					PX_OK);
			PX_CHECK(qdiff_sign(pp.q, p.q) <= 1e-14);
		}

		/* axis-angle: against Rodrigues, and back */
		{
			px_vec3 k = rand_dir(), k2;
			double th = px_rand_range(0.0, M_PI), th2;
			px_quat q;
			px_mat3 rr, rq;
			PX_CHECK_INT_EQ(
				px_quat_from_axis_angle(
					px_v3_scale(k, px_rand_range(0.1, 10.0)),
					th, &q),
				PX_OK);
			PX_CHECK_NEAR(qnorm(q), 1.0, TOL_ULP);
			rr = ref_rodrigues(k, th);
			rq = px_quat_to_mat3(q);
			PX_CHECK(mdiff(&rr, &rq) <= 1e-14);
			px_quat_to_axis_angle(q, &k2, &th2);
			PX_CHECK_NEAR(th2, th, 1e-13);
			if (th > 1e-6)
				CHECK_VEC_NEAR(k2, k, 1e-13 / sin(th / 2));
			/* negative angle = opposite axis */
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(k, -th, &q),
					PX_OK);
			px_quat_to_axis_angle(q, &k2, &th2);
			PX_CHECK_NEAR(th2, th, 1e-13);
			/* angle_between a and a * rot(th) is th */
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(k, th, &q),
					PX_OK);
			PX_CHECK_NEAR(px_quat_angle_between(
					      p.q, px_quat_mul(p.q, q)),
				      th, 1e-13);
			PX_CHECK_NEAR(px_quat_angle_between(
					      px_quat_mul(q, p.q), p.q),
				      th, 1e-13);
		}
	}
}

/* ---- normalisation edge cases ----------------------------------------- */

static void test_normalize_edges(void)
{
	const px_vec3 fb = px_v3(0.25, -7.0, 3.0); /* deliberately not unit */
	px_vec3 u;
	px_quat q;
	int n, rc;

	/* Zero and signed zero. */
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(0, 0, 0), fb, &u),
			PX_E_DEGENERATE);
	CHECK_VEC_NEAR(u, fb, 0.0);
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(-0.0, 0.0, -0.0), fb, &u),
			PX_E_DEGENERATE);
	CHECK_VEC_NEAR(u, fb, 0.0);
	/* Non-finite. */
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(NAN, 1, 1), fb, &u), PX_E_NAN);
	CHECK_VEC_NEAR(u, fb, 0.0);
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(1, INFINITY, 0), fb, &u),
			PX_E_NAN);
	CHECK_VEC_NEAR(u, fb, 0.0);
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(0, 0, -INFINITY), fb, &u),
			PX_E_NAN);
	/* Smallest denormal, huge, max. */
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(0, 4.9e-324, 0), fb, &u),
			PX_OK);
	CHECK_VEC_NEAR(u, px_v3(0, 1, 0), 0.0);
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(1e-310, -1e-310, 0), fb, &u),
			PX_OK);
	CHECK_VEC_NEAR(u, px_v3(M_SQRT1_2, -M_SQRT1_2, 0), TOL_ULP);
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(1e300, 1e300, 1e300), fb, &u),
			PX_OK);
	CHECK_VEC_NEAR(u, px_v3(1 / sqrt(3.0), 1 / sqrt(3.0), 1 / sqrt(3.0)),
		       TOL_ULP);
	PX_CHECK_INT_EQ(
		px_v3_normalize(px_v3(DBL_MAX, -DBL_MAX, DBL_MAX), fb, &u),
		PX_OK);
	CHECK_VEC_NEAR(u, px_v3(1 / sqrt(3.0), -1 / sqrt(3.0), 1 / sqrt(3.0)),
		       TOL_ULP);
	/* Huge and tiny at once: the tiny component must not matter. */
	PX_CHECK_INT_EQ(px_v3_normalize(px_v3(1e300, 1e-300, 0), fb, &u),
			PX_OK);
	CHECK_VEC_NEAR(u, px_v3(1, 0, 0), TOL_ULP);

	/* Random directions scaled by powers of two across the whole
	 * exponent range: the result must equal that of the unscaled
	 * vector (scaling back is exact even from denormals). */
	for (n = 0; n < 4000; n++) {
		px_vec3 d = rand_dir(), a, back, ud, ua;
		int e = px_rand_int(-1070, 1020);
		a = px_v3(ldexp(d.x, e), ldexp(d.y, e), ldexp(d.z, e));
		back = px_v3(ldexp(a.x, -e), ldexp(a.y, -e), ldexp(a.z, -e));
		if (back.x == 0 && back.y == 0 && back.z == 0)
			continue;
		PX_CHECK_INT_EQ(px_v3_normalize(back, fb, &ud), PX_OK);
		rc = px_v3_normalize(a, fb, &ua);
		PX_CHECK_INT_EQ(rc, PX_OK);
		PX_CHECK_NEAR(px_v3_norm(ua), 1.0, 1e-15);
		CHECK_VEC_NEAR(ua, ud, 1e-15);
		/* and against a plain reference for unscaled inputs */
		CHECK_VEC_NEAR(ud, ref_unit(back), 1e-15);
	}

	/* any_perp: unit and perpendicular, any scale, axis-aligned, zero */
	for (n = 0; n < 3000; n++) {
		px_vec3 a, p, ua;
		switch (n % 4) {
		case 0:
			a = rand_dir();
			break;
		case 1:
			a = px_v3_scale(rand_dir(), ldexp(1.0,
							  px_rand_int(-1000, 1000)));
			break;
		case 2:
			a = px_v3(0, 0, 0);
			a.x = (n & 8) ? 1.0 : 0.0;
			a.y = (n & 16) ? -2.0 : 0.0;
			a.z = (n & 32) ? 1e-300 : 0.0;
			break;
		default:
			a = px_v3_add(px_v3((n & 4) ? 1 : -1, 0, 0),
				      px_v3_scale(rand_dir(), 1e-12));
			break;
		}
		p = px_v3_any_perp(a);
		PX_CHECK(px_v3_isfinite(p));
		PX_CHECK_NEAR(px_v3_norm(p), 1.0, 1e-15);
		if (px_v3_normalize(a, fb, &ua) == PX_OK)
			PX_CHECK_NEAR(px_v3_dot(p, ua), 0.0, 1e-15);
	}
	u = px_v3_any_perp(px_v3(NAN, 0, 0));
	PX_CHECK(px_v3_isfinite(u));
	PX_CHECK_NEAR(px_v3_norm(u), 1.0, 0.0);

	/* Quaternion normalisation. */
	PX_CHECK_INT_EQ(px_quat_normalize((px_quat){0, 0, 0, 0}, &q),
			PX_E_DEGENERATE);
	PX_CHECK(qdiff_sign(q, px_quat_identity()) == 0.0 && q.w == 1.0);
	PX_CHECK_INT_EQ(px_quat_normalize((px_quat){NAN, 0, 0, 1}, &q),
			PX_E_NAN);
	PX_CHECK(q.w == 1.0 && q.x == 0.0 && q.y == 0.0 && q.z == 0.0);
	PX_CHECK_INT_EQ(px_quat_normalize((px_quat){1, 0, INFINITY, 1}, &q),
			PX_E_NAN);
	PX_CHECK(q.w == 1.0);
	PX_CHECK_INT_EQ(px_quat_normalize((px_quat){1e-320, 0, -1e-320, 0},
					  &q),
			PX_OK);
	PX_CHECK_NEAR(q.w, M_SQRT1_2, TOL_ULP);
	PX_CHECK_NEAR(q.y, -M_SQRT1_2, TOL_ULP);
	PX_CHECK_INT_EQ(px_quat_normalize((px_quat){-1e300, 1e300, 1e300,
						    1e300},
					  &q),
			PX_OK);
	PX_CHECK_NEAR(q.w, -0.5, TOL_ULP); /* sign kept */
	PX_CHECK_NEAR(q.z, 0.5, TOL_ULP);

	/* Constructors with degenerate input. */
	PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, 0, 0), 1.0, &q),
			PX_E_DEGENERATE);
	PX_CHECK(q.w == 1.0 && q.x == 0.0);
	PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, 1, 0), NAN, &q),
			PX_E_NAN);
	PX_CHECK(q.w == 1.0);
	PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, INFINITY, 0), 1, &q),
			PX_E_NAN);
	PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, 1e-310, 0), M_PI, &q),
			PX_OK);
	PX_CHECK_NEAR(q.y, 1.0, TOL_ULP);
	PX_CHECK_INT_EQ(px_quat_from_two_vectors(px_v3(0, 0, 0),
						 px_v3(1, 0, 0), &q),
			PX_E_DEGENERATE);
	PX_CHECK(q.w == 1.0);
	PX_CHECK_INT_EQ(px_quat_from_two_vectors(px_v3(1, 0, 0),
						 px_v3(NAN, 0, 0), &q),
			PX_E_NAN);
	PX_CHECK(q.w == 1.0);
	PX_CHECK_INT_EQ(px_quat_from_two_vectors(px_v3(0, 0, 0),
						 px_v3(NAN, 0, 0), &q),
			PX_E_NAN);
	/* Tiny and huge but valid. */
	PX_CHECK_INT_EQ(px_quat_from_two_vectors(px_v3(1e-310, 0, 0),
						 px_v3(0, 1e300, 0), &q),
			PX_OK);
	CHECK_VEC_NEAR(px_quat_rotate(q, px_v3(1, 0, 0)), px_v3(0, 1, 0),
		       TOL_ULP);

	/* Conversions of degenerate quaternions. */
	{
		px_mat3 m = px_quat_to_mat3((px_quat){0, 0, 0, 0}), id;
		px_vec3 ax;
		double th;
		id = px_mat3_identity();
		PX_CHECK(mdiff(&m, &id) == 0.0);
		m = px_quat_to_mat3((px_quat){NAN, 0, 0, 0});
		PX_CHECK(mdiff(&m, &id) == 0.0);
		/* scaled q gives the same rotation as unit q */
		q = rand_quat();
		{
			px_quat qs = {q.w * 1e200, q.x * 1e200, q.y * 1e200,
				      q.z * 1e200};
			px_mat3 a = px_quat_to_mat3(q), b = px_quat_to_mat3(qs);
			PX_CHECK(mdiff(&a, &b) <= 1e-15);
		}
		px_quat_to_axis_angle((px_quat){0, 0, 0, 0}, &ax, &th);
		CHECK_VEC_NEAR(ax, px_v3(1, 0, 0), 0.0);
		PX_CHECK(th == 0.0);
		px_quat_to_axis_angle((px_quat){NAN, 1, 0, 0}, &ax, &th);
		CHECK_VEC_NEAR(ax, px_v3(1, 0, 0), 0.0);
		PX_CHECK(th == 0.0);
		px_quat_to_axis_angle(px_quat_identity(), &ax, &th);
		CHECK_VEC_NEAR(ax, px_v3(1, 0, 0), 0.0);
		PX_CHECK(th == 0.0);
		px_quat_to_axis_angle((px_quat){-1, 0, 0, 0}, NULL, &th);
		PX_CHECK(th == 0.0);
		m.m[1][1] = INFINITY;
		q = px_quat_from_mat3(&m);
		PX_CHECK(q.w == 1.0 && q.x == 0.0);
		m = (px_mat3){{{0}}};
		q = px_quat_from_mat3(&m);
		PX_CHECK(qfinite(q));
		PX_CHECK_NEAR(qnorm(q), 1.0, TOL_ULP);
	}

	/* Pose sanitation: codes and the identity fallback. */
	{
		px_pose p = rand_pose(1.0), s;
		s = p;
		s.q.w *= 1.0 + 4e-7;
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_OK);
		PX_CHECK_NEAR(qnorm(s.q), 1.0, TOL_ULP);
		CHECK_VEC_NEAR(s.t, p.t, 0.0);
		s = p;
		s.q.x += 1e-3;
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_RANGE);
		PX_CHECK(s.q.w == 1.0 && s.t.x == 0.0);
		s = p;
		s.t.y = NAN;
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_NAN);
		PX_CHECK(s.q.w == 1.0 && s.t.y == 0.0);
		s = p;
		s.q = (px_quat){0, 0, 0, 0};
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_DEGENERATE);
		PX_CHECK(s.q.w == 1.0);
		s = p;
		s.q = (px_quat){1e-310, 0, 0, 0};
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_RANGE);
		s = p;
		s.q = (px_quat){1e300, 0, 0, 0};
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_RANGE);
		s = p;
		s.q.z = -INFINITY;
		PX_CHECK_INT_EQ(px_pose_sanitize(&s), PX_E_NAN);
		PX_CHECK_INT_EQ(px_pose_sanitize(NULL), PX_E_INVAL);
	}
	/* Pose from matrix: rejects non-rotations. */
	{
		px_mat3 m = px_mat3_identity();
		px_pose p;
		m.m[0][0] = -1.0; /* reflection */
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(&m, px_v3(1, 2, 3), &p),
				PX_E_RANGE);
		PX_CHECK(p.q.w == 1.0 && p.t.x == 0.0);
		m = px_mat3_identity();
		m.m[0][1] = 1e-3; /* not orthonormal */
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(&m, px_v3(1, 2, 3), &p),
				PX_E_RANGE);
		m.m[0][1] = NAN;
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(&m, px_v3(1, 2, 3), &p),
				PX_E_NAN);
		m = px_mat3_identity();
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(&m, px_v3(1, 2, INFINITY),
						    &p),
				PX_E_NAN);
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(&m, px_v3(1, 2, 3), &p),
				PX_OK);
		CHECK_VEC_NEAR(p.t, px_v3(1, 2, 3), 0.0);
		PX_CHECK_INT_EQ(px_pose_from_mat3_t(NULL, px_v3(1, 2, 3), &p),
				PX_E_INVAL);
	}
}

/* Every quaternion function fed garbage: codes may be errors, but no
 * output is ever NaN or infinite. */
static void test_no_nan_from_garbage(void)
{
	static const double vals[] = {0.0,     -0.0,     1.0,      -1.0,
				      1e-310,  -5e-324,  1e300,    -1e300,
				      DBL_MAX, NAN,      INFINITY, -INFINITY,
				      0.5,     1e-160,   3.0,      -2.5};
	const int nv = (int)(sizeof(vals) / sizeof(vals[0]));
	int n;
#define PICK() vals[px_rand_int(0, nv - 1)]
	for (n = 0; n < 20000; n++) {
		px_vec3 a = px_v3(PICK(), PICK(), PICK());
		px_vec3 b = px_v3(PICK(), PICK(), PICK()), u, ax;
		px_quat q = {PICK(), PICK(), PICK(), PICK()}, r;
		px_quat q2 = {PICK(), PICK(), PICK(), PICK()};
		px_mat3 m;
		px_pose p;
		double th = PICK(), ang;
		int rc, i, j;

		rc = px_v3_normalize(a, px_v3(1, 0, 0), &u);
		PX_CHECK(px_v3_isfinite(u));
		PX_CHECK(rc == PX_OK || rc == PX_E_NAN ||
			 rc == PX_E_DEGENERATE);
		PX_CHECK_INT_EQ(rc == PX_E_NAN, !px_v3_isfinite(a));
		PX_CHECK(px_v3_isfinite(px_v3_any_perp(a)));
		rc = px_quat_normalize(q, &r);
		PX_CHECK(qfinite(r));
		PX_CHECK_INT_EQ(rc == PX_E_NAN, !qfinite(q));
		if (rc == PX_OK)
			PX_CHECK_NEAR(qnorm(r), 1.0, 1e-15);
		rc = px_quat_from_axis_angle(a, th, &r);
		PX_CHECK(qfinite(r));
		PX_CHECK_INT_EQ(rc == PX_E_NAN,
				!px_v3_isfinite(a) || !isfinite(th));
		rc = px_quat_from_two_vectors(a, b, &r);
		PX_CHECK(qfinite(r));
		if (rc == PX_OK) {
			px_vec3 ua, ub;
			PX_CHECK_NEAR(qnorm(r), 1.0, 1e-15);
			px_v3_normalize(a, px_v3(1, 0, 0), &ua);
			px_v3_normalize(b, px_v3(1, 0, 0), &ub);
			CHECK_VEC_NEAR(px_quat_rotate(r, ua), ub, 4 * TOL_ULP);
		}
		px_quat_to_axis_angle(q, &ax, &ang);
		PX_CHECK(px_v3_isfinite(ax) && ang >= 0.0 && ang <= M_PI);
		m = px_quat_to_mat3(q);
		for (i = 0; i < 3; i++)
			for (j = 0; j < 3; j++)
				PX_CHECK(isfinite(m.m[i][j]));
		PX_CHECK(px_mat3_is_rotation(&m, 1e-14));
		PX_CHECK(qfinite(px_quat_from_mat3(&m)));
		/* a garbage matrix */
		for (i = 0; i < 3; i++)
			for (j = 0; j < 3; j++)
				m.m[i][j] = PICK();
		r = px_quat_from_mat3(&m);
		PX_CHECK(qfinite(r));
		PX_CHECK_NEAR(qnorm(r), 1.0, 1e-15);
		r = px_quat_slerp(q, q2, th);
		PX_CHECK(qfinite(r));
		PX_CHECK_NEAR(qnorm(r), 1.0, 1e-15);
		ang = px_quat_angle_between(q, q2);
		PX_CHECK(ang >= 0.0 && ang <= M_PI);
		p.q = q;
		p.t = b;
		rc = px_pose_sanitize(&p);
		PX_CHECK(qfinite(p.q) && px_v3_isfinite(p.t));
		PX_CHECK(rc == PX_OK || rc == PX_E_NAN || rc == PX_E_RANGE ||
			 rc == PX_E_DEGENERATE);
	}
#undef PICK
}

/* ---- near-180-degree rotations ---------------------------------------- */

/* Rotation angle between two unit vectors, accurate everywhere. */
static double ref_vec_angle(px_vec3 a, px_vec3 b)
{
	return atan2(px_v3_norm(px_v3_cross(a, b)), px_v3_dot(a, b));
}

static void test_near_180(void)
{
	int n, k;

	/* from_two_vectors with b = -a + noise of every size down to 0 */
	for (n = 0; n < 3000; n++) {
		px_vec3 a = px_v3_scale(rand_dir(), px_rand_range(0.01, 100.0));
		px_vec3 b, ua, ub;
		double eps = (n % 20 == 19) ? 0.0 : pow(10.0, -(n % 19));
		px_quat q;
		px_vec3 ax;
		double th;

		b = px_v3_add(px_v3_neg(a),
			      px_v3_scale(rand_dir(), eps * px_v3_norm(a)));
		b = px_v3_scale(b, px_rand_range(0.01, 100.0));
		PX_CHECK_INT_EQ(px_quat_from_two_vectors(a, b, &q), PX_OK);
		PX_CHECK_NEAR(qnorm(q), 1.0, 1e-15);
		ua = ref_unit(a);
		ub = ref_unit(b);
		/* maps a onto b ... */
		CHECK_VEC_NEAR(px_quat_rotate(q, ua), ub, 4 * TOL_ULP);
		CHECK_VEC_NEAR(ref_rotate(q, ua), ub, 4 * TOL_ULP);
		/* ... by the shortest rotation: angle = angle(a, b) */
		px_quat_to_axis_angle(q, &ax, &th);
		PX_CHECK_NEAR(th, ref_vec_angle(ua, ub), 1e-14);
		/* axis perpendicular to a (and b) */
		PX_CHECK_NEAR(px_v3_dot(ax, ua), 0.0, 1e-14);
	}
	/* The same for random pairs at any angle. */
	for (n = 0; n < 3000; n++) {
		px_vec3 a = rand_dir(), b = rand_dir(), ax;
		px_quat q;
		double th;
		PX_CHECK_INT_EQ(px_quat_from_two_vectors(a, b, &q), PX_OK);
		CHECK_VEC_NEAR(ref_rotate(q, a), b, 4 * TOL_ULP);
		px_quat_to_axis_angle(q, &ax, &th);
		PX_CHECK_NEAR(th, ref_vec_angle(a, b), 1e-14);
	}
	/* Exactly opposite along the axes. */
	for (k = 0; k < 6; k++) {
		px_vec3 a = px_v3(k == 0 ? 1 : k == 3 ? -1 : 0,
				  k == 1 ? 1 : k == 4 ? -1 : 0,
				  k == 2 ? 2 : k == 5 ? -3 : 0);
		px_quat q;
		PX_CHECK_INT_EQ(px_quat_from_two_vectors(a, px_v3_neg(a), &q),
				PX_OK);
		PX_CHECK_NEAR(q.w, 0.0, 0.0);
		CHECK_VEC_NEAR(px_quat_rotate(q, ref_unit(a)),
			       px_v3_neg(ref_unit(a)), TOL_ULP);
	}

	/* mat3 -> quat for angles pi - 10^-k .. pi, built by Rodrigues */
	for (n = 0; n < 2000; n++) {
		px_vec3 kx = rand_dir(), ax;
		int e = n % 12;
		double th = e == 11 ? M_PI : M_PI - pow(10.0, -e), th2;
		px_mat3 m = ref_rodrigues(kx, th), m2;
		px_quat q = px_quat_from_mat3(&m);
		px_quat ref = {cos(th / 2), sin(th / 2) * kx.x,
			       sin(th / 2) * kx.y, sin(th / 2) * kx.z};
		PX_CHECK(q.w >= 0.0);
		PX_CHECK_NEAR(qnorm(q), 1.0, 1e-15);
		PX_CHECK_MSG(qdiff_sign(q, ref) <= 1e-14,
			     "angle pi-1e-%d: diff %.3g", e,
			     qdiff_sign(q, ref));
		m2 = px_quat_to_mat3(q);
		PX_CHECK(mdiff(&m, &m2) <= 1e-14);
		px_quat_to_axis_angle(q, &ax, &th2);
		PX_CHECK_NEAR(th2, th, 1e-14);
		/* and the round trip through quat_to_mat3 of the reference */
		m2 = px_quat_to_mat3(ref);
		PX_CHECK(qdiff_sign(px_quat_from_mat3(&m2), ref) <= 1e-14);
	}
	/* Exact half turns about the axes (matrix has trace -1). */
	for (k = 0; k < 3; k++) {
		px_mat3 m = px_mat3_identity();
		px_quat q;
		m.m[(k + 1) % 3][(k + 1) % 3] = -1;
		m.m[(k + 2) % 3][(k + 2) % 3] = -1;
		q = px_quat_from_mat3(&m);
		PX_CHECK_NEAR(q.w, 0.0, 0.0);
		PX_CHECK_NEAR(fabs(k == 0 ? q.x : k == 1 ? q.y : q.z), 1.0, 0.0);
	}

	/* slerp between q and -q stays at q (shorter arc is zero) */
	for (n = 0; n < 500; n++) {
		px_quat q = rand_quat(), mq = {-q.w, -q.x, -q.y, -q.z}, s;
		double t = px_rand_range(-0.5, 1.5);
		s = px_quat_slerp(q, mq, t);
		PX_CHECK(qdiff_sign(s, q) <= 4 * TOL_ULP);
		PX_CHECK_NEAR(px_quat_angle_between(q, mq), 0.0, 0.0);
	}
	/* slerp follows the shorter great arc at constant speed, for
	 * angles near pi, near 0 (lerp branch) and in between */
	for (n = 0; n < 3000; n++) {
		px_quat a = rand_quat(), b, s, d, bf;
		px_vec3 kx = rand_dir();
		int c = n % 6;
		double th = c == 0 ? M_PI - 1e-9 * px_rand_unit()
			    : c == 1 ? 1e-9 * px_rand_unit()
			    : c == 2 ? 1e-6 * (0.5 + px_rand_unit())
			    : px_rand_range(0.0, M_PI);
		double t = px_rand_range(0.0, 1.0);
		PX_CHECK_INT_EQ(px_quat_from_axis_angle(kx, th, &d), PX_OK);
		b = px_quat_mul(a, d);
		if (n & 1) /* the other sign of b: same rotation */
			b = (px_quat){-b.w, -b.x, -b.y, -b.z};
		PX_CHECK_NEAR(px_quat_angle_between(a, b), th, 1e-13);
		s = px_quat_slerp(a, b, t);
		PX_CHECK_NEAR(qnorm(s), 1.0, 1e-15);
		PX_CHECK_NEAR(px_quat_angle_between(a, s), t * th, 1e-13);
		PX_CHECK_NEAR(px_quat_angle_between(s, b), (1 - t) * th,
			      1e-13);
		/* equals a rotated by t*th about the same axis */
		PX_CHECK_INT_EQ(px_quat_from_axis_angle(kx, t * th, &d), PX_OK);
		bf = px_quat_mul(a, d);
		PX_CHECK_MSG(qdiff_sign(s, bf) <= 1e-13, "th %.17g t %.17g %.3g",
			     th, t, qdiff_sign(s, bf));
		/* end points */
		PX_CHECK(qdiff_sign(px_quat_slerp(a, b, 0.0), a) <= 4 * TOL_ULP);
		PX_CHECK(qdiff_sign(px_quat_slerp(a, b, 1.0), b) <= 1e-14);
	}
}

/* ---- axis-aligned boxes ----------------------------------------------- */

static px_aabb rand_aabb(double r, double maxh)
{
	px_vec3 c = rand_box_point(r), h;
	px_aabb b;
	h = px_v3(px_rand_range(0, maxh), px_rand_range(0, maxh),
		  px_rand_range(0, maxh));
	if (px_rand_int(0, 9) == 0) /* flat */
		h.y = 0.0;
	b.min = px_v3_sub(c, h);
	b.max = px_v3_add(c, h);
	return b;
}

static px_vec3 aabb_corner(const px_aabb *b, int i)
{
	return px_v3((i & 1) ? b->max.x : b->min.x, (i & 2) ? b->max.y : b->min.y,
		     (i & 4) ? b->max.z : b->min.z);
}

/* Squared distance by sampling an n^3 lattice of the box plus the
 * analytic bound: every lattice point is at least dist, and the nearest
 * one at most dist + half the lattice diagonal. */
static double sample_min_dist2(px_vec3 (*at)(const void *, double, double,
					    double),
			       const void *box, px_vec3 p, int n)
{
	double best = INFINITY;
	int i, j, k;
	for (i = 0; i <= n; i++)
		for (j = 0; j <= n; j++)
			for (k = 0; k <= n; k++) {
				px_vec3 s = at(box, (double)i / n, (double)j / n,
					       (double)k / n);
				best = fmin(best, px_v3_dist2(s, p));
			}
	return best;
}

static px_vec3 aabb_at(const void *vb, double u, double v, double w)
{
	const px_aabb *b = vb;
	return px_v3(b->min.x + u * (b->max.x - b->min.x),
		     b->min.y + v * (b->max.y - b->min.y),
		     b->min.z + w * (b->max.z - b->min.z));
}

static void test_aabb(void)
{
	int n, i;
	px_aabb e = px_aabb_empty(), b, b2;

	/* empty box */
	PX_CHECK(px_aabb_is_empty(&e));
	PX_CHECK(px_aabb_dist2(&e, px_v3(0, 0, 0)) == INFINITY);
	PX_CHECK(px_aabb_max_dist2(&e, px_v3(0, 0, 0)) == INFINITY);
	PX_CHECK(!px_aabb_contains(&e, px_v3(0, 0, 0)));
	PX_CHECK(!px_aabb_overlap(&e, &e));
	PX_CHECK(px_aabb_diagonal(&e) == 0.0);
	CHECK_VEC_NEAR(px_aabb_center(&e), px_v3(0, 0, 0), 0.0);
	CHECK_VEC_NEAR(px_aabb_closest_point(&e, px_v3(1, 2, 3)),
		       px_v3(1, 2, 3), 0.0);
	b = px_aabb_transform(&e, rand_pose(1.0));
	PX_CHECK(px_aabb_is_empty(&b));
	b = px_aabb_inflate(&e, 1.0);
	PX_CHECK(px_aabb_is_empty(&b));
	b = (px_aabb){{0, NAN, 0}, {1, 1, 1}};
	PX_CHECK(px_aabb_is_empty(&b));
	b = px_aabb_from_points(NULL, 3);
	PX_CHECK(px_aabb_is_empty(&b));
	/* extend from empty gives the point; non-finite points ignored */
	b = px_aabb_empty();
	px_aabb_extend(&b, px_v3(1, 2, 3));
	px_aabb_extend(&b, px_v3(NAN, 100, 100));
	CHECK_VEC_NEAR(b.min, px_v3(1, 2, 3), 0.0);
	CHECK_VEC_NEAR(b.max, px_v3(1, 2, 3), 0.0);
	PX_CHECK(px_aabb_dist2(&b, px_v3(1, 2, 3)) == 0.0);
	b2 = px_aabb_union(&e, &b);
	CHECK_VEC_NEAR(b2.max, b.max, 0.0);
	b2 = px_aabb_union(&b, &e);
	CHECK_VEC_NEAR(b2.min, b.min, 0.0);
	/* centre of a huge box does not overflow */
	b = (px_aabb){{-DBL_MAX, 0, DBL_MAX / 2}, {DBL_MAX, 2, DBL_MAX}};
	CHECK_VEC_NEAR(px_aabb_center(&b), px_v3(0, 1, 0.75 * DBL_MAX), 0.0);

	for (n = 0; n < 3000; n++) {
		px_vec3 p, cp, pts[16];
		double d2, ref, lat;
		b = rand_aabb(2.0, 1.0);
		switch (n % 3) {
		case 0:
			p = rand_box_point(4.0);
			break;
		case 1: /* on or just off a face */
			p = aabb_at(&b, px_rand_unit(), px_rand_unit(),
				    px_rand_int(0, 1));
			p.z += px_rand_range(-1e-9, 1e-9);
			break;
		default:
			p = aabb_at(&b, px_rand_unit(), px_rand_unit(),
				    px_rand_unit());
			break;
		}
		/* reference: per-axis clamp written with fmin/fmax */
		cp = px_v3(fmin(fmax(p.x, b.min.x), b.max.x),
			   fmin(fmax(p.y, b.min.y), b.max.y),
			   fmin(fmax(p.z, b.min.z), b.max.z));
		ref = px_v3_dist2(cp, p);
		d2 = px_aabb_dist2(&b, p);
		PX_CHECK_CLOSE(d2, ref, 1e-300, 1e-14);
		CHECK_VEC_NEAR(px_aabb_closest_point(&b, p), cp, 0.0);
		PX_CHECK_INT_EQ(px_aabb_contains(&b, p),
				p.x >= b.min.x && p.x <= b.max.x &&
					p.y >= b.min.y && p.y <= b.max.y &&
					p.z >= b.min.z && p.z <= b.max.z);
		PX_CHECK_INT_EQ(d2 == 0.0, px_aabb_contains(&b, p));
		/* sampling: no box point is closer; the nearest lattice
		 * point is within half a lattice diagonal */
		if (n % 10 == 0) {
			double s = sample_min_dist2(aabb_at, &b, p, 12);
			lat = 0.5 * px_aabb_diagonal(&b) / 12;
			PX_CHECK(s >= d2 * (1 - 1e-14) - 1e-300);
			PX_CHECK(sqrt(s) <= sqrt(d2) + lat + 1e-12);
		}
		/* farthest point is a corner */
		ref = 0.0;
		for (i = 0; i < 8; i++)
			ref = fmax(ref, px_v3_dist2(aabb_corner(&b, i), p));
		PX_CHECK_REL(px_aabb_max_dist2(&b, p), ref, 1e-15);

		/* overlap vs per-axis interval test and a shared point */
		b2 = rand_aabb(2.0, 1.0);
		{
			int ref_ov = 1, k;
			for (k = 0; k < 3; k++)
				ref_ov &= px_v3_comp(b.min, k) <=
						  px_v3_comp(b2.max, k) &&
					  px_v3_comp(b2.min, k) <=
						  px_v3_comp(b.max, k);
			PX_CHECK_INT_EQ(px_aabb_overlap(&b, &b2), ref_ov);
			PX_CHECK_INT_EQ(px_aabb_overlap(&b2, &b), ref_ov);
			if (ref_ov) { /* the clamp of one centre is shared */
				px_vec3 s = px_aabb_closest_point(
					&b2, px_aabb_closest_point(
						     &b, px_aabb_center(&b2)));
				PX_CHECK(px_aabb_contains(&b, s) &&
					 px_aabb_contains(&b2, s));
			}
		}
		/* touching boxes overlap */
		b2 = b;
		b2.min.x = b.max.x;
		b2.max.x = b.max.x + 1.0;
		PX_CHECK(px_aabb_overlap(&b, &b2));
		b2.min.x = nextafter(b.max.x, INFINITY);
		PX_CHECK(!px_aabb_overlap(&b, &b2));

		/* union, from_points, inflate */
		b2 = rand_aabb(2.0, 1.0);
		{
			px_aabb u = px_aabb_union(&b, &b2), fp, inf;
			for (i = 0; i < 8; i++) {
				PX_CHECK(px_aabb_contains(&u, aabb_corner(&b, i)));
				PX_CHECK(px_aabb_contains(&u,
							  aabb_corner(&b2, i)));
				pts[i] = aabb_corner(&b, i);
				pts[8 + i] = aabb_corner(&b2, i);
			}
			fp = px_aabb_from_points(pts, 16);
			CHECK_VEC_NEAR(fp.min, u.min, 0.0);
			CHECK_VEC_NEAR(fp.max, u.max, 0.0);
			inf = px_aabb_inflate(&b, 0.5);
			{
				double g[3], rr = 0;
				int k;
				for (k = 0; k < 3; k++) {
					g[k] = fmax(fmax(px_v3_comp(b.min, k) -
								 px_v3_comp(p, k),
							 px_v3_comp(p, k) -
								 px_v3_comp(b.max, k)) -
							    0.5,
						    0.0);
					rr += g[k] * g[k];
				}
				PX_CHECK_CLOSE(px_aabb_dist2(&inf, p), rr,
					       1e-14, 1e-14);
			}
			PX_CHECK(px_aabb_dist2(&inf, p) <=
				 px_aabb_dist2(&b, p));
			CHECK_VEC_NEAR(inf.min, px_v3_sub(b.min,
							  px_v3(.5, .5, .5)),
				       0.0);
		}
	}
}

static void test_aabb_transform_encloses(void)
{
	int n, i, k;
	for (n = 0; n < 3000; n++) {
		double r = n % 3 == 0 ? 1e3 : 5.0;
		px_aabb b = rand_aabb(r, r / 2), t;
		px_pose p = rand_pose(r);
		double scale = r * 4;
		int touch_min[3] = {0, 0, 0}, touch_max[3] = {0, 0, 0};
		if (n % 7 == 0) /* a quarter turn: corners on the faces */
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(
						px_v3(0, 0, 1), M_PI / 2, &p.q),
					PX_OK);
		t = px_aabb_transform(&b, p);
		for (i = 0; i < 8; i++) {
			px_vec3 c = aabb_corner(&b, i);
			px_vec3 c1 = px_pose_transform_point(p, c);
			px_vec3 c2 = px_v3_add(ref_rotate(p.q, c), p.t);
			PX_CHECK_MSG(px_aabb_contains(&t, c1),
				     "corner %d outside", i);
			PX_CHECK_MSG(px_aabb_contains(&t, c2),
				     "ref corner %d outside", i);
			for (k = 0; k < 3; k++) {
				touch_min[k] |= px_v3_comp(c2, k) -
							px_v3_comp(t.min, k) <=
						1e-12 * scale;
				touch_max[k] |= px_v3_comp(t.max, k) -
							px_v3_comp(c2, k) <=
						1e-12 * scale;
			}
		}
		/* tight: every face is touched by a corner */
		for (k = 0; k < 3; k++)
			PX_CHECK(touch_min[k] && touch_max[k]);
		/* obb of the same box and its aabb agree with this */
		{
			px_obb o = px_obb_from_aabb(&b, p);
			px_aabb oa = px_obb_aabb(&o);
			for (i = 0; i < 8; i++) {
				px_vec3 c = px_obb_corner(&o, i);
				PX_CHECK(px_aabb_contains(&oa, c));
				CHECK_VEC_NEAR(c, px_v3_add(ref_rotate(p.q,
								  aabb_corner(&b, i)),
							      p.t),
					       1e-13 * scale);
			}
			CHECK_VEC_NEAR(oa.min, t.min, 1e-13 * scale);
			CHECK_VEC_NEAR(oa.max, t.max, 1e-13 * scale);
		}
	}
}

/* ---- oriented boxes ---------------------------------------------------- */

struct ref_obb {
	px_pose pose; /* box frame */
	px_vec3 h;
	px_obb o;
};

static struct ref_obb rand_obb(double r, double hmin, double hmax)
{
	struct ref_obb b;
	px_aabb a;
	b.pose = rand_pose(r);
	b.h = px_v3(px_rand_range(hmin, hmax), px_rand_range(hmin, hmax),
		    px_rand_range(hmin, hmax));
	a.min = px_v3_neg(b.h);
	a.max = b.h;
	b.o = px_obb_from_aabb(&a, b.pose);
	return b;
}

static px_vec3 obb_at(const void *vb, double u, double v, double w)
{
	const struct ref_obb *b = vb;
	px_vec3 l = px_v3((2 * u - 1) * b->h.x, (2 * v - 1) * b->h.y,
			  (2 * w - 1) * b->h.z);
	return px_v3_add(ref_rotate(b->pose.q, l), b->pose.t);
}

static void test_obb_distance(void)
{
	int n, i;
	for (n = 0; n < 4000; n++) {
		struct ref_obb b = rand_obb(3.0, 0.0, 1.5);
		px_vec3 p, l, cl, cp;
		px_quat qc = {b.pose.q.w, -b.pose.q.x, -b.pose.q.y,
			      -b.pose.q.z};
		double ref, d2, scale;
		int inside;

		if (n % 3 == 0) /* near a face */
			p = obb_at(&b, px_rand_unit(), px_rand_int(0, 1),
				   px_rand_unit());
		else
			p = px_v3_add(b.pose.t, rand_box_point(4.0));
		scale = px_v3_dist(p, b.pose.t) + px_v3_norm(b.pose.t) + 1.0;
		/* reference: local coordinates by q* (p - t) q, clamp */
		l = ref_rotate(qc, px_v3_sub(p, b.pose.t));
		cl = px_v3(fmin(fmax(l.x, -b.h.x), b.h.x),
			   fmin(fmax(l.y, -b.h.y), b.h.y),
			   fmin(fmax(l.z, -b.h.z), b.h.z));
		ref = px_v3_dist2(l, cl);
		d2 = px_obb_dist2(&b.o, p);
		/* distances agree to rounding of the coordinates */
		PX_CHECK_NEAR(sqrt(d2), sqrt(ref), 1e-14 * scale);
		CHECK_VEC_NEAR(px_obb_to_local(&b.o, p), l, 1e-14);
		cp = px_obb_closest_point(&b.o, p);
		CHECK_VEC_NEAR(cp, px_v3_add(ref_rotate(b.pose.q, cl), b.pose.t),
			       1e-14);
		PX_CHECK_NEAR(px_v3_dist(cp, p), sqrt(d2), 1e-14 * scale);
		/* containment, away from the boundary by 1e-12 */
		inside = fabs(l.x) <= b.h.x && fabs(l.y) <= b.h.y &&
			 fabs(l.z) <= b.h.z;
		if (fabs(fabs(l.x) - b.h.x) > 1e-12 &&
		    fabs(fabs(l.y) - b.h.y) > 1e-12 &&
		    fabs(fabs(l.z) - b.h.z) > 1e-12)
			PX_CHECK_INT_EQ(px_obb_contains(&b.o, p), inside);
		PX_CHECK_INT_EQ(px_obb_contains(&b.o, p), d2 == 0.0);
		/* dense sampling of the solid box */
		if (n % 8 == 0) {
			double s = sample_min_dist2(obb_at, &b, p, 10);
			double lat = sqrt(b.h.x * b.h.x + b.h.y * b.h.y +
					  b.h.z * b.h.z) / 10;
			PX_CHECK(sqrt(s) >= sqrt(d2) - 1e-13);
			PX_CHECK(sqrt(s) <= sqrt(d2) + lat + 1e-13);
		}
		/* corners, and transform of a box moves its corners */
		{
			px_pose m = rand_pose(2.0);
			px_obb t = px_obb_transform(&b.o, m);
			for (i = 0; i < 8; i++)
				CHECK_VEC_NEAR(px_obb_corner(&t, i),
					       px_pose_transform_point(
						       m, px_obb_corner(&b.o, i)),
					       1e-13);
			PX_CHECK_NEAR(sqrt(px_obb_dist2(
					      &t, px_pose_transform_point(m, p))),
				      sqrt(d2), 1e-14 * (scale + 4));
		}
	}
}

/*
 * Exact overlap reference: the boxes intersect iff the 12 half-spaces
 * n . x <= c (6 per box) have a common point; if they do, the
 * intersection (bounded) has a vertex, where 3 of the planes meet. Try
 * every triple, keep any solution that satisfies all 12 within chk. The
 * boxes are grown by grow (negative: shrunk, extents floored at 0).
 */
static int ref_obb_overlap(const struct ref_obb *a, const struct ref_obb *b,
			   double grow, double chk)
{
	px_vec3 nrm[12];
	double c[12];
	int i, j, k, m;
	const struct ref_obb *bx[2] = {a, b};

	for (m = 0; m < 2; m++) {
		for (k = 0; k < 3; k++) {
			px_vec3 e = px_v3(k == 0, k == 1, k == 2);
			px_vec3 ax = ref_rotate(bx[m]->pose.q, e);
			double h = fmax(px_v3_comp(bx[m]->h, k) + grow, 0.0);
			double o = px_v3_dot(ax, bx[m]->pose.t);
			nrm[m * 6 + 2 * k] = ax;
			c[m * 6 + 2 * k] = o + h;
			nrm[m * 6 + 2 * k + 1] = px_v3_neg(ax);
			c[m * 6 + 2 * k + 1] = -o + h;
		}
	}
	for (i = 0; i < 12; i++)
		for (j = i + 1; j < 12; j++)
			for (k = j + 1; k < 12; k++) {
				px_vec3 jk = px_v3_cross(nrm[j], nrm[k]);
				double det = px_v3_dot(nrm[i], jk), ok = 1;
				px_vec3 x;
				if (fabs(det) < 1e-9)
					continue;
				/* Cramer via cross products */
				x = px_v3_scale(
					px_v3_add(px_v3_add(
							  px_v3_scale(jk, c[i]),
							  px_v3_scale(px_v3_cross(nrm[k], nrm[i]),
								      c[j])),
						  px_v3_scale(px_v3_cross(nrm[i], nrm[j]),
							      c[k])),
					1.0 / det);
				for (m = 0; m < 12 && ok; m++)
					ok = px_v3_dot(nrm[m], x) <= c[m] + chk;
				if (ok)
					return 1;
			}
	return 0;
}

/* Overlap as seen by the 6 face axes only (to show the 9 edge axes are
 * needed). */
static int faces_only_overlap(const px_obb *a, const px_obb *b)
{
	const px_obb *bx[2] = {a, b};
	int m, k, i;
	for (m = 0; m < 2; m++)
		for (k = 0; k < 3; k++) {
			px_vec3 L = bx[m]->axis[k];
			double lo[2], hi[2];
			for (i = 0; i < 2; i++) {
				double c = px_v3_dot(L, bx[i]->center), r = 0;
				int j;
				for (j = 0; j < 3; j++)
					r += px_v3_comp(bx[i]->half, j) *
					     fabs(px_v3_dot(L, bx[i]->axis[j]));
				lo[i] = c - r;
				hi[i] = c + r;
			}
			if (lo[0] > hi[1] + 1e-12 || lo[1] > hi[0] + 1e-12)
				return 0;
		}
	return 1;
}

static void check_pair(const struct ref_obb *a, const struct ref_obb *b,
		       int *n_ov, int *n_sep, int *n_edge)
{
	const double delta = 1e-9, chk = 1e-12;
	int sat = px_obb_overlap(&a->o, &b->o);
	int strict = ref_obb_overlap(a, b, -delta, chk);
	int loose = ref_obb_overlap(a, b, delta, chk);

	PX_CHECK_INT_EQ(px_obb_overlap(&b->o, &a->o), sat);
	/* never misses an overlap deeper than delta */
	PX_CHECK_MSG(!strict || sat, "overlap missed");
	/* never claims one for boxes farther apart than delta */
	PX_CHECK_MSG(!sat || loose, "false overlap");
	if (sat)
		(*n_ov)++;
	else
		(*n_sep)++;
	if (!loose && faces_only_overlap(&a->o, &b->o))
		(*n_edge)++;
}

static void test_obb_overlap_random(void)
{
	int n, n_ov = 0, n_sep = 0, n_edge = 0;
	for (n = 0; n < 4000; n++) {
		struct ref_obb a, b;
		if (n % 2 == 0) {
			a = rand_obb(1.2, 0.05, 1.0);
			b = rand_obb(1.2, 0.05, 1.0);
		} else { /* sticks: edge-edge separations are common */
			a = rand_obb(0.4, 0.02, 0.05);
			b = rand_obb(0.4, 0.02, 0.05);
			a.h.x = px_rand_range(1.0, 2.0);
			b.h.y = px_rand_range(1.0, 2.0);
			a.o.half = a.h;
			b.o.half = b.h;
		}
		check_pair(&a, &b, &n_ov, &n_sep, &n_edge);
		/* points sampled in a that lie in b prove overlap */
		if (n % 4 == 0) {
			int i, hit = 0;
			for (i = 0; i < 200 && !hit; i++) {
				px_vec3 s = obb_at(&a, px_rand_unit(),
						   px_rand_unit(),
						   px_rand_unit());
				px_quat qc = {b.pose.q.w, -b.pose.q.x,
					      -b.pose.q.y, -b.pose.q.z};
				px_vec3 l = ref_rotate(qc,
						       px_v3_sub(s, b.pose.t));
				hit = fabs(l.x) <= b.h.x && fabs(l.y) <= b.h.y &&
				      fabs(l.z) <= b.h.z;
			}
			if (hit)
				PX_CHECK(px_obb_overlap(&a.o, &b.o));
		}
	}
	/* both outcomes common, and some pairs need an edge axis */
	PX_CHECK_MSG(n_ov > 500 && n_sep > 500, "ov %d sep %d", n_ov, n_sep);
	PX_CHECK_MSG(n_edge > 20, "edge-only separations %d", n_edge);
}

static void test_obb_overlap_special(void)
{
	int n, n_ov = 0, n_sep = 0, n_edge = 0, k;
	for (n = 0; n < 2000; n++) {
		struct ref_obb a = rand_obb(0.0, 0.1, 1.0), b = a;
		px_quat d;
		px_vec3 off;
		double gap;
		k = px_rand_int(0, 2);
		/* b: a turned about one of a's axes (so edges stay
		 * parallel), or not at all */
		if (n % 3 != 0) {
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(
						px_v3(k == 0, k == 1, k == 2),
						n % 3 == 1 ? px_rand_range(0, 2 * M_PI)
							   : 1e-10 * px_rand_normal(),
						&d),
					PX_OK);
			b.pose.q = px_quat_mul(a.pose.q, d);
		}
		b.h = px_v3(px_rand_range(0.0, 1.0), px_rand_range(0.0, 1.0),
			    px_rand_range(0.0, 1.0));
		if (n % 5 == 0) /* degenerate: a segment or a plate */
			b.h.y = 0.0;
		if (n % 10 == 0)
			b.h.z = 0.0;
		/* offset in a's frame */
		off = rand_box_point(2.0);
		b.pose.t = px_v3_add(a.pose.t, ref_rotate(a.pose.q, off));
		{
			px_aabb bb = {px_v3_neg(b.h), b.h};
			b.o = px_obb_from_aabb(&bb, b.pose);
		}
		check_pair(&a, &b, &n_ov, &n_sep, &n_edge);

		/* exact face contact along a's axis k when unrotated
		 * relative (n % 3 == 0): touching overlaps, a gap of
		 * 1e-6 does not */
		if (n % 3 == 0) {
			for (gap = 0.0; gap <= 1e-6; gap += 1e-6) {
				px_vec3 o2 = px_v3(px_rand_range(-0.5, 0.5) * a.h.x,
						   px_rand_range(-0.5, 0.5) * a.h.y,
						   px_rand_range(-0.5, 0.5) * a.h.z);
				px_aabb bb = {px_v3_neg(b.h), b.h};
				double along = px_v3_comp(a.h, k) +
					       px_v3_comp(b.h, k) + gap;
				if (k == 0)
					o2.x = along;
				else if (k == 1)
					o2.y = along;
				else
					o2.z = along;
				b.pose.t = px_v3_add(a.pose.t,
						     ref_rotate(a.pose.q, o2));
				b.o = px_obb_from_aabb(&bb, b.pose);
				PX_CHECK_INT_EQ(px_obb_overlap(&a.o, &b.o),
						gap == 0.0);
			}
		}
	}
	/* Collinear segments overlapping, and parallel ones 1e-6 apart. */
	for (n = 0; n < 500; n++) {
		px_pose p = rand_pose(1.0), p2;
		px_aabb seg = {{-1, 0, 0}, {1, 0, 0}};
		px_obb a = px_obb_from_aabb(&seg, p), b;
		double s = px_rand_range(-1.99, 1.99);
		p2 = p;
		p2.t = px_pose_transform_point(p, px_v3(s, 0, 0));
		b = px_obb_from_aabb(&seg, p2);
		PX_CHECK(px_obb_overlap(&a, &b));
		p2.t = px_pose_transform_point(p, px_v3(s, 1e-6, 0));
		b = px_obb_from_aabb(&seg, p2);
		PX_CHECK(!px_obb_overlap(&a, &b));
		/* end to end, touching */
		p2.t = px_pose_transform_point(p, px_v3(2.0, 0, 0));
		b = px_obb_from_aabb(&seg, p2);
		PX_CHECK(px_obb_overlap(&a, &b));
		p2.t = px_pose_transform_point(p, px_v3(2.0 + 1e-6, 0, 0));
		b = px_obb_from_aabb(&seg, p2);
		PX_CHECK(!px_obb_overlap(&a, &b));
	}
	/* Edge-on-edge contact of two cubes, one turned 45 degrees about
	 * the contact edge direction, separated only along the diagonal. */
	{
		px_aabb cube = {{-1, -1, -1}, {1, 1, 1}};
		px_pose pa = px_pose_identity(), pb = px_pose_identity();
		px_obb a, b;
		int sep;
		double g;
		for (sep = 0; sep < 2; sep++) {
			g = sep ? 1e-6 : 0.0;
			PX_CHECK_INT_EQ(px_quat_from_axis_angle(px_v3(0, 0, 1),
								M_PI / 4, &pb.q),
					PX_OK);
			/* b's corner edge points to -x; a's face at x=1 */
			pb.t = px_v3(1.0 + M_SQRT2 + g, 0.3, 0.0);
			a = px_obb_from_aabb(&cube, pa);
			b = px_obb_from_aabb(&cube, pb);
			PX_CHECK_INT_EQ(px_obb_overlap(&a, &b), !sep);
			/* crossed sticks: only an edge axis separates */
			{
				px_aabb sx = {{-2, -0.01, -0.01}, {2, 0.01, 0.01}};
				px_aabb sy = {{-0.01, -2, -0.01}, {0.01, 2, 0.01}};
				px_pose ps = px_pose_identity(), pt;
				PX_CHECK_INT_EQ(px_quat_from_axis_angle(
							px_v3(1, 1, 1), 0.3, &ps.q),
						PX_OK);
				pt = ps;
				pt.t = px_pose_transform_point(
					ps, px_v3(0, 0, 0.02 + (sep ? 1e-6 : 0)));
				a = px_obb_from_aabb(&sx, ps);
				b = px_obb_from_aabb(&sy, pt);
				PX_CHECK_INT_EQ(px_obb_overlap(&a, &b), !sep);
			}
		}
	}
	PX_CHECK_MSG(n_ov > 100 && n_sep > 100, "ov %d sep %d", n_ov, n_sep);
}

/* ---- zero allocations -------------------------------------------------- */

static void test_no_allocations(void)
{
	volatile double sink = 0.0;
	uint64_t r;
	int n;
	px_pose p = rand_pose(1.0), p2 = rand_pose(1.0);
	px_aabb b = rand_aabb(1.0, 1.0), b2 = rand_aabb(1.0, 1.0);
	px_obb o = px_obb_from_aabb(&b, p), o2 = px_obb_from_aabb(&b2, p2);
	px_vec3 pts[4] = {{0, 0, 0}, {1, 2, 3}, {-1, 0, 2}, {4, 4, 4}};

	r = px_alloc_region_begin();
	for (n = 0; n < 20000; n++) {
		px_vec3 x = px_v3(n * 1e-3, -n * 2e-3, 0.5), u, ax;
		px_quat q;
		px_mat3 m;
		px_aabb t;
		double th;
		(void)px_v3_normalize(x, px_v3(1, 0, 0), &u);
		u = px_v3_add(u, px_v3_any_perp(x));
		(void)px_quat_normalize(p.q, &q);
		(void)px_quat_from_axis_angle(x, n * 1e-3, &q);
		px_quat_to_axis_angle(q, &ax, &th);
		(void)px_quat_from_two_vectors(x, px_v3_neg(x), &q);
		m = px_quat_to_mat3(q);
		q = px_quat_slerp(q, px_quat_from_mat3(&m), 0.3);
		th += px_quat_angle_between(q, p.q) + px_mat3_det(&m);
		(void)px_pose_sanitize(&p2);
		(void)px_pose_from_mat3_t(&m, x, &p2);
		t = px_aabb_transform(&b, p);
		t = px_aabb_union(&t, &b2);
		px_aabb_extend(&t, x);
		t = px_aabb_from_points(pts, 4);
		th += px_aabb_dist2(&t, x) + px_aabb_max_dist2(&b, x) +
		      px_aabb_diagonal(&t) + px_aabb_overlap(&b, &t) +
		      px_aabb_contains(&b, x);
		th += px_obb_dist2(&o, x) + px_obb_overlap(&o, &o2) +
		      px_obb_contains(&o, x);
		u = px_v3_add(u, px_obb_closest_point(&o, x));
		u = px_v3_add(u, px_aabb_closest_point(&b, x));
		t = px_obb_aabb(&o2);
		sink += th + u.x + ax.y + t.min.x + q.w;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(r), 0);
	PX_CHECK(isfinite(sink));
}

static const struct px_test tests[] = {
	PX_T(test_identities),
	PX_T(test_round_trips),
	PX_T(test_normalize_edges),
	PX_T(test_no_nan_from_garbage),
	PX_T(test_near_180),
	PX_T(test_aabb),
	PX_T(test_aabb_transform_encloses),
	PX_T(test_obb_distance),
	PX_T(test_obb_overlap_random),
	PX_T(test_obb_overlap_special),
	PX_T(test_no_allocations),
};

PX_TEST_MAIN(tests)
