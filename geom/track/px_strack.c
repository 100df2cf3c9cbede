/*
 * px_strack.c - coherent tracking of point-surface critical distances.
 *
 * f(u, v) = |S - p|^2 / 2 has gradient E = ((S - p) . Su, (S - p) . Sv)
 * and Hessian H = [Su.Su + (S - p).Suu, Su.Sv + (S - p).Suv; .,
 * Sv.Sv + (S - p).Svv]. With p = S + l N on the normal line, H = I - l II
 * (first and second fundamental forms), singular exactly at l = 1 / k_i:
 * the focal sheets, where critical points are born and die in pairs
 * (Seong-Johnson-Cohen section 4.3). Moving p by dp moves a regular
 * critical point by H^-1 (Su . dp, Sv . dp) (differentiate E = 0, their
 * section 4.2): the predictor.
 *
 * A critical point that is already tracked is only ever followed; a new
 * one comes from the solve of a cell whose transition region the path
 * came near.
 * Everything found is a verified zero of E (Newton converged), so the
 * tracked set never holds a false point. The transition regions are
 * proven (cert_radius()); what is left to Newton is finding the points
 * of a cell that is solved again (seed grid per cell) in the boxes where
 * no contraction proves what they hold (contract_solve()), which the
 * index check and the optional verification would report if it failed.
 */
#include "px_strack.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gov_internal.h"
#include "math_internal.h"
#include "nurbs_internal.h"
#include "track_internal.h"
#include "px_bern.h"

#define ST_NEWTON 16
/* Newton's last step where the Hessian is well conditioned (snewton()):
 * this share of a patch's span, on a surface whose rational patches (if
 * any) have weights at most ST_QUICK_WRATIO apart */
#define ST_QUICK 3e-5
#define ST_QUICK_WRATIO 3.0
/* Safety factor on certificate radii and relative padding of the
 * enclosures for rounding. */
#define ST_RSAFE (1.0 - 1e-9)
#define ST_PAD 1e-12
/* Steps of contract_solve()'s iteration before it gives up, and the
 * largest rate it runs with (0.75^64 ~ 1e-8: nearer 1 the iteration
 * crawls, and seeds cost less) */
#define ST_CONTRACT 64
#define ST_RHO_MAX 0.75
/* contract_solve() hands over to Newton this close (of the box's half
 * widths) to the point */
#define ST_POLISH 3e-2

enum { ST_TRACK = 0, ST_LAG = 1, ST_REBUILD = 2, ST_PEND = 3 };

/* Pending items (struct px_strack's pend): a cell solve, one past where a
 * long step met the cell's region, the escape bound of a ring. */
enum { PK_SOLVE = 0, PK_CROSS = 1, PK_RING = 2 };

struct crit {
	double u, v;
	int type;       /* +1 min, -1 max, 0 saddle */
	uint32_t id;
	px_vec3 s, su, sv;
	double h11, h12, h22;
};

/* Closed interval. */
struct iv {
	double lo, hi;
};

/* Centre values on a cell side that the edge test needs. */
struct cside {
	px_vec3 s, su, sv;
	double n1, n2;  /* |su|_1, |sv|_1 */
	int along;      /* 0: the side runs along u (v fixed), 1: along v */
	double h;       /* half length of the side in its parameter */
};

/*
 * Certificate data of a region cell: enclosures over the whole cell of
 * S and its derivatives up to order 2 (from the Bezier net of the cell:
 * the convex hull property for S, difference nets for the derivatives,
 * for rational cells the tighter of the interval quotient rule and the
 * numerators' bounds, rat_tight()), the first
 * fundamental form entries Si.Sj, the centre values of S, Su, Sv and the
 * sides on an open domain edge or a crease (less than C2 between
 * patches), where points enter and leave.
 */
struct rcert {
	struct iv S[3], Suu[3], Suv[3], Svv[3];
	struct iv G11, G12, G22;
	double m11, m12, m22;   /* sum over x, y, z of max |Sij| */
	/* the same in midpoint-radius form for the run-time test: with
	 * w = S - x, H_ij lies in A_ij - x . B_ij +- (R_ij + |mid w| . Q_ij)
	 * (entries 0: 11, 1: 12, 2: 22) */
	px_vec3 smid, B[3], Q[3];
	double A[3], R[3];
	px_vec3 sc, suc, svc;
	double n1, n2;          /* |suc|_1, |svc|_1 */
	double hu, hv;          /* half widths of the cell in u, v */
	/* the inverses cert_radius() multiplies by instead of dividing
	 * (centre_set()): of the E test's
	 * denominators n1 + m11 hu + m12 hv and n2 + m12 hu + m22 hv, and
	 * of m11 and m22 */
	double ie1, ie2, im11, im22;
	int nside;
	struct cside side[4];
	/* bounds over the cell of |S_uuu|, |S_uuv|, |S_uvv|, |S_vvv| per
	 * coordinate, from which the certificates of its sub-boxes are made
	 * (taylor_cert()) */
	double t3[4][3];
	int rat;        /* the net's weights differ */
};

/* The certificates of the four pieces of quarter key (4 ri + k), those
 * made so far (bit j: piece j). */
struct pcache {
	int key;
	unsigned filled;
	struct rcert rc[4];
};

/* The certificates of first-level sub-box key (4 (5 ri + q + 1) + k1)
 * of a solve (rc[0]) and of its four quarters (rc[1 + k2]); bit i of
 * filled: rc[i] made. */
struct scache {
	int key;
	unsigned filled;
	struct rcert rc[5];
};

struct scell {
	double u0, u1, v0, v1;
	int surf;
	double size;    /* diameter of the cell's box (solve cells) */
	/* on a collapsed edge: E2 vanishes along the pole, so no
	 * certificate holds near its normal lines; solved whenever hit
	 * (within the budget, as any cell; never past the crossing) */
	int always;
	struct rcert cert; /* region cells */
	uint32_t mark;
	double cross;   /* hit: segment parameter where the region is met */
	int child;      /* solve cell: first of its 2 x 2 region cells */
	/* escape bound (ring_build()): dmark == epoch when dist is the
	 * cell's ring (0: a source) */
	uint32_t dmark;
	int dist;
	/* its K over the step of epoch kmark (ring_cell()): regions', and
	 * quarters' (NAN where not worked out); its solve at p takes what
	 * they prove at p from them (cell_done()) */
	uint32_t kmark;
	double kr[4], kq[16];
};

/*
 * A region cell's side on the open domain boundary, traversed
 * counter-clockwise in (u, v): the region's certificate and the entry of
 * that side in its side tests, the same for the two quarters along it
 * (in the order traversed), and S, Su, Sv at the start, middle and end.
 */
struct wpiece {
	int ri, side, qk[2], qside[2];
	px_vec3 s[3], su[3], sv[3];
};

/* A Bezier patch of a surface in power form of its local (s, t) in
 * [0, 1]^2: coefficients of x w, y w, z w, w; c[k][j (p + 1) + i] is
 * the coefficient of s^i t^j. */
struct patch {
	double u0, u1, v0, v1, iu, iv;
	int p, q;
	int rat;         /* weights not all equal */
	double wratio;   /* largest weight over the smallest */
	const double *c; /* 4 (p + 1)(q + 1) */
	/* bicubic with the 4-wide evaluation (eval4_bicubic()): the same
	 * coefficients x, y, z, w side by side, (j, i) row-major; else
	 * NULL */
	const double *c4;
};

struct ssurf {
	struct px_nurbs_surf s;
	struct patch *pt;       /* npu x npv, u fastest */
	double *pool;
	double *pool4;          /* c4 of every patch (64-byte aligned) */
	double *pu, *pv;        /* patch bounds (npu + 1, npv + 1) */
	int npu, npv;
	double *mem;            /* owned copy of knots and pw */
	double u0, u1, v0, v1, du, dv;
	int wrap_u, wrap_v;
	/* snewton()'s quick last step where the Hessian is well
	 * conditioned: ST_QUICK of a patch's span when no patch's weights
	 * are more than ST_QUICK_WRATIO apart, else 0 (only the general
	 * 1e-6 of the domain) */
	double quick_u, quick_v;
	int quick_loose;        /* px__strack_quick_fault: any Hessian */
	int pole[4];            /* edge collapsed: u0, u1, v0, v1 */
	int first_cell, ncu, ncv;
	double *cu, *cv;        /* cell bounds along u (ncu + 1), v */
	struct crit *z, *tmp;
	int nz, cap;
	/* the domain boundary for the index check (winding()): the region
	 * sides on its open edges, counter-clockwise (none when both
	 * directions wrap: the sum is then 0); wind_ok 0, no check, with a
	 * collapsed edge or a C0 line */
	struct wpiece *wp;
	int nwp, wind_ok;
	/* the ring of the escape bound in progress (ring_build()): rl_n
	 * cells in ring_list, the next rl_next; its quarter layers' largest
	 * K and least width */
	int rl_n, rl_next;
	double rl_kl[4], rl_wl[4];
};

struct edge {
	int surf, dir;  /* dir 0: curve in u at v = t; 1: curve in v at u = t */
	double t;
};

struct pole {
	px_vec3 q;
	double u, v;
	int surf;
};

/* The cube a cell's expiry is of: its certificate holds for every point
 * within max-norm distance crad of ctr (col_begin() checks a due cell
 * against it before a test). By cell, in a compact array of its own:
 * keeping a due cell reads no cell. */
struct cube {
	px_vec3 ctr;
	double crad;
};

struct px_strack {
	struct px_strack_opts opts;
	struct px_dist_model *dist;
	struct px_track *ct;    /* free curves + edges */
	/* boxes of half knot spans of every curve of ct: while the best
	 * interior minimum is closer than all of them, ct is left out */
	px_aabb *cbox;
	int n_cbox, ct_ncrit;
	px_vec3 ct_p;           /* where ct was last updated */
	/* the curves proven not closest within ct_rc of ct_q (straight
	 * distance; ct_rc2 its square, -1 none): ct_note() */
	px_vec3 ct_q;
	double ct_rc, ct_rc2;
	int n_curves, n_surf, n_edges, n_cells, n_poles, n_unbounded;
	int n_patches;
	struct ssurf *sf;
	struct scell *cell;
	/* transition regions are held by 2 x 2 children of each solve cell:
	 * tighter cones and height intervals, the same seeds */
	struct scell *rcell;
	/* the quarters of each region cell (qcert[4 ri + k]): tried where
	 * the region's own certificate proves nothing, which happens when
	 * its enclosures are too wide for a critical point or a focal point
	 * close by (the quarters' are about half as wide) */
	struct rcert *qcert;
	/* the pieces' certificates of rational regions' quarters, made at
	 * update time (piece_radius()) and kept, direct-mapped by quarter:
	 * they do not depend on the point, and the cells about a point
	 * near a focal sheet are tested again and again (up to three
	 * radii a test); pcache_n a power of two, 0 without rational
	 * regions */
	struct pcache *pcache;
	int pcache_n;
	/* the same for the boxes a solve cuts (sub_solve(): four quarters
	 * of a region or quarter, and four of each of those), by the box
	 * cut and its first-level quarter; scache_n a power of two */
	struct scache *scache;
	int scache_n;
	struct edge *edge;
	struct pole *pole;
	/* each cell's expiry (ex, by cell; the cube it is of in cube), the
	 * least of each group of ST_GROUP cells and of all: an update with
	 * cells due scans the groups once, the usual update compares one
	 * number (a heap's sifts cost more as soon as cells are kept,
	 * col_begin()) */
	double *ex, *gdue, next_due;
	struct cube *cube;
	int *popped, *hits;
	/* solves owed to the set at p (mode ST_PEND): cell pend[i] solved
	 * at pend_ps[i] and followed to p; pend_next the next one. Where
	 * pend_kind[i] is PK_CROSS, pend_ps[i] is where the step began and
	 * the seed point is still to be found along it (cross_at(), work
	 * counted in the budget when the solve comes up); PK_RING + k - 1:
	 * the escape bound of ring k of surface pend[i] for the step from
	 * pend_ps[i], the rings inside it needing pend_need[i] of
	 * travel (ring_check()). pend_epoch: the epoch of the step (its
	 * cells' marks); pend_nh its sources (hits 0..pend_nh). ring_list:
	 * each surface's ring in progress, from its first cell on */
	int *pend, n_pend, pend_next, pend_nh;
	int *ring_list;
	px_vec3 *pend_ps;
	double *pend_need;
	unsigned char *pend_kind;
	uint32_t pend_epoch;
	/* path length (the 1-Lipschitz certificates of the hot path); ctravel
	 * the same path in the max norm (the cells' certificates are cubes:
	 * a point whose max-norm path from p is below r stays in the cube of
	 * half width r about p, and that path is often half the length) */
	double travel, ctravel;
	int ex_ok;              /* ex, gdue, next_due valid */
	/* seeds of a cell solve with no region or quarter proven
	 * (cell_seeds()), the work of ST_UNITS */
	int full_seeds;
	/* the sub-boxes' work in the solve in progress (sub_solve()), in
	 * 1/ST_SUB_SEED of a seed */
	int sub_work, sub_left;
	/* the due cells of the segment col_p0 -> col_p1 tested over several
	 * updates (more of them than max_tests): taken out (popped, their
	 * expiries infinite until tested), col_k of the col_np tested,
	 * col_nh of those hit (in hits) */
	int col_on, col_np, col_k, col_nh;
	px_vec3 col_p0, col_p1;
	px_aabb work;
	double scale;
	px_vec3 p;
	int init;
	uint32_t epoch, next_id;
	/* the tracked set is at p (ST_TRACK), or catching up with the query
	 * point (ST_LAG), or being re-established at p (ST_REBUILD: rb_next
	 * the next cell to solve; rb_started 0: start at the next point
	 * inside the working volume) */
	int mode, rb_started, rb_next;
	/* the set's membership changed in the step in progress: its index
	 * sums are checked when its solves are done (ix_check()) */
	int ix_on;
	px_vec3 last_point, last_q; /* last answer and its query point */
	int last_entity, have_last;
	int best_kind;          /* 0 none, 1 surface min, 2 curve tracker, 3 pole */
	uint32_t best_id;
	int ans_s, ans_j;       /* answer(): the answering surface minimum */
	/* hot path: every critical point but hot_j of surface hot_s rests at
	 * its state of hot_p (track_step starts them there); while the path
	 * stays below hot_until and no cell is due, an update follows that
	 * one point alone; hot_s -1 when off */
	int hot_s, hot_j;
	int hot_curves;         /* the curve tracker runs with the minimum */
	px_vec3 hot_p;
	double hot_until;
	int hot_nmin, hot_nmax, hot_nsad, hot_ncrit, hot_ccrit;
	int fault_hot;          /* test hook: 1 hot path off, 2 never expires */
	/* test hook: 1 a step's solves drop the minima they find, 2 the
	 * index check off too; pend_on: in a step's solves */
	int fault_drop, pend_on;
	/* cold switch (gov_internal.h): gov_q the last query point (step
	 * lengths); ret_left > 0 while the set is re-established after
	 * cold answers (those updates are not timed: the rebuild is the
	 * return's cost, not tracking's); cprev the last answer when it is
	 * an interior point of a surface (a cold answer's jumped follows it) */
	struct px_gov gov;
	px_vec3 gov_q;
	int ret_left;
	struct {
		int ok, s;
		struct crit z;
		px_vec3 q;
	} cprev;
	struct px_strack_stats st;
};

/* ------------------------------------------------------------------ */
/* evaluation and Newton                                               */

static int bsearch_bounds(const double *b, int n, double x)
{
	int lo = 0, hi = n - 1;
	while (lo < hi) {
		int mid = (lo + hi + 1) / 2;
		if (b[mid] <= x)
			lo = mid;
		else
			hi = mid - 1;
	}
	return lo;
}

/* H, H_s, H_t, H_ss, H_st, H_tt of one coordinate of a patch (power
 * basis, rows along t) at (s, t) into h[0..5][k]: Horner in t over the
 * rows a_j(s) and their s-derivatives (V = H, H_t, H_tt; W = H_s, H_st;
 * X = H_ss). */
static inline __attribute__((always_inline)) void
eval_one(const double *c, int p, int q, double s, double t, double h[6][4],
	 int k)
{
	double V0 = 0, V1 = 0, V2 = 0, W0 = 0, W1 = 0, X0 = 0;
	int i, j;
	/* (unrolled where the degrees are constants: the bicubic call) */
#pragma GCC unroll 4
	for (j = q; j >= 0; j--) {
		const double *row = c + j * (p + 1);
		double a = row[p], a1 = 0.0, a2 = 0.0;
#pragma GCC unroll 4
		for (i = p - 1; i >= 0; i--) {
			a2 = a2 * s + 2.0 * a1;
			a1 = a1 * s + a;
			a = a * s + row[i];
		}
		V2 = V2 * t + 2.0 * V1;
		V1 = V1 * t + V0;
		V0 = V0 * t + a;
		W1 = W1 * t + W0;
		W0 = W0 * t + a1;
		X0 = X0 * t + a2;
	}
	h[0][k] = V0;
	h[1][k] = W0;
	h[2][k] = V1;
	h[3][k] = X0;
	h[4][k] = W1;
	h[5][k] = V2;
}

/* Two coordinates at once where the compiler has generic vectors (GCC,
 * clang): lane by lane eval_one()'s arithmetic in the same order, so
 * the same values bit for bit, in about half the instructions (the
 * evaluation is most of a hot update). */
#if defined(__GNUC__) && !defined(PX_STRACK_NO_VEC)
#define ST_VEC 1
typedef double st_v2 __attribute__((vector_size(16)));

static inline __attribute__((always_inline)) void
eval_pair(const double *c0, const double *c1, int p, int q, double s,
	  double t, double h[6][4], int k)
{
	const st_v2 S = {s, s}, T = {t, t}, two = {2.0, 2.0};
	st_v2 V0 = {0.0, 0.0}, V1 = V0, V2 = V0, W0 = V0, W1 = V0, X0 = V0;
	int i, j;
#pragma GCC unroll 4
	for (j = q; j >= 0; j--) {
		const double *r0 = c0 + j * (p + 1), *r1 = c1 + j * (p + 1);
		st_v2 a = {r0[p], r1[p]}, a1 = {0.0, 0.0}, a2 = {0.0, 0.0};
#pragma GCC unroll 4
		for (i = p - 1; i >= 0; i--) {
			const st_v2 ci = {r0[i], r1[i]};
			a2 = a2 * S + two * a1;
			a1 = a1 * S + a;
			a = a * S + ci;
		}
		V2 = V2 * T + two * V1;
		V1 = V1 * T + V0;
		V0 = V0 * T + a;
		W1 = W1 * T + W0;
		W0 = W0 * T + a1;
		X0 = X0 * T + a2;
	}
	h[0][k] = V0[0], h[0][k + 1] = V0[1];
	h[1][k] = W0[0], h[1][k + 1] = W0[1];
	h[2][k] = V1[0], h[2][k + 1] = V1[1];
	h[3][k] = X0[0], h[3][k + 1] = X0[1];
	h[4][k] = W1[0], h[4][k + 1] = W1[1];
	h[5][k] = V2[0], h[5][k + 1] = V2[1];
}
#else
#define ST_VEC 0
#endif

/* All four coordinates of a bicubic at once (x, y, z, w in the lanes of
 * one 256-bit vector, fused multiply-adds) where the processor has
 * AVX2 and FMA (checked at setup: have_fma()); eval_one()'s
 * Horner scheme, each multiply-add rounded once. About a third of the
 * instructions of the two-lane form, and the evaluation is most of a
 * hot update. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(PX_STRACK_NO_VEC)
#include <immintrin.h>
#define ST_FMA 1
__attribute__((target("avx2,fma"))) static void
eval4_bicubic(const double *c4, double s, double t, double h[6][4])
{
	const __m256d S = _mm256_set1_pd(s), T = _mm256_set1_pd(t);
	__m256d V0 = _mm256_setzero_pd(), V1 = V0, V2 = V0, W0 = V0, W1 = V0,
		X0 = V0;
	int i, j;
	for (j = 3; j >= 0; j--) {
		const double *row = c4 + 16 * j;
		__m256d a = _mm256_load_pd(row + 12), a1 = _mm256_setzero_pd(),
			a2 = a1;
		for (i = 2; i >= 0; i--) {
			a2 = _mm256_fmadd_pd(a2, S, _mm256_add_pd(a1, a1));
			a1 = _mm256_fmadd_pd(a1, S, a);
			a = _mm256_fmadd_pd(a, S, _mm256_load_pd(row + 4 * i));
		}
		V2 = _mm256_fmadd_pd(V2, T, _mm256_add_pd(V1, V1));
		V1 = _mm256_fmadd_pd(V1, T, V0);
		V0 = _mm256_fmadd_pd(V0, T, a);
		W1 = _mm256_fmadd_pd(W1, T, W0);
		W0 = _mm256_fmadd_pd(W0, T, a1);
		X0 = _mm256_fmadd_pd(X0, T, a2);
	}
	_mm256_storeu_pd(h[0], V0);
	_mm256_storeu_pd(h[1], W0);
	_mm256_storeu_pd(h[2], V1);
	_mm256_storeu_pd(h[3], X0);
	_mm256_storeu_pd(h[4], W1);
	_mm256_storeu_pd(h[5], V2);
}

int px__strack_no_fma = 0;

static int have_fma(void)
{
	return !px__strack_no_fma && __builtin_cpu_supports("avx2") &&
	       __builtin_cpu_supports("fma");
}
#else
#define ST_FMA 0
int px__strack_no_fma = 0;
static int have_fma(void)
{
	return 0;
}
#endif

/* Point and derivatives up to order 2 from the patch holding (u, v). */
static void surf_eval2(const struct ssurf *f, double u, double v,
		       struct px_nurbs_surf_derivs *d)
{
	const struct patch *pt;
	/* H, Hs, Ht, Hss, Hst, Htt by coordinate x, y, z, w */
	double s, t, h[6][4];
	int p, q;
	size_t n;
	pt = &f->pt[bsearch_bounds(f->pv, f->npv, v) * f->npu +
		    bsearch_bounds(f->pu, f->npu, u)];
	p = pt->p;
	q = pt->q;
	n = (size_t)(p + 1) * (size_t)(q + 1);
	s = (u - pt->u0) * pt->iu;
	t = (v - pt->v0) * pt->iv;
#if ST_FMA
	if (pt->c4)
		eval4_bicubic(pt->c4, s, t, h);
	else
#endif
#if ST_VEC
	if (p == 3 && q == 3) {
		/* bicubic, the usual patch: the loops unrolled */
		eval_pair(pt->c, pt->c + 16, 3, 3, s, t, h, 0);
		if (pt->rat)
			eval_pair(pt->c + 32, pt->c + 48, 3, 3, s, t, h, 2);
		else
			eval_one(pt->c + 32, 3, 3, s, t, h, 2);
	} else {
		eval_pair(pt->c, pt->c + n, p, q, s, t, h, 0);
		if (pt->rat)
			eval_pair(pt->c + 2 * n, pt->c + 3 * n, p, q, s, t, h, 2);
		else
			eval_one(pt->c + 2 * n, p, q, s, t, h, 2);
	}
#else
	{
		int k;
		for (k = 0; k < (pt->rat ? 4 : 3); k++)
			eval_one(pt->c + (size_t)k * n, p, q, s, t, h, k);
	}
#endif
	if (!pt->rat) {
		/* polynomial (weights normalised to 1 at setup) */
		d->s = px_v3(h[0][0], h[0][1], h[0][2]);
		d->su = px_v3(h[1][0] * pt->iu, h[1][1] * pt->iu, h[1][2] * pt->iu);
		d->sv = px_v3(h[2][0] * pt->iv, h[2][1] * pt->iv, h[2][2] * pt->iv);
		d->suu = px_v3_scale(px_v3(h[3][0], h[3][1], h[3][2]), pt->iu * pt->iu);
		d->suv = px_v3_scale(px_v3(h[4][0], h[4][1], h[4][2]), pt->iu * pt->iv);
		d->svv = px_v3_scale(px_v3(h[5][0], h[5][1], h[5][2]), pt->iv * pt->iv);
		return;
	}
	{
		double w = h[0][3], iw = 1.0 / w, ws = h[1][3], wt = h[2][3],
		       wss = h[3][3], wst = h[4][3], wtt = h[5][3];
		px_vec3 C, Cs, Ct, Css, Cst, Ctt;
		C = px_v3(h[0][0] * iw, h[0][1] * iw, h[0][2] * iw);
		Cs = px_v3((h[1][0] - ws * C.x) * iw, (h[1][1] - ws * C.y) * iw,
			   (h[1][2] - ws * C.z) * iw);
		Ct = px_v3((h[2][0] - wt * C.x) * iw, (h[2][1] - wt * C.y) * iw,
			   (h[2][2] - wt * C.z) * iw);
		Css = px_v3((h[3][0] - 2.0 * ws * Cs.x - wss * C.x) * iw,
			    (h[3][1] - 2.0 * ws * Cs.y - wss * C.y) * iw,
			    (h[3][2] - 2.0 * ws * Cs.z - wss * C.z) * iw);
		Ctt = px_v3((h[5][0] - 2.0 * wt * Ct.x - wtt * C.x) * iw,
			    (h[5][1] - 2.0 * wt * Ct.y - wtt * C.y) * iw,
			    (h[5][2] - 2.0 * wt * Ct.z - wtt * C.z) * iw);
		Cst = px_v3((h[4][0] - ws * Ct.x - wt * Cs.x - wst * C.x) * iw,
			    (h[4][1] - ws * Ct.y - wt * Cs.y - wst * C.y) * iw,
			    (h[4][2] - ws * Ct.z - wt * Cs.z - wst * C.z) * iw);
		d->s = C;
		d->su = px_v3_scale(Cs, pt->iu);
		d->sv = px_v3_scale(Ct, pt->iv);
		d->suu = px_v3_scale(Css, pt->iu * pt->iu);
		d->suv = px_v3_scale(Cst, pt->iu * pt->iv);
		d->svv = px_v3_scale(Ctt, pt->iv * pt->iv);
	}
}

/* z evaluated at its (u, v) for p: point, first derivatives, Hessian
 * of E; the gradient of E into grad_out and the surface derivatives
 * into d. */
static void crit_eval_d(const struct ssurf *f, struct crit *z, px_vec3 p,
			px_vec3 *grad_out, struct px_nurbs_surf_derivs *d)
{
	px_vec3 w;
	surf_eval2(f, z->u, z->v, d);
	w = px_v3_sub(d->s, p);
	z->s = d->s;
	z->su = d->su;
	z->sv = d->sv;
	z->h11 = px_v3_dot(d->su, d->su) + px_v3_dot(w, d->suu);
	z->h12 = px_v3_dot(d->su, d->sv) + px_v3_dot(w, d->suv);
	z->h22 = px_v3_dot(d->sv, d->sv) + px_v3_dot(w, d->svv);
	grad_out->x = px_v3_dot(w, d->su);
	grad_out->y = px_v3_dot(w, d->sv);
	grad_out->z = 0.0;
}

static void crit_eval(const struct ssurf *f, struct crit *z, px_vec3 p,
		      px_vec3 *grad_out)
{
	struct px_nurbs_surf_derivs d;
	crit_eval_d(f, z, p, grad_out, &d);
}

static int crit_type(const struct crit *z)
{
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (det > 0.0)
		return z->h11 > 0.0 ? 1 : -1;
	return 0;
}

/* Bring (u, v) into the domain: wrap a seam direction; 1 when an open
 * direction is left. */
static int domain_fix(const struct ssurf *f, double *u, double *v)
{
	if (*u < f->u0 || *u > f->u1) {
		if (!f->wrap_u)
			return 1;
		*u = f->u0 + fmod(*u - f->u0, f->du);
		if (*u < f->u0)
			*u += f->du;
	}
	if (*v < f->v0 || *v > f->v1) {
		if (!f->wrap_v)
			return 1;
		*v = f->v0 + fmod(*v - f->v0, f->dv);
		if (*v < f->v0)
			*v += f->dv;
	}
	return 0;
}

static int has_pole(const struct ssurf *f)
{
	return f->pole[0] | f->pole[1] | f->pole[2] | f->pole[3];
}

/* Distance of (u, v) from the nearest collapsed edge, relative to the
 * domain (1 when none is nearer): below 1e-9, a zero of E there is the
 * pole, not an interior critical point (snewton() rejects it). */
static double pole_gap(const struct ssurf *f, double u, double v)
{
	return fmin(fmin(f->pole[0] ? u - f->u0 : f->du, f->pole[1] ? f->u1 - u : f->du) /
			    f->du,
		    fmin(f->pole[2] ? v - f->v0 : f->dv, f->pole[3] ? f->v1 - v : f->dv) /
			    f->dv);
}

/*
 * The Hessian at z far from singular: its eigenvalues within a factor 10
 * of each other in size. Newton then converges quadratically from a step
 * away, the error left O(step^2 / span) (a near-fold point, where one
 * eigenvalue goes to 0, converges linearly and a short step says
 * little); on a rational patch whose weights are far apart the
 * parametrization's own speed changes too fast for the constant to be
 * small (ST_QUICK_WRATIO).
 */
static inline int well_posed(const struct crit *z)
{
	double d = z->h11 - z->h22, tr = z->h11 + z->h22;
	double disc = sqrt(d * d + 4.0 * z->h12 * z->h12);
	double a = fabs(tr + disc), b = fabs(tr - disc);
	return a < b ? a >= 0.1 * b : b >= 0.1 * a;
}

/*
 * Newton on E = 0 with p fixed from z->u, z->v; steps clamped to lu, lv.
 * Returns 0 with z evaluated at the root, 1 on failure (no convergence,
 * singular Hessian, the domain left through an open edge).
 */
static int snewton(const struct ssurf *f, struct crit *z, px_vec3 p,
		   double lu, double lv, const struct scell *home)
{
	double tu = 1e-11 * f->du, tv = 1e-11 * f->dv;
	double qu = 1e-6 * f->du, qv = 1e-6 * f->dv;
	int k, outs = 0;
	for (k = 0; k < ST_NEWTON; k++) {
		struct px_nurbs_surf_derivs d;
		px_vec3 g;
		double det, su, sv;
		int tiny;
		if (domain_fix(f, &z->u, &z->v)) {
			/* an overshoot past an open edge: back onto it (a
			 * point just inside the edge is reached from there);
			 * pushing out again means the point has left */
			if (++outs > 2)
				return 1;
			z->u = fmin(fmax(z->u, f->u0 + 1e-9 * f->du), f->u1 - 1e-9 * f->du);
			z->v = fmin(fmax(z->v, f->v0 + 1e-9 * f->dv), f->v1 - 1e-9 * f->dv);
		}
		crit_eval_d(f, z, p, &g, &d);
		det = z->h11 * z->h22 - z->h12 * z->h12;
		if (has_pole(f)) {
			/* At a collapsed edge u = u0 the v-derivative vanishes,
			 * so (S - p) . Sv = 0 holds along the whole edge: a
			 * spurious root set that attracts Newton. Solve with
			 * that equation divided by the distance to the edge
			 * (regular there) and reject the edge itself (the pole
			 * is a candidate of its own). */
			double du0 = z->u - f->u0, du1 = f->u1 - z->u;
			double dv0 = z->v - f->v0, dv1 = f->v1 - z->v;
			double bu = 1.0, bup = 0.0, av = 1.0, avp = 0.0;
			double j11, j12, j21, j22, g1, g2, dj;
			if (f->pole[0] && f->pole[1]) {
				bu = 1.0 / (du0 * du1);
				bup = -(du1 - du0) * bu * bu;
			} else if (f->pole[0]) {
				bu = 1.0 / du0;
				bup = -bu * bu;
			} else if (f->pole[1]) {
				bu = 1.0 / du1;
				bup = bu * bu;
			}
			if (f->pole[2] && f->pole[3]) {
				av = 1.0 / (dv0 * dv1);
				avp = -(dv1 - dv0) * av * av;
			} else if (f->pole[2]) {
				av = 1.0 / dv0;
				avp = -av * av;
			} else if (f->pole[3]) {
				av = 1.0 / dv1;
				avp = av * av;
			}
			if (pole_gap(f, z->u, z->v) < 1e-9)
				return 1;
			g1 = g.x * av;
			g2 = g.y * bu;
			j11 = z->h11 * av;
			j12 = z->h12 * av + g.x * avp;
			j21 = z->h12 * bu + g.y * bup;
			j22 = z->h22 * bu;
			dj = j11 * j22 - j12 * j21;
			if (!(fabs(dj) > 0.0))
				return 1;
			su = -(j22 * g1 - j12 * g2) / dj;
			sv = -(-j21 * g1 + j11 * g2) / dj;
		} else {
			if (!(fabs(det) > 0.0))
				return 1;
			su = -(z->h22 * g.x - z->h12 * g.y) / det;
			sv = -(-z->h12 * g.x + z->h11 * g.y) / det;
		}
		if (!isfinite(su) || !isfinite(sv))
			return 1;
		if (fabs(su) <= tu && fabs(sv) <= tv) {
			z->type = crit_type(z);
			return 0;
		}
		tiny = fabs(su) <= qu && fabs(sv) <= qv;
		if ((tiny || (fabs(su) <= f->quick_u && fabs(sv) <= f->quick_v &&
			      (f->quick_loose || well_posed(z)))) &&
		    z->u + su >= f->u0 && z->u + su <= f->u1 && z->v + sv >= f->v0 &&
		    z->v + sv <= f->v1) {
			/* quadratic convergence: after this step the error is
			 * O(step^2), far below the tolerance; move the point by
			 * the second-order Taylor step instead of evaluating
			 * again. (To first order the point is off the surface by
			 * S'' step^2 / 2, along the normal, so straight into
			 * the distance: 3.7e-9 of it on the rational sheet's
			 * 5 % steps, over the 1e-9 the answers are held to;
			 * below 1e-6 of the domain the first order is enough.) */
			z->u += su;
			z->v += sv;
			z->s = px_v3_add(z->s, px_v3_add(px_v3_scale(z->su, su),
							 px_v3_scale(z->sv, sv)));
			if (!tiny)
				z->s = px_v3_add(z->s, px_v3_add(px_v3_scale(d.suu, 0.5 * su * su),
								 px_v3_add(px_v3_scale(d.suv, su * sv),
									   px_v3_scale(d.svv, 0.5 * sv * sv))));
			z->type = crit_type(z);
			return 0;
		}
		if (fabs(su) > lu)
			su = su > 0 ? lu : -lu;
		if (fabs(sv) > lv)
			sv = sv > 0 ? lv : -lv;
		z->u += su;
		z->v += sv;
		if (home) {
			/* a seed heading out of its cell (beyond one cell width)
			 * converges to a point its own cell answers for */
			double w = home->u1 - home->u0, h = home->v1 - home->v0;
			if (z->u < home->u0 - w || z->u > home->u1 + w ||
			    z->v < home->v0 - h || z->v > home->v1 + h)
				return 1;
		}
	}
	return 1;
}

/* ------------------------------------------------------------------ */
/* critical-point sets                                                 */

static int crit_dup(const struct ssurf *f, const struct crit *a,
		    const struct crit *b)
{
	double du = fabs(a->u - b->u), dv = fabs(a->v - b->v);
	if (f->wrap_u)
		du = fmin(du, f->du - du);
	if (f->wrap_v)
		dv = fmin(dv, f->dv - dv);
	return du <= 1e-7 * f->du && dv <= 1e-7 * f->dv;
}

/* Add z unless it duplicates a held point. Returns 1 added, 0 duplicate,
 * PX_E_NOSPC. */
static int crit_add(struct px_strack *t, struct ssurf *f, const struct crit *z)
{
	int i;
	for (i = 0; i < f->nz; i++)
		if (crit_dup(f, &f->z[i], z))
			return 0;
	if (f->nz >= f->cap)
		return PX_E_NOSPC;
	f->z[f->nz] = *z;
	if (!f->z[f->nz].id) {
		if (++t->next_id >= 0x7fffffffu)
			t->next_id = 1;
		f->z[f->nz].id = t->next_id;
	}
	f->nz++;
	return 1;
}

static int follow(const struct ssurf *f, struct crit *z, px_vec3 p0,
		  px_vec3 dp, px_vec3 p, struct crit *last);
static int region_empty(const struct px_strack *t, int ri, px_vec3 p);
static int no_root(const struct rcert *c, px_vec3 p);
static inline void hess_at(const struct rcert *c, px_vec3 p, double mid[3],
			   double rad[3]);
static int no_root_h(const struct rcert *c, px_vec3 p, const double mid[3],
		     const double rad[3]);
static int one_root_h(const double mid[3], const double rad[3]);
static int contract_h(const struct rcert *c, const double mid[3],
		      const double rad_in[3], double y[2][2], double *rho);
static int contract_rate(const struct rcert *c, px_vec3 p, double y[2][2],
			 double *rho);

/* 1 when f holds a point in the box b (u0, u1, v0, v1). */
static int holds(const struct ssurf *f, const double b[4])
{
	int i;
	for (i = 0; i < f->nz; i++)
		if (f->z[i].u >= b[0] && f->z[i].u <= b[1] && f->z[i].v >= b[2] &&
		    f->z[i].v <= b[3])
			return 1;
	return 0;
}

/* What a solve at p does in a box: nothing (proven to hold no
 * critical point, or none but a held one), contract_solve() (at most
 * one, found or proven absent), its seeds (not proven). */
enum { BOX_SEEDS = 0, BOX_DONE = 1, BOX_EXACT = 2 };

/* The work of box b (with certificate c) at p (known: the held set is at
 * p): done when proven free of critical points, or its Hessian enclosure
 * regular - at most one critical point in it - and a held point lies in
 * it, which is then the only one; exact when it holds none and the
 * contraction of contract_rate() runs on it. */
static int box_done(const struct ssurf *f, const struct rcert *c,
		    const double b[4], px_vec3 p, int known)
{
	double y[2][2], rho, mid[3], rad[3];
	int held;
	hess_at(c, p, mid, rad);
	if (no_root_h(c, p, mid, rad))
		return BOX_DONE;
	held = known && holds(f, b);
	if (held && one_root_h(mid, rad))
		return BOX_DONE;
	if (!contract_h(c, mid, rad, y, &rho))
		return BOX_SEEDS;
	return held ? BOX_DONE : BOX_EXACT;
}

/*
 * The work of cell solves, in ST_UNITS per full solve (every region and
 * quarter seeded): the checks of a cell's regions and quarters
 * (cell_done(); measured on the 16-patch bench surface: about 2,200
 * instructions) are one unit, each Newton run from a seed (about 7,500,
 * and 14,000 more where its root is followed) a share of the rest in
 * proportion to the seeds run. Budgets (max_solves) count full solves, so
 * a rebuild, mostly empty cells, takes a few updates instead of one per
 * max_solves / 2 cells, and a cell near a focal sheet, where only the
 * quarters the sheet passes through need seeds, costs a part of a solve:
 * a path hovering there would otherwise go over the budget every step,
 * by the checks of the hit cell's neighbours.
 */
#define ST_UNITS 8

/* The box (u0, u1, v0, v1) of cell g (k < 0) or of its quarter k (k & 1:
 * the upper half in u, k & 2: in v). */
static void box_of(const struct scell *g, int k, double b[4])
{
	double um = 0.5 * (g->u0 + g->u1), vm = 0.5 * (g->v0 + g->v1);
	b[0] = k >= 0 && (k & 1) ? um : g->u0;
	b[1] = k >= 0 && !(k & 1) ? um : g->u1;
	b[2] = k >= 0 && (k & 2) ? vm : g->v0;
	b[3] = k >= 0 && !(k & 2) ? vm : g->v1;
}

/* What the parts of a solve cell need (box_done(): BOX_DONE nothing,
 * BOX_EXACT contract_solve(), BOX_SEEDS seeds): region[ch] its region
 * cells (BOX_SEEDS: as its quarters say), quarter[ch][k] their quarters
 * (worked out only where the region's own test does not prove it
 * done). */
struct cell_done {
	int region[4];
	int quarter[4][4];
};

/* box_done() from the K of box b over the step that ends at the held
 * set's point (NAN: none worked out): 0, no critical point in it at any
 * point of the step, so none at its end; finite, H regular there
 * throughout, so at most one, the held one if any (without one the
 * box's own test is still to be made). */
static int speed_done(const struct ssurf *f, double k, const double b[4])
{
	return k == 0.0 || (k < INFINITY && holds(f, b));
}

/* cell_done for c at ps (known: the held set is at ps; a seed converges
 * to a point near it, so those parts give none): a region needs none
 * when its own test or each of its quarters' holds. Returns the
 * certificate tests made (none where a ring's K covers them). */
static int cell_done(const struct px_strack *t, const struct scell *c,
		     px_vec3 ps, int known, struct cell_done *d)
{
	const struct ssurf *f = &t->sf[c->surf];
	/* the ring's K hold for ps: the end of the step they were worked
	 * out for (speed_done()) */
	int sp = c->kmark == t->pend_epoch && t->pend_on && known &&
		 px_v3_dist2(ps, t->p) == 0.0;
	int ch, k, tests = 0, open, seeds;
	for (ch = 0; ch < 4; ch++) {
		int ri = c->child + ch;
		const struct scell *g = &t->rcell[ri];
		double b[4];
		box_of(g, -1, b);
		d->region[ch] = speed_done(f, sp ? c->kr[ch] : NAN, b);
		if (!d->region[ch]) {
			d->region[ch] = box_done(f, &g->cert, b, ps, known);
			tests++;
		}
		if (d->region[ch] == BOX_DONE)
			continue;
		open = seeds = 0;
		for (k = 0; k < 4; k++) {
			box_of(g, k, b);
			d->quarter[ch][k] = speed_done(f, sp ? c->kq[4 * ch + k] : NAN, b);
			if (!d->quarter[ch][k]) {
				d->quarter[ch][k] = box_done(f, &t->qcert[4 * ri + k], b, ps, known);
				tests++;
			}
			open += d->quarter[ch][k] != BOX_DONE;
			seeds += d->quarter[ch][k] == BOX_SEEDS;
		}
		/* the quarters' tests first (a few hundred instructions each,
		 * a contraction some thousands); the region's contraction
		 * where they leave seeds or more than one to solve */
		if (!open)
			d->region[ch] = BOX_DONE;
		else if (!(d->region[ch] == BOX_EXACT && (seeds || open > 1)))
			d->region[ch] = BOX_SEEDS;
	}
	return tests;
}

/* contract_solve()'s outcomes */
enum { CS_FOUND = 0, CS_EMPTY = 1, CS_OPEN = 2 };

/* 1 when z lies in box b, within Newton's tolerance. */
static int in_box(const struct ssurf *f, const struct crit *z, const double b[4])
{
	double tu = 1e-9 * f->du, tv = 1e-9 * f->dv;
	return z->u >= b[0] - tu && z->u <= b[1] + tu && z->v >= b[2] - tv &&
	       z->v <= b[3] + tv;
}

/*
 * The critical point of box b (certificate rc: contract_rate() holds) at
 * p, into z: x - Y E(x) iterated from the box's centre, each step put
 * back onto the box (clamping does not move a point away from one in the
 * box). If the box holds a point x*, |x_k - x*| <= rho^k (weighted norm,
 * the centre within 1 of anything in the box), so the k-th step
 * |g(x_k) - x_k| is at most (1 + rho) rho^k: a longer one proves the box
 * empty; a short one is the iteration converging, which Newton finishes
 * (within ST_POLISH). Returns CS_FOUND, CS_EMPTY, or CS_OPEN when
 * neither within ST_CONTRACT steps (rho near 1, or a point just outside
 * the box).
 */
static int contract_solve(const struct ssurf *f, const struct rcert *rc,
			  const double b[4], struct crit *z, px_vec3 p,
			  const struct scell *home)
{
	double y[2][2], rho, lim = 1.0, hu = 0.5 * (b[1] - b[0]),
	       hv = 0.5 * (b[3] - b[2]);
	int k, polish = 2;
	if (!contract_rate(rc, p, y, &rho) || px__strack_contract_fault == 2)
		return CS_OPEN;
	z->u = b[0] + hu;
	z->v = b[2] + hv;
	for (k = 0; k < ST_CONTRACT; k++) {
		px_vec3 g, w;
		double du, dv, pu, pv, pad, step, r, u = z->u, v = z->v;
		crit_eval(f, z, p, &g);
		w = px_v3_sub(z->s, p);
		/* E's rounding, as e_pad() */
		pad = ST_PAD *
		      (fabs(w.x) + fabs(w.y) + fabs(w.z) + fabs(p.x) + fabs(p.y) + fabs(p.z)) *
		      (fabs(z->su.x) + fabs(z->su.y) + fabs(z->su.z) + fabs(z->sv.x) +
		       fabs(z->sv.y) + fabs(z->sv.z));
		du = -(y[0][0] * g.x + y[0][1] * g.y);
		dv = -(y[1][0] * g.x + y[1][1] * g.y);
		pu = (fabs(y[0][0]) + fabs(y[0][1])) * pad;
		pv = (fabs(y[1][0]) + fabs(y[1][1])) * pad;
		step = fmax((fabs(du) - pu) / hu, (fabs(dv) - pv) / hv);
		if (step > (1.0 + rho) * (lim + 1e-9))
			return CS_EMPTY;
		/* a posteriori, from any x of the box: |x - x*| <= s / (1 - rho)
		 * with s = |g(x) - x|, so x* = g(x*) lies within rho s / (1 -
		 * rho) of g(x); outside the box there, none in it */
		r = fmax((fabs(du) + pu) / hu, (fabs(dv) + pv) / hv) / (1.0 - rho);
		if (fabs(u + du - (b[0] + hu)) - pu > hu * (1.0 + rho * r) * (1.0 + 1e-9) ||
		    fabs(v + dv - (b[2] + hv)) - pv > hv * (1.0 + rho * r) * (1.0 + 1e-9))
			return CS_EMPTY;
		/* the box's zero, within r of x, on a collapsed edge: the
		 * pole (a candidate of its own), no interior point */
		if (has_pole(f) && pole_gap(f, u, v) + r * fmax(hu / f->du, hv / f->dv) < 1e-9)
			return CS_EMPTY;
		if (fabs(du) <= ST_POLISH * hu && fabs(dv) <= ST_POLISH * hv && polish > 0) {
			/* twice at most: where Newton converges just outside the
			 * box, the iteration's growing bound proves it empty */
			polish--;
			if (!snewton(f, z, p, hu, hv, home) && in_box(f, z, b))
				return CS_FOUND;
			z->u = u;
			z->v = v;
		}
		z->u = fmin(fmax(u + du, b[0]), b[1]);
		z->v = fmin(fmax(v + dv, b[2]), b[3]);
		lim *= rho;
	}
	return CS_OPEN;
}

/* Newton from (u, v) of cell c at ps, or (rc not NULL) contract_solve()
 * of box b with certificate rc, the root followed to p and added.
 * Returns 0, 1 (contract_solve() undecided) or PX_E_NOSPC. */
static int seed_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		      double u, double v, px_vec3 ps, px_vec3 p,
		      const struct rcert *rc, const double b[4])
{
	struct crit z, last;
	int rc_;
	memset(&z, 0, sizeof(z));
	z.u = u;
	z.v = v;
	if (rc) {
		rc_ = contract_solve(f, rc, b, &z, ps, c);
		t->st.exact_solves++;
		t->st.exact_open += rc_ == CS_OPEN;
		if (rc_ != CS_FOUND)
			return rc_ == CS_OPEN;
	} else {
		t->st.seed_runs++;
		if (snewton(f, &z, ps, 0.5 * (c->u1 - c->u0), 0.5 * (c->v1 - c->v0), c))
			return 0;
	}
	if (px_v3_dist2(ps, p) != 0.0 &&
	    follow(f, &z, ps, px_v3_sub(p, ps), p, &last))
		return 0;
	if (t->fault_drop && t->pend_on && z.type == 1) {
		/* the fault: the point is lost, the step's finding it is
		 * not (as when a pair's other member is found) */
		t->ix_on = 1;
		return 0;
	}
	rc_ = crit_add(t, f, &z);
	if (rc_ < 0)
		return PX_E_NOSPC;
	/* a point found: the set's membership changed */
	t->ix_on |= rc_;
	return 0;
}

/*
 * The work of cell c's solve (done: cell_done() at the seed point): a
 * region or quarter proven to hold at most one point has its centre,
 * solved by contract_solve() (sk: 5 ch for region ch, 5 ch + 1 + k for
 * its quarter k); a quarter left open is cut into sub-boxes with
 * certificates of their own (sub_solve(); sk: ST_SK_SUB plus its number
 * as before). Puts up to 16 of them in sk; returns their count.
 */
#define ST_SK_SUB 32
static int cell_seeds(const struct cell_done *done, int *sk)
{
	int ch, k, ns = 0;
	for (ch = 0; ch < 4; ch++) {
		const int *qe = done->quarter[ch];
		if (done->region[ch] == BOX_DONE)
			continue;
		if (done->region[ch] == BOX_EXACT) {
			sk[ns++] = 5 * ch;
			continue;
		}
		for (k = 0; k < 4; k++) {
			if (qe[k] == BOX_DONE)
				continue;
			sk[ns++] = (qe[k] == BOX_EXACT ? 0 : ST_SK_SUB) + 5 * ch + 1 + k;
		}
	}
	return ns;
}

/* Room for cell_seeds(): every quarter of the four regions. */
#define ST_SEEDS_MAX 16

/* The units of a solve running ns seeds: 1 for the checks, rounded up
 * to ST_UNITS for a full one. */
static int solve_units(const struct px_strack *t, int ns)
{
	return 1 + (ns * (ST_UNITS - 1) + t->full_seeds - 1) / t->full_seeds;
}

/* ------------------------------------------------------------------ */
/* run-time subdivision of the boxes the setup certificates leave open */

static void taylor_cert(const struct ssurf *f, const double b[4],
			const struct rcert *top, struct rcert *ce);

/* Test hook (internal.h): 1 leaves every open box uncut (Newton from
 * its centre, as before the cuts). */
int px__strack_sub_fault = 0;

/* Levels of sub-boxes below a region's quarter (or a box whose
 * contraction stayed undecided): 4 + 16 certificates at most each. */
#define ST_SUB_DEPTH 2

/* Quarter k of box b into q (k & 1: upper half in u, k & 2: in v). */
static void box_quarter(const double b[4], int k, double q[4])
{
	double um = 0.5 * (b[0] + b[1]), vm = 0.5 * (b[2] + b[3]);
	q[0] = (k & 1) ? um : b[0];
	q[1] = (k & 1) ? b[1] : um;
	q[2] = (k & 2) ? vm : b[2];
	q[3] = (k & 2) ? b[3] : vm;
}

static int seed_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		      double u, double v, px_vec3 ps, px_vec3 p,
		      const struct rcert *rc, const double b[4]);

/* The work of a solve in sixteenths of a seed's run: a certificate
 * made at update time (taylor_cert()) and its tests cost about 3/16 of
 * one (measured on the 16-patch bench surface: 3,500 instructions,
 * against 17,000 for a seed's Newton run with the following of its
 * root). */
#define ST_SUB_CERT 3
#define ST_SUB_SEED 16

/*
 * Box b of cell c, left open by the certificates it has (setup's, top,
 * or a contraction that stayed undecided), at ps (roots followed to p):
 * its quarters get certificates of their own (taylor_cert() from top's
 * third-derivative bounds; about half as wide) and are each done
 * (proven empty, or holding a held point and no other), solved exactly
 * (contract_solve()) or cut again, down to ST_SUB_DEPTH levels below
 * the box; a piece still open there, or where the solve's allowance
 * (t->sub_left) has no room for another cut, gets Newton from its
 * centre. t->sub_work holds the work made or reserved:
 * every open piece holds one seed's worth (the box's own is in it when
 * this is called), a cut reserves its four certificates and a seed for
 * each quarter and gives back what a quarter proven done does not use.
 * The held set counts where it is at ps. Returns 0 or PX_E_NOSPC.
 */
static int sub_solve(struct px_strack *t, struct ssurf *f, const struct scell *c,
		     const struct rcert *top, const double b[4], int depth, px_vec3 ps,
		     px_vec3 p, int top_id, int k1)
{
	int known = px_v3_dist2(ps, p) == 0.0, k, r,
	    cut = 4 * ST_SUB_CERT + 3 * ST_SUB_SEED;
	if (depth > ST_SUB_DEPTH || t->sub_work + cut > t->sub_left ||
	    px__strack_sub_fault) {
		t->st.sub_open++;
		return seed_solve(t, f, c, 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), ps, p,
				  NULL, b);
	}
	t->sub_work += cut;
	for (k = 0; k < 4; k++) {
		struct rcert own, *rcp = &own;
		double sb[4];
		int w;
		box_quarter(b, k, sb);
		if (t->scache_n > 0 && top_id >= 0 && depth <= 2) {
			/* (two levels a slot: ST_SUB_DEPTH's) */
			/* made before (the point does not enter a certificate) */
			const int key = 4 * top_id + (depth == 1 ? k : k1),
				  slot = depth == 1 ? 0 : 1 + k;
			struct scache *e = &t->scache[key & (t->scache_n - 1)];
			if (e->key != key) {
				e->key = key;
				e->filled = 0;
			}
			rcp = &e->rc[slot];
			if (!(e->filled & (1u << slot))) {
				taylor_cert(f, sb, top, rcp);
				e->filled |= 1u << slot;
			}
		} else
			taylor_cert(f, sb, top, rcp);
		t->st.sub_boxes++;
		w = box_done(f, rcp, sb, ps, known);
		if (w == BOX_DONE) {
			t->sub_work -= ST_SUB_SEED;
			continue;
		}
		/* a contraction takes the piece's seed; undecided (rare:
		 * none in the tests), the piece goes on as an open one */
		r = w == BOX_EXACT ? seed_solve(t, f, c, 0.0, 0.0, ps, p, rcp, sb) : 1;
		if (r == 1)
			r = sub_solve(t, f, c, top, sb, depth + 1, ps, p, top_id,
				      depth == 1 ? k : k1);
		if (r < 0)
			return r;
	}
	return 0;
}

/* The ns items of cell_seeds() for cell c at ps, each root found then
 * followed from ps to p (a pair born where the path met the cell's
 * region keeps moving for the rest of the step, possibly out of the
 * cell); t->sub_work the subdivisions' work. Returns 0 or PX_E_NOSPC. */
static int seeds_run(struct px_strack *t, const struct scell *c, px_vec3 ps,
		     px_vec3 p, const int *sk, int ns)
{
	struct ssurf *f = &t->sf[c->surf];
	int i, rc;
	t->st.cell_solves++;
	/* every item holds one seed's worth; sub_solve() adds its cuts */
	t->sub_work = ns * ST_SUB_SEED;
	for (i = 0; i < ns; i++) {
		int n = sk[i] % ST_SK_SUB, ri = c->child + n / 5, q = n % 5 - 1;
		const struct rcert *xc = q < 0 ? &t->rcell[ri].cert : &t->qcert[4 * ri + q];
		double b[4];
		box_of(&t->rcell[ri], q, b);
		rc = 1;
		if (sk[i] < ST_SK_SUB)
			rc = seed_solve(t, f, c, 0.0, 0.0, ps, p, xc, b);
		/* open, or its contraction undecided: cut into sub-boxes */
		if (rc == 1)
			rc = sub_solve(t, f, c, xc, b, 1, ps, p, 5 * ri + q + 1, -1);
		if (rc < 0)
			return rc;
	}
	return 0;
}

/* Solve cell c at p from its seeds (cell_seeds()); the held set is at p
 * (every caller), so a region or quarter holding one of its points
 * needs no seeds if it can hold only one. Returns 0 or PX_E_NOSPC. */
static int cell_solve(struct px_strack *t, const struct scell *c, px_vec3 p)
{
	struct cell_done done;
	int sk[ST_SEEDS_MAX];
	cell_done(t, c, p, 1, &done);
	t->sub_left = INT_MAX / 2;
	return seeds_run(t, c, p, p, sk, cell_seeds(&done, sk));
}

/* Solve c at ps (roots followed to p) if its work fits: *units grows by
 * the cost (solve_units()) unless that passes lim (lim <= 0: no bound).
 * Returns 0 solved, 1 left for later (nothing done), PX_E_NOSPC. */
static int cell_solve_budget(struct px_strack *t, const struct scell *c,
			     px_vec3 ps, px_vec3 p, int *units, int lim)
{
	struct cell_done done;
	int sk[ST_SEEDS_MAX];
	int ns, cost, rc, more, tests = cell_done(t, c, ps, px_v3_dist2(ps, p) == 0.0, &done);
	ns = cell_seeds(&done, sk);
	/* the checks' unit only where they were made */
	cost = solve_units(t, ns) - (tests == 0);
	if (lim > 0 && *units > 0 && *units + cost > lim)
		return 1;
	*units += cost;
	/* the cuts of open boxes may use what the bound leaves (m more
	 * seeds cost at most ceil(7 m / full_seeds) units more), up to
	 * half a full solve more: a cell's cuts must not take the work of
	 * the other cells of the step (they would wait, the set lagging) */
	more = lim > 0 ? (lim - *units) * t->full_seeds / (ST_UNITS - 1) : INT_MAX / 64;
	if (more > t->full_seeds / 2)
		more = t->full_seeds / 2;
	t->sub_left = ST_SUB_SEED * (ns + more);
	rc = seeds_run(t, c, ps, p, sk, ns);
	/* the sub-boxes' work past the one seed each item was counted as
	 * (bounded: ST_SUB_DEPTH levels) */
	more = (t->sub_work + ST_SUB_SEED - 1) / ST_SUB_SEED - ns;
	if (more > 0)
		*units += solve_units(t, ns + more) - solve_units(t, ns);
	return rc;
}

static int surf_reinit(struct px_strack *t, struct ssurf *f, int si, px_vec3 p)
{
	int c, rc;
	f->nz = 0;
	for (c = 0; c < f->ncu * f->ncv; c++) {
		const struct scell *cl = &t->cell[f->first_cell + c];
		if (cl->surf != si)
			continue;
		rc = cell_solve(t, cl, p);
		if (rc)
			return rc;
	}
	return 0;
}

/* ------------------------------------------------------------------ */
/* transition boxes: lazy tests                                        */

static struct iv iv_mul(struct iv a, struct iv b)
{
	double p1 = a.lo * b.lo, p2 = a.lo * b.hi, p3 = a.hi * b.lo,
	       p4 = a.hi * b.hi;
	struct iv r;
	/* (no NaN here: plain comparisons, as fmin and fmax would give) */
	r.lo = p1 < p2 ? p1 : p2;
	r.lo = p3 < r.lo ? p3 : r.lo;
	r.lo = p4 < r.lo ? p4 : r.lo;
	r.hi = p1 > p2 ? p1 : p2;
	r.hi = p3 > r.hi ? p3 : r.hi;
	r.hi = p4 > r.hi ? p4 : r.hi;
	return r;
}

static double iv_mag(struct iv a)
{
	return fmax(fabs(a.lo), fabs(a.hi));
}

/*
 * Certified radius of a region cell at p: no transition of the cell
 * happens while the point stays in the cube |x - p|_inf <= r. A pair of
 * critical points is born or dies only at a degenerate critical point,
 * E = 0 and det H = 0 (the focal sheets, Seong-Johnson-Cohen section
 * 4.3), and a point enters or leaves only through a side that is an open
 * edge or a crease. For x in the cube and (u, v) in the cell:
 *  - H_ij = Si.Sj + (S - x).Sij lies in [H_ij(p)] + [-r m_ij, r m_ij];
 *  - E(u, v; x) lies in E(c; p) +- r |Su(c)|_1 + [H] * (cell half
 *    widths) (mean value form about the centre c, dE/du = (H11, H12)).
 * The cell is safe when E1 or E2 keeps its sign (no critical point at
 * all), or when det H keeps its sign (no degenerate one: the points only
 * move) and on every open side E1 or E2 keeps its sign. Each condition
 * is monotone in r; the radius is the largest r that keeps one of them
 * (closed forms: linear in r for E, quadratic for det H). Curvatures are
 * never divided by, so parabolic lines and umbilics need no care.
 */
#define ST_MIN(a, b) ((a) < (b) ? (a) : (b))
#define ST_MAX(a, b) ((a) > (b) ? (a) : (b))

/* Test hook (internal.h): 0 leaves the preconditioned test out, 2 drops
 * its remainder terms (unsound). */
int px__strack_precond = 1;

/* Y, the inverse of the symmetric mid (entries 11, 12, 22), and
 * q = |I - Y mid| (zero but for rounding; padded by the rounding of the
 * products): the preconditioner of the Krawczyk tests. 0 when mid is
 * singular. */
static int precond(const double mid[3], double y[2][2], double q[2][2])
{
	double det = mid[0] * mid[2] - mid[1] * mid[1];
	if (!(fabs(det) > 0.0))
		return 0;
	y[0][0] = mid[2] / det;
	y[0][1] = y[1][0] = -mid[1] / det;
	y[1][1] = mid[0] / det;
	if (!(isfinite(y[0][0]) && isfinite(y[0][1]) && isfinite(y[1][1])))
		return 0;
	q[0][0] = fabs(1.0 - (y[0][0] * mid[0] + y[0][1] * mid[1])) + 1e-12;
	q[0][1] = fabs(y[0][0] * mid[1] + y[0][1] * mid[2]) + 1e-12;
	q[1][0] = fabs(y[1][0] * mid[0] + y[1][1] * mid[1]) + 1e-12;
	q[1][1] = fabs(1.0 - (y[1][0] * mid[1] + y[1][1] * mid[2])) + 1e-12;
	return 1;
}

/*
 * The E test preconditioned (Krawczyk's exclusion): by the mean value
 * theorem E(c + d) = E(c) + J d, each row of J the Hessian's at some point
 * of the cell, so a zero at c + d gives d = -Y E(c) + (I - Y J) d for any
 * Y; with Y the inverse of the midpoint of the Hessian's enclosure, a row
 * i with |(Y E(c))_i| > h_i + sum_j |I - Y J|_ij h_j proves there is none.
 * Unlike the plain test this sees where Newton from the centre would go:
 * a cell beside a critical point (its E small in both components, the
 * point just across a side) is proven empty when the step leads out of
 * it. For x in the cube of radius r about p, E(c) moves by r |Su(c)|_1
 * (resp. Sv) and J by r m_ij, so each row's test is linear in r: the
 * largest r that keeps one of them. mid and rad: the Hessian enclosure
 * at p (rad with its rounding pad), e1, e2: E(c) at p (signed), epad
 * their rounding.
 */
static double pre_radius(const struct rcert *c, const double mid[3],
			 const double rad_in[3], double e1, double e2, double epad)
{
	double y[2][2], q[2][2], best = 0.0;
	double rad[3] = {rad_in[0], rad_in[1], rad_in[2]};
	int i;
	if (!px__strack_precond || !precond(mid, y, q))
		return 0.0;
	if (px__strack_precond == 2)
		rad[0] = rad[1] = rad[2] = 0.0;
	for (i = 0; i < 2; i++) {
		double a = fabs(y[i][0]), b = fabs(y[i][1]);
		double ye = y[i][0] * e1 + y[i][1] * e2;
		double num = fabs(ye) - (a + b) * epad -
			     ST_PAD * (a * fabs(e1) + b * fabs(e2)) -
			     (i ? c->hv : c->hu) -
			     c->hu * (q[i][0] + a * rad[0] + b * rad[1]) -
			     c->hv * (q[i][1] + a * rad[1] + b * rad[2]);
		double den = a * c->n1 + b * c->n2 +
			     c->hu * (a * c->m11 + b * c->m12) +
			     c->hv * (a * c->m12 + b * c->m22);
		double r = num / den;
		if (r > best)
			best = r;
	}
	return best;
}

/* The Hessian's enclosure over the cell for the point p, midpoint and
 * radius (entries 11, 12, 22), the radius padded for rounding. Inline:
 * cert_radius() runs in every cell test. */
static inline void hess_at(const struct rcert *c, px_vec3 p, double mid[3],
			   double rad[3])
{
	double pad;
	px_vec3 aw;
	int k;
	aw = px_v3_sub(c->smid, p);
	aw = px_v3(fabs(aw.x), fabs(aw.y), fabs(aw.z));
	for (k = 0; k < 3; k++) {
		mid[k] = c->A[k] - px_v3_dot(p, c->B[k]);
		rad[k] = c->R[k] + px_v3_dot(aw, c->Q[k]);
	}
	pad = ST_PAD * (fabs(mid[0]) + fabs(mid[1]) + fabs(mid[2]) + rad[0] +
			rad[1] + rad[2] +
			(aw.x + aw.y + aw.z + fabs(p.x) + fabs(p.y) + fabs(p.z)) *
				(c->m11 + c->m12 + c->m22));
	for (k = 0; k < 3; k++)
		rad[k] += pad;
}

/* Rounding pad of E's components, w = S - p at the point where they
 * are taken, for certificate c. */
static inline double e_pad(const struct rcert *c, px_vec3 w, px_vec3 p)
{
	return ST_PAD *
	       (fabs(w.x) + fabs(w.y) + fabs(w.z) + fabs(p.x) + fabs(p.y) + fabs(p.z)) *
	       (c->n1 + c->n2);
}

/* Open side sd, w = S - p at its centre, M11, M12, M22 bounds of |H|
 * over the cell: num[i] > 0 proves Ei keeps its sign along the side at
 * p (mean value form along it); cert_radius() divides it by the rate at
 * which it falls as the point moves. */
static inline void side_num(const struct cside *sd, px_vec3 w, double epad,
			    double M11, double M12, double M22, double num[2])
{
	num[0] = fabs(px_v3_dot(w, sd->su)) - epad - (sd->along ? M12 : M11) * sd->h;
	num[1] = fabs(px_v3_dot(w, sd->sv)) - epad - (sd->along ? M22 : M12) * sd->h;
}

/* The E test of cert_radius(): the largest r that keeps E1 or E2 of one
 * sign over the cell for every x in the cube of half width r about p,
 * e1, e2 (padded by epad) E at the cell's centre and M11, M12, M22
 * bounds of |H| over the cell at p (0 when none). Inline, as hess_at():
 * every cell test runs it. */
static inline double e_radius(const struct rcert *c, double M11, double M12,
			      double M22, double e1, double e2, double epad)
{
	double r1 = (fabs(e1) - epad - M11 * c->hu - M12 * c->hv) * c->ie1;
	double r2 = (fabs(e2) - epad - M12 * c->hu - M22 * c->hv) * c->ie2;
	double r = r1 > r2 ? r1 : r2;
	return r > 0.0 ? r : 0.0;
}

static double cert_radius(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3], a11, b11, a22, b22, M11, M12, M22,
	       m11 = c->m11, m12 = c->m12, m22 = c->m22, rE, rD, r, e1, e2, epad;
	px_vec3 w;
	int k;
	hess_at(c, p, mid, rad);
	a11 = mid[0] - rad[0];
	b11 = mid[0] + rad[0];
	a22 = mid[2] - rad[2];
	b22 = mid[2] + rad[2];
	M11 = fabs(mid[0]) + rad[0];
	M12 = fabs(mid[1]) + rad[1];
	M22 = fabs(mid[2]) + rad[2];
	/* E test */
	w = px_v3_sub(c->sc, p);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, p);
	rE = e_radius(c, M11, M12, M22, e1, e2, epad);
	/* det H test */
	rD = 0.0;
	{
		double x = 0.0, y = 0.0;
		int definite = 0;
		if (a11 > 0.0 && a22 > 0.0) {
			x = a11;
			y = a22;
			definite = 1;
		} else if (b11 < 0.0 && b22 < 0.0) {
			x = -b11;
			y = -b22;
			definite = 1;
		} else if (a11 > 0.0 && b22 < 0.0) {
			rD = ST_MIN(a11 * c->im11, -b22 * c->im22);
		} else if (b11 < 0.0 && a22 > 0.0) {
			rD = ST_MIN(-b11 * c->im11, a22 * c->im22);
		}
		if (definite) {
			/* f(r) = (x - r m11)(y - r m22) - (M12 + r m12)^2 falls
			 * on [0, min(x / m11, y / m22)]: its first root */
			double A = m11 * m22 - m12 * m12;
			double B = -(x * m22 + y * m11) - 2.0 * M12 * m12;
			double C = x * y - M12 * M12;
			double cap = ST_MIN(x * c->im11, y * c->im22);
			if (C > 0.0) {
				double disc = B * B - 4.0 * A * C;
				double root = disc < 0.0 ? INFINITY
							 : 2.0 * C / (-B + sqrt(disc));
				rD = ST_MIN(cap, root);
			}
		}
		if (!(rD > 0.0))
			rD = 0.0;
	}
	if (!(rE > 0.0) && !(rD > 0.0)) {
		/* neither: the preconditioned E test (costs as much again,
		 * so only here) */
		rE = pre_radius(c, mid, rad, e1, e2, epad);
	}
	for (k = 0; k < c->nside && rD > rE; k++) {
		/* open side: E restricted to it, mean value form along it */
		const struct cside *sd = &c->side[k];
		double q1 = sd->along ? m12 : m11, q2 = sd->along ? m22 : m12;
		double num[2], r1, r2;
		side_num(sd, px_v3_sub(sd->s, p), epad, M11, M12, M22, num);
		r1 = num[0] / (sd->n1 + q1 * sd->h);
		r2 = num[1] / (sd->n2 + q2 * sd->h);
		r1 = r1 > r2 ? r1 : r2;
		r1 = r1 > 0.0 ? r1 : 0.0;
		rD = ST_MIN(rD, r1);
	}
	r = (rE > rD ? rE : rD) * ST_RSAFE;
	return r > 0.0 ? r : 0.0;
}

/* 1 when E is proven not to vanish on the cell for the point p: no
 * critical point there (the E tests of cert_radius() at r = 0); mid and
 * rad: hess_at() at p. */
static int no_root_h(const struct rcert *c, px_vec3 p, const double mid[3],
		     const double rad[3])
{
	double mag[3], e1, e2, epad;
	px_vec3 w;
	int k;
	for (k = 0; k < 3; k++)
		mag[k] = fabs(mid[k]) + rad[k];
	w = px_v3_sub(c->sc, p);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, p);
	return fabs(e1) - epad > mag[0] * c->hu + mag[1] * c->hv ||
	       fabs(e2) - epad > mag[1] * c->hu + mag[2] * c->hv ||
	       pre_radius(c, mid, rad, e1, e2, epad) > 0.0;
}

static int no_root(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return no_root_h(c, p, mid, rad);
}

/*
 * 1 when every symmetric matrix with entries 11, 12, 22 in [lo, hi] is
 * regular, and then (sig not NULL) a lower bound on the absolute values
 * of their eigenvalues into *sig. Definite (h11 h22 > h12^2 throughout,
 * the product rounded down): the least eigenvalue grows with the
 * diagonal and falls with |h12|, so the corner bounds it (the product
 * form avoids the cancellation of (x + y) / 2 - root); h11 h22 < 0 <=
 * h12^2: both |eigenvalues| are at least the lesser |diagonal|.
 */
static int sym_regular(const double lo[3], const double hi[3], double *sig)
{
	double b = fmax(fabs(lo[1]), fabs(hi[1])), x, y, det;
	if ((lo[0] > 0.0 && lo[2] > 0.0) || (hi[0] < 0.0 && hi[2] < 0.0)) {
		x = lo[0] > 0.0 ? lo[0] : -hi[0];
		y = lo[0] > 0.0 ? lo[2] : -hi[2];
		det = x * y * (1.0 - 1e-12) - b * b;
		if (!(det > 0.0))
			return 0;
		if (sig)
			*sig = det / (0.5 * (x + y) + hypot(0.5 * (x - y), b));
		return 1;
	}
	if (lo[0] > 0.0 && hi[2] < 0.0) {
		if (sig)
			*sig = fmin(lo[0], -hi[2]);
		return 1;
	}
	if (hi[0] < 0.0 && lo[2] > 0.0) {
		if (sig)
			*sig = fmin(-hi[0], lo[2]);
		return 1;
	}
	return 0;
}

/* Test hook (internal.h): 1 drops the Hessian enclosure's radius from
 * one_root() (unsound: its test must see it). */
int px__strack_one_fault = 0;

/*
 * 1 when every symmetric matrix in the Hessian's enclosure over the cell
 * at p is regular (the det H test of cert_radius() at r = 0): then the
 * cell holds at most one critical point, since E(a) - E(b) = M (a - b)
 * with M the Hessian averaged along the segment, a matrix of the
 * enclosure. mid, rad: hess_at() at p.
 */
static int one_root_h(const double mid[3], const double rad[3])
{
	double lo[3], hi[3];
	int k;
	for (k = 0; k < 3; k++) {
		double r = px__strack_one_fault ? 0.0 : rad[k];
		lo[k] = mid[k] - r;
		hi[k] = mid[k] + r;
	}
	return sym_regular(lo, hi, NULL);
}

static int one_root(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return one_root_h(mid, rad);
}

/* Test hook (internal.h): 1 drops the Hessian enclosure's radius from
 * contract_rate() (unsound: its test must see it); 2 leaves every
 * contract_solve() undecided. */
int px__strack_contract_fault = 0;

/*
 * 1 when x - Y E(x), Y the inverse of the Hessian enclosure's midpoint,
 * contracts the cell at p (Krawczyk): by the mean value theorem
 * g(x) - g(x') = (I - Y J)(x - x') with the rows of J in the enclosure,
 * so in the norm weighted by the half widths the map shrinks distances
 * by rho = max_i sum_j |I - Y [H]|_ij h_j / h_i, into *rho, when that is
 * below 1. Every matrix of the enclosure is then regular: the cell holds
 * at most one critical point, and contract_solve() finds it or proves
 * there is none. mid, rad: hess_at() at p.
 */
static int contract_h(const struct rcert *c, const double mid[3],
		      const double rad_in[3], double y[2][2], double *rho)
{
	double rad[3] = {rad_in[0], rad_in[1], rad_in[2]}, q[2][2], worst = 0.0;
	int i;
	if (px__strack_contract_fault)
		rad[0] = rad[1] = rad[2] = 0.0;
	if (!precond(mid, y, q))
		return 0;
	for (i = 0; i < 2; i++) {
		double a = fabs(y[i][0]), b = fabs(y[i][1]);
		double spread = c->hu * (q[i][0] + a * rad[0] + b * rad[1]) +
				c->hv * (q[i][1] + a * rad[1] + b * rad[2]);
		worst = fmax(worst, spread / (i ? c->hv : c->hu));
	}
	*rho = worst;
	return worst < ST_RHO_MAX;
}

static int contract_rate(const struct rcert *c, px_vec3 p, double y[2][2],
			 double *rho)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return contract_h(c, mid, rad, y, rho);
}

/* Test hook (internal.h): a factor on every certified radius. */
double px__strack_radius_scale = 1.0;

static void sides_open(const struct ssurf *f, const struct scell *c, int open[4]);
static void cert_sides(const struct ssurf *f, const struct scell *c, struct rcert *ce,
		       const int side_open[4]);
static void box_quarter(const double b[4], int k, double q[4]);

/* Test hook (internal.h): 1 makes the curve tracker's certificate
 * (ct_note()) unbounded (unsound: a curve that comes nearer is missed). */
int px__strack_ct_fault = 0;

/* Test hook (internal.h): 1 leaves the pieces out of the radii
 * (region_radius_full(), cell_radius()). */
int px__strack_piece_fault = 0;

/*
 * Certified radius at p of piece b of surface s, its certificate made as
 * a cut's (taylor_cert() from top, the certificate of a box holding it)
 * with the side tests of the open sides it lies on. The union argument
 * of region_radius() holds for the pieces as for quarters (pieces of a
 * second level gained nothing on the rational bench model).
 */
static double piece_radius(const struct px_strack *t, int s, const struct rcert *top,
			   const double b[4], px_vec3 p, int key, int j)
{
	const struct ssurf *f = &t->sf[s];
	struct rcert own, *rcp = &own;
	struct scell pc;
	int open[4];
	if (t->pcache_n > 0) {
		struct pcache *e = &t->pcache[key & (t->pcache_n - 1)];
		if (e->key != key) {
			e->key = key;
			e->filled = 0;
		}
		if (e->filled & (1u << j))
			return cert_radius(&e->rc[j], p);
		e->filled |= 1u << j; /* (made below) */
		rcp = &e->rc[j];
	}
	memset(&pc, 0, sizeof(pc));
	pc.surf = s;
	pc.u0 = b[0];
	pc.u1 = b[1];
	pc.v0 = b[2];
	pc.v1 = b[3];
	taylor_cert(f, b, top, rcp);
	sides_open(f, &pc, open);
	cert_sides(f, &pc, rcp, open);
	return cert_radius(rcp, p);
}

/*
 * The radius of a rational region whose quarters left it none: each
 * quarter without a radius stands for by its four pieces'
 * (piece_radius()). Where the parametrization varies fast, as at a
 * corner with weights far apart, a quarter's enclosures are too wide
 * ever to hold, and its cell would be due, tested and solved in every
 * update. On polynomial patches the pieces seldom hold where the
 * quarter does not (near a focal sheet) and cost 4 % of the
 * instructions of the 16-patch bench paths: not used there.
 */
static double region_pieces(const struct px_strack *t, int ri, px_vec3 p)
{
	const struct scell *g = &t->rcell[ri];
	double r = INFINITY;
	int k, j;
	for (k = 0; k < 4 && r > 0.0; k++) {
		const struct rcert *q = &t->qcert[4 * ri + k];
		double b[4], sb[4], rq = cert_radius(q, p);
		if (!(rq > 0.0)) {
			box_of(g, k, b);
			rq = INFINITY;
			for (j = 0; j < 4 && rq > 0.0; j++) {
				box_quarter(b, j, sb);
				rq = fmin(rq, piece_radius(t, g->surf, q, sb, p, 4 * ri + k, j));
			}
		}
		r = fmin(r, rq);
	}
	return r;
}

/*
 * Certified radius of region cell ri at p; where its own certificate
 * gives none, or less than need, the least of its quarters' (each
 * quarter free of degenerate critical points, or of any, and the open
 * sides kept: so is their union, the interior sides between them being
 * no way in or out).
 */
static double region_radius_to(const struct px_strack *t, int ri, px_vec3 p,
			       double need)
{
	/* (cert_radius() is never negative: none is r == 0) */
	double r = cert_radius(&t->rcell[ri].cert, p);
	if (!(r > 0.0) || r < need) {
		/* the quarters' enclosures are about half as wide, and their
		 * least radius is as good a proof for the region (the larger
		 * of the two stands); the loop stops once it cannot be */
		const struct rcert *q = &t->qcert[4 * ri];
		double rq = INFINITY;
		int k;
		for (k = 0; k < 4 && rq > r; k++)
			rq = fmin(rq, cert_radius(&q[k], p));
		if (rq > r)
			r = rq;
	}
	return r * px__strack_radius_scale;
}

static double region_radius(const struct px_strack *t, int ri, px_vec3 p)
{
	return region_radius_to(t, ri, p, 0.0);
}

/* region_radius() with the pieces of a rational region's quarters that
 * have none (region_pieces()). */
static double region_radius_full(const struct px_strack *t, int ri, px_vec3 p)
{
	double r = region_radius(t, ri, p);
	if (!(r > 0.0) && t->rcell[ri].cert.rat && !px__strack_piece_fault)
		r = region_pieces(t, ri, p) * px__strack_radius_scale;
	return r;
}

/* 1 when region ri holds no critical point for p (its own E tests, or
 * each of its quarters'). */
static int region_empty(const struct px_strack *t, int ri, px_vec3 p)
{
	const struct rcert *q = &t->qcert[4 * ri];
	return no_root(&t->rcell[ri].cert, p) ||
	       (no_root(&q[0], p) && no_root(&q[1], p) && no_root(&q[2], p) &&
		no_root(&q[3], p));
}

/* ... and of a solve cell: its children's regions cover all of it. */
static __attribute__((noinline)) double cell_pieces(const struct px_strack *t,
						    const struct scell *c, px_vec3 p, double r0,
						    double r1, double r2, double r3);

static double cell_radius_to(const struct px_strack *t, const struct scell *c,
			     px_vec3 p, double need)
{
	int ri = c->child;
	double r0 = region_radius_to(t, ri, p, need),
	       r1 = region_radius_to(t, ri + 1, p, need),
	       r2 = region_radius_to(t, ri + 2, p, need),
	       r3 = region_radius_to(t, ri + 3, p, need);
	double r = fmin(fmin(r0, r1), fmin(r2, r3));
	/* rational: quarters without a radius by their pieces (rarely run:
	 * out of line, so that the usual test stays as lean as it was) */
	if (!(r > 0.0) && t->rcell[ri].cert.rat && !px__strack_piece_fault)
		r = cell_pieces(t, c, p, r0, r1, r2, r3);
	return r;
}

static double cell_radius(const struct px_strack *t, const struct scell *c,
			  px_vec3 p)
{
	return cell_radius_to(t, c, p, 0.0);
}

/* cell_radius() where a region's radius (r0..r3) is none: by the
 * pieces of its quarters (the others as they were). */
static __attribute__((noinline)) double cell_pieces(const struct px_strack *t,
						    const struct scell *c, px_vec3 p, double r0,
						    double r1, double r2, double r3)
{
	const double r[4] = {r0, r1, r2, r3};
	double m = INFINITY;
	int i;
	for (i = 0; i < 4; i++)
		m = fmin(m, r[i] > 0.0 ? r[i]
				       : region_pieces(t, c->child + i, p) * px__strack_radius_scale);
	return m;
}

/*
 * Index check. A critical point's index is the sign of det H (+1 a
 * minimum or maximum, -1 a saddle), and by degree theory the index sum
 * of the critical points in the domain equals the winding number of
 * E = (E1, E2) along the domain's boundary (Poincare-Hopf for the plane;
 * a wrapped direction's seam sides cancel). Births and deaths keep the
 * sum, a point crossing an open edge changes it and the winding number
 * with it. A tracked set whose index sum differs from the winding number
 * is incomplete: a point a cell's seed grid missed, or a point followed
 * onto another's branch. It sees every miss whose indices do not
 * cancel, never a missing pair of a saddle and a minimum or maximum (the
 * escape bound keeps pairs from being carried out of the solved cells).
 *
 * The winding number is exact when each boundary side keeps E in an open
 * half plane (E1 or E2 of one sign on it: the open-side test of the
 * certificates): then the angle turned along the side is the principal
 * angle between its end values. Sides whose test fails are split into
 * their quarters' sides; when one of those fails too the winding number
 * is not known at p.
 */

/* Sign test of open side entry k of certificate c at p: 1 when E1 or E2
 * keeps its sign on the side. */
static int side_keeps(const struct rcert *c, int k, px_vec3 p)
{
	const struct cside *sd = &c->side[k];
	double mid[3], rad[3], num[2];
	px_vec3 w = px_v3_sub(sd->s, p);
	hess_at(c, p, mid, rad);
	side_num(sd, w, e_pad(c, w, p), fabs(mid[0]) + rad[0], fabs(mid[1]) + rad[1],
		 fabs(mid[2]) + rad[2], num);
	return num[0] > 0.0 || num[1] > 0.0;
}

/* The angle E turns from point a to point b of piece w at p (principal
 * value: E stays in a half plane between them). */
static double piece_turn(const struct wpiece *w, int a, int b, px_vec3 p)
{
	px_vec3 da = px_v3_sub(w->s[a], p), db = px_v3_sub(w->s[b], p);
	double a1 = px_v3_dot(da, w->su[a]), a2 = px_v3_dot(da, w->sv[a]);
	double b1 = px_v3_dot(db, w->su[b]), b2 = px_v3_dot(db, w->sv[b]);
	return atan2(a1 * b2 - a2 * b1, a1 * b1 + a2 * b2);
}

/* Test hook (internal.h): 1 turns every boundary piece the wrong way
 * (the winding number negated: the check must see it). */
int px__strack_wind_fault = 0;

/* Winding number of E along f's boundary at p into *w: 1 when known,
 * 0 when not (a side whose test fails, or no boundary to use). */
static int winding(const struct px_strack *t, const struct ssurf *f,
		   px_vec3 p, int *w)
{
	double sum = 0.0, x;
	int i, k;
	if (!f->wind_ok)
		return 0;
	for (i = 0; i < f->nwp; i++) {
		const struct wpiece *wp = &f->wp[i];
		if (side_keeps(&t->rcell[wp->ri].cert, wp->side, p)) {
			sum += piece_turn(wp, 0, 2, p);
			continue;
		}
		for (k = 0; k < 2; k++) {
			if (!side_keeps(&t->qcert[4 * wp->ri + wp->qk[k]], wp->qside[k], p))
				return 0;
			sum += piece_turn(wp, k, k + 1, p);
		}
	}
	if (px__strack_wind_fault)
		sum = -sum;
	x = sum / (2.0 * M_PI);
	*w = (int)lround(x);
	/* each turn is exact up to rounding: far from an integer means
	 * a side's end value was zero to rounding */
	return fabs(x - *w) < 1e-6;
}

static int crit_index(const struct crit *z)
{
	return z->type ? 1 : -1;
}

/* 1 when every surface whose winding number is known at p (the set's
 * point) has a held set of that index sum. */
static int ix_balanced(const struct px_strack *t, px_vec3 p)
{
	int i, k, w;
	for (i = 0; i < t->n_surf; i++) {
		const struct ssurf *f = &t->sf[i];
		int sum = 0;
		if (!winding(t, f, p, &w))
			continue;
		for (k = 0; k < f->nz; k++)
			sum += crit_index(&f->z[k]);
		if (sum != w)
			return 0;
	}
	return 1;
}

/* The check owed by a step whose membership changed, once its solves
 * are done: 0 when none is owed or it holds; 1 when it fails (counted:
 * the caller re-establishes the set). */
static int ix_check(struct px_strack *t)
{
	if (!t->ix_on || t->pend_next < t->n_pend || t->fault_drop == 2)
		return 0;
	t->ix_on = 0;
	if (ix_balanced(t, t->p))
		return 0;
	t->st.unbalanced++;
	return 1;
}

/* Cells per group of the expiry scan. */
#define ST_GROUP 8

/* Every group's least expiry and the least of all, afresh. */
static void groups_rebuild(struct px_strack *t)
{
	int g, k, n = t->n_cells, ng = (n + ST_GROUP - 1) / ST_GROUP;
	double nd = INFINITY;
	for (g = 0; g < ng; g++) {
		int k1 = (g + 1) * ST_GROUP < n ? (g + 1) * ST_GROUP : n;
		double gm = INFINITY;
		for (k = g * ST_GROUP; k < k1; k++)
			gm = t->ex[k] < gm ? t->ex[k] : gm;
		t->gdue[g] = gm;
		nd = gm < nd ? gm : nd;
	}
	t->next_due = nd;
}

/* The cell's certificate was proven for the cube of half width r about
 * p (max norm): due when the path from here could leave it. */
static void cell_expire(struct px_strack *t, struct scell *c, px_vec3 p, double r)
{
	struct cube *q = &t->cube[c - t->cell];
	q->ctr = p;
	q->crad = r;
	t->ex[c - t->cell] = t->ctravel + r;
}

static void expiries_rebuild(struct px_strack *t, px_vec3 p)
{
	int i;
	for (i = 0; i < t->n_cells; i++)
		cell_expire(t, &t->cell[i], p,
			    cell_radius(t, &t->cell[i], p) * (1.0 - 1e-9));
	groups_rebuild(t);
	t->ex_ok = 1;
	t->col_on = 0;
}

/* Solves of a hit cell itself: one; two after a long step past the
 * crossing (solved where the region was met too); 0 for a pole cell. */
static int hit_work(const struct px_strack *t, int ci, double step)
{
	const struct scell *c = &t->cell[ci];
	if (c->always)
		return 0;
	return 1 + ((1.0 - c->cross) * step > 0.05 * c->size);
}

/* The cell tests one update may make (0: no bound); only with a solve
 * budget, without one every case re-initialises at once anyway. */
static int tests_budget(const struct px_strack *t)
{
	return t->opts.max_solves > 0 ? t->opts.max_tests : 0;
}

/* (the points are finite: plain comparisons, not fmax's calls) */
static inline double max_norm(px_vec3 d)
{
	double x = fabs(d.x), y = fabs(d.y), z = fabs(d.z);
	return x > y ? (x > z ? x : z) : (y > z ? y : z);
}

/* A due cell whose cube still holds the step's end with at least this
 * share of its half width to spare is not tested again: the path wound
 * about inside it (an expiry counts the path, not the way from the
 * centre); a test there would prove a cube about as large. Keeping one
 * costs a comparison, so the share can be small (0.25 -> 0.1: 7-12 %
 * fewer tests on the random paths). */
#define ST_REKEY 0.1

/* Test hook (internal.h): 1 takes the cubes twice as wide. */
int px__strack_rekey_fault = 0;
int px__strack_quick_fault = 0;

/* Start collecting the cells whose certificates the segment p0 -> p1
 * may break: the travel grows by the segment and the cells it makes due
 * are taken out (popped), to be tested by col_test().
 * A due cell whose cube still holds p1 well inside keeps it: p0 is in
 * it too (every cell's expiry less the travel is at most its half width
 * less the way of the point from its centre, by induction over the
 * steps), so the cube holds the segment; its expiry becomes the travel
 * plus what is left of the half width beyond p1, the same bound. */
static void col_begin(struct px_strack *t, px_vec3 p0, px_vec3 p1)
{
	int np = 0;
	if (!t->ex_ok)
		expiries_rebuild(t, p0);
	t->travel += px_v3_dist(p0, p1);
	t->ctravel += max_norm(px_v3_sub(p1, p0));
	if (t->next_due <= t->ctravel) {
		double nd = INFINITY, tr = t->ctravel, *ex = t->ex;
		int g, k, n = t->n_cells, ng = (n + ST_GROUP - 1) / ST_GROUP;
		for (g = 0; g < ng; g++) {
			int k1 = (g + 1) * ST_GROUP < n ? (g + 1) * ST_GROUP : n;
			double gm = INFINITY;
			if (!(t->gdue[g] <= tr)) {
				nd = t->gdue[g] < nd ? t->gdue[g] : nd;
				continue;
			}
			for (k = g * ST_GROUP; k < k1; k++) {
				if (ex[k] <= tr) {
					const struct cube *q = &t->cube[k];
					double left = q->crad * (px__strack_rekey_fault ? 2.0 : 1.0) -
						      max_norm(px_v3_sub(p1, q->ctr));
					if (left > ST_REKEY * q->crad) {
						ex[k] = tr + left;
						t->st.rekeys++;
					} else {
						/* its next expiry comes with its
						 * test (col_test(), col_end()) */
						t->popped[np++] = k;
						ex[k] = INFINITY;
					}
				}
				gm = ex[k] < gm ? ex[k] : gm;
			}
			t->gdue[g] = gm;
			nd = gm < nd ? gm : nd;
		}
		t->next_due = nd;
	}
	t->col_np = np;
	t->col_k = 0;
	t->col_nh = 0;
	t->col_p0 = p0;
	t->col_p1 = p1;
	t->col_on = 1;
}

/* Test up to limit (0: all) more of the popped cells; each gets its
 * next expiry, the hit ones go to hits. Returns 1 when all are tested. */
static int col_test(struct px_strack *t, int limit)
{
	px_vec3 p0 = t->col_p0, p1 = t->col_p1;
	px_vec3 mid = px_v3_scale(px_v3_add(p0, p1), 0.5);
	/* the segment lies in the cube of half width dinf about p1 and in
	 * the cube of half width dinf / 2 about its middle */
	double dinf = max_norm(px_v3_sub(p1, p0));
	/* A region whose radius falls short of clearing the segment is
	 * given its quarters' too before the cell counts as hit: a hit cell
	 * is solved, and with the quarters 25-35 % fewer cells are solved on
	 * most bench paths at 0.1-1 % (3-9 % fewer instructions; the larger
	 * radii also put the next test off). Not while catching up: the
	 * segment then spans many updates' travel, most regions fall short
	 * of it by far and the quarters' work was 17-38 % more at 5 %
	 * steps. */
	double fine = t->mode == ST_TRACK ? 1.0 : 0.0;
	int end = t->col_np;
	if (limit > 0 && t->col_k + limit < end)
		end = t->col_k + limit;
	for (; t->col_k < end; t->col_k++) {
		int ci = t->popped[t->col_k];
		struct scell *c = &t->cell[ci];
		double r1 = cell_radius_to(t, c, p1, fine * dinf);
		t->st.box_tests++;
		if (r1 < dinf && cell_radius_to(t, c, mid, fine * 0.5 * dinf) < 0.5 * dinf) {
			/* where along the segment the region can first be met */
			double r0 = cell_radius(t, c, p0);
			double s0 = fmin(1.0, r0 / dinf);
			double s1 = fmax(s0, 1.0 - r1 / dinf);
			c->cross = 0.5 * (s0 + s1);
			t->hits[t->col_nh++] = ci;
		}
		cell_expire(t, c, p1, r1);
	}
	return t->col_k >= t->col_np;
}

/* End the collection: the popped cells' expiries count again, the hit ones
 * are marked with this update's epoch (track_step() adds the cells of
 * lost points to them once). Returns the count of hits. */
static int col_end(struct px_strack *t)
{
	int k;
	for (k = 0; k < t->col_np; k++) {
		int ci = t->popped[k], g = ci / ST_GROUP;
		double x = t->ex[ci];
		if (x < t->gdue[g])
			t->gdue[g] = x;
		if (x < t->next_due)
			t->next_due = x;
	}
	for (k = 0; k < t->col_nh; k++)
		t->cell[t->hits[k]].mark = t->epoch;
	t->col_on = 0;
	return t->col_nh;
}

/*
 * Cells whose certificates the segment p0 -> p1 may break. Returns their
 * count (in hits); -1 when more than max_tests cells are due: then that
 * many are tested now and the collection goes on over the next updates
 * (col_on; the tracked set stays at p0).
 */
static int collect_cells(struct px_strack *t, px_vec3 p0, px_vec3 p1)
{
	int lim = tests_budget(t);
	col_begin(t, p0, p1);
	if (t->col_np == 0) {
		/* none due (most updates): nothing to test or put back */
		t->col_on = 0;
		return 0;
	}
	if (lim > 0 && t->col_np > lim) {
		col_test(t, lim);
		return -1;
	}
	col_test(t, 0);
	return col_end(t);
}

/* The next max_tests of a collection in progress: as collect_cells(). */
static int col_resume(struct px_strack *t)
{
	return col_test(t, tests_budget(t)) ? col_end(t) : -1;
}

/* ------------------------------------------------------------------ */
/* answer                                                              */

static int in_work(const struct px_strack *t, px_vec3 p)
{
	/* (px_aabb_contains() inline: twice in every update) */
	const px_aabb *b = &t->work;
	return p.x >= b->min.x && p.x <= b->max.x && p.y >= b->min.y &&
	       p.y <= b->max.y && p.z >= b->min.z && p.z <= b->max.z;
}

static void fill_dir(struct px_strack_result *r, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, r->point);
	double n = px_v3_norm(d);
	r->dist = n;
	r->dir = n > 0.0 ? px_v3_scale(d, 1.0 / n) : px_v3(0, 0, 0);
}

static void count_crit(const struct px_strack *t, struct px_strack_result *r,
		       int curve_crit)
{
	int i, j;
	r->n_min = r->n_max = r->n_saddle = 0;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			int ty = t->sf[i].z[j].type;
			if (ty > 0)
				r->n_min++;
			else if (ty < 0)
				r->n_max++;
			else
				r->n_saddle++;
		}
	r->n_crit = r->n_min + r->n_max + r->n_saddle + curve_crit;
}

/* The curve tracker's answer (a free curve or a surface edge) into r. */
static void answer_curve(const struct px_strack *t,
			 const struct px_track_result *cr,
			 struct px_strack_result *r)
{
	r->point = cr->point;
	if (cr->entity < t->n_curves) {
		r->entity = cr->entity;
		r->u = cr->u;
		r->v = 0.0;
		r->feature = PX_STRACK_CURVE;
	} else {
		const struct edge *e = &t->edge[cr->entity - t->n_curves];
		r->entity = t->n_curves + e->surf;
		r->u = e->dir ? e->t : cr->u;
		r->v = e->dir ? cr->u : e->t;
		r->feature = PX_STRACK_EDGE;
	}
}

static void answer(struct px_strack *t, px_vec3 p,
		   const struct px_track_result *cr, struct px_strack_result *r)
{
	double best = INFINITY;
	int kind = 0, i, j;
	uint32_t id = 0;

	t->ans_s = -1;
	if (cr->entity >= 0) {
		best = cr->dist * cr->dist;
		kind = 2;
		answer_curve(t, cr, r);
	}
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			double d2;
			if (z->type <= 0)
				continue;
			d2 = px_v3_dist2(z->s, p);
			if (d2 < best) {
				best = d2;
				kind = 1;
				id = z->id;
				r->point = z->s;
				r->u = z->u;
				r->v = z->v;
				r->entity = t->n_curves + i;
				r->feature = PX_STRACK_MIN;
				t->ans_s = i;
				t->ans_j = j;
			}
		}
	for (i = 0; i < t->n_poles; i++) {
		double d2 = px_v3_dist2(t->pole[i].q, p);
		if (d2 < best) {
			best = d2;
			kind = 3;
			id = (uint32_t)i;
			r->point = t->pole[i].q;
			r->u = t->pole[i].u;
			r->v = t->pole[i].v;
			r->entity = t->n_curves + t->pole[i].surf;
			r->feature = PX_STRACK_POLE;
		}
	}
	fill_dir(r, p);
	count_crit(t, r, cr->n_crit);
	r->jumped = kind != t->best_kind || (kind == 2 && cr->jumped) ||
		    (kind != 2 && id != t->best_id);
	if (t->best_kind == 0 && t->have_last)
		/* after a global answer: judged as there */
		r->jumped = r->entity != t->last_entity ||
			    px_v3_dist(r->point, t->last_point) >
				    4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	t->best_kind = kind;
	t->best_id = id;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
}

static void answer_global(struct px_strack *t, px_vec3 p,
			  struct px_strack_result *r)
{
	struct px_dist_result g;
	px_dist_query(t->dist, p, &g);
	r->point = g.point;
	r->u = g.u;
	r->v = g.v;
	r->entity = g.entity;
	r->feature = PX_STRACK_GLOBAL;
	fill_dir(r, p);
	count_crit(t, r, 0);
	/* no feature identity here: a jump is a change of entity or a foot
	 * point that moved far more than the query point */
	r->jumped = !t->have_last || r->entity != t->last_entity ||
		    px_v3_dist(r->point, t->last_point) >
			    4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	t->best_kind = 0;
	r->source = PX_TRACK_GLOBAL;
	t->st.fallbacks++;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
}

static int reinit_all(struct px_strack *t, px_vec3 p)
{
	int i, rc = 0;
	t->hot_s = -1;
	for (i = 0; i < t->n_surf; i++) {
		int r2 = surf_reinit(t, &t->sf[i], i, p);
		if (r2 && !rc)
			rc = r2;
	}
	return rc;
}

static void rebuild_start(struct px_strack *t);

static void verify(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_dist_result g;
	if (t->opts.verify_every <= 0 ||
	    t->st.updates % (uint64_t)t->opts.verify_every != 0)
		return;
	if (px_dist_query(t->dist, p, &g))
		return;
	t->st.verifications++;
	r->verified = 1;
	if (r->dist > g.dist + 1e-9 * (t->scale + g.dist)) {
		t->st.disagreements++;
		t->st.reinits++;
		if (t->opts.max_solves > 0) {
			/* re-established over the next updates */
			rebuild_start(t);
		} else if (reinit_all(t, p)) {
			t->st.overflows++;
		}
		answer_global(t, p, r);
		r->verified = 1;
	}
}

static void result_clear(struct px_strack_result *r)
{
	memset(r, 0, sizeof(*r));
	r->entity = -1;
}

/* The curve tracker's answer (none when the model has no curve and no
 * open edge: closed in both directions or all poles). */
static void curves_update(struct px_strack *t, px_vec3 p,
			  struct px_track_result *cr, int reset)
{
	if (!t->ct) {
		memset(cr, 0, sizeof(*cr));
		cr->entity = -1;
		return;
	}
	if (reset)
		px_track_reset(t->ct, p, cr);
	else
		px_track_update(t->ct, p, cr);
	t->ct_p = p;
	t->ct_ncrit = cr->n_crit;
}

/*
 * The curve tracker's exact answer as a certificate for leaving it out:
 * with dc its distance at q and best that of some surface point (a
 * tracked minimum or a pole), at any x the curves are at least
 * dc - |x - q| away and the closest point at most best + |x - q|, so no
 * curve is closest while |x - q| < (dc - best) / 2. Where the boxes of
 * the curves' half spans reach nearer than best (a point beside an edge,
 * or far from the surface, its distance ball over the edges' boxes) they
 * prove nothing, and the curve tracker ran every update.
 */
static void ct_note(struct px_strack *t, px_vec3 q, double dc, double best)
{
	double m = dc - best - 1e-9 * (best + t->scale);
	t->ct_q = q;
	t->ct_rc = m > 0.0 ? 0.5 * m * (1.0 - 1e-9) : -1.0;
	t->ct_rc2 = m > 0.0 ? t->ct_rc * t->ct_rc : -1.0;
	if (px__strack_ct_fault)
		t->ct_rc = t->ct_rc2 = INFINITY;
}

/* The curve tracker's last update more than 2 % of the model size from
 * p: it must run before its step grows longer than it is made for. */
static inline int ct_stale(const struct px_strack *t, px_vec3 p)
{
	double lim = 0.02 * t->scale;
	return px_v3_dist2(p, t->ct_p) > lim * lim;
}

/* Its last answer still proves every curve farther than the closest
 * point at p (ct_note()). */
static inline int ct_proves(const struct px_strack *t, px_vec3 p)
{
	return px_v3_dist2(p, t->ct_q) < t->ct_rc2;
}

/*
 * 1 when the curve tracker must answer this update: a curve or edge can
 * be closest (some box of the curves is not farther than the best
 * interior minimum or pole), or it was left out over more than 2 % of
 * the model size (its next step stays of the length it is made for);
 * else 2 when its own last answer proves the curves farther, 0 when the
 * boxes do (or there are no curves).
 */
static int curves_needed(const struct px_strack *t, px_vec3 p)
{
	double best = INFINITY;
	int i, j;
	if (!t->ct)
		return 0;
	if (ct_stale(t, p))
		return 1;
	if (ct_proves(t, p))
		return 2;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			double d2 = px_v3_dist2(z->s, p);
			if (z->type > 0 && d2 < best)
				best = d2;
		}
	for (i = 0; i < t->n_poles; i++) {
		double d2 = px_v3_dist2(t->pole[i].q, p);
		if (d2 < best)
			best = d2;
	}
	if (!(best < INFINITY))
		return 1;
	/* a margin for the rounding of both sides */
	best *= 1.0 + 1e-9;
	for (i = 0; i < t->n_cbox; i++)
		if (px_aabb_dist2(&t->cbox[i], p) <= best)
			return 1;
	return 0;
}

static int full_reset(struct px_strack *t, px_vec3 p,
		      struct px_strack_result *r)
{
	struct px_track_result cr;
	int rc;
	curves_update(t, p, &cr, 1);
	rc = reinit_all(t, p);
	/* every cell's certificate here, not in the next update */
	expiries_rebuild(t, p);
	r->source = PX_TRACK_REINIT;
	if (rc) {
		t->st.overflows++;
		if (t->opts.max_solves > 0)
			rebuild_start(t);
		answer_global(t, p, r);
	} else {
		answer(t, p, &cr, r);
		r->jumped = 1;
		verify(t, p, r);
	}
	return PX_OK;
}

int px_strack_reset(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	if (!t || !r)
		return PX_E_INVAL;
	if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
		return PX_E_NAN;
	result_clear(r);
	t->st.updates++;
	t->p = p;
	t->init = 1;
	if (t->gov.cold)
		t->st.cold_left++;
	px__gov_restart(&t->gov);
	t->gov_q = p;
	t->ret_left = 0;
	t->best_kind = 0;
	t->have_last = 0;
	t->mode = ST_TRACK;
	t->hot_s = -1;
	return full_reset(t, p, r);
}

/* Cell index (within the surface) holding (u, v). */
static int cell_of(const struct ssurf *f, double u, double v)
{
	int i = bsearch_bounds(f->cu, f->ncu, u), j = bsearch_bounds(f->cv, f->ncv, v);
	return j * f->ncu + i;
}

/* Follow one point from its state at p0 to p (predictor, Newton). */
static int evolve(const struct ssurf *f, struct crit *z, px_vec3 dp,
		  px_vec3 p)
{
	double a = px_v3_dot(z->su, dp), b = px_v3_dot(z->sv, dp);
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (fabs(det) > 0.0) {
		double su = (z->h22 * a - z->h12 * b) / det;
		double sv = (-z->h12 * a + z->h11 * b) / det;
		if (isfinite(su) && isfinite(sv) && fabs(su) <= 0.25 * f->du &&
		    fabs(sv) <= 0.25 * f->dv) {
			z->u += su;
			z->v += sv;
		}
	}
	return snewton(f, z, p, 0.125 * f->du, 0.125 * f->dv, NULL);
}

/*
 * Follow z from p0 to p0 + dp, keeping its type (a point changes type only
 * at a fold, where it dies). A long step that fails or changes the type
 * is retried as a continuation in 4, then 16 sub-steps. Returns 0, or 1
 * with *last the furthest point reached (to solve its cell again).
 */
static int follow(const struct ssurf *f, struct crit *z, px_vec3 p0,
		  px_vec3 dp, px_vec3 p, struct crit *last)
{
	struct crit w = *z;
	int ns, k;
	if (!evolve(f, &w, dp, p) && w.type == z->type) {
		*z = w;
		return 0;
	}
	*last = *z;
	for (ns = 4; ns <= 16; ns *= 4) {
		px_vec3 sd = px_v3_scale(dp, 1.0 / ns);
		w = *z;
		for (k = 1; k <= ns; k++) {
			px_vec3 pk = k == ns ? p : px_v3_add(p0, px_v3_scale(dp, (double)k / ns));
			int ty = w.type;
			if (evolve(f, &w, sd, pk) || w.type != ty)
				break;
			if (ns == 16)
				*last = w;
		}
		if (k > ns) {
			*z = w;
			return 0;
		}
	}
	return 1;
}

static double cross_at(const struct px_strack *t, const struct scell *c,
		       px_vec3 p0, px_vec3 p1, int *rounds);

/* Rounds of cross_at() at most. */
#define ST_CROSS_ROUNDS 8

static int ring_check(struct px_strack *t, int i, int lim, int *units,
		      int *spare);

/* Solve pending items from pend_next on, at most budget solves (0: all;
 * counted in solve_units(), a seed point still to be found by its
 * cross_at() rounds, an escape bound by the speeds it works out).
 * Returns 0 or PX_E_NOSPC; *done the solves made (rounded up). */
static int pend_solve(struct px_strack *t, int budget, int *done)
{
	int rc = 0, units = 0, spare = 0, lim = budget * ST_UNITS;
	t->pend_on = t->mode != ST_REBUILD;
	while (t->pend_next < t->n_pend) {
		int i = t->pend_next;
		const struct scell *c;
		if (t->pend_kind[i] >= PK_RING) {
			if (ring_check(t, i, lim, &units, &spare))
				break;
			t->pend_next++;
			continue;
		}
		c = &t->cell[t->pend[i]];
		if (t->pend_kind[i] == PK_CROSS) {
			/* its rounds (two cell radii each, about a check's
			 * work) count as units, at most ST_CROSS_ROUNDS */
			px_vec3 p0 = t->pend_ps[i];
			int rounds = 0;
			double s;
			if (lim > 0 && units > 0 && units + ST_CROSS_ROUNDS > lim)
				break;
			s = cross_at(t, c, p0, t->p, &rounds);
			t->pend_ps[i] = px_v3_add(p0, px_v3_scale(px_v3_sub(t->p, p0), s));
			t->pend_kind[i] = PK_SOLVE;
			t->st.cross_rounds += (uint64_t)rounds;
			units += rounds;
		}
		rc = cell_solve_budget(t, c, t->pend_ps[i], t->p, &units, lim);
		if (rc == 1)
			break;
		t->pend_next++;
		if (rc < 0)
			break;
	}
	t->pend_on = 0;
	*done = (units + ST_UNITS - 1) / ST_UNITS;
	return rc < 0 ? rc : 0;
}

/*
 * Where along p0 -> p1 to solve hit cell c again after a long step: past
 * the part of the segment its certificates leave open, so that a pair
 * born there is found near where it was born (and followed to p1), not
 * looked for after it may have left the cell. The certified radius at
 * either end of the open part [a, b] clears a stretch of it; a few
 * rounds from both ends narrow it down to where the transition can be.
 * Returns b (the col_test() estimate when all of it is cleared); *rounds
 * the rounds made.
 */
static double cross_at(const struct px_strack *t, const struct scell *c,
		       px_vec3 p0, px_vec3 p1, int *rounds)
{
	px_vec3 dp = px_v3_sub(p1, p0);
	double dinf = max_norm(dp);
	double a = 0.0, b = 1.0;
	int k;
	*rounds = 0;
	if (!(dinf > 0.0))
		return 1.0;
	for (k = 0; k < ST_CROSS_ROUNDS && b - a > 1e-3; k++) {
		double ra = cell_radius(t, c, px_v3_add(p0, px_v3_scale(dp, a))) / dinf;
		double rb = cell_radius(t, c, px_v3_add(p0, px_v3_scale(dp, b))) / dinf;
		*rounds = k + 1;
		if (!(ra > 0.0) && !(rb > 0.0))
			break;
		a += ra;
		b -= rb;
		if (a >= b)
			return c->cross;
	}
	return b;
}

/*
 * Escape bound. A critical point at p that no follow accounts for was,
 * at some time of the step, in a source cell: a hit cell (pairs are born
 * only where a certificate fails, and points enter only through the open
 * sides of those) or the cell where a lost point was last seen. After it
 * last left a source it moved through cells whose certificates hold, and
 * there H d(u, v) = (Su . dx, Sv . dx) (differentiate E = 0), so
 * |d(u, v)| <= K |dx| with K = sqrt(max Su.Su + max Sv.Sv) / sigma,
 * sigma a lower bound on the singular values of every H in the piece's
 * enclosure while x runs over the segment; where E is proven nonzero it
 * does not pass at all (K = 0). Ring k is the cells at Chebyshev
 * distance k from the sources (the cell grid, wrapped where the surface
 * is); within it the quarters at distance j (in quarters) from rings
 * 0..k-1 make layer j = 1..4, each one quarter thick: no two quarters of
 * layers j - 1 and j + 1 touch. A point ending outside ring k crossed
 * every layer of rings 1..k, each at K at most its largest and over at
 * least its least quarter width w, so the step's travel |dp| is at least
 * the sum of w / K over them. Rings are solved out to the first k where
 * that sum exceeds |dp|. Near a focal sheet points move fast and one
 * ring is not always enough; K is taken over the regions, and over the
 * quarters of those that would spoil their layers (tighter enclosures
 * near a fold).
 */

/* Test hook (internal.h): bit 0 solves the first ring only, bound or
 * not; bit 1 leaves out the solves past where a long step met a hit
 * cell's region (the bound alone must hold). */
int px__strack_ring_fault = 0;

/* Rings solved about a source at most; past them the whole surface. */
#define ST_RINGS 3

/* K of certificate c (above) while x runs over the cube of half width r
 * about xm: 0 when E is proven nonzero, INFINITY when no bound. */
static double cert_speed(const struct rcert *c, px_vec3 xm, double r)
{
	double mid[3], rad[3], lo[3], hi[3], e1, e2, epad, sig;
	const double m[3] = {c->m11, c->m12, c->m22};
	px_vec3 w;
	int k;
	hess_at(c, xm, mid, rad);
	w = px_v3_sub(c->sc, xm);
	e1 = px_v3_dot(w, c->suc);
	e2 = px_v3_dot(w, c->svc);
	epad = e_pad(c, w, xm);
	/* cert_radius()'s E test over the cube */
	if (e_radius(c, fabs(mid[0]) + rad[0], fabs(mid[1]) + rad[1],
		     fabs(mid[2]) + rad[2], e1, e2, epad) * ST_RSAFE > r)
		return 0.0;
	for (k = 0; k < 3; k++) {
		lo[k] = mid[k] - rad[k] - r * m[k];
		hi[k] = mid[k] + rad[k] + r * m[k];
	}
	if (!sym_regular(lo, hi, &sig) || !(sig > 0.0))
		/* the preconditioned E test last: it costs as much again */
		return pre_radius(c, mid, rad, e1, e2, epad) > r ? 0.0 : INFINITY;
	return sqrt(c->G11.hi + c->G22.hi) / sig * (1.0 + 1e-9);
}

static void pend_item(struct px_strack *t, int ci, int kind, px_vec3 ps,
		      double need)
{
	t->pend[t->n_pend] = ci;
	t->pend_kind[t->n_pend] = (unsigned char)kind;
	t->pend_need[t->n_pend] = need;
	t->pend_ps[t->n_pend++] = ps;
}

/* Pend cell ci of the step's solves at p, once. */
static void pend_at(struct px_strack *t, int ci, px_vec3 p)
{
	if (t->cell[ci].mark == t->pend_epoch)
		return;
	t->cell[ci].mark = t->pend_epoch;
	pend_item(t, ci, PK_SOLVE, p, 0.0);
}

/* Cell (cu + du, cv + dv) of f, wrapped; -1 off the domain. */
static int cell_at(const struct ssurf *f, int cu, int cv, int du, int dv)
{
	int nu = cu + du, nv = cv + dv;
	if (f->wrap_u)
		nu = ((nu % f->ncu) + f->ncu) % f->ncu;
	if (f->wrap_v)
		nv = ((nv % f->ncv) + f->ncv) % f->ncv;
	if (nu < 0 || nu >= f->ncu || nv < 0 || nv >= f->ncv)
		return -1;
	return f->first_cell + nv * f->ncu + nu;
}

/* Ring k of surface si: the cells at distance k from its sources (hits
 * 0..pend_nh) get that distance and make its list (ring_list from the
 * surface's first cell on; ring_check() pends their solves); its bound
 * starts. */
static void ring_build(struct px_strack *t, int si, int k)
{
	struct ssurf *f = &t->sf[si];
	int i, du, dv;
	f->rl_n = f->rl_next = 0;
	for (i = 0; i < 4; i++) {
		f->rl_kl[i] = 0.0;
		f->rl_wl[i] = INFINITY;
	}
	for (i = 0; i < t->pend_nh; i++) {
		int ci = t->hits[i], loc, cu, cv;
		if (t->cell[ci].surf != si)
			continue;
		loc = ci - f->first_cell;
		cu = loc % f->ncu;
		cv = loc / f->ncu;
		for (dv = -k; dv <= k; dv++)
			for (du = -k; du <= k; du += (dv == -k || dv == k) ? 1 : 2 * k) {
				int nc = cell_at(f, cu, cv, du, dv);
				struct scell *c;
				if (nc < 0)
					continue;
				c = &t->cell[nc];
				/* nearer rings were built whole: unmarked here is
				 * distance k */
				if (c->dmark == t->pend_epoch)
					continue;
				c->dmark = t->pend_epoch;
				c->dist = k;
				t->ring_list[f->first_cell + f->rl_n++] = nc;
			}
	}
}

/* Distance in pieces (res a side) of piece (a, b) of a ring cell from the
 * inner neighbours in (in[dv + 1][du + 1]); 1..res. */
static int piece_dist(const int in[3][3], int res, int a, int b)
{
	int lo_u = a + 1, hi_u = res - a, lo_v = b + 1, hi_v = res - b, d = res;
	if (in[1][0] && lo_u < d)
		d = lo_u;
	if (in[1][2] && hi_u < d)
		d = hi_u;
	if (in[0][1] && lo_v < d)
		d = lo_v;
	if (in[2][1] && hi_v < d)
		d = hi_v;
	if (in[0][0] && ST_MAX(lo_u, lo_v) < d)
		d = ST_MAX(lo_u, lo_v);
	if (in[0][2] && ST_MAX(hi_u, lo_v) < d)
		d = ST_MAX(hi_u, lo_v);
	if (in[2][0] && ST_MAX(lo_u, hi_v) < d)
		d = ST_MAX(lo_u, hi_v);
	if (in[2][2] && ST_MAX(hi_u, hi_v) < d)
		d = ST_MAX(hi_u, hi_v);
	return d;
}

/*
 * Add ring cell ci of surface f to its ring's layers (quarter layers
 * rl_kl, rl_wl): each region's K, or its quarters' where the region's
 * could leave the four layers short of rem of travel. Returns the K
 * worked out.
 */
static int ring_cell(struct px_strack *t, struct ssurf *f, int ci, px_vec3 xm,
		     double r, double rem)
{
	struct scell *c = &t->cell[ci];
	int loc = ci - f->first_cell, cu = loc % f->ncu, cv = loc / f->ncu, in[3][3],
	    du, dv, a, b, n = 0;
	double wq = 0.25 * fmin(c->u1 - c->u0, c->v1 - c->v0);
	for (dv = -1; dv <= 1; dv++)
		for (du = -1; du <= 1; du++) {
			int nc = cell_at(f, cu, cv, du, dv);
			in[dv + 1][du + 1] = nc >= 0 && t->cell[nc].dmark == t->pend_epoch &&
					     t->cell[nc].dist < c->dist;
		}
	for (b = 0; b < 2; b++)
		for (a = 0; a < 2; a++) {
			int ri = c->child + a + 2 * b, d = piece_dist(in, 2, a, b), q;
			double k = cert_speed(&t->rcell[ri].cert, xm, r);
			n++;
			c->kr[2 * b + a] = k;
			for (q = 0; q < 4; q++)
				c->kq[4 * (2 * b + a) + q] = NAN;
			if (!(k * rem > 3.8 * wq)) {
				/* both of its quarter layers get the region's: with
				 * every piece so, the four layers take over rem */
				for (q = 2 * d - 2; q < 2 * d; q++) {
					f->rl_kl[q] = fmax(f->rl_kl[q], k);
					f->rl_wl[q] = fmin(f->rl_wl[q], wq);
				}
				continue;
			}
			for (q = 0; q < 4; q++) {
				int l = piece_dist(in, 4, 2 * a + (q & 1), 2 * b + (q >> 1)) - 1;
				k = cert_speed(&t->qcert[4 * ri + q], xm, r);
				c->kq[4 * (2 * b + a) + q] = k;
				n++;
				f->rl_kl[l] = fmax(f->rl_kl[l], k);
				f->rl_wl[l] = fmin(f->rl_wl[l], wq);
			}
		}
	c->kmark = t->pend_epoch;
	return n;
}

/* Units a ring cell's bound may take at most (4 regions and their 16
 * quarters, 8 speeds a unit, about a check's work). */
#define ST_RING_CELL_UNITS 3

/*
 * The escape bound of pending item i (ring k of surface pend[i], the step
 * from pend_ps[i]; the rings inside it take pend_need[i] of travel): its
 * cells' layers, then held (done) or ring k + 1 built and pended; past
 * ST_RINGS the whole surface. *spare: speeds already counted in *units.
 * Not continued past lim after other work; returns 1 when left for later
 * (resumed at the next cell).
 */
static int ring_check(struct px_strack *t, int i, int lim, int *units,
		      int *spare)
{
	int si = t->pend[i], k = t->pend_kind[i] - PK_RING + 1, j;
	struct ssurf *f = &t->sf[si];
	px_vec3 p0 = t->pend_ps[i], dp = px_v3_sub(t->p, p0),
		xm = px_v3_scale(px_v3_add(p0, t->p), 0.5);
	double r = 0.5 * max_norm(dp), len = px_v3_norm(dp), need = t->pend_need[i];
	while (f->rl_next < f->rl_n) {
		int n, ci;
		if (lim > 0 && *units > 0 && *units + ST_RING_CELL_UNITS > lim)
			return 1;
		ci = t->ring_list[f->first_cell + f->rl_next++];
		n = ring_cell(t, f, ci, xm, r, len - need);
		/* its solve after its K: they prove most of its checks */
		pend_at(t, ci, t->p);
		t->st.ring_speeds += (uint64_t)n;
		for (*spare -= n; *spare < 0; *spare += 8)
			++*units;
	}
	for (j = 0; j < 4; j++)
		need += f->rl_kl[j] > 0.0 ? f->rl_wl[j] / f->rl_kl[j] : INFINITY;
	/* held; or nothing to cross (no ring left in the domain), or no
	 * motion (a point of a fixed x stays put) */
	if (need > len || f->rl_n == 0 || !(len > 0.0))
		return 0;
	if (k < ST_RINGS) {
		ring_build(t, si, k + 1);
		pend_item(t, si, PK_RING + k, p0, need);
		return 0;
	}
	t->st.ring_all++;
	for (j = 0; j < f->ncu * f->ncv; j++)
		pend_at(t, f->first_cell + j, t->p);
	return 0;
}

/*
 * Move the tracked set from p0 to p (t->p becomes p), the nh cells whose
 * certificates the segment may break collected (collect_cells()): follow
 * every point, add the cells of lost points, and solve them (a hit after
 * a long step also past where its region was met, its roots followed to
 * p) with the rings of cells about them that the escape bound names
 * (ring_check()). Returns 0; 1 when that work exceeds the
 * budget: the budget's worth is done, the rest left pending (mode
 * ST_PEND, solved over the next updates at p); 2 when the index check
 * fails (ix_check()); PX_E_NOSPC.
 */
static int track_step(struct px_strack *t, px_vec3 p0, px_vec3 p,
		      struct px_strack_result *r, int nh)
{
	px_vec3 dp = px_v3_sub(p, p0);
	double step = px_v3_norm(dp);
	int i, j, rc = 0, before = 0, after = 0, done = 0,
		      budget = t->opts.max_solves;

	t->ix_on = 0;
	for (i = 0; i < t->n_surf; i++) {
		struct ssurf *f = &t->sf[i];
		int n = f->nz;
		memcpy(f->tmp, f->z, (size_t)n * sizeof(*f->z));
		f->nz = 0;
		for (j = 0; j < n; j++) {
			struct crit z = f->tmp[j], last;
			/* a point that rested on the hot path starts where it
			 * was last followed */
			int rest = t->hot_s >= 0 && !(i == t->hot_s && j == t->hot_j);
			px_vec3 q0 = rest ? t->hot_p : p0;
			if (follow(f, &z, q0, px_v3_sub(p, q0), p, &last)) {
				/* died at a fold (or left through an edge), or
				 * Newton lost it: solve its cell and the cell
				 * where it was last seen, so a survivor is found
				 * again */
				int q;
				t->st.lost++;
				r->died++;
				t->ix_on = 1;
				for (q = 0; q < 2; q++) {
					const struct crit *o = q ? &last : &f->tmp[j];
					int ci = f->first_cell + cell_of(f, o->u, o->v);
					if (t->cell[ci].mark != t->epoch && nh < t->n_cells) {
						t->cell[ci].mark = t->epoch;
						t->cell[ci].cross = 1.0;
						t->hits[nh++] = ci;
					}
				}
				continue;
			}
			rc = crit_add(t, f, &z);
			if (rc < 0) {
				t->hot_s = -1;
				return rc;
			}
			/* followed onto a held point's branch */
			t->ix_on |= rc == 0;
		}
	}
	t->hot_s = -1;
	t->p = p;
	/* the work list: solve at p, after a long step also past where the
	 * region was met (not for pole cells: hit_work()); and the
	 * cells about it at p */
	t->n_pend = t->pend_next = 0;
	t->pend_epoch = t->epoch;
	for (i = 0; i < nh; i++) {
		int ci = t->hits[i];
		pend_item(t, ci, PK_SOLVE, p, 0.0);
		if (hit_work(t, ci, step) > 1 && !(px__strack_ring_fault & 2))
			pend_item(t, ci, PK_CROSS, p0, 0.0);
	}
	/* a pair born in a hit cell may have moved on into the cells about
	 * it, both its members sometimes (the index check does not see
	 * that): the rings of the escape bound (mostly cheap: their regions
	 * are proven empty or hold the one point they can) */
	t->pend_nh = nh;
	for (i = 0; i < nh; i++) {
		t->cell[t->hits[i]].dmark = t->epoch;
		t->cell[t->hits[i]].dist = 0;
	}
	for (i = 0; i < t->n_surf; i++) {
		const struct ssurf *f = &t->sf[i];
		ring_build(t, i, 1);
		if (!(px__strack_ring_fault & 1)) {
			if (f->rl_n > 0)
				pend_item(t, i, PK_RING, p0, 0.0);
			continue;
		}
		/* the fault: the first ring solved, its bound not made */
		for (j = 0; j < f->rl_n; j++)
			pend_at(t, t->ring_list[f->first_cell + j], p);
	}
	for (i = 0; i < t->n_surf; i++)
		before += t->sf[i].nz;
	/* within the budget all of it; over it, the budget's worth now and
	 * the rest over the next updates */
	rc = pend_solve(t, budget, &done);
	for (i = 0; i < t->n_surf; i++)
		after += t->sf[i].nz;
	/* new points only come from solved cells: births (pairs at a focal
	 * sheet) and entries through an edge */
	r->born = after - before;
	t->st.born += (uint64_t)r->born;
	r->cells_solved = done;
	if (rc < 0)
		return rc;
	if (t->pend_next < t->n_pend) {
		t->st.over_budget++;
		t->mode = ST_PEND;
		return 1;
	}
	return ix_check(t) ? 2 : 0;
}

/* Cells solved per update of a rebuild (max_solves > 0). */
static int rebuild_slice(const struct px_strack *t)
{
	return t->opts.max_solves > 1 ? t->opts.max_solves / 2 : 1;
}

/* Re-establish the critical points from scratch over the next updates,
 * starting at the next point inside the working volume. */
static void rebuild_start(struct px_strack *t)
{
	int i;
	t->hot_s = -1;
	t->mode = ST_REBUILD;
	t->rb_started = 0;
	t->rb_next = 0;
	t->ex_ok = 0;
	t->col_on = 0;
	t->ix_on = 0;
	for (i = 0; i < t->n_surf; i++)
		t->sf[i].nz = 0;
}

/*
 * One update while the tracked set is not at the query point; the answer
 * is the global query's unless the set reaches p in this update and
 * agrees with it.
 *  - ST_PEND: the set is at t->p but owes cell solves there: up to the
 *    budget of them now; when none is left: ST_LAG.
 *  - ST_REBUILD: a slice of cells is solved at the fixed point t->p
 *    where the rebuild started, each cell's certificate taken there;
 *    when all are, the set is complete at t->p: ST_LAG.
 *  - ST_LAG: the set moves from t->p to p by one tracked step; solves
 *    over the budget are left pending (ST_PEND) at p. When more than
 *    max_tests cells are due, the step's end is held at that p and its
 *    cells are tested max_tests per update first. It catches up when the
 *    work of the distance travelled meanwhile fits the budgets: while
 *    the point moves with less work per update than the budgets on
 *    average.
 */
static int catch_up(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	struct px_dist_result g;
	int rc = 0;
	t->st.rebuild_updates++;
	curves_update(t, p, &cr, 0);
	if (t->mode == ST_PEND) {
		int done = 0, i, before = 0, after = 0;
		for (i = 0; i < t->n_surf; i++)
			before += t->sf[i].nz;
		rc = pend_solve(t, t->opts.max_solves > 0 ? t->opts.max_solves : 0, &done);
		for (i = 0; i < t->n_surf; i++)
			after += t->sf[i].nz;
		r->born = after - before;
		t->st.born += (uint64_t)r->born;
		r->cells_solved = done;
		if (rc < 0) {
			t->st.overflows++;
			rebuild_start(t);
		} else if (t->pend_next >= t->n_pend) {
			t->mode = ST_LAG;
			if (ix_check(t))
				rebuild_start(t);
		}
		answer_global(t, p, r);
		return PX_OK;
	}
	if (t->mode == ST_REBUILD) {
		int slice = rebuild_slice(t);
		if (!t->rb_started) {
			if (!in_work(t, p)) {
				t->st.outside++;
				answer_global(t, p, r);
				return PX_OK;
			}
			t->rb_started = 1;
			t->p = p;
			t->travel = t->ctravel = 0.0;
		}
		int units = 0;
		while (t->rb_next < t->n_cells && rc >= 0) {
			struct scell *c = &t->cell[t->rb_next];
			rc = cell_solve_budget(t, c, t->p, t->p, &units,
					       slice * ST_UNITS);
			if (rc == 1) {
				rc = 0;
				break;
			}
			cell_expire(t, c, t->p, cell_radius(t, c, t->p));
			t->rb_next++;
		}
		r->cells_solved = (units + ST_UNITS - 1) / ST_UNITS;
		if (rc < 0) {
			t->st.overflows++;
			rebuild_start(t);
		} else if (t->rb_next >= t->n_cells) {
			groups_rebuild(t);
			t->ex_ok = 1;
			t->mode = ST_LAG;
		}
		answer_global(t, p, r);
		return PX_OK;
	}
	/* ST_LAG */
	if (t->col_on || in_work(t, p)) {
		int nh = t->col_on ? col_resume(t) : collect_cells(t, t->p, p);
		px_vec3 p1;
		if (nh < 0) {
			answer_global(t, p, r);
			return PX_OK;
		}
		/* the step ends where its collection started */
		p1 = t->col_p1;
		rc = track_step(t, t->p, p1, r, nh);
		if (rc < 0 || rc == 2) {
			t->st.overflows += rc < 0;
			rebuild_start(t);
		} else if (rc == 0 && p1.x == p.x && p1.y == p.y && p1.z == p.z) {
			/* caught up: checked against the global answer */
			answer(t, p, &cr, r);
			if (px_dist_query(t->dist, p, &g) == PX_OK) {
				t->st.verifications++;
				r->verified = 1;
				if (fabs(r->dist - g.dist) <= 1e-9 * (t->scale + g.dist)) {
					t->mode = ST_TRACK;
					r->source = PX_TRACK_REINIT;
					return PX_OK;
				}
				t->st.disagreements++;
			}
			rebuild_start(t);
		}
	} else {
		t->st.outside++;
	}
	answer_global(t, p, r);
	return PX_OK;
}

/*
 * Arm the hot path after a tracked update answered by surface minimum
 * (ans_s, ans_j), with every point current at p. The global distance is
 * 1-Lipschitz and best is that of a real surface point followed
 * continuously, so after a further path L it is at most best + L, while
 * another minimum, a pole or any curve or edge (bounded below by the
 * distance to the boxes of its half spans) at distance d now is at least
 * d - L away: none can answer while L < (d - best) / 2. While no cell is
 * due the set of critical points keeps its count and types (the cell
 * certificates), so the answering minimum is followed alone. The curve
 * tracker is left out for at most 2 % of the size of travel, as
 * curves_needed() does.
 */
static void hot_arm(struct px_strack *t, px_vec3 p,
		    const struct px_strack_result *r)
{
	double best = r->dist, tol = 1e-9 * (best + t->scale), until, m, lim,
	       cc = INFINITY;
	int i, j;
	int curve = r->feature == PX_STRACK_CURVE || r->feature == PX_STRACK_EDGE;
	t->hot_s = -1;
	if (t->mode != ST_TRACK || r->source != PX_TRACK_TRACKED ||
	    (t->fault_hot & 1) ||
	    !(curve ? t->best_kind == 2 && t->ct_p.x == p.x && t->ct_p.y == p.y &&
			      t->ct_p.z == p.z
		    : r->feature == PX_STRACK_MIN && t->ans_s >= 0))
		return;
	until = INFINITY;
	for (i = 0; i < t->n_surf; i++)
		for (j = 0; j < t->sf[i].nz; j++) {
			const struct crit *z = &t->sf[i].z[j];
			if (z->type <= 0 ||
			    (!curve && i == t->ans_s && j == t->ans_j))
				continue;
			m = px_v3_dist(z->s, p) - best - tol;
			if (!(m > 0.0))
				return;
			if (m < until)
				until = m;
		}
	for (i = 0; i < t->n_poles; i++) {
		m = px_v3_dist(t->pole[i].q, p) - best - tol;
		if (!(m > 0.0))
			return;
		if (m < until)
			until = m;
	}
	/* when the curve tracker answers it runs every update (the least
	 * distance to the curves is 1-Lipschitz too); else the curves are
	 * left out while the curve tracker's last answer proves them
	 * farther (ct_note(): cc, already halved) or their boxes do (and
	 * for 2 % of the size at most, as curves_needed()), or updated
	 * along with the minimum every update */
	t->hot_curves = 0;
	lim = INFINITY;
	if (!curve && t->ct) {
		double uc = until;
		lim = 0.02 * t->scale - px_v3_dist(p, t->ct_p);
		t->hot_curves = !(lim > 0.0);
		for (i = 0; i < t->n_cbox && !t->hot_curves; i++) {
			m = sqrt(px_aabb_dist2(&t->cbox[i], p)) - best - tol;
			if (!(m > 0.0))
				t->hot_curves = 1;
			else if (m < uc)
				uc = m;
		}
		if (t->hot_curves && lim > 0.0 && t->ct_rc > 0.0) {
			/* the boxes prove nothing: the curve tracker's
			 * answer may, when it does not cut the certificate
			 * short (else the curves run with the minimum, and
			 * hot_update() notes their answers) */
			cc = t->ct_rc - px_v3_dist(p, t->ct_q);
			if (cc >= 0.5 * fmin(until, 2.0 * lim)) {
				t->hot_curves = 0;
				uc = until;
			} else
				cc = INFINITY;
		}
		if (t->hot_curves)
			lim = INFINITY;
		else
			until = uc;
	}
	until *= 0.5;
	if (lim < until)
		until = lim;
	if (cc < until)
		until = cc;
	t->hot_s = curve ? t->n_surf : t->ans_s;
	t->hot_j = curve ? -1 : t->ans_j;
	t->hot_p = p;
	t->hot_until = (t->fault_hot & 2) ? INFINITY
					   : t->travel + until * (1.0 - 1e-9);
	t->hot_nmin = r->n_min;
	t->hot_nmax = r->n_max;
	t->hot_nsad = r->n_saddle;
	t->hot_ncrit = r->n_crit;
	t->hot_ccrit = t->ct_ncrit;
}

/* An update on the hot path (the certificate running, the due cells
 * tested and none hit; the travelled path includes this step): the
 * answering minimum followed by one predictor and Newton (on a copy,
 * kept when it stays a minimum), or the curve tracker updated. Returns 0
 * when answered, 1 when the full update must run (the point set is as
 * it was). */
static int hot_update(struct px_strack *t, px_vec3 p,
		      struct px_strack_result *r)
{
	struct ssurf *f = NULL;
	struct crit w;
	struct px_track_result cr;
	int use_min = t->hot_s < t->n_surf, kind = 1;
	if (use_min) {
		f = &t->sf[t->hot_s];
		w = f->z[t->hot_j];
		if (evolve(f, &w, px_v3_sub(p, t->p), p) || w.type != 1)
			return 1;
	}
	r->n_crit = t->hot_ncrit;
	if (!use_min || (t->hot_curves && (ct_stale(t, p) || !ct_proves(t, p)))) {
		/* the curve tracker answers, or could (its own update,
		 * exact; left out while its last answer proves the curves
		 * farther, ct_note(), for 2 % of the size at most); the
		 * margin of the other minima and the poles holds against
		 * either answer, and the nearer answers */
		curves_update(t, p, &cr, 0);
		if (!use_min && cr.entity < 0)
			return 1; /* not expected: the full update decides */
		if (cr.entity >= 0 &&
		    (!use_min || cr.dist * cr.dist < px_v3_dist2(w.s, p)))
			kind = 2;
		if (use_min && kind == 1 && cr.entity >= 0)
			ct_note(t, p, cr.dist, px_v3_dist(w.s, p));
	} else if (t->hot_curves) {
		t->st.curve_cert_skips++;
	}
	if (!use_min || t->hot_curves)
		r->n_crit = t->hot_ncrit - t->hot_ccrit + t->ct_ncrit;
	if (use_min)
		f->z[t->hot_j] = w;
	t->p = p;
	r->source = PX_TRACK_TRACKED;
	if (kind == 2) {
		answer_curve(t, &cr, r);
		if (cr.source != PX_TRACK_TRACKED)
			r->source = cr.source;
		r->jumped = t->best_kind != 2 || cr.jumped;
	} else {
		r->point = w.s;
		r->u = w.u;
		r->v = w.v;
		r->entity = t->n_curves + t->hot_s;
		r->feature = PX_STRACK_MIN;
		r->jumped = t->best_kind != 1;
	}
	t->best_kind = kind;
	fill_dir(r, p);
	r->n_min = t->hot_nmin;
	r->n_max = t->hot_nmax;
	r->n_saddle = t->hot_nsad;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->st.hot++;
	return 0;
}

/* The tracked update (every mode but cold). */
static int strack_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	px_vec3 p0;
	int rc, nh, ran;

	result_clear(r);
	t->st.updates++;
	if (++t->epoch == 0)
		t->epoch = 1;
	if (t->mode != ST_TRACK)
		return catch_up(t, p, r);
	p0 = t->p;
	nh = -1;
	if (t->hot_s >= 0 && t->ex_ok && in_work(t, p) && in_work(t, p0) &&
	    t->travel + px_v3_dist(p0, p) < t->hot_until) {
		/* the due cells first (as track_step would): none hit and
		 * the hot path answers */
		nh = collect_cells(t, p0, p);
		if (nh == 0 && !hot_update(t, p, r)) {
			verify(t, p, r);
			return PX_OK;
		}
	}
	r->source = PX_TRACK_TRACKED;
	if (!in_work(t, p) || !in_work(t, p0)) {
		if (t->opts.max_solves > 0) {
			/* the set waits at p0 for the point to come back */
			t->mode = ST_LAG;
			return catch_up(t, p, r);
		}
		t->p = p;
		t->st.outside++;
		return full_reset(t, p, r);
	}
	if (nh < 0 && !t->col_on)
		nh = collect_cells(t, p0, p);
	if (t->col_on) {
		/* more cells due than max_tests: tested over the next updates
		 * (the set waits at p0), answered globally meanwhile */
		t->st.over_budget++;
		t->mode = ST_LAG;
		answer_global(t, p, r);
		return PX_OK;
	}
	rc = track_step(t, p0, p, r, nh);
	if (rc == 1) {
		/* over the budget: answer globally; the rest of the solves
		 * is done over the next updates, then the set catches up */
		answer_global(t, p, r);
		return PX_OK;
	}
	if (rc) {
		/* capacity, or the index check failed: the set is
		 * re-established (over the next updates with a budget) */
		t->st.overflows += rc < 0;
		t->st.reinits++;
		if (t->opts.max_solves > 0) {
			rebuild_start(t);
		} else {
			t->p = p;
			if (reinit_all(t, p))
				t->st.overflows++;
			expiries_rebuild(t, p);
		}
		answer_global(t, p, r);
		return PX_OK;
	}
	ran = curves_needed(t, p);
	if (ran == 1) {
		curves_update(t, p, &cr, 0);
	} else {
		memset(&cr, 0, sizeof(cr));
		cr.entity = -1;
		cr.n_crit = t->ct_ncrit;
		t->st.curve_skips++;
		t->st.curve_cert_skips += ran == 2;
	}
	answer(t, p, &cr, r);
	if (ran == 1 && cr.entity >= 0 && isfinite(r->dist))
		ct_note(t, p, cr.dist, r->dist);
	if (cr.source != PX_TRACK_TRACKED)
		r->source = cr.source;
	verify(t, p, r);
	hot_arm(t, p, r);
	return PX_OK;
}

/* ------------------------------------------------------------------ */
/* cold switch                                                         */

/* (u, v) off the open domain edges (a seam direction has none). */
static int uv_inner(const struct ssurf *f, double u, double v)
{
	return (f->wrap_u || (u > f->u0 + 1e-9 * f->du && u < f->u1 - 1e-9 * f->du)) &&
	       (f->wrap_v || (v > f->v0 + 1e-9 * f->dv && v < f->v1 - 1e-9 * f->dv));
}

/* The answer r at p as a critical point, when it is an interior one of
 * a surface that is a minimum there (the cold answers' jumped follows
 * it): 1 with *z evaluated, else 0. One evaluation. */
static int cold_crit(const struct px_strack *t, px_vec3 p,
		     const struct px_strack_result *r, struct crit *z)
{
	const struct ssurf *f;
	px_vec3 gr;
	int s = r->entity - t->n_curves;
	if (s < 0 || s >= t->n_surf ||
	    (r->feature != PX_STRACK_MIN && r->feature != PX_STRACK_GLOBAL))
		return 0;
	f = &t->sf[s];
	if (!uv_inner(f, r->u, r->v))
		return 0;
	memset(z, 0, sizeof(*z));
	z->u = r->u;
	z->v = r->v;
	crit_eval(f, z, p, &gr);
	z->type = crit_type(z);
	return z->type == 1;
}

/* Keep the answer r at p (z: cold_crit()'s, ok its return) as the last
 * one for the cold answers' jumped. */
static void cold_keep(struct px_strack *t, px_vec3 p,
		      const struct px_strack_result *r, const struct crit *z,
		      int ok)
{
	t->cprev.ok = ok;
	t->cprev.s = r->entity - t->n_curves;
	if (ok)
		t->cprev.z = *z;
	t->cprev.q = p;
	t->last_point = r->point;
	t->last_q = p;
	t->last_entity = r->entity;
	t->have_last = 1;
	t->best_kind = 0;
}

/* Parameter offset a - b of surface f as a length in domain units (the
 * shorter way round a seam). */
static double uv_gap(const struct ssurf *f, double du, double dv)
{
	if (f->wrap_u)
		du = px__wrap_half(du, f->du);
	if (f->wrap_v)
		dv = px__wrap_half(dv, f->dv);
	return hypot(du / f->du, dv / f->dv);
}

/* The predictor (section 4.2) of z for a move dp: (su, sv). 0 when H is
 * singular. */
static int predict(const struct crit *z, px_vec3 dp, double *su, double *sv)
{
	double a = px_v3_dot(z->su, dp), b = px_v3_dot(z->sv, dp);
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (!(fabs(det) > 0.0))
		return 0;
	*su = (z->h22 * a - z->h12 * b) / det;
	*sv = (-z->h12 * a + z->h11 * b) / det;
	return isfinite(*su) && isfinite(*sv);
}

/*
 * jumped for a cold answer g at p (c: g as a critical point when c_ok).
 * Nothing was followed, so the last answer decides, when it was an
 * interior minimum of the same surface:
 *  - both interior minima and the predictor, run forward from the last
 *    one and backward from the new one, lands each within half the
 *    parameter moved of the other: the same branch (on one branch its
 *    error is second order in the step, a jump lands it far off);
 *  - else the last minimum is followed to p (predictor and Newton, in
 *    one step or four): landing on g means g continues it; on another
 *    minimum, the closest point left a living minimum (a jump); losing
 *    it means it died at a fold (a jump when g is interior) or left
 *    through an edge.
 * Otherwise (edges, curves, poles) as a global answer: a foot point that
 * moved far more than the query point.
 */
static int cold_jumped(struct px_strack *t, px_vec3 p,
		       const struct px_dist_result *g, const struct crit *c,
		       int c_ok)
{
	const struct ssurf *f;
	const struct crit *z = &t->cprev.z;
	struct crit w;
	double moved, du, dv, gap, su, sv;
	int far, n, s = g->entity - t->n_curves;
	if (!t->have_last || g->entity != t->last_entity)
		return 1;
	moved = px_v3_dist(g->point, t->last_point);
	if (moved <= 1e-9 * (t->scale + g->dist))
		return 0;
	far = moved > 4.0 * px_v3_dist(p, t->last_q) + 1e-9 * t->scale;
	if (!t->cprev.ok || t->cprev.s != s || s < 0 || s >= t->n_surf)
		return far;
	f = &t->sf[s];
	if (c_ok) {
		du = c->u - z->u;
		dv = c->v - z->v;
		gap = uv_gap(f, du, dv);
		if (predict(z, px_v3_sub(p, t->cprev.q), &su, &sv) &&
		    uv_gap(f, du - su, dv - sv) <= 0.5 * gap &&
		    predict(c, px_v3_sub(t->cprev.q, p), &su, &sv) &&
		    uv_gap(f, du + su, dv + sv) <= 0.5 * gap)
			return 0;
	}
	/* one step, else four (a long step near a focal point; bounded
	 * work: at most five corrections) */
	for (n = 1; n <= 4; n *= 4) {
		px_vec3 dp = px_v3_scale(px_v3_sub(p, t->cprev.q), 1.0 / n);
		int k;
		w = *z;
		for (k = 1; k <= n; k++) {
			px_vec3 pk = k == n ? p : px_v3_add(t->cprev.q, px_v3_scale(dp, (double)k));
			if (evolve(f, &w, dp, pk) || w.type != 1)
				break;
		}
		if (k > n)
			return uv_gap(f, w.u - g->u, w.v - g->v) > 1e-7;
	}
	return c_ok ? 1 : far;
}

/* An update answered cold: the global query alone. Returns 0 or the
 * query's error (the caller then tracks again). */
static int cold_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_dist_result g;
	struct crit c;
	int ok, rc = px__gov_cold_query(&t->gov, t->dist, p, &g);
	if (rc)
		return rc;
	result_clear(r);
	t->st.updates++;
	t->st.cold++;
	r->dist = g.dist;
	r->point = g.point;
	r->u = g.u;
	r->v = g.v;
	r->entity = g.entity;
	r->dir = g.dir;
	r->feature = PX_STRACK_GLOBAL;
	r->n_crit = r->n_min = r->n_max = r->n_saddle = -1;
	r->source = PX_TRACK_COLD;
	ok = cold_crit(t, p, r, &c);
	r->jumped = cold_jumped(t, p, &g, &c, ok);
	cold_keep(t, p, r, &c, ok);
	return 0;
}

/* The tracker goes cold after the update that answered r at p: the set
 * is dropped (it is not followed; px_strack_critical() holds none). */
static void cold_enter(struct px_strack *t, px_vec3 p,
		       const struct px_strack_result *r)
{
	struct crit c;
	int i;
	t->st.cold_entered++;
	t->hot_s = -1;
	t->ret_left = 0;
	for (i = 0; i < t->n_surf; i++)
		t->sf[i].nz = 0;
	cold_keep(t, p, r, &c, cold_crit(t, p, r, &c));
}

/* Back from cold answers at p: the curve tracker starts afresh at p and
 * the surface set is re-established in slices (max_solves > 0, answered
 * globally meanwhile) or at once. The curve tracker's restart has an
 * update of its own: with the first slice and the global query, after a
 * thousand cold updates had pushed the tracker's memory out of the
 * caches, it was the worst update of the return. */
static int cold_return(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	struct px_track_result cr;
	int slice = rebuild_slice(t);
	t->st.cold_left++;
	result_clear(r);
	t->st.updates++;
	if (t->opts.max_solves > 0) {
		curves_update(t, p, &cr, 1);
		rebuild_start(t);
		/* this update, the rebuild's slices, then a margin for
		 * catching up */
		t->ret_left = 1 + t->n_cells / slice + 2 * PX_GOV_MIN_COLD;
		t->st.rebuild_updates++;
		answer_global(t, p, r);
		return PX_OK;
	}
	t->p = p;
	t->mode = ST_TRACK;
	t->hot_s = -1;
	return full_reset(t, p, r);
}

int px_strack_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r)
{
	int64_t t0;
	int rc;

	if (!t || !r)
		return PX_E_INVAL;
	if (!isfinite(p.x) || !isfinite(p.y) || !isfinite(p.z))
		return PX_E_NAN;
	if (!t->init)
		return px_strack_reset(t, p, r);
	if (t->gov.on) {
		px__gov_step(&t->gov, px_v3_dist(t->gov_q, p));
		t->gov_q = p;
		if (t->gov.cold) {
			if (!px__gov_leave(&t->gov)) {
				if (cold_update(t, p, r) == 0)
					return PX_OK;
				/* no global answer here: track again */
				px__gov_restart(&t->gov);
			}
			return cold_return(t, p, r);
		}
	}
	t0 = t->ret_left == 0 ? px__gov_start(&t->gov) : PX_GOV_UNTIMED;
	rc = strack_update(t, p, r);
	if (t->ret_left > 0 && (t->mode == ST_TRACK || --t->ret_left == 0))
		t->ret_left = 0;
	if (px__gov_stop(&t->gov, t0))
		cold_enter(t, p, r);
	return rc;
}

void px__strack_set_drop_fault(struct px_strack *t, int fault)
{
	if (t)
		t->fault_drop = fault;
}

void px__strack_set_clock(struct px_strack *t, int64_t (*fn)(void *), void *ctx)
{
	if (t)
		px__gov_set_clock(&t->gov, fn, ctx);
}

struct px_gov *px__strack_gov(struct px_strack *t)
{
	return t ? &t->gov : NULL;
}

void px__strack_set_hot_fault(struct px_strack *t, int fault)
{
	if (t) {
		t->fault_hot = fault;
		t->hot_s = -1;
	}
}

/* The region cell of surface s holding (u, v), NULL for bad arguments
 * (the test hooks below). */
static const struct scell *region_at(const struct px_strack *t, int s,
				     double u, double v)
{
	const struct ssurf *f;
	const struct scell *c;
	int ch;
	if (!t || s < 0 || s >= t->n_surf)
		return NULL;
	f = &t->sf[s];
	if (u < f->u0 || u > f->u1 || v < f->v0 || v > f->v1)
		return NULL;
	c = &t->cell[f->first_cell + cell_of(f, u, v)];
	ch = (u >= 0.5 * (c->u0 + c->u1)) + 2 * (v >= 0.5 * (c->v0 + c->v1));
	return &t->rcell[c->child + ch];
}

double px__strack_cert_radius(const struct px_strack *t, int s, double u,
			      double v, px_vec3 p)
{
	const struct scell *g = region_at(t, s, u, v);
	return g ? region_radius_full(t, (int)(g - t->rcell), p) : -1.0;
}

int px__strack_region(const struct px_strack *t, int s, double u, double v,
		       px_vec3 p, double box[4])
{
	const struct scell *g = region_at(t, s, u, v);
	if (!g)
		return -1;
	box_of(g, -1, box);
	return region_empty(t, (int)(g - t->rcell), p);
}

int px__strack_one(const struct px_strack *t, int s, double u, double v,
		   px_vec3 p, double box[4])
{
	const struct scell *g = region_at(t, s, u, v);
	int ri, k, m;
	if (!g)
		return -1;
	box_of(g, -1, box);
	ri = (int)(g - t->rcell);
	m = one_root(&g->cert, p);
	for (k = 0; k < 4; k++)
		m |= one_root(&t->qcert[4 * ri + k], p) << (k + 1);
	return m;
}

int px__strack_contract(const struct px_strack *t, int s, double u, double v,
			px_vec3 p, double box[4], int out[5], double fu[5], double fv[5])
{
	const struct scell *g = region_at(t, s, u, v), *home;
	int ri, k;
	if (!g)
		return -1;
	box_of(g, -1, box);
	ri = (int)(g - t->rcell);
	home = &t->cell[t->sf[s].first_cell + cell_of(&t->sf[s], u, v)];
	for (k = -1; k < 4; k++) {
		const struct rcert *c = k < 0 ? &g->cert : &t->qcert[4 * ri + k];
		double y[2][2], rho, b[4];
		struct crit z;
		memset(&z, 0, sizeof(z));
		box_of(g, k, b);
		out[k + 1] = -1;
		if (!contract_rate(c, p, y, &rho))
			continue;
		out[k + 1] = contract_solve(&t->sf[s], c, b, &z, p, home);
		fu[k + 1] = z.u;
		fv[k + 1] = z.v;
	}
	return 0;
}

int px__strack_sub(const struct px_strack *t, int s, const double box[4], px_vec3 p,
		   int *regular, double *fu, double *fv)
{
	const struct ssurf *f;
	const struct scell *home, *g;
	const struct rcert *top;
	struct rcert rc;
	struct crit z;
	double mid[3], rad[3], y[2][2], rho, gb[4], qb[4];
	int k, ri;
	if (!t || s < 0 || s >= t->n_surf || !box || !regular || !fu || !fv)
		return -1;
	f = &t->sf[s];
	g = region_at(t, s, 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]));
	if (!g)
		return -1;
	/* the certificate a solve cuts the box from: its quarter's, or
	 * its region's */
	ri = (int)(g - t->rcell);
	box_of(g, -1, gb);
	if (!(box[0] >= gb[0] && box[1] <= gb[1] && box[2] >= gb[2] && box[3] <= gb[3]))
		return -1;
	top = &g->cert;
	for (k = 0; k < 4; k++) {
		box_of(g, k, qb);
		if (box[0] >= qb[0] && box[1] <= qb[1] && box[2] >= qb[2] && box[3] <= qb[3])
			top = &t->qcert[4 * ri + k];
	}
	taylor_cert(f, box, top, &rc);
	home = &t->cell[t->sf[s].first_cell +
			cell_of(f, 0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]))];
	hess_at(&rc, p, mid, rad);
	*regular = one_root_h(mid, rad);
	if (no_root_h(&rc, p, mid, rad))
		return 1;
	if (!contract_h(&rc, mid, rad, y, &rho))
		return 2;
	memset(&z, 0, sizeof(z));
	switch (contract_solve(f, &rc, box, &z, p, home)) {
	case CS_FOUND:
		*fu = z.u;
		*fv = z.v;
		return 0;
	case CS_EMPTY:
		return 1;
	default:
		return 2;
	}
}

int px__strack_winding(const struct px_strack *t, int s, px_vec3 p, int *w)
{
	if (!t || s < 0 || s >= t->n_surf || !w)
		return -1;
	return winding(t, &t->sf[s], p, w);
}

int px_strack_critical(const struct px_strack *t, int s, double *u, double *v,
		       int *type, int cap)
{
	const struct ssurf *f;
	int i;
	if (!t || (cap > 0 && (!u || !v || !type)))
		return PX_E_INVAL;
	if (s < 0 || s >= t->n_surf)
		return PX_E_RANGE;
	f = &t->sf[s];
	for (i = 0; i < f->nz && i < cap; i++) {
		struct crit w = f->z[i], last;
		/* a point resting on the hot path, followed to the current
		 * point on a copy (the state stays as the next update
		 * expects it); as it was if that fails */
		if (t->hot_s >= 0 && !(s == t->hot_s && i == t->hot_j) &&
		    follow(f, &w, t->hot_p, px_v3_sub(t->p, t->hot_p), t->p,
			   &last))
			w = f->z[i];
		u[i] = w.u;
		v[i] = w.v;
		type[i] = w.type;
	}
	return f->nz;
}

void px_strack_get_stats(const struct px_strack *t, struct px_strack_stats *s)
{
	if (!s)
		return;
	if (!t) {
		memset(s, 0, sizeof(*s));
		return;
	}
	*s = t->st;
	s->tracked_ns = t->gov.trk_ns;
	s->cold_ns = t->gov.cold_ns;
}

void px_strack_get_info(const struct px_strack *t, struct px_strack_info *info)
{
	if (!info)
		return;
	memset(info, 0, sizeof(*info));
	if (!t)
		return;
	info->n_surfaces = t->n_surf;
	info->n_curves = t->n_curves;
	info->n_patches = t->n_patches;
	info->n_cells = t->n_cells;
	info->n_edges = t->n_edges;
	info->n_poles = t->n_poles;
	info->n_unbounded = t->n_unbounded;
	info->work = t->work;
}

struct px_dist_model *px_strack_dist_model(struct px_strack *t)
{
	return t ? t->dist : NULL;
}

/* ------------------------------------------------------------------ */
/* setup                                                               */

void px_strack_opts_default(struct px_strack_opts *o)
{
	if (!o)
		return;
	memset(o, 0, sizeof(*o));
	o->cells_per_span = 3;
	o->seeds = 2;
	o->samples = 6;
	o->max_crit = 256;
	o->work_margin = 1.0;
	o->verify_every = 0;
	o->max_solves = 4;
	o->dist = NULL;
	o->cold_switch = 1;
	o->max_tests = 32;
}

/* Distinct knot values of one direction inside the domain, with both
 * ends: the Bezier patch bounds. Returns the count. */
static int span_bounds(const struct px_nurbs_surf *s, int dir, double a,
		       double b, double *out)
{
	const double *U = s->knots[dir];
	int i, n = 0;
	out[n++] = a;
	for (i = 0; i < s->n_knots[dir]; i++)
		if (U[i] > out[n - 1] && U[i] < b)
			out[n++] = U[i];
	out[n++] = b;
	return n;
}

static struct iv iv_pt(double x)
{
	struct iv r = {x, x};
	return r;
}

static struct iv iv_add(struct iv a, struct iv b)
{
	struct iv r = {a.lo + b.lo, a.hi + b.hi};
	return r;
}

static struct iv iv_sub(struct iv a, struct iv b)
{
	struct iv r = {a.lo - b.hi, a.hi - b.lo};
	return r;
}

static struct iv iv_scale(struct iv a, double k)
{
	struct iv r = {fmin(a.lo * k, a.hi * k), fmax(a.lo * k, a.hi * k)};
	return r;
}

/* a / w for w > 0 */
static struct iv iv_divw(struct iv a, struct iv w)
{
	struct iv iw = {1.0 / w.hi, 1.0 / w.lo};
	return iv_mul(a, iw);
}

static struct iv iv_pad(struct iv a)
{
	double e = ST_PAD * (fabs(a.lo) + fabs(a.hi)) + 1e-300;
	struct iv r = {a.lo - e, a.hi + e};
	return r;
}

static void iv_grow(struct iv *a, double x)
{
	/* as fmin and fmax (a NaN x leaves a as it is), without their
	 * calls: run for every point of a net at update time too */
	a->lo = x < a->lo ? x : a->lo;
	a->hi = x > a->hi ? x : a->hi;
}

/*
 * Enclosures of the homogeneous coordinates (k = 0..3) of the difference
 * nets of the Bezier net P ((p + 1) x (q + 1), u fastest, 4 per point),
 * all in one pass over the net: the derivative of order (a, b) in (u, v)
 * is a Bezier patch whose control points are the forward differences
 * times p!/(p - a)! q!/(q - b)! / (du^a dv^b); its range lies within
 * their hull. r[0]: order (0, 0), r[1] (1, 0), r[2] (0, 1), r[3] (2, 0),
 * r[4] (1, 1), r[5] (0, 2); an order above the degree is 0.
 */
static void net_ranges(const double *P, int p, int q, double du, double dv,
		       struct iv r[6][4])
{
	static const int oa[6] = {0, 1, 0, 2, 1, 0}, ob[6] = {0, 0, 1, 0, 1, 2};
	int i, j, k, o, n = p + 1;
	for (o = 0; o < 6; o++)
		for (k = 0; k < 4; k++) {
			r[o][k].lo = INFINITY;
			r[o][k].hi = -INFINITY;
		}
#define NR_AT(a, b) P[4 * ((b) * n + (a)) + k]
	for (j = 0; j <= q; j++)
		for (i = 0; i <= p; i++)
			for (k = 0; k < 4; k++) {
				double x = NR_AT(i, j);
				/* the sums in the order of the signed binomial
				 * terms (v outer, u inner) */
				iv_grow(&r[0][k], x);
				if (i < p)
					iv_grow(&r[1][k], -x + NR_AT(i + 1, j));
				if (j < q)
					iv_grow(&r[2][k], -x + NR_AT(i, j + 1));
				if (i + 1 < p)
					iv_grow(&r[3][k], (x - 2.0 * NR_AT(i + 1, j)) + NR_AT(i + 2, j));
				if (i < p && j < q)
					iv_grow(&r[4][k], ((x - NR_AT(i + 1, j)) - NR_AT(i, j + 1)) +
							      NR_AT(i + 1, j + 1));
				if (j + 1 < q)
					iv_grow(&r[5][k], (x - 2.0 * NR_AT(i, j + 1)) + NR_AT(i, j + 2));
			}
#undef NR_AT
	for (o = 0; o < 6; o++) {
		double f = 1.0;
		for (i = 0; i < oa[o]; i++)
			f *= (double)(p - i) / du;
		for (j = 0; j < ob[o]; j++)
			f *= (double)(q - j) / dv;
		for (k = 0; k < 4; k++) {
			struct iv *x = &r[o][k];
			if (oa[o] > p || ob[o] > q) {
				*x = iv_pt(0.0);
				continue;
			}
			/* f > 0: rounding is monotone, so the scaled bounds are
			 * the bounds of the scaled differences */
			x->lo *= f;
			x->hi *= f;
			*x = iv_pad(*x);
		}
	}
}

static void cert_fill(struct rcert *ce, const struct iv Su[3], const struct iv Sv[3],
		      double du, double dv);
static void net_ranges3(const double *P, int p, int q, double du, double dv,
			struct iv r[4][4]);

/*
 * Rational patches: the interval quotient rule on S = X / W counts the
 * ranges of S, S_u, W, W_u ... as if independent, and its enclosures of
 * the derivatives come out several times wider than the polynomial
 * case's (certificate radii 0.25 against 0.81 on the same net with unit
 * weights). The numerators of the derivatives over a power of W are
 * polynomials, products of Bernstein tensor polynomials: their hulls
 * are tight. Setup only (allocates).
 */
struct tpoly {
	int m, n;       /* degrees in u, v */
	double *c;      /* (m + 1) (n + 1), u fastest */
	double mag;     /* bound on the rounding of its coefficients */
};

#define TP_LEN ((3 * PX_NURBS_MAX_DEGREE + 1) * (3 * PX_NURBS_MAX_DEGREE + 1))

static void tp_net(const double *pw, int p, int q, int k, struct tpoly *o)
{
	int i;
	o->m = p;
	o->n = q;
	o->mag = 0.0;
	for (i = 0; i < (p + 1) * (q + 1); i++) {
		o->c[i] = pw[4 * i + k];
		o->mag = fmax(o->mag, 1e-16 * fabs(o->c[i]));
	}
}

/* Derivative along u (dir 0, box width h) or v. */
static void tp_d(const struct tpoly *a, int dir, double h, struct tpoly *o)
{
	int i, j, m = a->m, n = a->n;
	double f = (dir ? n : m) / h;
	o->m = dir ? m : m - 1;
	o->n = dir ? n - 1 : n;
	o->mag = 2.0 * f * a->mag;
	for (j = 0; j <= o->n; j++)
		for (i = 0; i <= o->m; i++) {
			double x1 = dir ? a->c[(j + 1) * (m + 1) + i] : a->c[j * (m + 1) + i + 1];
			o->c[j * (o->m + 1) + i] = f * (x1 - a->c[j * (m + 1) + i]);
		}
}

/* Binomials C(n, k) for n up to the numerators' degrees. */
#define TP_DEG (3 * PX_NURBS_MAX_DEGREE)
struct tp_binom {
	double c[TP_DEG + 1][TP_DEG + 1];
};

static void tp_binom_init(struct tp_binom *b)
{
	int n, k;
	for (n = 0; n <= TP_DEG; n++) {
		b->c[n][0] = b->c[n][n] = 1.0;
		for (k = 1; k < n; k++)
			b->c[n][k] = b->c[n - 1][k - 1] + b->c[n - 1][k];
	}
}

/* o = a b (o not a or b; scratch: TP_LEN): the coefficients times their
 * binomials convolve, then divided by the product's; each is a convex
 * combination of the products a_i b_j (Vandermonde), so its rounding is
 * at most a few units of the terms' count times amax bmax. */
static void tp_mul(const struct tpoly *a, const struct tpoly *b, struct tpoly *o,
		   const struct tp_binom *bc, double *scratch)
{
	int i, j, x, y, M = a->m + b->m, N = a->n + b->n, na = (a->m + 1) * (a->n + 1);
	double amax = 0.0, bmax = 0.0;
	o->m = M;
	o->n = N;
	for (i = 0; i < (M + 1) * (N + 1); i++)
		o->c[i] = 0.0;
	for (j = 0; j <= b->n; j++)
		for (i = 0; i <= b->m; i++) {
			double v = b->c[j * (b->m + 1) + i];
			bmax = fmax(bmax, fabs(v));
			scratch[j * (b->m + 1) + i] = v * bc->c[b->m][i] * bc->c[b->n][j];
		}
	for (j = 0; j <= a->n; j++)
		for (i = 0; i <= a->m; i++) {
			double ca = a->c[j * (a->m + 1) + i];
			amax = fmax(amax, fabs(ca));
			ca *= bc->c[a->m][i] * bc->c[a->n][j];
			for (y = 0; y <= b->n; y++) {
				double *restrict row = o->c + (j + y) * (M + 1) + i;
				const double *restrict bs = scratch + y * (b->m + 1);
				for (x = 0; x <= b->m; x++)
					row[x] += ca * bs[x];
			}
		}
	for (j = 0; j <= N; j++)
		for (i = 0; i <= M; i++)
			o->c[j * (M + 1) + i] /= bc->c[M][i] * bc->c[N][j];
	o->mag = amax * b->mag + bmax * a->mag + 2.3e-16 * (na + 4) * amax * bmax;
}

/* y += s a (the same degrees). */
static void tp_axpy(struct tpoly *y, double s, const struct tpoly *a)
{
	int i;
	for (i = 0; i < (y->m + 1) * (y->n + 1); i++)
		y->c[i] += s * a->c[i];
	y->mag += fabs(s) * a->mag + 1e-16 * fabs(s);
}

/* a raised to degrees (m, n) (not below its own), into o (not a;
 * scratch: TP_LEN). */
static void tp_elevate(const struct tpoly *a, int m, int n, struct tpoly *o,
		       double *scratch)
{
	double *cur = scratch, *nxt = o->c, *sw;
	int cm = a->m, cn = a->n, i, j;
	memcpy(cur, a->c, (size_t)((cm + 1) * (cn + 1)) * sizeof(double));
	for (; cm < m; cm++) {
		for (j = 0; j <= cn; j++)
			for (i = 0; i <= cm + 1; i++) {
				double x = (double)i / (cm + 1);
				double lo = i > 0 ? cur[j * (cm + 1) + i - 1] : 0.0;
				double hi = i <= cm ? cur[j * (cm + 1) + i] : 0.0;
				nxt[j * (cm + 2) + i] = x * lo + (1.0 - x) * hi;
			}
		sw = cur;
		cur = nxt;
		nxt = sw;
	}
	for (; cn < n; cn++) {
		for (j = 0; j <= cn + 1; j++)
			for (i = 0; i <= cm; i++) {
				double x = (double)j / (cn + 1);
				double lo = j > 0 ? cur[(j - 1) * (cm + 1) + i] : 0.0;
				double hi = j <= cn ? cur[j * (cm + 1) + i] : 0.0;
				nxt[j * (cm + 1) + i] = x * lo + (1.0 - x) * hi;
			}
		sw = cur;
		cur = nxt;
		nxt = sw;
	}
	if (cur != o->c)
		memcpy(o->c, cur, (size_t)((cm + 1) * (cn + 1)) * sizeof(double));
	o->m = cm;
	o->n = cn;
	/* convex combinations: no growth beyond a rounding each */
	o->mag = a->mag * (1.0 + 1e-15 * (m + n));
}

/* The range of a / d over the box, d > 0 of a's degrees: a / d is a
 * convex combination of the ratios of their Bernstein coefficients
 * (weights d_i B_i / sum d_j B_j), so it lies within their hull. */
static struct iv tp_ratio_range(const struct tpoly *a, const struct tpoly *d)
{
	struct iv r = {INFINITY, -INFINITY};
	int i;
	for (i = 0; i < (a->m + 1) * (a->n + 1); i++) {
		double x, e;
		if (!(d->c[i] > 0.0)) {
			r.lo = -INFINITY;
			r.hi = INFINITY;
			return r;
		}
		x = a->c[i] / d->c[i];
		e = (8.0 * a->mag + 1e-15 * fabs(a->c[i])) / d->c[i] +
		    fabs(x) * (8.0 * d->mag / d->c[i] + 1e-15);
		iv_grow(&r, x - e);
		iv_grow(&r, x + e);
	}
	return iv_pad(r);
}

/* Test hook (internal.h): 1 shrinks rat_tight()'s enclosures to a
 * third of their width about their midpoints (unsound: the focal test
 * must see it). Read at setup. */
int px__strack_rat_fault = 0;

static struct iv iv_meet(struct iv a, struct iv b)
{
	struct iv r = {a.lo > b.lo ? a.lo : b.lo, a.hi < b.hi ? a.hi : b.hi};
	if (px__strack_rat_fault) {
		double m = 0.5 * (b.lo + b.hi), h = (b.hi - b.lo) / 6.0;
		r.lo = m - h;
		r.hi = m + h;
		return r;
	}
	return r.lo <= r.hi ? r : a;
}

/* y += s a b (tmp: a product's room; as tp_mul() then tp_axpy()). */
static void tp_muladd(struct tpoly *y, double s, const struct tpoly *a,
		      const struct tpoly *b, struct tpoly *tmp, const struct tp_binom *bc,
		      double *scratch)
{
	tp_mul(a, b, tmp, bc, scratch);
	tp_axpy(y, s, tmp);
}

/* *x met with the range of num / den: num raised to den's degrees (into
 * el), then the hull of the coefficients' ratios. */
static void tp_bound(struct iv *x, const struct tpoly *num, const struct tpoly *den,
		     struct tpoly *el, double *scratch)
{
	tp_elevate(num, den->m, den->n, el, scratch);
	*x = iv_meet(*x, tp_ratio_range(el, den));
}

/*
 * Tighter enclosures of the derivatives of S = X / W for each coordinate
 * of a rational net (degrees 2 or more): S_u = A_u / W^2 with
 * A_u = X_u W - X W_u, S_uu = (X_uu W^2 - X W W_uu - 2 W_u A_u) / W^3,
 * S_uv = ((X_uv W + X_u W_v - X_v W_u - X W_uv) W - 2 W_v A_u) / W^3, and
 * so for v; each numerator raised to its power of W's degree and
 * bounded by the ratios of their coefficients. They are met with the
 * interval quotient rule's (both hold). mem: ST_RAT_POLYS * TP_LEN
 * doubles; W's products once for the three coordinates.
 */
enum {
	R_X, R_W, R_XU, R_XV, R_WU, R_WV, R_XUU, R_XUV, R_XVV, R_WUU, R_WUV, R_WVV,
	R_AU, R_AV, R_T1, R_T2, R_W2, R_W3, R_EL, R_SC, R_XW, ST_RAT_POLYS
};
/* Coordinate k of the net and its derivatives to order 2 (du, dv: the
 * cell's sides), into t[f], t[fu], ... */
static void tp_jet(const double *pw, int p, int q, int k, double du, double dv,
		   struct tpoly *t, int f, int fu, int fv, int fuu, int fuv, int fvv)
{
	tp_net(pw, p, q, k, &t[f]);
	tp_d(&t[f], 0, du, &t[fu]);
	tp_d(&t[f], 1, dv, &t[fv]);
	tp_d(&t[fu], 0, du, &t[fuu]);
	tp_d(&t[fu], 1, dv, &t[fuv]);
	tp_d(&t[fv], 1, dv, &t[fvv]);
}

static void rat_tight(const double *pw, int p, int q, double du, double dv,
		      struct iv Su[3], struct iv Sv[3], struct iv Suu[3], struct iv Suv[3],
		      struct iv Svv[3], double *mem, const struct tp_binom *bc)
{
	struct tpoly t[ST_RAT_POLYS];
	double *sc;
	int i, k;
	for (i = 0; i < ST_RAT_POLYS; i++)
		t[i].c = mem + (size_t)i * TP_LEN;
	sc = t[R_SC].c;
	tp_jet(pw, p, q, 3, du, dv, t, R_W, R_WU, R_WV, R_WUU, R_WUV, R_WVV);
	tp_mul(&t[R_W], &t[R_W], &t[R_W2], bc, sc);
	tp_mul(&t[R_W2], &t[R_W], &t[R_W3], bc, sc);
	for (k = 0; k < 3; k++) {
		int d;
		tp_jet(pw, p, q, k, du, dv, t, R_X, R_XU, R_XV, R_XUU, R_XUV, R_XVV);
		tp_mul(&t[R_X], &t[R_W], &t[R_XW], bc, sc);
		for (d = 0; d < 2; d++) {
			/* A_d = X_d W - X W_d over W^2; S_dd W^3 = X_dd W^2 -
			 * (X W) W_dd - 2 W_d A_d */
			int xd = d ? R_XV : R_XU, wd = d ? R_WV : R_WU, ad = d ? R_AV : R_AU;
			tp_mul(&t[xd], &t[R_W], &t[ad], bc, sc);
			tp_muladd(&t[ad], -1.0, &t[R_X], &t[wd], &t[R_T1], bc, sc);
			tp_bound(d ? &Sv[k] : &Su[k], &t[ad], &t[R_W2], &t[R_EL], sc);
			tp_mul(&t[d ? R_XVV : R_XUU], &t[R_W2], &t[R_T1], bc, sc);
			tp_muladd(&t[R_T1], -1.0, &t[R_XW], &t[d ? R_WVV : R_WUU], &t[R_T2], bc,
				  sc);
			tp_muladd(&t[R_T1], -2.0, &t[wd], &t[ad], &t[R_T2], bc, sc);
			tp_bound(d ? &Svv[k] : &Suu[k], &t[R_T1], &t[R_W3], &t[R_EL], sc);
		}
		/* S_uv W^3: (X_uv W + X_u W_v - X_v W_u - X W_uv) W - 2 W_v A_u */
		tp_mul(&t[R_XUV], &t[R_W], &t[R_T1], bc, sc);
		tp_muladd(&t[R_T1], 1.0, &t[R_XU], &t[R_WV], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T1], -1.0, &t[R_XV], &t[R_WU], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T1], -1.0, &t[R_X], &t[R_WUV], &t[R_T2], bc, sc);
		tp_mul(&t[R_T1], &t[R_W], &t[R_T2], bc, sc);
		tp_muladd(&t[R_T2], -2.0, &t[R_WV], &t[R_AU], &t[R_T1], bc, sc);
		tp_bound(&Suv[k], &t[R_T2], &t[R_W3], &t[R_EL], sc);
	}
}

/*
 * The enclosures of certificate ce over a box of size du x dv from its
 * Bezier net pw ((p + 1) x (q + 1) homogeneous points, u fastest): S and
 * its derivatives up to order 2, the first fundamental form, the
 * midpoint-radius form of H, and the bounds of the third derivatives
 * that the certificates of its sub-boxes are made from (taylor_cert()).
 * Returns 0, or PX_E_INVAL where the weights are not positive.
 */
static int net_cert(const double *pw, int p, int q, double du, double dv,
		    struct rcert *ce)
{
	struct iv W, Wu, Wv, Wuu, Wuv, Wvv, Su[3], Sv[3], nr[6][4];
	double *mem = NULL;
	int k, i, rational = 0;
	memset(ce, 0, sizeof(*ce));
	for (i = 1; i < (p + 1) * (q + 1); i++)
		rational |= pw[4 * i + 3] != pw[3];
	net_ranges(pw, p, q, du, dv, nr);
	W = nr[0][3];
	if (!(W.lo > 0.0))
		return PX_E_INVAL;
	ce->rat = rational;
	if (rational && p >= 2 && q >= 2) {
		mem = malloc((size_t)ST_RAT_POLYS * TP_LEN * sizeof(double) +
			     sizeof(struct tp_binom));
		if (!mem)
			return PX_E_NOMEM;
		tp_binom_init((struct tp_binom *)(mem + (size_t)ST_RAT_POLYS * TP_LEN));
	}
	Wu = nr[1][3];
	Wv = nr[2][3];
	Wuu = nr[3][3];
	Wuv = nr[4][3];
	Wvv = nr[5][3];
	for (k = 0; k < 3; k++) {
		struct iv S = {INFINITY, -INFINITY};
		/* the surface lies in the hull of its projected net */
		for (i = 0; i < (p + 1) * (q + 1); i++)
			iv_grow(&S, pw[4 * i + k] / pw[4 * i + 3]);
		S = iv_pad(S);
		ce->S[k] = S;
		/* quotient rule on S = X / W, differentiated */
		Su[k] = iv_pad(iv_divw(iv_sub(nr[1][k],
					      iv_mul(S, Wu)), W));
		Sv[k] = iv_pad(iv_divw(iv_sub(nr[2][k],
					      iv_mul(S, Wv)), W));
		ce->Suu[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(nr[3][k],
				      iv_scale(iv_mul(Su[k], Wu), 2.0)),
			       iv_mul(S, Wuu)), W));
		ce->Svv[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(nr[5][k],
				      iv_scale(iv_mul(Sv[k], Wv), 2.0)),
			       iv_mul(S, Wvv)), W));
		ce->Suv[k] = iv_pad(iv_divw(
			iv_sub(iv_sub(iv_sub(nr[4][k],
					     iv_mul(Su[k], Wv)),
				      iv_mul(Sv[k], Wu)),
			       iv_mul(S, Wuv)), W));
	}
	if (mem)
		rat_tight(pw, p, q, du, dv, Su, Sv, ce->Suu, ce->Suv, ce->Svv, mem,
			  (const struct tp_binom *)(mem + (size_t)ST_RAT_POLYS * TP_LEN));
	free(mem);
	{
		/* third derivatives, for the certificates of sub-boxes
		 * (taylor_cert()): X = S W differentiated three times */
		struct iv n3[4][4], Wt[4];
		net_ranges3(pw, p, q, du, dv, n3);
		for (i = 0; i < 4; i++)
			Wt[i] = n3[i][3];
		for (k = 0; k < 3; k++) {
			struct iv S = ce->S[k], T[4];
			T[0] = iv_sub(iv_sub(iv_sub(n3[0][k], iv_scale(iv_mul(ce->Suu[k], Wu), 3.0)),
					     iv_scale(iv_mul(Su[k], Wuu), 3.0)),
				      iv_mul(S, Wt[0]));
			T[1] = iv_sub(iv_sub(iv_sub(iv_sub(iv_sub(n3[1][k], iv_mul(ce->Suu[k], Wv)),
						      iv_scale(iv_mul(ce->Suv[k], Wu), 2.0)),
					       iv_scale(iv_mul(Su[k], Wuv), 2.0)),
					iv_mul(Sv[k], Wuu)),
				      iv_mul(S, Wt[1]));
			T[2] = iv_sub(iv_sub(iv_sub(iv_sub(iv_sub(n3[2][k], iv_mul(ce->Svv[k], Wu)),
						      iv_scale(iv_mul(ce->Suv[k], Wv), 2.0)),
					       iv_scale(iv_mul(Sv[k], Wuv), 2.0)),
					iv_mul(Su[k], Wvv)),
				      iv_mul(S, Wt[2]));
			T[3] = iv_sub(iv_sub(iv_sub(n3[3][k], iv_scale(iv_mul(ce->Svv[k], Wv), 3.0)),
					     iv_scale(iv_mul(Sv[k], Wvv), 3.0)),
				      iv_mul(S, Wt[3]));
			for (i = 0; i < 4; i++)
				ce->t3[i][k] = iv_mag(iv_pad(iv_divw(iv_pad(T[i]), W)));
		}
	}
	cert_fill(ce, Su, Sv, du, dv);
	return PX_OK;
}

/* The rest of certificate ce from its enclosures of S, Su, Sv and the
 * second derivatives over a box of size du x dv: the first fundamental
 * form, the bounds m_ij and the midpoint-radius form of H. */
static void cert_fill(struct rcert *ce, const struct iv Su[3], const struct iv Sv[3],
		      double du, double dv)
{
	int k, i;
	ce->G11 = ce->G12 = ce->G22 = iv_pt(0.0);
	ce->m11 = ce->m12 = ce->m22 = 0.0;
	for (k = 0; k < 3; k++) {
		struct iv a = Su[k], b = Sv[k], sa = iv_mul(a, a), sb = iv_mul(b, b);
		/* squares are not negative */
		if (a.lo <= 0.0 && a.hi >= 0.0)
			sa.lo = 0.0;
		if (b.lo <= 0.0 && b.hi >= 0.0)
			sb.lo = 0.0;
		ce->G11 = iv_add(ce->G11, sa);
		ce->G22 = iv_add(ce->G22, sb);
		ce->G12 = iv_add(ce->G12, iv_mul(a, b));
		ce->m11 += iv_mag(ce->Suu[k]);
		ce->m12 += iv_mag(ce->Suv[k]);
		ce->m22 += iv_mag(ce->Svv[k]);
	}
	ce->G11 = iv_pad(ce->G11);
	ce->G12 = iv_pad(ce->G12);
	ce->G22 = iv_pad(ce->G22);
	{
		/* midpoint-radius form: (S - x) . Sij with S = sm +- sr,
		 * Sij = hm +- hr per coordinate lies in
		 * (sm - x) . hm +- (|sm - x| . hr + sr . |hm| + sr . hr) */
		const struct iv *G[3] = {&ce->G11, &ce->G12, &ce->G22};
		const struct iv *D[3] = {ce->Suu, ce->Suv, ce->Svv};
		double *sm = &ce->smid.x;
		for (k = 0; k < 3; k++)
			sm[k] = 0.5 * (ce->S[k].lo + ce->S[k].hi);
		for (i = 0; i < 3; i++) {
			double *b = &ce->B[i].x, *qq = &ce->Q[i].x;
			ce->A[i] = 0.5 * (G[i]->lo + G[i]->hi);
			ce->R[i] = 0.5 * (G[i]->hi - G[i]->lo);
			for (k = 0; k < 3; k++) {
				double hm = 0.5 * (D[i][k].lo + D[i][k].hi);
				double hr = 0.5 * (D[i][k].hi - D[i][k].lo);
				double sr = 0.5 * (ce->S[k].hi - ce->S[k].lo);
				b[k] = hm;
				qq[k] = hr;
				ce->A[i] += sm[k] * hm;
				ce->R[i] += sr * fabs(hm) + sr * hr;
			}
			ce->R[i] = iv_pad(iv_pt(ce->R[i])).hi;
		}
	}
	ce->hu = 0.5 * du;
	ce->hv = 0.5 * dv;
}

/*
 * Enclosures of the third difference nets of the Bezier net P (as
 * net_ranges() the lower ones), every homogeneous coordinate: r[0] order
 * (3, 0), r[1] (2, 1), r[2] (1, 2), r[3] (0, 3); an order above the
 * degree is 0.
 */
static void net_ranges3(const double *P, int p, int q, double du, double dv,
			struct iv r[4][4])
{
	int i, j, k, o, n = p + 1;
	for (o = 0; o < 4; o++) {
		int a = 3 - o, b = o, x, y;
		double f = 1.0;
		for (i = 0; i < a; i++)
			f *= (double)(p - i) / du;
		for (j = 0; j < b; j++)
			f *= (double)(q - j) / dv;
		for (k = 0; k < 4; k++) {
			struct iv *z = &r[o][k];
			if (a > p || b > q) {
				*z = iv_pt(0.0);
				continue;
			}
			z->lo = INFINITY;
			z->hi = -INFINITY;
			for (j = 0; j + b <= q; j++)
				for (i = 0; i + a <= p; i++) {
					double d = 0.0;
					for (y = 0; y <= b; y++)
						for (x = 0; x <= a; x++)
							d += ((a - x + b - y) & 1 ? -1.0 : 1.0) *
							     px_bern_binom(a, x) * px_bern_binom(b, y) *
							     P[4 * ((j + y) * n + i + x) + k];
					iv_grow(z, d);
				}
			z->lo *= f;
			z->hi *= f;
			*z = iv_pad(*z);
		}
	}
}

/* The centre values of certificate ce from the evaluation d there. */
static void centre_set(struct rcert *ce, const struct px_nurbs_surf_derivs *d)
{
	ce->sc = d->s;
	ce->suc = d->su;
	ce->svc = d->sv;
	ce->n1 = fabs(d->su.x) + fabs(d->su.y) + fabs(d->su.z);
	ce->n2 = fabs(d->sv.x) + fabs(d->sv.y) + fabs(d->sv.z);
	/* (hu, hv and the m_ij are set: cert_fill() comes first) */
	ce->ie1 = 1.0 / (ce->n1 + ce->m11 * ce->hu + ce->m12 * ce->hv);
	ce->ie2 = 1.0 / (ce->n2 + ce->m12 * ce->hu + ce->m22 * ce->hv);
	ce->im11 = 1.0 / ce->m11;
	ce->im22 = 1.0 / ce->m22;
}

/*
 * Certificate of sub-box b (u0, u1, v0, v1) of the box of certificate
 * top, at update time: the values at b's centre and the mean value
 * theorem per coordinate, S_uu in S_uu(c) +- (|S_uuu| h_u + |S_uuv| h_v)
 * and so on down to S, with top's third-derivative bounds (they hold
 * over every piece of its box); then cert_fill(). About as wide as b:
 * the width falls with the piece, which a hull of the box's own net
 * cut down to it would give too, at a seventh of the cost (measured:
 * 2,000 instructions against 14,000).
 */
static void taylor_cert(const struct ssurf *f, const double b[4],
			const struct rcert *top, struct rcert *ce)
{
	struct px_nurbs_surf_derivs d;
	struct iv Su[3], Sv[3];
	double hu = 0.5 * (b[1] - b[0]), hv = 0.5 * (b[3] - b[2]);
	int k;
	memset(ce, 0, sizeof(*ce));
	surf_eval2(f, b[0] + hu, b[2] + hv, &d);
	for (k = 0; k < 3; k++) {
		const double *t = &top->t3[0][0];
		double s = (&d.s.x)[k], su = (&d.su.x)[k], sv = (&d.sv.x)[k];
		double suu = (&d.suu.x)[k], suv = (&d.suv.x)[k], svv = (&d.svv.x)[k];
		double ruu = t[0 * 3 + k] * hu + t[1 * 3 + k] * hv;
		double ruv = t[1 * 3 + k] * hu + t[2 * 3 + k] * hv;
		double rvv = t[2 * 3 + k] * hu + t[3 * 3 + k] * hv;
		struct iv x;
		x.lo = suu - ruu;
		x.hi = suu + ruu;
		ce->Suu[k] = iv_pad(x);
		x.lo = suv - ruv;
		x.hi = suv + ruv;
		ce->Suv[k] = iv_pad(x);
		x.lo = svv - rvv;
		x.hi = svv + rvv;
		ce->Svv[k] = iv_pad(x);
		ruu = iv_mag(ce->Suu[k]) * hu + iv_mag(ce->Suv[k]) * hv;
		rvv = iv_mag(ce->Suv[k]) * hu + iv_mag(ce->Svv[k]) * hv;
		x.lo = su - ruu;
		x.hi = su + ruu;
		Su[k] = iv_pad(x);
		x.lo = sv - rvv;
		x.hi = sv + rvv;
		Sv[k] = iv_pad(x);
		ruu = iv_mag(Su[k]) * hu + iv_mag(Sv[k]) * hv;
		x.lo = s - ruu;
		x.hi = s + ruu;
		ce->S[k] = iv_pad(x);
	}
	cert_fill(ce, Su, Sv, 2.0 * hu, 2.0 * hv);
	centre_set(ce, &d);
}

/* The centre values of certificate ce of box (u0, u1, v0, v1). */
static void cert_centre(const struct ssurf *f, double u0, double u1, double v0,
			double v1, struct rcert *ce)
{
	struct px_nurbs_surf_derivs d;
	surf_eval2(f, 0.5 * (u0 + u1), 0.5 * (v0 + v1), &d);
	centre_set(ce, &d);
}

/* Certificate data of region cell c (setup; work: extraction scratch). */
static int cell_cert(struct px_strack *t, struct scell *c, const struct ssurf *f,
		     double *work, size_t wl, const int side_open[4])
{
	struct rcert *ce = &c->cert;
	struct px_nurbs_surf sub;
	double du = c->u1 - c->u0, dv = c->v1 - c->v0;
	int p = f->s.degree[0], q = f->s.degree[1], rc;
	rc = px_nurbs_surf_extract_work(&f->s, c->u0, c->u1, c->v0, c->v1, work,
					wl, &sub);
	if (rc)
		return rc;
	if (sub.n_ctrl[0] != p + 1 || sub.n_ctrl[1] != q + 1)
		return PX_E_INVAL;
	rc = net_cert(sub.pw, p, q, du, dv, ce);
	if (rc)
		return rc;
	cert_centre(f, c->u0, c->u1, c->v0, c->v1, ce);
	cert_sides(f, c, ce, side_open);
	(void)t;
	return PX_OK;
}

/* The side tests' data of certificate ce (hu, hv set) of box c for its
 * open sides (side_open: u0, u1, v0, v1). */
static void cert_sides(const struct ssurf *f, const struct scell *c, struct rcert *ce,
		       const int side_open[4])
{
	struct px_nurbs_surf_derivs d;
	double du = c->u1 - c->u0, dv = c->v1 - c->v0;
	int k;
	ce->nside = 0;
	for (k = 0; k < 4; k++) {
		struct cside *sd;
		double u, v;
		if (!side_open[k])
			continue;
		sd = &ce->side[ce->nside++];
		/* sides 0, 1: u = u0, u1 (along v); 2, 3: v = v0, v1 */
		u = k == 0 ? c->u0 : k == 1 ? c->u1 : 0.5 * (c->u0 + c->u1);
		v = k == 2 ? c->v0 : k == 3 ? c->v1 : 0.5 * (c->v0 + c->v1);
		/* evaluate on the cell's own patch (one-sided at a crease) */
		u = fmin(fmax(u, c->u0 + 1e-13 * du), c->u1 - 1e-13 * du);
		v = fmin(fmax(v, c->v0 + 1e-13 * dv), c->v1 - 1e-13 * dv);
		surf_eval2(f, u, v, &d);
		sd->s = d.s;
		sd->su = d.su;
		sd->sv = d.sv;
		sd->n1 = fabs(d.su.x) + fabs(d.su.y) + fabs(d.su.z);
		sd->n2 = fabs(d.sv.x) + fabs(d.sv.y) + fabs(d.sv.z);
		sd->along = k < 2;
		sd->h = k < 2 ? ce->hv : ce->hu;
		/* the side point is off the exact side by 1e-13 of the cell:
		 * cover it in the half length */
		sd->h *= 1.0 + 1e-12;
	}
}

/* 1 when x is a break of the surface along dir where it is less than
 * C2 (knot multiplicity above degree - 2): points enter and leave a
 * patch there as through an edge. */
static int crease_at(const struct ssurf *f, int dir, double x)
{
	return px__nurbs_mult(f->s.knots[dir], f->s.n_knots[dir], x) >
	       f->s.degree[dir] - 2;
}

/* Which sides of cell c are open domain edges or creases (u0, u1, v0,
 * v1): where critical points enter and leave. */
static void sides_open(const struct ssurf *f, const struct scell *c, int open[4])
{
	open[0] = c->u0 == f->u0 ? !f->wrap_u : crease_at(f, 0, c->u0);
	open[1] = c->u1 == f->u1 ? !f->wrap_u : crease_at(f, 0, c->u1);
	open[2] = c->v0 == f->v0 ? !f->wrap_v : crease_at(f, 1, c->v0);
	open[3] = c->v1 == f->v1 ? !f->wrap_v : crease_at(f, 1, c->v1);
}

/* Quarter k of region cell rg as a cell of its own (bounds and
 * surface; box_of()). */
static void quarter_of(const struct scell *rg, int k, struct scell *q)
{
	double b[4];
	memset(q, 0, sizeof(*q));
	q->surf = rg->surf;
	box_of(rg, k, b);
	q->u0 = b[0];
	q->u1 = b[1];
	q->v0 = b[2];
	q->v1 = b[3];
}

/* The entry of side k (sides_open()'s order) among c's side tests:
 * cell_cert() keeps the open sides alone, in that order. */
static int side_entry(const struct ssurf *f, const struct scell *c, int k)
{
	int open[4], a, n = 0;
	sides_open(f, c, open);
	for (a = 0; a < k; a++)
		n += open[a];
	return n;
}

/* The certificates of the four quarters of region cell rg. */
static int quarter_certs(struct px_strack *t, const struct scell *rg,
			 const struct ssurf *f, double *work, size_t wl,
			 struct rcert out[4])
{
	int k, rc, open[4];
	for (k = 0; k < 4; k++) {
		struct scell q;
		quarter_of(rg, k, &q);
		sides_open(f, &q, open);
		rc = cell_cert(t, &q, f, work, wl, open);
		if (rc)
			return rc;
		out[k] = q.cert;
	}
	return 0;
}

/* The boundary pieces of surface si for winding() (after the region
 * and quarter certificates are made). Returns 0 or PX_E_NOMEM. */
static int wind_pieces(struct px_strack *t, int si)
{
	struct ssurf *f = &t->sf[si];
	int nu = 2 * f->ncu, nv = 2 * f->ncv, e, n, i;
	f->wind_ok = 0;
	f->nwp = 0;
	/* E jumps at a C0 line */
	if (has_pole(f) || px_nurbs_surf_breaks(&f->s, 0, NULL, 0) > 0 ||
	    px_nurbs_surf_breaks(&f->s, 1, NULL, 0) > 0)
		return 0;
	n = (f->wrap_v ? 0 : 2 * nu) + (f->wrap_u ? 0 : 2 * nv);
	if (n > 0) {
		f->wp = calloc((size_t)n, sizeof(*f->wp));
		if (!f->wp)
			return PX_E_NOMEM;
	}
	/* e 0: v = v0, u rising; 1: u = u1, v rising; 2: v = v1, u falling;
	 * 3: u = u0, v falling (counter-clockwise) */
	for (e = 0; e < 4; e++) {
		int len = e & 1 ? nv : nu, side = (int[]){2, 1, 3, 0}[e];
		/* the quarters along the side, in the order traversed */
		static const int qk[4][2] = {{0, 1}, {1, 3}, {3, 2}, {2, 0}};
		if ((e & 1) ? f->wrap_u : f->wrap_v)
			continue;
		for (i = 0; i < len; i++) {
			int s2 = e >= 2 ? len - 1 - i : i;
			int I = e == 0 ? s2 : e == 1 ? nu - 1 : e == 2 ? s2 : 0;
			int J = e == 0 ? 0 : e == 1 ? s2 : e == 2 ? nv - 1 : s2;
			int ri = 4 * (f->first_cell + (J / 2) * f->ncu + I / 2) + (I & 1) + 2 * (J & 1);
			const struct scell *rg = &t->rcell[ri];
			struct wpiece *w = &f->wp[f->nwp++];
			int q;
			double x0, x1;
			w->ri = ri;
			w->side = side_entry(f, rg, side);
			for (q = 0; q < 2; q++) {
				struct scell qc;
				quarter_of(rg, qk[e][q], &qc);
				w->qk[q] = qk[e][q];
				w->qside[q] = side_entry(f, &qc, side);
			}
			x0 = e & 1 ? (e == 1 ? rg->v0 : rg->v1) : (e == 0 ? rg->u0 : rg->u1);
			x1 = e & 1 ? (e == 1 ? rg->v1 : rg->v0) : (e == 0 ? rg->u1 : rg->u0);
			for (q = 0; q < 3; q++) {
				struct px_nurbs_surf_derivs d;
				double x = x0 + 0.5 * q * (x1 - x0);
				double u = e & 1 ? (e == 1 ? f->u1 : f->u0) : x;
				double v = e & 1 ? x : (e == 0 ? f->v0 : f->v1);
				surf_eval2(f, u, v, &d);
				w->s[q] = d.s;
				w->su[q] = d.su;
				w->sv[q] = d.sv;
			}
		}
	}
	f->wind_ok = 1;
	return 0;
}

void px_strack_free(struct px_strack *t)
{
	int i;
	if (!t)
		return;
	px_dist_model_free(t->dist);
	px_track_free(t->ct);
	if (t->sf)
		for (i = 0; i < t->n_surf; i++) {
			free(t->sf[i].mem);
			free(t->sf[i].pt);
			free(t->sf[i].pool);
			free(t->sf[i].pool4);
			free(t->sf[i].pu);
			free(t->sf[i].pv);
			free(t->sf[i].cu);
			free(t->sf[i].cv);
			free(t->sf[i].z);
			free(t->sf[i].tmp);
			free(t->sf[i].wp);
		}
	free(t->sf);
	free(t->cell);
	free(t->rcell);
	free(t->qcert);
	free(t->pcache);
	free(t->scache);
	free(t->edge);
	free(t->pole);
	free(t->ex);
	free(t->gdue);
	free(t->cube);
	free(t->popped);
	free(t->hits);
	free(t->pend);
	free(t->pend_ps);
	free(t->pend_kind);
	free(t->ring_list);
	free(t->pend_need);
	free(t->cbox);
	free(t);
}

/* Copy a surface into owned memory. */
static int surf_copy(struct ssurf *f, const struct px_nurbs_surf *s)
{
	size_t nu = (size_t)s->n_knots[0], nv = (size_t)s->n_knots[1];
	size_t np = 4 * (size_t)s->n_ctrl[0] * (size_t)s->n_ctrl[1];
	f->mem = malloc((nu + nv + np) * sizeof(double));
	if (!f->mem)
		return PX_E_NOMEM;
	memcpy(f->mem, s->knots[0], nu * sizeof(double));
	memcpy(f->mem + nu, s->knots[1], nv * sizeof(double));
	memcpy(f->mem + nu + nv, s->pw, np * sizeof(double));
	f->s = *s;
	f->s.knots[0] = f->mem;
	f->s.knots[1] = f->mem + nu;
	f->s.pw = f->mem + nu + nv;
	return PX_OK;
}

/*
 * Cells per span along u (ncs_u, one per patch column) and v. A rational
 * patch's derivative enclosures widen with the spread of its weights
 * (the quotient rule over a cell where W changes by a factor: the
 * bench's sheet with weights 0.6-1.5 had S_uu enclosed in [-130, 11]
 * over a cell), and with them the certificates' radii fall to nothing;
 * halving the cells narrows them about fourfold. So a span whose patches
 * have weights more than ST_WRATIO_FINE apart gets twice the cells (at
 * most 16): on that sheet instructions over the bench paths at 0.01 and
 * 0.1 % steps fell 1.2-2.5 times, their 99th percentile 1.8-2.2 times
 * (at 1 % they stayed: the steps cross cells either way); the setup
 * and memory of those cells grow fourfold. Polynomial patches and
 * circular arcs (weights 1 and 0.71) keep cells_per_span.
 */
#define ST_WRATIO_FINE 1.5

int px__strack_coarse = 0;

static void span_cells(const struct ssurf *f, int cps, int *ncs_u, int *ncs_v)
{
	int a, b, fine = 2 * cps > 16 ? 16 : 2 * cps;
	for (a = 0; a < f->npu; a++)
		ncs_u[a] = cps;
	for (b = 0; b < f->npv; b++)
		ncs_v[b] = cps;
	for (b = 0; b < f->npv; b++)
		for (a = 0; a < f->npu; a++)
			if (f->pt[b * f->npu + a].wratio > ST_WRATIO_FINE &&
			    !px__strack_coarse) {
				ncs_u[a] = fine;
				ncs_v[b] = fine;
			}
}

/* Cell bounds: each span [b[k], b[k + 1]] cut in ncs[k] equal parts. */
static void span_bounds_fill(double *cb, const double *b, int nb, const int *ncs)
{
	int k, j, n = 0;
	for (k = 0; k < nb - 1; k++)
		for (j = 0; j < ncs[k]; j++)
			cb[n++] = b[k] + (b[k + 1] - b[k]) * j / ncs[k];
}

/* Power-form Bezier patches of a surface between the bounds ub x vb. */
static int build_patches(struct ssurf *f, const double *ub, int nu,
			 const double *vb, int nv)
{
	int p = f->s.degree[0], q = f->s.degree[1], np = (p + 1) * (q + 1);
	int a, b, i, j, k, r;
	size_t wl = PX_NURBS_SURF_WORK_LEN(p, q, f->s.n_ctrl[0], f->s.n_ctrl[1]);
	double *work = malloc(wl * sizeof(double)), tmp[PX_NURBS_MAX_DEGREE + 1];
	f->npu = nu - 1;
	f->npv = nv - 1;
	f->pt = calloc((size_t)(f->npu * f->npv), sizeof(*f->pt));
	f->pool = calloc((size_t)(f->npu * f->npv) * 4 * (size_t)np, sizeof(double));
	f->pool4 = NULL;
	if (p == 3 && q == 3 && have_fma()) {
		/* 512 bytes a patch: a multiple of the alignment */
		f->pool4 = aligned_alloc(64, (size_t)(f->npu * f->npv) * 64 * sizeof(double));
		if (!f->pool4) {
			free(work);
			return PX_E_NOMEM;
		}
	}
	f->pu = malloc((size_t)nu * sizeof(double));
	f->pv = malloc((size_t)nv * sizeof(double));
	if (!work || !f->pt || !f->pool || !f->pu || !f->pv) {
		free(work);
		return PX_E_NOMEM;
	}
	memcpy(f->pu, ub, (size_t)nu * sizeof(double));
	memcpy(f->pv, vb, (size_t)nv * sizeof(double));
	/* the fault: a thousand times as long, on any Hessian and weights */
	f->quick_loose = px__strack_quick_fault;
	f->quick_u = (f->quick_loose ? 1e3 : 1.0) * ST_QUICK * f->du / f->npu;
	f->quick_v = (f->quick_loose ? 1e3 : 1.0) * ST_QUICK * f->dv / f->npv;
	for (b = 0; b < f->npv; b++)
		for (a = 0; a < f->npu; a++) {
			struct patch *pt = &f->pt[b * f->npu + a];
			struct px_nurbs_surf sub;
			double pt_w;
			double *c = f->pool + (size_t)(b * f->npu + a) * 4 * (size_t)np;
			int rc = px_nurbs_surf_extract_work(&f->s, ub[a], ub[a + 1], vb[b],
							    vb[b + 1], work, wl, &sub);
			if (rc || sub.n_ctrl[0] != p + 1 || sub.n_ctrl[1] != q + 1) {
				free(work);
				return rc ? rc : PX_E_INVAL;
			}
			pt->u0 = ub[a];
			pt->u1 = ub[a + 1];
			pt->v0 = vb[b];
			pt->v1 = vb[b + 1];
			pt->iu = 1.0 / (pt->u1 - pt->u0);
			pt->iv = 1.0 / (pt->v1 - pt->v0);
			pt->p = p;
			pt->q = q;
			pt->c = c;
			{
				/* equal weights: divide them out, evaluate as a
				 * polynomial */
				double w0 = sub.pw[3], wlo = w0, whi = w0;
				int m;
				pt->rat = 0;
				for (m = 0; m < np; m++) {
					double w = sub.pw[4 * m + 3];
					if (w != w0)
						pt->rat = 1;
					wlo = w < wlo ? w : wlo;
					whi = w > whi ? w : whi;
				}
				pt->wratio = whi / wlo;
				pt_w = pt->rat ? 1.0 : w0;
				if (pt->wratio > ST_QUICK_WRATIO && !f->quick_loose)
					f->quick_u = f->quick_v = 0.0;
			}
			for (k = 0; k < 4; k++) {
				double *ck = c + k * np;
				for (j = 0; j <= q; j++)
					for (i = 0; i <= p; i++)
						ck[j * (p + 1) + i] =
							k == 3 && !pt->rat ? 1.0
									   : sub.pw[4 * (j * (p + 1) + i) + k] / pt_w;
				/* Bernstein to power form along s, then along t */
				for (j = 0; j <= q; j++) {
					double *row = ck + j * (p + 1);
					for (i = 0; i <= p; i++) {
						double v = 0.0;
						for (r = 0; r <= i; r++)
							v += (((i - r) & 1) ? -1.0 : 1.0) *
							     px_bern_binom(i, r) * row[r];
						tmp[i] = px_bern_binom(p, i) * v;
					}
					memcpy(row, tmp, (size_t)(p + 1) * sizeof(double));
				}
				for (i = 0; i <= p; i++) {
					for (j = 0; j <= q; j++) {
						double v = 0.0;
						for (r = 0; r <= j; r++)
							v += (((j - r) & 1) ? -1.0 : 1.0) *
							     px_bern_binom(j, r) * ck[r * (p + 1) + i];
						tmp[j] = px_bern_binom(q, j) * v;
					}
					for (j = 0; j <= q; j++)
						ck[j * (p + 1) + i] = tmp[j];
				}
			}
			pt->c4 = NULL;
			if (f->pool4) {
				double *c4 = f->pool4 + (size_t)(b * f->npu + a) * 64;
				for (k = 0; k < 4; k++)
					for (i = 0; i < 16; i++)
						c4[4 * i + k] = c[k * 16 + i];
				pt->c4 = c4;
			}
		}
	free(work);
	return PX_OK;
}

int px_strack_create(const struct px_nurbs_curve *curves, int n_curves,
		     const struct px_nurbs_surf *surfs, int n_surfs,
		     const struct px_strack_opts *opts, struct px_strack **out)
{
	struct px_strack *t;
	struct px_strack_opts o;
	struct px_nurbs_curve *cc = NULL;
	double **cpw = NULL, *ub = NULL, *vb = NULL;
	int *ncs_u = NULL, *ncs_v = NULL;
	double *work = NULL;
	size_t wl = 0, npend;
	int rc, i, j, k, max_knots = 0, cap_edges, n_cc = 0, cell_cap = 0;
	px_aabb bounds;

	if (!out || (n_curves > 0 && !curves) || !surfs || n_surfs <= 0 ||
	    n_curves < 0)
		return PX_E_INVAL;
	*out = NULL;
	if (opts)
		o = *opts;
	else
		px_strack_opts_default(&o);
	if (o.cells_per_span < 1 || o.cells_per_span > 16 || o.seeds < 1 ||
	    o.seeds > 8 || o.samples < 2 || o.samples > 32 || o.max_crit < 2 ||
	    o.max_crit > 1 << 20 || o.verify_every < 0 || o.max_solves < 0 ||
	    o.max_tests < 0 ||
	    !(o.work_margin >= 0.0))
		return PX_E_INVAL;
	for (i = 0; i < n_surfs; i++) {
		if (surfs[i].degree[0] < 1 || surfs[i].degree[1] < 1 ||
		    surfs[i].degree[0] > PX_NURBS_MAX_DEGREE ||
		    surfs[i].degree[1] > PX_NURBS_MAX_DEGREE)
			return PX_E_RANGE;
		if (!surfs[i].knots[0] || !surfs[i].knots[1] || !surfs[i].pw)
			return PX_E_INVAL;
		for (k = 0; k < 2; k++)
			if (surfs[i].n_knots[k] > max_knots)
				max_knots = surfs[i].n_knots[k];
	}
	t = calloc(1, sizeof(*t));
	if (!t)
		return PX_E_NOMEM;
	t->opts = o;
	{
		struct cell_done none;
		int sk[ST_SEEDS_MAX];
		memset(&none, 0, sizeof(none));
		t->full_seeds = cell_seeds(&none, sk);
	}
	t->n_curves = n_curves;
	t->n_surf = n_surfs;
	rc = px_dist_model_create(curves, n_curves, surfs, n_surfs, o.dist,
				  &t->dist);
	if (rc) {
		free(t);
		return rc;
	}
	t->sf = calloc((size_t)n_surfs, sizeof(*t->sf));
	ub = calloc((size_t)max_knots + 2, sizeof(double));
	vb = calloc((size_t)max_knots + 2, sizeof(double));
	ncs_u = calloc((size_t)max_knots + 2, sizeof(int));
	ncs_v = calloc((size_t)max_knots + 2, sizeof(int));
	if (!t->sf || !ub || !vb || !ncs_u || !ncs_v) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	/* surfaces, domains, cells */
	bounds = px_aabb_empty();
	for (i = 0; i < n_curves; i++) {
		px_aabb hb = px_nurbs_curve_aabb(&curves[i]);
		bounds = px_aabb_union(&bounds, &hb);
	}
	for (i = 0; i < n_surfs; i++) {
		struct ssurf *f = &t->sf[i];
		px_aabb hb = px_nurbs_surf_aabb(&surfs[i]);
		int nu, nv;
		bounds = px_aabb_union(&bounds, &hb);
		rc = surf_copy(f, &surfs[i]);
		if (rc)
			goto fail;
		px_nurbs_surf_domain(&f->s, &f->u0, &f->u1, &f->v0, &f->v1);
		f->du = f->u1 - f->u0;
		f->dv = f->v1 - f->v0;
		{
			double tol = 1e-12 * (1.0 + px_aabb_diagonal(&hb));
			f->wrap_u = px_nurbs_surf_seam(&f->s, 0, tol, 1e-9) >= 1;
			f->wrap_v = px_nurbs_surf_seam(&f->s, 1, tol, 1e-9) >= 1;
		}
		nu = span_bounds(&f->s, 0, f->u0, f->u1, ub);
		nv = span_bounds(&f->s, 1, f->v0, f->v1, vb);
		t->n_patches += (nu - 1) * (nv - 1);
		rc = build_patches(f, ub, nu, vb, nv);
		if (rc)
			goto fail;
		span_cells(f, o.cells_per_span, ncs_u, ncs_v);
		for (f->ncu = 0, k = 0; k < nu - 1; k++)
			f->ncu += ncs_u[k];
		for (f->ncv = 0, k = 0; k < nv - 1; k++)
			f->ncv += ncs_v[k];
		f->cu = calloc((size_t)f->ncu + 1, sizeof(double));
		f->cv = calloc((size_t)f->ncv + 1, sizeof(double));
		f->cap = o.max_crit;
		f->z = calloc((size_t)f->cap, sizeof(*f->z));
		f->tmp = calloc((size_t)f->cap, sizeof(*f->tmp));
		if (!f->cu || !f->cv || !f->z || !f->tmp) {
			rc = PX_E_NOMEM;
			goto fail;
		}
		span_bounds_fill(f->cu, ub, nu, ncs_u);
		f->cu[f->ncu] = f->u1;
		span_bounds_fill(f->cv, vb, nv, ncs_v);
		f->cv[f->ncv] = f->v1;
		f->first_cell = cell_cap;
		cell_cap += f->ncu * f->ncv;
	}
	t->scale = px_aabb_diagonal(&bounds);
	if (!(t->scale > 0.0))
		t->scale = 1.0;
	{
		double m = o.work_margin * t->scale;
		t->work.min = px_v3_sub(bounds.min, px_v3(m, m, m));
		t->work.max = px_v3_add(bounds.max, px_v3(m, m, m));
	}
	t->cell = calloc((size_t)cell_cap + 1, sizeof(*t->cell));
	t->rcell = calloc(4 * (size_t)cell_cap + 1, sizeof(*t->rcell));
	t->qcert = calloc(16 * (size_t)cell_cap + 1, sizeof(*t->qcert));
	t->ex = calloc((size_t)cell_cap + 1, sizeof(*t->ex));
	t->gdue = calloc((size_t)cell_cap / ST_GROUP + 2, sizeof(*t->gdue));
	t->cube = calloc((size_t)cell_cap + 1, sizeof(*t->cube));
	t->popped = calloc((size_t)cell_cap + 1, sizeof(int));
	t->hits = calloc((size_t)cell_cap + 1, sizeof(int));
	/* pending items: each cell once, a crossing solve a hit, ST_RINGS
	 * bounds a surface */
	npend = (2 + ST_RINGS) * (size_t)cell_cap + 2;
	t->pend = calloc(npend, sizeof(int));
	t->pend_ps = calloc(npend, sizeof(px_vec3));
	t->pend_need = calloc(npend, sizeof(double));
	t->pend_kind = calloc(npend, 1);
	t->ring_list = calloc((size_t)cell_cap + 1, sizeof(int));
	for (i = 0; i < n_surfs; i++) {
		const struct px_nurbs_surf *sf = &t->sf[i].s;
		size_t l = PX_NURBS_SURF_WORK_LEN(sf->degree[0], sf->degree[1],
						  sf->n_ctrl[0], sf->n_ctrl[1]);
		if (l > wl)
			wl = l;
	}
	work = malloc(wl * sizeof(double));
	if (!t->cell || !t->rcell || !t->qcert || !t->ex || !t->gdue || !t->cube || !t->popped || !t->hits ||
	    !t->pend || !t->pend_ps || !t->pend_kind || !t->pend_need ||
	    !t->ring_list || !work) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	for (i = 0; i < n_surfs; i++) {
		struct ssurf *f = &t->sf[i];
		for (k = 0; k < 4; k++)
			/* as for the poles below */
			f->pole[k] = !((k < 2 && f->wrap_u) || (k >= 2 && f->wrap_v)) &&
				     px_nurbs_surf_edge_collapsed(&f->s, k,
								  1e-12 * (1.0 + t->scale));
		for (j = 0; j < f->ncv; j++)
			for (k = 0; k < f->ncu; k++) {
				struct scell *c = &t->cell[f->first_cell + j * f->ncu + k];
				c->surf = i;
				c->u0 = f->cu[k];
				c->u1 = f->cu[k + 1];
				c->v0 = f->cv[j];
				c->v1 = f->cv[j + 1];
				{
					double um = 0.5 * (c->u0 + c->u1), vm = 0.5 * (c->v0 + c->v1);
					int ch;
					px_aabb cb = px_aabb_empty();
					c->child = 4 * (f->first_cell + j * f->ncu + k);
					for (ch = 0; ch < 4; ch++) {
						struct scell *rg = &t->rcell[c->child + ch];
						int open[4];
						px_aabb rb;
						rg->surf = i;
						rg->u0 = ch & 1 ? um : c->u0;
						rg->u1 = ch & 1 ? c->u1 : um;
						rg->v0 = ch & 2 ? vm : c->v0;
						rg->v1 = ch & 2 ? c->v1 : vm;
						sides_open(f, rg, open);
						if ((rg->u0 == f->u0 && f->pole[0]) ||
						    (rg->u1 == f->u1 && f->pole[1]) ||
						    (rg->v0 == f->v0 && f->pole[2]) ||
						    (rg->v1 == f->v1 && f->pole[3]))
							c->always = 1;
						rc = cell_cert(t, rg, f, work, wl, open);
						if (rc)
							goto fail;
						rc = quarter_certs(t, rg, f, work, wl,
								   &t->qcert[4 * (c->child + ch)]);
						if (rc)
							goto fail;
						rb.min = px_v3(rg->cert.S[0].lo, rg->cert.S[1].lo, rg->cert.S[2].lo);
						rb.max = px_v3(rg->cert.S[0].hi, rg->cert.S[1].hi, rg->cert.S[2].hi);
						cb = px_aabb_union(&cb, &rb);
					}
					c->size = px_aabb_diagonal(&cb);
					t->n_unbounded += c->always;
				}
			}
	}
	t->n_cells = cell_cap;
	for (i = 0; i < n_surfs; i++) {
		rc = wind_pieces(t, i);
		if (rc)
			goto fail;
	}

	/* curve tracker: free curves, then open (uncollapsed) edges and
	 * C0 creases as iso-curves; collapsed edges become poles */
	cap_edges = 0;
	for (i = 0; i < n_surfs; i++)
		cap_edges += 4 + 2 * max_knots;
	t->edge = calloc((size_t)cap_edges, sizeof(*t->edge));
	t->pole = calloc((size_t)4 * n_surfs, sizeof(*t->pole));
	cc = calloc((size_t)(n_curves + cap_edges), sizeof(*cc));
	cpw = calloc((size_t)cap_edges, sizeof(*cpw));
	if (!t->edge || !t->pole || !cc || !cpw) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	for (i = 0; i < n_curves; i++)
		cc[n_cc++] = curves[i];
	for (i = 0; i < n_surfs; i++) {
		struct ssurf *f = &t->sf[i];
		double tol = 1e-12 * (1.0 + t->scale), brk[64];
		int e, nb, d;
		for (e = 0; e < 4; e++) {
			int dir = e < 2 ? 1 : 0; /* curve direction */
			double tv = e == 0 ? f->u0 : e == 1 ? f->u1 : e == 2 ? f->v0 : f->v1;
			if ((e < 2 && f->wrap_u) || (e >= 2 && f->wrap_v))
				continue;
			if (px_nurbs_surf_edge_collapsed(&f->s, e, tol)) {
				struct pole *pl = &t->pole[t->n_poles++];
				f->pole[e] = 1;
				pl->u = e < 2 ? tv : f->u0;
				pl->v = e < 2 ? f->v0 : tv;
				pl->q = px_nurbs_surf_point(&f->s, pl->u, pl->v);
				pl->surf = i;
				continue;
			}
			{
				size_t len = 4 * (size_t)f->s.n_ctrl[dir];
				struct edge *ed = &t->edge[t->n_edges];
				cpw[t->n_edges] = malloc(len * sizeof(double));
				if (!cpw[t->n_edges]) {
					rc = PX_E_NOMEM;
					goto fail;
				}
				rc = px_nurbs_surf_iso_curve(&f->s, dir, tv, cpw[t->n_edges],
							     len, &cc[n_cc]);
				if (rc) {
					free(cpw[t->n_edges]);
					cpw[t->n_edges] = NULL;
					goto fail;
				}
				ed->surf = i;
				ed->dir = dir;
				ed->t = tv;
				t->n_edges++;
				n_cc++;
			}
		}
		for (d = 0; d < 2; d++) {
			/* creases across direction d: curves along the other */
			nb = px_nurbs_surf_breaks(&f->s, d, brk, 64);
			for (k = 0; k < nb && k < 64; k++) {
				int dir = 1 - d;
				size_t len = 4 * (size_t)f->s.n_ctrl[dir];
				struct edge *ed = &t->edge[t->n_edges];
				if (t->n_edges >= cap_edges)
					break;
				cpw[t->n_edges] = malloc(len * sizeof(double));
				if (!cpw[t->n_edges]) {
					rc = PX_E_NOMEM;
					goto fail;
				}
				rc = px_nurbs_surf_iso_curve(&f->s, dir, brk[k], cpw[t->n_edges],
							     len, &cc[n_cc]);
				if (rc) {
					free(cpw[t->n_edges]);
					cpw[t->n_edges] = NULL;
					goto fail;
				}
				ed->surf = i;
				ed->dir = dir;
				ed->t = brk[k];
				t->n_edges++;
				n_cc++;
			}
		}
	}
	if (n_cc > 0) {
		struct px_track_opts to;
		double *cw = NULL;
		size_t cwl = 0;
		int nb = 0;
		for (i = 0; i < n_cc; i++) {
			size_t l = PX_NURBS_CURVE_WORK_LEN(cc[i].degree, cc[i].n_ctrl);
			cwl = l > cwl ? l : cwl;
			nb += 2 * cc[i].n_knots;
		}
		t->cbox = calloc((size_t)nb, sizeof(*t->cbox));
		cw = malloc(cwl * sizeof(double));
		if (!t->cbox || !cw) {
			free(cw);
			rc = PX_E_NOMEM;
			goto fail;
		}
		for (i = 0; i < n_cc && rc == PX_OK; i++) {
			const double *U = cc[i].knots;
			int p = cc[i].degree, n = cc[i].n_ctrl, h;
			for (k = p; k < n && rc == PX_OK; k++) {
				if (!(U[k + 1] > U[k]))
					continue;
				for (h = 0; h < 2 && rc == PX_OK; h++) {
					double a = U[k] + 0.5 * h * (U[k + 1] - U[k]);
					double b = h ? U[k + 1] : 0.5 * (U[k] + U[k + 1]);
					px_aabb bx;
					rc = px_nurbs_curve_sub_aabb(&cc[i], a, b, cw, cwl, &bx);
					if (rc == PX_OK)
						/* rounding of evaluated points */
						t->cbox[t->n_cbox++] = px_aabb_inflate(&bx, 1e-12 * t->scale);
				}
			}
		}
		free(cw);
		if (rc)
			goto fail;
		px_track_opts_default(&to);
		/* the surface tracker decides what is followed; its curve
		 * tracker must always track */
		to.cold_switch = 0;
		to.work = t->work;
		to.dist = o.dist;
		rc = px_track_create(cc, n_cc, &to, &t->ct);
		if (rc)
			goto fail;
	}
	{
		/* the piece cache where a region is rational: a slot for each
		 * quarter of up to 64 such regions (about 4.4 KiB a slot),
		 * fewer when the model has fewer */
		int nrat = 0, n = 1;
		for (i = 0; i < 4 * t->n_cells; i++)
			nrat += t->rcell[i].cert.rat;
		if (nrat > 0) {
			while (n < 4 * nrat && n < 256)
				n *= 2;
			t->pcache = malloc((size_t)n * sizeof(*t->pcache));
			if (!t->pcache) {
				rc = PX_E_NOMEM;
				goto fail;
			}
			for (i = 0; i < n; i++) {
				t->pcache[i].key = -1;
				t->pcache[i].filled = 0;
			}
			t->pcache_n = n;
		}
	}
	{
		/* the cut cache: 128 slots (about 5.4 KiB each), fewer for
		 * small models */
		int n = 1;
		while (n < 4 * t->n_cells && n < 128)
			n *= 2;
		t->scache = malloc((size_t)n * sizeof(*t->scache));
		if (!t->scache) {
			rc = PX_E_NOMEM;
			goto fail;
		}
		for (i = 0; i < n; i++) {
			t->scache[i].key = -1;
			t->scache[i].filled = 0;
		}
		t->scache_n = n;
	}
	t->epoch = 1;
	t->hot_s = -1;
	t->ans_s = -1;
	{
		/* the cold query's cost where a tool works: about the model
		 * (as px_track does) */
		px_aabb cb = bounds;
		double m = 0.3 * t->scale;
		cb.min = px_v3_sub(cb.min, px_v3(m, m, m));
		cb.max = px_v3_add(cb.max, px_v3(m, m, m));
		px__gov_init(&t->gov, o.cold_switch != 0,
			     o.cold_switch ? px__gov_calibrate(t->dist, cb) : 1.0);
	}
	rc = PX_OK;
	*out = t;
	t = NULL;
fail:
	if (cpw)
		for (i = 0; i < cap_edges; i++)
			free(cpw[i]);
	free(cpw);
	free(cc);
	free(ub);
	free(vb);
	free(ncs_u);
	free(ncs_v);
	free(work);
	px_strack_free(t);
	return rc;
}
