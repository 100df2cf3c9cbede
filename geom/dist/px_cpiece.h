/*
 * px_cpiece.h - certified closest point on one rational Bezier curve piece.
 *
 * The distance core cuts every curve into rational Bezier pieces at setup.
 * For a query point P the squared distance f(u) = |C(u) - P|^2 has
 * critical points where (C - P) . C' = 0. Writing C = H / w with the
 * homogeneous polynomial H and the weight w > 0,
 *
 *     g(u) = (H - w P) . (H' w - H w') = w^3 (C - P) . C'
 *
 * is a polynomial of degree 3p - 1 with the sign of f'(u). Its Bernstein
 * coefficients are a(u) - P . b(u) with a = H . K, b = w K and
 * K = H' w - H w', all computed once here, so a query forms them with
 * 3 multiply-adds per coefficient. Descartes' rule in Bernstein form then
 * proves, interval by interval, where f has no interior minimum (no sign
 * change, or one change from + to -), exactly one (one change from - to
 * +, found by a bracketed Newton iteration that cannot leave its
 * bracket), or possibly several (subdivide, with the control-net box of
 * every sub-interval as the lower bound that prunes it). The lower bound
 * comes from the same idea: w^2 f = |H - w P|^2 and w^2 are polynomials
 * of degree 2p with positive weight coefficients, so f on an interval is
 * a convex combination of the coefficient ratios and at least their
 * minimum; that bound tightens quadratically under subdivision and is
 * exact for a circle seen from its centre. The piece's end
 * points are always candidates, which covers open ends, C0 corners and
 * cusps at knots. This is what lets the distance core promise the global
 * minimum rather than the minimum nearest to a sample.
 *
 * Memory and real-time rules: a piece is a fixed-size plain struct filled
 * at setup (px_cpiece_init); the query uses a small fixed stack and no
 * heap, and every loop is bounded (depth PX_CPIECE_MAX_DEPTH, at most
 * PX_CPIECE_MAX_NODES intervals, PX_CPIECE_MAX_ITERS root steps).
 */
#ifndef PX_CPIECE_H
#define PX_CPIECE_H

#include "px_base.h"
#include "px_bern.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PX_CPIECE_MAX_DEGREE 10
#define PX_CPIECE_NG (3 * PX_CPIECE_MAX_DEGREE)
#define PX_CPIECE_NF (2 * PX_CPIECE_MAX_DEGREE + 1)
/* Subdivision depth: a piece interval of width 2^-44 is far below the
 * parameter resolution that matters at 1e-9 of a model's size. */
#define PX_CPIECE_MAX_DEPTH 44
#define PX_CPIECE_MAX_NODES 512
#define PX_CPIECE_MAX_ITERS 64

/* A rational Bezier piece. Plain struct: members are private. */
struct px_cpiece {
	int degree_;
	/* Degree of g: 3p - 1, or 2p - 1 when every weight is equal (w is
	 * then divided out: wconst_, and w^2 = 1 needs no bound). */
	int gdeg_;
	int wconst_;
	double u0_, u1_;                            /* global parameter range */
	double h_[4][PX_CPIECE_MAX_DEGREE + 1];     /* x w, y w, z w, w */
	double hb_[4][PX_CPIECE_MAX_DEGREE + 1];    /* h_ times binomials */
	double hd_[4][PX_CPIECE_MAX_DEGREE];        /* derivative, scaled */
	double ga_[PX_CPIECE_NG];                   /* a(u) coefficients */
	double gb_[3][PX_CPIECE_NG];                /* b(u) coefficients */
	double fa_[PX_CPIECE_NF];                   /* |H|^2 */
	double fb_[3][PX_CPIECE_NF];                /* w H */
	double fw_[PX_CPIECE_NF];                   /* w^2 */
	px_aabb box_;                               /* hull of the control net */
	px_vec3 center_;                            /* of box_ */
	double radius_;                             /* half diagonal of box_ */
	px_vec3 end_[2];                            /* end points */
};

struct px_cpiece_hit {
	double d2;     /* squared distance */
	double u;      /* global parameter of the foot point */
	px_vec3 point; /* foot point */
	int iters;     /* root-refinement iterations spent */
	int nodes;     /* intervals examined */
	/* 1 when every interval was resolved by a proof; 0 when the depth
	 * or node bound cut an interval short, in which case gap bounds how
	 * much smaller the true minimum on this piece might be. */
	int certified;
	double gap;
};

/*
 * Fill a piece of the given degree (1..PX_CPIECE_MAX_DEGREE) from
 * degree + 1 homogeneous control points hw[i] = (x w, y w, z w, w) over
 * the global parameter range [u0, u1] (u0 < u1). Weights must be positive
 * and everything finite. Returns PX_OK, PX_E_RANGE (degree), PX_E_NAN or
 * PX_E_INVAL (weight <= 0, u0 >= u1).
 */
PX_API int px_cpiece_init(struct px_cpiece *pc, int degree,
			  const double (*hw)[4], double u0, double u1);

/* Box that contains the whole piece. @note RT-safe. */
PX_API px_aabb px_cpiece_box(const struct px_cpiece *pc);

/* Point and first derivative (with respect to the global parameter) at
 * local parameter t in [0, 1]. @note RT-safe. */
PX_API px_vec3 px_cpiece_eval(const struct px_cpiece *pc, double t,
			      px_vec3 *d1);

/*
 * Closest point of the piece to p, if closer than *best_d2.
 * best_d2 is in/out: an upper bound on entry (INFINITY for none); lowered
 * when the piece holds a closer point, in which case hit is filled and 1
 * is returned. Returns 0 when nothing on the piece is closer than the
 * bound (hit->nodes, iters, certified, gap still describe the work).
 * @note RT-safe.
 */
PX_API int px_cpiece_closest(const struct px_cpiece *pc, px_vec3 p,
			     double *best_d2, struct px_cpiece_hit *hit);

#ifdef __cplusplus
}
#endif

#endif
