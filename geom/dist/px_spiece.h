/*
 * px_spiece.h - certified interior closest point on one rational Bezier
 * patch.
 *
 * The surface counterpart of px_cpiece.h. With S = H / w on the patch's
 * local square (s, t) in [0, 1]^2, the critical points of f = |S - P|^2
 * are the common zeros of
 *
 *     gu = (H - w P) . (H_s w - H w_s) = (w^3 / 2) df/ds
 *     gv = (H - w P) . (H_t w - H w_t) = (w^3 / 2) df/dt
 *
 * tensor-product polynomials whose Bernstein coefficients are
 * a - P . b with a and b computed once here. A query subdivides the
 * square and settles each rectangle by a proof:
 *  - F / W bound: w^2 f and w^2 in Bernstein form give f >= min F_ij /
 *    W_ij; a rectangle that cannot beat the best distance is dropped;
 *  - no critical point: all coefficients of gu (or of gv) of one strict
 *    sign mean df/ds (or df/dt) never vanishes on the closed rectangle;
 *  - at most one, and it is a minimum: Bernstein bounds of the Jacobian
 *    of (gu, gv) make its symmetric part positive definite, so (gu, gv)
 *    is strictly monotone on the rectangle; Newton started inside finds
 *    that single zero. Where a cross term near the size of the diagonal
 *    defeats those bounds (a skewed parametrization, a twist), the same
 *    test is made on M^T S M, M from the Cholesky factor of the symmetric
 *    part S at the rectangle's middle, its entries formed as polynomials
 *    before their ranges are taken (congruence keeps definiteness, and
 *    the preconditioned entries vary only as S does). Negative definite
 *    means a single maximum: dropped.
 *    When the minimum lies just outside the rectangle (beside a piece
 *    border or the patch edge), a projected Newton ends on the border
 *    with the gradient pointing out, and the monotonicity modulus bounds
 *    how far an interior zero could be from that point and how much
 *    lower it could be (by the square of the gradient's part along the
 *    border over the modulus, as for strongly convex functions): within
 *    rounding, the rectangle is settled without subdividing towards the
 *    border. Newton takes a step whose predicted decrease is below f's
 *    rounding whole (a line search cannot judge it), and where the
 *    cross term pushes its step out through a border the gradient points
 *    in through, the diagonal step instead.
 * Anything else is split in four, down to a depth and node bound; what
 * the bound cuts short is reported as uncertified with a gap. A split
 * rectangle keeps its restricted tensors for its children (a fixed pool
 * on the stack): a child's are one half split per direction from its
 * parent's, each level of the sweep one flat loop, instead of two full
 * restrictions from the whole patch per node (the cost near focal
 * points, where dozens of rectangles stay open).
 *
 * Only interior critical points are searched here. Minima on the
 * boundary of a surface (and on C0 creases) are minima of the boundary
 * curves, which the distance core handles as curve pieces.
 *
 * Memory and real-time rules: a piece lives in caller memory: a small
 * struct plus px_spiece_doubles(p, q) doubles filled by px_spiece_init()
 * at setup. px_spiece_closest() uses fixed stack arrays (about 410 KiB
 * deep: the rectangle heap, a pool of parent tensors and tensors sized
 * for PX_SPIECE_MAX_DEGREE, 363 KiB, and the preconditioned test's 46
 * KiB) and no heap; all loops are bounded.
 */
#ifndef PX_SPIECE_H
#define PX_SPIECE_H

#include <stddef.h>

#include "px_base.h"
#include "px_math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Same limit as the NURBS kernel. A query's stack arrays are sized for
 * it: about 410 KiB deep, whatever the actual degree (only the used part
 * is touched); real-time threads must have that much prefaulted stack
 * (px_rt's default prefaults 1 MiB). */
#define PX_SPIECE_MAX_DEGREE 10
#define PX_SPIECE_MAX_DEPTH 24
#define PX_SPIECE_MAX_NODES 1024
#define PX_SPIECE_MAX_ITERS 40

struct px_spiece {
	int p_, q_;
	double u0_, u1_, v0_, v1_; /* global parameter rectangle */
	px_aabb box_;
	px_vec3 center_;
	double radius_;
	/* Degrees of the gu and gv tensors: (3p - 1, 3q) and (3p, 3q - 1)
	 * for a rational patch, (2p - 1, 2q) and (2p, 2q - 1) when every
	 * weight is equal (then w is the constant 1 and W = w^2 is not
	 * needed: wconst_). */
	int gun_, gum_, gvn_, gvm_;
	int wconst_;
	/* Arrays inside the caller block (see px_spiece_doubles()):
	 * homogeneous control net h_[c][i][j] (c = x w, y w, z w, w; i along
	 * s, j along t), and the coefficient tensors of F, W, gu, gv. */
	double *h_;
	double *fa_, *fb_, *fw_;
	double *gua_, *gub_;
	double *gva_, *gvb_;
};

struct px_spiece_hit {
	double d2;
	double u, v;   /* global parameters */
	px_vec3 point;
	int iters, nodes;
	/* Rectangles restricted from the whole patch because the query's
	 * pool of parent tensors was full (cost only, see spiece_solve.c). */
	int pool_misses;
	int certified; /* as px_cpiece_hit */
	double gap;
};

/* Doubles of caller memory a piece of degrees (p, q) needs whatever its
 * weights; 0 when a degree is outside 1..PX_SPIECE_MAX_DEGREE. */
PX_API size_t px_spiece_doubles(int p, int q);

/* Doubles the piece with these control points (as px_spiece_init())
 * needs: fewer than px_spiece_doubles(p, q) when every weight is equal
 * (lower-degree critical-point tensors, about 37 % less for bicubics);
 * 0 for a bad degree or NULL. */
PX_API size_t px_spiece_doubles_hw(int p, int q, const double (*hw)[4]);

/*
 * Fill a piece from (p + 1) * (q + 1) homogeneous control points
 * hw[i * (q + 1) + j] = (x w, y w, z w, w), i along u, over the global
 * rectangle [u0, u1] x [v0, v1]. mem holds px_spiece_doubles_hw(p, q, hw)
 * doubles (px_spiece_doubles(p, q) always suffice) and must outlive the
 * piece. Returns PX_OK, PX_E_RANGE, PX_E_NAN
 * or PX_E_INVAL (weights <= 0, empty rectangle).
 */
PX_API int px_spiece_init(struct px_spiece *sp, int p, int q,
			  const double (*hw)[4], double u0, double u1,
			  double v0, double v1, double *mem);

/* Point and first/second partial derivatives (global parameters; any
 * pointer may be NULL) at local (s, t). @note RT-safe. */
PX_API px_vec3 px_spiece_eval(const struct px_spiece *sp, double s, double t,
			      px_vec3 *su, px_vec3 *sv, px_vec3 *suu,
			      px_vec3 *suv, px_vec3 *svv);

/*
 * Interior critical minimum of the patch closer than *best_d2 (in/out,
 * as px_cpiece_closest()). Returns 1 and fills hit when it lowers the
 * bound. @note RT-safe.
 */
PX_API int px_spiece_closest(const struct px_spiece *sp, px_vec3 p,
			     double *best_d2, struct px_spiece_hit *hit);

/* As px_spiece_closest(), with a guess (s, t) in local coordinates (for
 * example the nearest pre-sample) that Newton starts from when it lies in
 * the rectangle being solved. The guess changes speed, never the answer.
 * @note RT-safe. */
PX_API int px_spiece_closest_hint(const struct px_spiece *sp, px_vec3 p,
				  double hint_s, double hint_t,
				  double *best_d2, struct px_spiece_hit *hit);

#ifdef __cplusplus
}
#endif

#endif
