/*
 * px_recog.h - knowledge step of the distance core: recognise NURBS
 * entities that are exactly a line segment, a circle or circular arc, a
 * parallelogram, or a patch of a surface of revolution whose profile is a
 * line segment or a circular arc (cylinder, cone, planar annulus, sphere,
 * torus), and answer point queries on them in closed form.
 *
 * What is proved. Recognition never trusts samples; it is decided from
 * the control data, and a primitive is reported only with a bound H
 * (px_recog_shape.hausdorff) on the Hausdorff distance between the entity and
 * the primitive piece that px_recog_closest() measures against, including
 * the piece's boundary (an arc, not the whole circle; a sphere patch, not
 * the whole sphere). So for every query p,
 *     |distance(p, entity) - distance(p, primitive piece)| <= H,
 * and an entity is recognised only when H <= rel_tol * size (size: the
 * diagonal of the box of points evaluated on the entity). The proofs:
 *  - Segment: every control point lies within d of the line through the
 *    end points (so the curve does, convex hull) and the control points'
 *    projections on it are monotone (so the projection of the curve is
 *    monotone: variation diminishing, weights > 0); H = d.
 *  - Arc (any degree, rational or not): control points within dz of the
 *    plane; on every Bezier span the polynomial F = |X - cW|^2 - r^2 W^2
 *    (X, W homogeneous numerator and weight) has Bernstein coefficients
 *    F_m with |F_m| <= e G_m (plus a rounding margin), G_m > 0 the
 *    coefficients of W^2, so |F| <= e W^2 and ||C - c| - r| <= e / r on
 *    the whole span; the angular speed polynomial
 *    n . (Y x Y') (Y = X - cW) has Bernstein coefficients of one sign on
 *    every span (the angle is monotone, so the image is exactly the arc
 *    between the end angles); the sweep is summed over sub-pieces whose
 *    control points lie in an open half-plane through the centre (each
 *    turns by less than pi, so no turn is lost). H = e / r + 2 dz.
 *    Sweeps above a full turn are not recognised.
 *  - Surfaces: the homogeneous control net must factor as
 *    P_ij = c + h_j a + rho_j E_i with weights alpha_i beta_j, within a
 *    proved deviation (control-point deviation plus the effect of the
 *    weight mismatch, both bounded through the convex-hull property); the
 *    control row with the largest extent, (P_ij* - c)/r*, is a proved unit
 *    arc (the angular direction) and the planar profile (h_j, rho_j) with
 *    weights beta_j is a proved segment or arc with rho >= 0. The surface
 *    is then c + H(v) a + R(v) E(u): the profile swept over the proved
 *    angular range, so closest points reduce exactly to the meridian
 *    half-plane (or to the nearer end meridian when the query's angle is
 *    outside the range). H = (control deviation) + 2 eps/(1 - eps) R_net
 *    (eps the relative weight mismatch, R_net the net's half box
 *    diagonal) + 2 H_profile + rho_max H_row / r* + 2 max(0, -rho_min of
 *    the ideal profile). The same factorisation with two straight,
 *    monotone directions proves a parallelogram.
 * Floating point: every bound includes a margin of 64 ulp of the
 * entity's coordinates for the rounding of extraction and products; the
 * sign tests (monotone projections, angular speed) are made on computed
 * values and refuse exact zeros, so a wrong sign can only come from a
 * quantity within rounding of zero (a backtrack of rounding size). A
 * planar patch that is neither a parallelogram nor a revolution is
 * reported as PX_RECOG_PLANE (its trimmed outline has no closed form here:
 * px_recog_closest() refuses it). Anything else is PX_RECOG_NONE.
 *
 * Parameters. The closest point's parameters are exact (closed form)
 * for segments, parallelograms and segment profiles whose
 * parametrization is linear (all weights equal and control points at the
 * Greville abscissae) and for degree-2 arcs (any weights: per-span
 * Moebius map to the standard form, see struct px_recog_qarc); otherwise
 * the monotone map parameter -> position (projection or angle, proved
 * monotone at recognition) is inverted by safeguarded Newton/bisection in
 * at most PX_RECOG_INV_ITERS evaluations, to a few ulp of the domain.
 * Either way the entity at (u, v) lies within about H of hit.point (the
 * parameters map the primitive's point through the entity's own
 * monotone angle / position functions). When the query is on an axis or
 * centre (hit.tie), they are those of one of the equally near points.
 *
 * Memory and real-time rules. px_recog_curve()/px_recog_surf() are
 * setup-time: no heap, but tens of kilobytes of stack, work linear in
 * the number of spans (each extracted once or a few times);
 * entities with more than PX_RECOG_MAX_CTRL control points in a direction
 * are not recognised. A px_recog_shape is a plain value holding a copy of the
 * entity descriptor (not of its arrays: they must outlive it).
 * px_recog_closest() is RT-safe: no allocation, no locks, bounded loops;
 * several threads may query one px_recog_shape at once.
 */
#ifndef PX_RECOG_H
#define PX_RECOG_H

#include "px_base.h"
#include "px_math.h"
#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Default relative tolerance: H <= 1e-10 * size. */
#define PX_RECOG_REL_TOL_DEFAULT 1e-10
/* Largest control-point count per direction that is examined. */
#define PX_RECOG_MAX_CTRL 256
/* Evaluation bound of a parameter inversion. */
#define PX_RECOG_INV_ITERS 100

enum px_recog_kind {
	PX_RECOG_NONE = 0,
	PX_RECOG_SEGMENT = 1,       /* curve: straight segment */
	PX_RECOG_ARC = 2,           /* curve: circular arc or full circle */
	PX_RECOG_PLANE = 3,         /* planar patch, outline not closed form */
	PX_RECOG_PARALLELOGRAM = 4, /* planar patch with a parallelogram image */
	PX_RECOG_CYLINDER = 5,      /* revolution, profile parallel to axis */
	PX_RECOG_CONE = 6,          /* revolution, profile a slanted segment */
	PX_RECOG_ANNULUS = 7,       /* revolution, profile normal to the axis */
	PX_RECOG_SPHERE = 8,        /* revolution, profile arc centred on axis */
	PX_RECOG_TORUS = 9          /* revolution, profile arc off the axis */
};

/* Segment p0 + t dir, t in [0, len]; t grows with the parameter. */
struct px_recog_seg {
	px_vec3 p0, dir;
	double len;
};

/* Arc center + r (cos f e0 + sin f e1), f in [0, sweep], sweep in
 * (0, 2 pi]; e1 = normal x e0; f grows with the parameter. trig: the
 * sweep's middle direction (cos, sin of sweep / 2), the cosine of half
 * the sweep (-2 for a full turn) and the end direction (cos, sin of
 * sweep), so closest points need no angle functions. */
struct px_recog_arc {
	px_vec3 center, normal, e0, e1;
	double radius, sweep;
	double trig[5];
};

/*
 * Patch of a surface of revolution: origin + h axis + rho (cos t e0 +
 * sin t e1) for t in [0, sweep] and (h, rho) on the profile, which is
 * stored in meridian coordinates as 3D points (h, rho, 0): a segment
 * (profile_is_arc 0) or an arc (1). dir_angle is the surface parameter
 * direction (0 u, 1 v) that turns about the axis; the other one runs
 * along the profile.
 */
struct px_recog_rev {
	px_vec3 origin, axis, e0, e1;
	double sweep, trig[5]; /* trig as in struct px_recog_arc */
	int profile_is_arc;
	struct px_recog_seg pseg;
	struct px_recog_arc parc;
	int dir_angle;
	double ref_param[2]; /* fixed parameter used when inverting each dir */
};

/*
 * Angle -> parameter table of a degree-2 arc (PX_RECOG_QSPANS spans at
 * most; n = 0 when absent): span k covers parameters [u[k], u[k+1]] and
 * angles [a[k], a[k+1]]; its Bezier weights (w0, w1, w2) give
 * lam = sqrt(w0 / w2) and half = acos(w1 / sqrt(w0 w2)), half the span's
 * turn. On the standard form (end weights equal, reached by the Moebius
 * map t = lam s / (1 - s + lam s)) the angle from the span's bisector is
 * f = 2 atan(tan(half / 2) (2 s - 1)), so parameters invert in closed
 * form; with the bisector's direction mid (angle a[k] + half), cos(half)
 * and tan(half / 2) kept, from the point's direction without angle
 * functions.
 */
#define PX_RECOG_QSPANS 16
struct px_recog_qarc {
	int n;
	double u[PX_RECOG_QSPANS + 1], a[PX_RECOG_QSPANS + 1];
	double lam[PX_RECOG_QSPANS], half[PX_RECOG_QSPANS];
	double mid[PX_RECOG_QSPANS][2], chalf[PX_RECOG_QSPANS],
		tquart[PX_RECOG_QSPANS];
};

/* Parallelogram origin + x e1 + y e2, x in [x0, x1], y in [y0, y1]
 * (x along u, y along v; x0 may exceed x1 when x falls with u). f1, f2
 * are the dual vectors (f1.e1 = 1, f1.e2 = 0, ...). */
struct px_recog_quad {
	px_vec3 origin, e1, e2, f1, f2, normal;
	double x0, x1, y0, y1;
};

struct px_recog_shape {
	enum px_recog_kind kind;
	int is_surface;
	double hausdorff;   /* proved bound H (model units); for PLANE only
			     * the distance of the patch from the plane */
	double size;        /* entity size the tolerance was relative to */
	/* Informational shape parameters: SPHERE center/radius; CYLINDER
	 * radius; CONE apex (center) and half_angle; TORUS center, radius
	 * (major), radius2 (minor); ARC center/radius; PLANE: center is a
	 * point of the plane, normal its normal. */
	px_vec3 center, normal;
	double radius, radius2, half_angle;
	/* Exactly one of these describes the closed form, by kind. */
	struct px_recog_seg seg;
	struct px_recog_arc arc;
	struct px_recog_rev rev;
	struct px_recog_quad quad;
	/* Linear parametrization (parameters in closed form): bit 0 for the
	 * curve / u, bit 1 for v. */
	int linear;
	/* Closed-form angle inversion of degree-2 arcs: [0] the curve (ARC)
	 * or the angular direction of a revolution, [1] its profile arc. */
	struct px_recog_qarc qarc[2];
	/* Copy of the entity descriptor, for parameter inversion. */
	struct px_nurbs_curve curve;
	struct px_nurbs_surf surf;
	double dom[4];      /* u0, u1 (, v0, v1) */
};

/* Parameter quality in px_recog_hit.param. */
enum px_recog_param {
	PX_RECOG_PARAM_NONE = 0,   /* not computed (flag not given) */
	PX_RECOG_PARAM_EXACT = 1,  /* closed form */
	PX_RECOG_PARAM_SOLVED = 2  /* monotone inversion, a few ulp */
};

/* Ask px_recog_closest() for the parameters of the closest point. */
#define PX_RECOG_WANT_PARAMS 1

struct px_recog_hit {
	double dist;      /* distance to the primitive piece */
	px_vec3 point;    /* closest point on the primitive piece */
	px_vec3 dir;      /* unit vector point -> query; zero when on it */
	double u, v;      /* parameters (v = 0 for curves), see param */
	int param;        /* enum px_recog_param */
	int tie;          /* 1: other points are equally near (query on the
			   * axis / centre, or angularly midway) */
};

/*
 * Recognise a curve. rel_tol <= 0 takes PX_RECOG_REL_TOL_DEFAULT.
 * Returns 1 and fills *out (SEGMENT or ARC) when recognised, 0 when not
 * (out->kind NONE), PX_E_INVAL for NULL arguments. Setup-time.
 */
PX_API int px_recog_curve(const struct px_nurbs_curve *c, double rel_tol,
			  struct px_recog_shape *out);

/*
 * Recognise a surface: PARALLELOGRAM, CYLINDER, CONE, ANNULUS, SPHERE,
 * TORUS (returns 1), PLANE (returns 1; no closed form), else 0 with
 * kind NONE. PX_E_INVAL for NULL arguments. Setup-time.
 */
PX_API int px_recog_surf(const struct px_nurbs_surf *s, double rel_tol,
			 struct px_recog_shape *out);

/*
 * Closest point of the primitive piece to p. flags: PX_RECOG_WANT_PARAMS
 * also computes the parameters (inverting through the entity). Returns
 * PX_OK; PX_E_UNSUPPORTED when the closed form cannot settle the query
 * (kind PLANE or NONE: use the general solver); PX_E_INVAL (NULL);
 * PX_E_NAN (p not finite). The distance to the entity itself is within
 * pr->hausdorff of hit->dist. @note RT-safe.
 */
PX_API int px_recog_closest(const struct px_recog_shape *pr, px_vec3 p, int flags,
			   struct px_recog_hit *hit);

/* Name of a kind ("sphere"), for logs. @note RT-safe. */
PX_API const char *px_recog_kind_name(enum px_recog_kind k);

#ifdef __cplusplus
}
#endif

#endif
