/*
 * strack_internal.h - the surface tracker's private layout, shared by its
 * files (geom/track/strack_*.c). Not installed, not part of the API.
 *
 * How it tracks the point-surface critical distances:
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
#ifndef PX_STRACK_INTERNAL_H
#define PX_STRACK_INTERNAL_H

#include "px_strack.h"

#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gov_internal.h"
#include "math_internal.h"
#include "nurbs_internal.h"
#include "track_hooks.h"
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
	/* a trimmed surface (px__strack_create_trimmed()): dom_in(dom, u,
	 * v) nonzero where (u, v) is in its closed domain; NULL untrimmed */
	int (*dom_in)(const void *dom, double u, double v);
	const void *dom;
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
	/* answer(): the nearest tracked candidate is a trimmed surface's
	 * crease outside its domain (it proves nothing of the others): the
	 * update is answered globally */
	int ans_open;
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

/* ---- constants and types of more than one part ---- */

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

/* What the parts of a solve cell need (box_done(): BOX_DONE nothing,
 * BOX_EXACT contract_solve(), BOX_SEEDS seeds): region[ch] its region
 * cells (BOX_SEEDS: as its quarters say), quarter[ch][k] their quarters
 * (worked out only where the region's own test does not prove it
 * done). */
struct cell_done {
	int region[4];
	int quarter[4][4];
};

/* contract_solve()'s outcomes */
enum { CS_FOUND = 0, CS_EMPTY = 1, CS_OPEN = 2 };

/* Room for cell_seeds(): every quarter of the four regions. */
#define ST_SEEDS_MAX 16

/* min and max by plain comparisons */
#define ST_MIN(a, b) ((a) < (b) ? (a) : (b))
#define ST_MAX(a, b) ((a) > (b) ? (a) : (b))

/* Cells per group of the expiry scan. */
#define ST_GROUP 8

/* Rings solved about a source at most; past them the whole surface. */
#define ST_RINGS 3

/* ---- functions shared between the files, by the file that defines them ---- */

/* strack_eval.c */
void px__st_crit_eval_d(const struct ssurf *f, struct crit *z, px_vec3 p,
			px_vec3 *grad_out, struct px_nurbs_surf_derivs *d);
int px__st_have_fma(void);
double px__st_pole_gap(const struct ssurf *f, double u, double v);
int px__st_snewton(const struct ssurf *f, struct crit *z, px_vec3 p,
		   double lu, double lv, const struct scell *home);
void px__st_surf_eval2(const struct ssurf *f, double u, double v,
		       struct px_nurbs_surf_derivs *d);

/* strack_crit.c */
void px__st_box_of(const struct scell *g, int k, double b[4]);
void px__st_box_quarter(const double b[4], int k, double q[4]);
int px__st_cell_seeds(const struct cell_done *done, int *sk);
int px__st_cell_solve_budget(struct px_strack *t, const struct scell *c,
			     px_vec3 ps, px_vec3 p, int *units, int lim);
int px__st_contract_solve(const struct ssurf *f, const struct rcert *rc,
			  const double b[4], struct crit *z, px_vec3 p,
			  const struct scell *home);
int px__st_crit_add(struct px_strack *t, struct ssurf *f, const struct crit *z);
int px__st_surf_reinit(struct px_strack *t, struct ssurf *f, int si, px_vec3 p);

/* strack_proof.c */
double px__st_cell_radius_to(const struct px_strack *t, const struct scell *c,
			     px_vec3 p, double need);
int px__st_col_end(struct px_strack *t);
int px__st_col_test(struct px_strack *t, int limit);
int px__st_collect_cells(struct px_strack *t, px_vec3 p0, px_vec3 p1);
int px__st_contract_h(const struct rcert *c, const double mid[3],
		      const double rad_in[3], double y[2][2], double *rho);
void px__st_expiries_rebuild(struct px_strack *t, px_vec3 p);
void px__st_groups_rebuild(struct px_strack *t);
int px__st_ix_check(struct px_strack *t);
int px__st_no_root_h(const struct rcert *c, px_vec3 p, const double mid[3],
		     const double rad[3]);
int px__st_one_root_h(const double mid[3], const double rad[3]);
double px__st_pre_radius(const struct rcert *c, const double mid[3],
			 const double rad_in[3], double e1, double e2, double epad);
double px__st_region_pieces(const struct px_strack *t, int ri, px_vec3 p);
double px__st_region_radius_to(const struct px_strack *t, int ri, px_vec3 p,
			       double need);
int px__st_sym_regular(const double lo[3], const double hi[3], double *sig);
int px__st_winding(const struct px_strack *t, const struct ssurf *f,
		   px_vec3 p, int *w);

/* strack_setup.c */

/*
 * px_strack_create() for trimmed surfaces (the B-rep's streams): trims
 * (n_surfs entries) the distance core's view of each surface's domain
 * (dist_internal.h; inside NULL: untrimmed), in(ctx, u, v) nonzero where
 * (u, v) lies in the closed domain of the surface whose ctx it is. A
 * trimmed surface's interior critical points are followed over the
 * whole surface, but only those in its domain answer; its domain edges
 * and poles are no candidates (the caller gives the trimming edges as
 * curves and checks the points a loop collapses to itself); a crease
 * of it answering outside its domain makes the update global. The
 * global query (fall-back, verification, cold switch) is the distance
 * core over the trimmed domains. Setup only.
 */
struct px__dist_trim;
int px__strack_create_trimmed(const struct px_nurbs_curve *curves, int n_curves,
			      const struct px_nurbs_surf *surfs, int n_surfs,
			      const struct px__dist_trim *trims,
			      int (*in)(const void *ctx, double u, double v),
			      const struct px_strack_opts *opts,
			      struct px_strack **out);

/* strack_update.c */
void px__st_answer_global(struct px_strack *t, px_vec3 p,
			  struct px_strack_result *r);
int px__st_cell_of(const struct ssurf *f, double u, double v);
void px__st_curves_update(struct px_strack *t, px_vec3 p,
			  struct px_track_result *cr, int reset);
int px__st_evolve(const struct ssurf *f, struct crit *z, px_vec3 dp,
		  px_vec3 p);
int px__st_follow(const struct ssurf *f, struct crit *z, px_vec3 p0,
		  px_vec3 dp, px_vec3 p, struct crit *last);
int px__st_full_reset(struct px_strack *t, px_vec3 p,
		      struct px_strack_result *r);
int px__st_rebuild_slice(const struct px_strack *t);
void px__st_rebuild_start(struct px_strack *t);

/* strack_cold.c */
void px__st_cold_enter(struct px_strack *t, px_vec3 p,
		       const struct px_strack_result *r);
int px__st_cold_return(struct px_strack *t, px_vec3 p, struct px_strack_result *r);
int px__st_cold_update(struct px_strack *t, px_vec3 p, struct px_strack_result *r);

/* strack_cert.c */
int px__st_cell_cert(struct px_strack *t, struct scell *c, const struct ssurf *f,
		     double *work, size_t wl, const int side_open[4]);
void px__st_cert_sides(const struct ssurf *f, const struct scell *c, struct rcert *ce,
		       const int side_open[4]);
int px__st_quarter_certs(struct px_strack *t, const struct scell *rg,
			 const struct ssurf *f, double *work, size_t wl,
			 struct rcert out[4]);
void px__st_sides_open(const struct ssurf *f, const struct scell *c, int open[4]);
int px__st_span_bounds(const struct px_nurbs_surf *s, int dir, double a,
		       double b, double *out);
void px__st_taylor_cert(const struct ssurf *f, const double b[4],
			const struct rcert *top, struct rcert *ce);
int px__st_wind_pieces(struct px_strack *t, int si);

/* ---- small functions of the hot path, inline in every file that calls them ---- */

static inline int bsearch_bounds(const double *b, int n, double x)
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

static inline void crit_eval(const struct ssurf *f, struct crit *z, px_vec3 p,
		      px_vec3 *grad_out)
{
	struct px_nurbs_surf_derivs d;
	px__st_crit_eval_d(f, z, p, grad_out, &d);
}

static inline int crit_type(const struct crit *z)
{
	double det = z->h11 * z->h22 - z->h12 * z->h12;
	if (det > 0.0)
		return z->h11 > 0.0 ? 1 : -1;
	return 0;
}

/* (u, v) in the closed domain of f (always, untrimmed). */
static inline int st_in_domain(const struct ssurf *f, double u, double v)
{
	return !f->dom_in || f->dom_in(f->dom, u, v);
}

static inline int has_pole(const struct ssurf *f)
{
	return f->pole[0] | f->pole[1] | f->pole[2] | f->pole[3];
}

/* Interval arithmetic on struct iv, one set for the proofs at update
 * time and the certificates made at setup. */
static inline struct iv iv_mul(struct iv a, struct iv b)
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

static inline double iv_mag(struct iv a)
{
	return fmax(fabs(a.lo), fabs(a.hi));
}

static inline struct iv iv_pt(double x)
{
	struct iv r = {x, x};
	return r;
}

static inline struct iv iv_add(struct iv a, struct iv b)
{
	struct iv r = {a.lo + b.lo, a.hi + b.hi};
	return r;
}

static inline struct iv iv_sub(struct iv a, struct iv b)
{
	struct iv r = {a.lo - b.hi, a.hi - b.lo};
	return r;
}

static inline struct iv iv_scale(struct iv a, double k)
{
	struct iv r = {fmin(a.lo * k, a.hi * k), fmax(a.lo * k, a.hi * k)};
	return r;
}

/* a / w for w > 0 */
static inline struct iv iv_divw(struct iv a, struct iv w)
{
	struct iv iw = {1.0 / w.hi, 1.0 / w.lo};
	return iv_mul(a, iw);
}

static inline struct iv iv_pad(struct iv a)
{
	double e = ST_PAD * (fabs(a.lo) + fabs(a.hi)) + 1e-300;
	struct iv r = {a.lo - e, a.hi + e};
	return r;
}

static inline void iv_grow(struct iv *a, double x)
{
	/* as fmin and fmax (a NaN x leaves a as it is), without their
	 * calls: run for every point of a net at update time too */
	a->lo = x < a->lo ? x : a->lo;
	a->hi = x > a->hi ? x : a->hi;
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

static inline int no_root(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return px__st_no_root_h(c, p, mid, rad);
}

static inline int one_root(const struct rcert *c, px_vec3 p)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return px__st_one_root_h(mid, rad);
}

static inline int contract_rate(const struct rcert *c, px_vec3 p, double y[2][2],
			 double *rho)
{
	double mid[3], rad[3];
	hess_at(c, p, mid, rad);
	return px__st_contract_h(c, mid, rad, y, rho);
}

static inline double region_radius(const struct px_strack *t, int ri, px_vec3 p)
{
	return px__st_region_radius_to(t, ri, p, 0.0);
}

/* region_radius() with the pieces of a rational region's quarters that
 * have none (region_pieces()). */
static inline double region_radius_full(const struct px_strack *t, int ri, px_vec3 p)
{
	double r = region_radius(t, ri, p);
	if (!(r > 0.0) && t->rcell[ri].cert.rat && !px__strack_piece_fault)
		r = px__st_region_pieces(t, ri, p) * px__strack_radius_scale;
	return r;
}

/* 1 when region ri holds no critical point for p (its own E tests, or
 * each of its quarters'). */
static inline int region_empty(const struct px_strack *t, int ri, px_vec3 p)
{
	const struct rcert *q = &t->qcert[4 * ri];
	return no_root(&t->rcell[ri].cert, p) ||
	       (no_root(&q[0], p) && no_root(&q[1], p) && no_root(&q[2], p) &&
		no_root(&q[3], p));
}

static inline double cell_radius(const struct px_strack *t, const struct scell *c,
			  px_vec3 p)
{
	return px__st_cell_radius_to(t, c, p, 0.0);
}

/* The cell's certificate was proven for the cube of half width r about
 * p (max norm): due when the path from here could leave it. */
static inline void cell_expire(struct px_strack *t, struct scell *c, px_vec3 p, double r)
{
	struct cube *q = &t->cube[c - t->cell];
	q->ctr = p;
	q->crad = r;
	t->ex[c - t->cell] = t->ctravel + r;
}

/* Solves of a hit cell itself: one; two after a long step past the
 * crossing (solved where the region was met too); 0 for a pole cell. */
static inline int hit_work(const struct px_strack *t, int ci, double step)
{
	const struct scell *c = &t->cell[ci];
	if (c->always)
		return 0;
	return 1 + ((1.0 - c->cross) * step > 0.05 * c->size);
}

/* The cell tests one update may make (0: no bound); only with a solve
 * budget, without one every case re-initialises at once anyway. */
static inline int tests_budget(const struct px_strack *t)
{
	return t->opts.max_solves > 0 ? t->opts.max_tests : 0;
}

/* (the points are finite: plain comparisons, not fmax's calls) */
static inline double max_norm(px_vec3 d)
{
	double x = fabs(d.x), y = fabs(d.y), z = fabs(d.z);
	return x > y ? (x > z ? x : z) : (y > z ? y : z);
}

/* The next max_tests of a collection in progress: as collect_cells(). */
static inline int col_resume(struct px_strack *t)
{
	return px__st_col_test(t, tests_budget(t)) ? px__st_col_end(t) : -1;
}

static inline void result_clear(struct px_strack_result *r)
{
	memset(r, 0, sizeof(*r));
	r->entity = -1;
}

#endif
