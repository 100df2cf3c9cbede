#include "px_dist.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "math_internal.h"
#include "px_arena.h"
#include "px_cpiece.h"
#include "px_spiece.h"
#include "px_recog.h"

/* Hot-path box distance: boxes here are never empty, and fmin/fmax
 * would be library calls without -ffast-math. */
static inline double gap1(double v, double lo, double hi)
{
	return v < lo ? lo - v : (v > hi ? v - hi : 0.0);
}

static inline double box_d2(const px_aabb *b, px_vec3 p)
{
	double dx = gap1(p.x, b->min.x, b->max.x);
	double dy = gap1(p.y, b->min.y, b->max.y);
	double dz = gap1(p.z, b->min.z, b->max.z);
	return dx * dx + dy * dy + dz * dz;
}

struct cand {
	double lb; /* squared lower bound */
	int piece;
};

enum { PK_CURVE = 0, PK_PATCH = 1 };

/* What one query in flight needs besides the read-only model: per-piece
 * visit stamps (an epoch, so nothing is cleared per query) and the
 * candidate list. */
struct px_dist_ws {
	uint32_t epoch;
	uint32_t *stamp;
	uint32_t *ent_stamp; /* entities answered in closed form */
	struct cand *cand;
	int n_pieces, n_ent;
	int owned; /* allocated by px_dist_ws_create() */
};

/* One entry of the grid's index space: a curve piece or a patch. */
struct piece {
	px_aabb box;
	int kind;    /* PK_CURVE or PK_PATCH */
	int idx;     /* into cp or spc */
	int ent;     /* entity */
	/* Boundary curve of a surface: the curve runs along u (iso_dir 0,
	 * v fixed at iso_t) or along v (iso_dir 1); -1 for an entity's own
	 * curve pieces and patches. */
	int iso_dir;
	double iso_t;
	int sample_start;
	int ns, nt; /* samples: ns along the piece (curves) or ns x nt */
	/* Oriented box around the control net (so around the piece):
	 * candidates the axis-aligned box kept are dropped by it before
	 * their solve reads the coefficient tables (most neighbours of the
	 * foot point are nearly flat slabs that it bounds tightly). */
	px_obb obb;
};

struct px_dist_model {
	struct px_arena arena;
	struct px_dist_opts opts;
	int n_ent;
	struct px_dist_entity_info *ent;
	/* Knowledge step: entities that are exactly a primitive (with the
	 * arrays their parameter inversion reads, copied here). */
	struct px_recog_shape *shape;
	int n_pieces;
	struct piece *pieces;
	int n_cp, n_sp;
	struct px_cpiece *cp;
	struct px_spiece *spc;
	int n_samples;
	px_vec3 *samples;
	/* grid */
	px_aabb bounds;
	double h, inv_h;
	int nx, ny, nz;
	long n_cells, n_spill;
	int cap;
	int *cell_count;
	/* Chebyshev distance (in cells) to the nearest non-empty cell: the
	 * wave starts at that shell, all nearer ones being empty. */
	uint16_t *cell_empty_r;
	int *cell_slot;  /* n_cells * cap */
	int *cell_spill; /* first spill index of each cell */
	int *spill;
	/* the workspace of px_dist_query() */
	struct px_dist_ws ws;
};

void px_dist_opts_default(struct px_dist_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->sample_tol = 0.01;
	o->cell_cap = PX_DIST_CELL_CAP_DEFAULT;
	o->max_cells = 1L << 18;
	o->max_pieces_per_entity = 4096;
}

/* ---- knowledge step: parametrization factor ---------------------------- */

/*
 * Decomposition tolerance and jitter by parametrization factor (paper
 * section 5 and its table): the further the speed |C'| varies, the finer
 * the pieces and the more uniform their spacing. The table's finest row
 * (1 %) serves Newton starts; pieces here carry their own proofs, so the
 * callers floor it at the paper's recommended settings (5 % for curves,
 * 10 % for surfaces), where boxes are tight and candidates few.
 */
static void pf_table(double pf, double *tol, double *jit)
{
	if (pf <= 0.2) {
		*tol = 0.2;
		*jit = 0.5;
	} else if (pf <= 0.4) {
		*tol = 0.1;
		*jit = 0.6;
	} else if (pf <= 0.7) {
		*tol = 0.05;
		*jit = 0.7;
	} else {
		*tol = 0.01;
		*jit = 0.8;
	}
}

/* Settings for an entity from its info->pf: the table, floored at
 * floor_tol, unless the options fix tolerance or jitter. */
static void decomp_settings(struct px_dist_entity_info *info, double floor_tol,
			    const struct px_dist_opts *o)
{
	double tol, jit;
	pf_table(info->pf, &tol, &jit);
	if (tol < floor_tol)
		tol = floor_tol;
	info->tol = o->decomp_tol > 0.0 ? o->decomp_tol : tol;
	info->jitter = o->jitter > 0.0 ? o->jitter : jit;
}

static double speed(const struct px_nurbs_curve *c, double u, int side)
{
	px_vec3 d[2];
	px_nurbs_curve_eval_side(c, u, side, 1, d);
	return px_v3_norm(d[1]);
}

/* Sorted distinct interior knots: the span boundaries. */
static int interior_knots(const struct px_nurbs_curve *c, double a, double b,
			  double *out)
{
	int i, n = 0;
	for (i = 0; i < c->n_knots; i++) {
		double k = c->knots[i];
		if (k > a && k < b && (n == 0 || k > out[n - 1]))
			out[n++] = k;
	}
	return n;
}

#define SPAN_SAMPLES 16

struct decomp {
	double *u;
	int n, cap;
};

static int push(struct decomp *d, double u)
{
	if (d->n == d->cap) {
		int nc = d->cap ? 2 * d->cap : 64;
		double *nu = realloc(d->u, (size_t)nc * sizeof(double));
		if (!nu)
			return PX_E_NOMEM;
		d->u = nu;
		d->cap = nc;
	}
	d->u[d->n++] = u;
	return PX_OK;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/*
 * Parameters that cut one curve into pieces: domain ends, every interior
 * knot (so pieces are Bezier), cusps, and nearly uniform steps (paper
 * section 5) with chord length in [jit * tol * L, tol * L].
 */
static int decompose(const struct px_nurbs_curve *c, const struct px_dist_opts *o,
		     struct px_dist_entity_info *info, struct decomp *out)
{
	double a, b, *knots = NULL, dmin = INFINITY, dmax = 0.0, len = 0.0;
	double tol, jit, eps_u, eps_l, u, du;
	struct decomp cusps = {0}, steps = {0};
	int nk, i, j, rc = PX_OK, guard;
	px_vec3 prev;

	px_nurbs_curve_domain(c, &a, &b);
	knots = malloc((size_t)c->n_knots * sizeof(double));
	if (!knots)
		return PX_E_NOMEM;
	nk = interior_knots(c, a, b, knots);
	info->n_breaks = px_nurbs_curve_breaks(c, NULL, 0);
	{
		px_aabb hull = px_nurbs_curve_aabb(c);
		info->closed = px_nurbs_curve_seam(
				       c, 1e-12 * (1.0 + px_aabb_diagonal(&hull)),
				       1e-9) >= 0;
	}

	/* Speed range and arc length from SPAN_SAMPLES per span; speeds at
	 * knots from both sides (they differ at C0 breaks). */
	prev = px_nurbs_curve_point(c, a);
	for (i = 0; i <= nk; i++) {
		double s0 = i == 0 ? a : knots[i - 1], s1 = i == nk ? b : knots[i];
		double sp[SPAN_SAMPLES + 1];
		for (j = 0; j <= SPAN_SAMPLES; j++) {
			double t = s0 + (s1 - s0) * j / SPAN_SAMPLES;
			px_vec3 q = px_nurbs_curve_point(c, t);
			sp[j] = speed(c, t, j == SPAN_SAMPLES ? -1 : 1);
			dmin = fmin(dmin, sp[j]);
			dmax = fmax(dmax, sp[j]);
			len += px_v3_dist(prev, q);
			prev = q;
		}
		/* Cusp candidates: local minima of the sampled speed, refined
		 * by golden section; a cusp is where the speed (almost)
		 * vanishes inside the span. */
		for (j = 1; j < SPAN_SAMPLES; j++) {
			double lo, hi;
			int k;
			if (!(sp[j] <= sp[j - 1] && sp[j] <= sp[j + 1]))
				continue;
			lo = s0 + (s1 - s0) * (j - 1) / SPAN_SAMPLES;
			hi = s0 + (s1 - s0) * (j + 1) / SPAN_SAMPLES;
			for (k = 0; k < 80; k++) {
				double x1 = hi - (hi - lo) * 0.6180339887498949;
				double x2 = lo + (hi - lo) * 0.6180339887498949;
				if (speed(c, x1, 1) < speed(c, x2, 1))
					hi = x2;
				else
					lo = x1;
			}
			u = 0.5 * (lo + hi);
			if (speed(c, u, 1) <= 1e-7 * dmax && u > s0 && u < s1) {
				rc = push(&cusps, u);
				if (rc)
					goto out;
			}
		}
	}
	info->n_cusps = cusps.n;
	info->arc_length = len;
	info->pf = dmax > 0.0 ? (dmax - dmin) / dmax : 1.0;
	decomp_settings(info, 0.05, o);
	tol = info->tol;
	jit = info->jitter;

	/* Nearly uniform stepping: each step starts from the previous
	 * increment (spatial coherence) and is brought into the chord band
	 * by bisection. */
	eps_u = tol * len;
	eps_l = jit * eps_u;
	u = a;
	du = (b - a) * tol;
	prev = px_nurbs_curve_point(c, a);
	for (guard = 0; len > 0.0 && guard < o->max_pieces_per_entity; guard++) {
		double lo = u, hi = b, x = fmin(u + du, b), d;
		int k, overshot = 0;
		for (k = 0; k < 60; k++) {
			d = px_v3_dist(prev, px_nurbs_curve_point(c, x));
			if (d > eps_u) {
				hi = x;
				overshot = 1;
			} else if (d < eps_l && x < b) {
				lo = x;
			} else {
				break;
			}
			/* Grow the step until the chord overshoots, then
			 * bisect: growing from the last step rather than
			 * bisecting towards the domain end keeps the step from
			 * jumping across a loop to a far part of the curve. */
			x = overshot ? 0.5 * (lo + hi) : fmin(b, u + 2 * (x - u));
		}
		if (x >= b || b - x < 1e-3 * (x - u))
			break;
		rc = push(&steps, x);
		if (rc)
			goto out;
		du = x - u;
		u = x;
		prev = px_nurbs_curve_point(c, u);
	}
	if (guard >= o->max_pieces_per_entity) {
		rc = PX_E_NOSPC;
		goto out;
	}

	/* Merge: ends, knots, cusps, then steps not crowding a mandatory
	 * cut (which would leave a sliver piece). */
	rc = push(out, a);
	for (i = 0; !rc && i < nk; i++)
		rc = push(out, knots[i]);
	for (i = 0; !rc && i < cusps.n; i++)
		rc = push(out, cusps.u[i]);
	if (!rc)
		rc = push(out, b);
	if (rc)
		goto out;
	qsort(out->u, (size_t)out->n, sizeof(double), cmp_double);
	{
		int mandatory = out->n;
		double gap = (b - a) * tol * 0.25;
		for (i = 0; i < steps.n; i++) {
			double s = steps.u[i];
			int ok = 1;
			for (j = 0; j < mandatory; j++)
				if (fabs(out->u[j] - s) < gap)
					ok = 0;
			if (ok && (rc = push(out, s)))
				goto out;
		}
	}
	qsort(out->u, (size_t)out->n, sizeof(double), cmp_double);
	/* Drop exact duplicates. */
	for (i = 1, j = 1; i < out->n; i++)
		if (out->u[i] > out->u[j - 1])
			out->u[j++] = out->u[i];
	out->n = j;
	if (out->n - 1 > o->max_pieces_per_entity)
		rc = PX_E_NOSPC;
out:
	free(knots);
	free(cusps.u);
	free(steps.u);
	return rc;
}

/* ---- surfaces: decomposition ------------------------------------------ */

/* Speed of a surface along one direction at (u, v). */
static double surf_speed(const struct px_nurbs_surf *s, double u, double v,
			 int dir)
{
	struct px_nurbs_surf_derivs d;
	px_nurbs_surf_eval(s, u, v, 1, &d);
	return px_v3_norm(dir == 0 ? d.su : d.sv);
}

/* Approximate length of a curve from SPAN_SAMPLES chords per span. */
static double curve_length(const struct px_nurbs_curve *c)
{
	double a, b, len = 0.0;
	int k, j;
	px_vec3 prev;
	px_nurbs_curve_domain(c, &a, &b);
	prev = px_nurbs_curve_point(c, a);
	for (k = c->degree; k < c->n_ctrl; k++) {
		double s0 = c->knots[k], s1 = c->knots[k + 1];
		if (!(s1 > s0) || s1 <= a || s0 >= b)
			continue;
		for (j = 1; j <= SPAN_SAMPLES; j++) {
			px_vec3 q = px_nurbs_curve_point(c, s0 + (s1 - s0) * j / SPAN_SAMPLES);
			len += px_v3_dist(prev, q);
			prev = q;
		}
	}
	return len;
}

/*
 * Cut parameters of a surface in direction dir: the nearly uniform steps
 * of its longest iso-curve in that direction (paper section 5), which
 * include the direction's knots. The iso-curves compared are those at
 * the other direction's knots and span middles.
 */
static int surf_cuts(const struct px_nurbs_surf *s, int dir,
		     const struct px_dist_opts *o, double *len_out,
		     struct decomp *out)
{
	int other = 1 - dir, nk = s->n_knots[other], k, rc;
	const double *kn = s->knots[other];
	size_t pwl = 4 * (size_t)s->n_ctrl[dir];
	double *pw = malloc(pwl * sizeof(double)), best_len = -1.0, best_t = 0.0;
	double a, b, c0, c1;
	struct px_nurbs_curve iso;
	struct px_dist_entity_info info;

	if (!pw)
		return PX_E_NOMEM;
	px_nurbs_surf_domain(s, &a, &b, &c0, &c1);
	if (other == 0) {
		c0 = a;
		c1 = b;
	}
	for (k = 0; k + 1 < nk; k++) {
		double t0 = kn[k], t1 = kn[k + 1], ts[2];
		int j;
		if (!(t1 > t0) || t1 <= c0 || t0 >= c1)
			continue;
		ts[0] = t0 < c0 ? c0 : t0;
		ts[1] = 0.5 * (t0 + t1);
		for (j = 0; j < 2; j++) {
			double l;
			if (px_nurbs_surf_iso_curve(s, dir, ts[j], pw, pwl, &iso))
				continue;
			l = curve_length(&iso);
			if (l > best_len) {
				best_len = l;
				best_t = ts[j];
			}
		}
	}
	{
		double l;
		if (!px_nurbs_surf_iso_curve(s, dir, c1, pw, pwl, &iso)) {
			l = curve_length(&iso);
			if (l > best_len) {
				best_len = l;
				best_t = c1;
			}
		}
	}
	rc = px_nurbs_surf_iso_curve(s, dir, best_t, pw, pwl, &iso);
	if (!rc) {
		memset(&info, 0, sizeof(info));
		rc = decompose(&iso, o, &info, out);
	}
	*len_out = best_len > 0.0 ? best_len : 0.0;
	free(pw);
	return rc;
}

/* Parametrization factor of a surface: speed range in u and in v over
 * SPAN_SAMPLES^2 samples per knot rectangle. */
static double surf_pf(const struct px_nurbs_surf *s)
{
	double a, b, c, d, pf = 0.0;
	int dir;
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	for (dir = 0; dir < 2; dir++) {
		double mn = INFINITY, mx = 0.0;
		int i, j, ku, kv;
		for (ku = s->degree[0]; ku < s->n_ctrl[0]; ku++) {
			double u0 = s->knots[0][ku], u1 = s->knots[0][ku + 1];
			if (!(u1 > u0))
				continue;
			for (kv = s->degree[1]; kv < s->n_ctrl[1]; kv++) {
				double v0 = s->knots[1][kv], v1 = s->knots[1][kv + 1];
				if (!(v1 > v0))
					continue;
				for (i = 0; i <= 4; i++)
					for (j = 0; j <= 4; j++) {
						double sp = surf_speed(s, u0 + (u1 - u0) * i / 4,
								       v0 + (v1 - v0) * j / 4, dir);
						mn = sp < mn ? sp : mn;
						mx = sp > mx ? sp : mx;
					}
			}
		}
		/* A collapsed edge (pole) has zero speed along it: that is a
		 * property of the parametrization, and pf says so. */
		if (mx > 0.0 && (mx - mn) / mx > pf)
			pf = (mx - mn) / mx;
	}
	return pf;
}

/* ---- setup ---------------------------------------------------------------- */

/* Pieces in temporary memory while the model is being built. */
struct tmp_piece {
	struct piece pc;
	struct px_cpiece cp;  /* kind PK_CURVE */
	double *hw;           /* kind PK_PATCH: (p+1)(q+1) x 4, i along u */
	int p, q;
	double r[4];          /* patch rectangle */
};

struct builder {
	struct tmp_piece *tp;
	int n, cap;
	long n_samples;
	double sample_tol;
};

static struct tmp_piece *new_piece(struct builder *bl)
{
	if (bl->n == bl->cap) {
		int nc = bl->cap ? 2 * bl->cap : 64;
		struct tmp_piece *nt = realloc(bl->tp, (size_t)nc * sizeof(*nt));
		if (!nt)
			return NULL;
		bl->tp = nt;
		bl->cap = nc;
	}
	memset(&bl->tp[bl->n], 0, sizeof(bl->tp[0]));
	return &bl->tp[bl->n++];
}

/*
 * Oriented box of n control points pw (x w, y w, z w, w): first axis
 * along a0, second along a1 made orthogonal to it (any perpendicular
 * when degenerate), extents from the projections of the points, padded
 * by 1e-12 of the size so rounding cannot cut the piece.
 */
static px_obb net_obb(const double *pw, int n, px_vec3 a0, px_vec3 a1)
{
	px_obb b;
	px_vec3 lo = px_v3(INFINITY, INFINITY, INFINITY);
	px_vec3 hi = px_v3(-INFINITY, -INFINITY, -INFINITY);
	double l0 = px_v3_norm(a0), l1, pad;
	int k, d;

	if (!(l0 > 0.0) || !isfinite(l0)) {
		a0 = px_v3(1, 0, 0);
		a1 = px_v3(0, 1, 0);
	} else {
		a0 = px_v3_scale(a0, 1.0 / l0);
	}
	a1 = px_v3_madd(a1, a0, -px_v3_dot(a1, a0));
	l1 = px_v3_norm(a1);
	if (!(l1 > 1e-9) || !isfinite(l1)) {
		/* Any perpendicular: cross with the coordinate axis least
		 * aligned with a0. */
		px_vec3 e = fabs(a0.x) < 0.6 ? px_v3(1, 0, 0)
				: (fabs(a0.y) < 0.6 ? px_v3(0, 1, 0) : px_v3(0, 0, 1));
		a1 = px_v3_cross(a0, e);
		l1 = px_v3_norm(a1);
	}
	b.axis[0] = a0;
	b.axis[1] = px_v3_scale(a1, 1.0 / l1);
	b.axis[2] = px_v3_cross(b.axis[0], b.axis[1]);
	for (k = 0; k < n; k++) {
		px_vec3 x = px_v3(pw[4 * k] / pw[4 * k + 3], pw[4 * k + 1] / pw[4 * k + 3],
				  pw[4 * k + 2] / pw[4 * k + 3]);
		double c[3];
		for (d = 0; d < 3; d++)
			c[d] = px_v3_dot(x, b.axis[d]);
		lo = px_v3(c[0] < lo.x ? c[0] : lo.x, c[1] < lo.y ? c[1] : lo.y,
			   c[2] < lo.z ? c[2] : lo.z);
		hi = px_v3(c[0] > hi.x ? c[0] : hi.x, c[1] > hi.y ? c[1] : hi.y,
			   c[2] > hi.z ? c[2] : hi.z);
	}
	pad = 1e-12 * (px_v3_norm(px_v3_sub(hi, lo)) + px_v3_norm(lo) + px_v3_norm(hi)) +
	      1e-300;
	b.half = px_v3(0.5 * (hi.x - lo.x) + pad, 0.5 * (hi.y - lo.y) + pad,
		       0.5 * (hi.z - lo.z) + pad);
	b.center = px_v3_add(px_v3_add(px_v3_scale(b.axis[0], 0.5 * (lo.x + hi.x)),
				       px_v3_scale(b.axis[1], 0.5 * (lo.y + hi.y))),
			     px_v3_scale(b.axis[2], 0.5 * (lo.z + hi.z)));
	return b;
}

static px_vec3 net_point(const double *pw, int k)
{
	return px_v3(pw[4 * k] / pw[4 * k + 3], pw[4 * k + 1] / pw[4 * k + 3],
		     pw[4 * k + 2] / pw[4 * k + 3]);
}

static int clamp_count(double x, int lo, int hi)
{
	if (!(x >= lo))
		return lo;
	if (x > hi)
		return hi;
	return (int)ceil(x);
}

/*
 * Curve pieces of one curve: the entity's own (iso_dir -1) or a boundary
 * curve of a surface entity. len_scale is the arc length that the sample
 * spacing refers to.
 */
static int add_curve_pieces(struct builder *bl, const struct px_nurbs_curve *c,
			    const struct px_dist_opts *o,
			    struct px_dist_entity_info *info, int ent,
			    int iso_dir, double iso_t, double len_scale)
{
	struct decomp d = {0};
	double *work;
	size_t wl = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
	int i, rc;

	if (c->degree < 1 || c->degree > PX_CPIECE_MAX_DEGREE)
		return PX_E_RANGE;
	rc = decompose(c, o, info, &d);
	if (rc) {
		free(d.u);
		return rc;
	}
	if (len_scale <= 0.0)
		len_scale = info->arc_length;
	work = malloc(wl * sizeof(double));
	if (!work) {
		free(d.u);
		return PX_E_NOMEM;
	}
	for (i = 0; i + 1 < d.n; i++) {
		struct px_nurbs_curve bz;
		struct tmp_piece *t = new_piece(bl);
		double l = 0.0;
		int k;
		if (!t) {
			rc = PX_E_NOMEM;
			break;
		}
		rc = px_nurbs_curve_extract_work(c, d.u[i], d.u[i + 1], work, wl, &bz);
		if (rc)
			break;
		if (bz.n_ctrl != c->degree + 1) {
			rc = PX_E_STATE; /* a piece must lie in one span */
			break;
		}
		rc = px_cpiece_init(&t->cp, c->degree, (const double(*)[4])bz.pw,
				    d.u[i], d.u[i + 1]);
		if (rc)
			break;
		t->pc.kind = PK_CURVE;
		t->pc.ent = ent;
		t->pc.iso_dir = iso_dir;
		t->pc.iso_t = iso_t;
		t->pc.box = px_cpiece_box(&t->cp);
		{
			/* Along the chord; the second axis towards the control
			 * point farthest from it. */
			px_vec3 p0 = net_point(bz.pw, 0);
			px_vec3 ch = px_v3_sub(net_point(bz.pw, c->degree), p0), far = ch;
			double cl = px_v3_dot(ch, ch), fd = -1.0;
			for (k = 1; k < c->degree; k++) {
				px_vec3 v = px_v3_sub(net_point(bz.pw, k), p0);
				px_vec3 r = cl > 0.0 ? px_v3_madd(v, ch, -px_v3_dot(v, ch) / cl) : v;
				if (px_v3_dot(r, r) > fd) {
					fd = px_v3_dot(r, r);
					far = r;
				}
			}
			t->pc.obb = net_obb(bz.pw, c->degree + 1, ch, far);
		}
		/* The control polygon is longer than the piece. */
		for (k = 0; k < c->degree; k++)
			l += px_v3_dist(px_v3(bz.pw[4 * k] / bz.pw[4 * k + 3],
					      bz.pw[4 * k + 1] / bz.pw[4 * k + 3],
					      bz.pw[4 * k + 2] / bz.pw[4 * k + 3]),
					px_v3(bz.pw[4 * k + 4] / bz.pw[4 * k + 7],
					      bz.pw[4 * k + 5] / bz.pw[4 * k + 7],
					      bz.pw[4 * k + 6] / bz.pw[4 * k + 7]));
		t->pc.ns = len_scale > 0.0
				   ? clamp_count(l / (bl->sample_tol * len_scale) + 1.0, 2, 64)
				   : 2;
		t->pc.nt = 1;
		bl->n_samples += t->pc.ns;
	}
	free(work);
	free(d.u);
	return rc;
}

static int add_surface(struct builder *bl, const struct px_nurbs_surf *s,
		       const struct px_dist_opts *o,
		       struct px_dist_entity_info *info, int ent)
{
	struct px_dist_opts so = *o;
	struct decomp cu = {0}, cv = {0};
	double len_u = 0.0, len_v = 0.0, a, b, c, d, len, diag;
	double *work = NULL, *pw = NULL, brk[64];
	size_t wl, pwl;
	int i, j, rc, e, dir, first_boundary;
	px_aabb hull = px_nurbs_surf_aabb(s);

	if (s->degree[0] < 1 || s->degree[1] < 1 ||
	    s->degree[0] > PX_SPIECE_MAX_DEGREE ||
	    s->degree[1] > PX_SPIECE_MAX_DEGREE)
		return PX_E_RANGE;
	info->kind = PX_DIST_SURFACE;
	info->pf = surf_pf(s);
	/* Memory grows with the square of the count: surfaces stop at the
	 * paper's 10 % (see pf_table()). */
	decomp_settings(info, 0.1, o);
	so.decomp_tol = info->tol;
	so.jitter = info->jitter;
	rc = surf_cuts(s, 0, &so, &len_u, &cu);
	if (!rc)
		rc = surf_cuts(s, 1, &so, &len_v, &cv);
	if (rc)
		goto out;
	if ((long)(cu.n - 1) * (cv.n - 1) > o->max_pieces_per_entity) {
		rc = PX_E_NOSPC;
		goto out;
	}
	len = len_u > len_v ? len_u : len_v;
	info->arc_length = len;
	diag = px_aabb_diagonal(&hull);
	info->closed = (px_nurbs_surf_closed(s, 0, 1e-12 * (1.0 + diag)) ? 1 : 0) |
		       (px_nurbs_surf_closed(s, 1, 1e-12 * (1.0 + diag)) ? 2 : 0);
	info->n_breaks = px_nurbs_surf_breaks(s, 0, NULL, 0) +
			 px_nurbs_surf_breaks(s, 1, NULL, 0);

	/* Patches: every cell of the cut grid lies in one knot rectangle. */
	wl = PX_NURBS_SURF_WORK_LEN(s->degree[0], s->degree[1], s->n_ctrl[0],
				    s->n_ctrl[1]);
	work = malloc(wl * sizeof(double));
	if (!work) {
		rc = PX_E_NOMEM;
		goto out;
	}
	info->first_piece = bl->n;
	for (i = 0; i + 1 < cu.n; i++)
		for (j = 0; j + 1 < cv.n; j++) {
			struct px_nurbs_surf bz;
			struct tmp_piece *t;
			int p = s->degree[0], q = s->degree[1], ii, jj, k;
			double ext;
			rc = px_nurbs_surf_extract_work(s, cu.u[i], cu.u[i + 1], cv.u[j],
							cv.u[j + 1], work, wl, &bz);
			if (rc)
				goto out;
			if (bz.n_ctrl[0] != p + 1 || bz.n_ctrl[1] != q + 1) {
				rc = PX_E_STATE;
				goto out;
			}
			t = new_piece(bl);
			if (!t) {
				rc = PX_E_NOMEM;
				goto out;
			}
			t->hw = malloc((size_t)(p + 1) * (q + 1) * 4 * sizeof(double));
			if (!t->hw) {
				rc = PX_E_NOMEM;
				goto out;
			}
			t->p = p;
			t->q = q;
			t->r[0] = cu.u[i];
			t->r[1] = cu.u[i + 1];
			t->r[2] = cv.u[j];
			t->r[3] = cv.u[j + 1];
			t->pc.kind = PK_PATCH;
			t->pc.ent = ent;
			t->pc.iso_dir = -1;
			t->pc.box = px_aabb_empty();
			/* The extracted net has u fastest; patches want i
			 * (along u) as the slow index. */
			for (ii = 0; ii <= p; ii++)
				for (jj = 0; jj <= q; jj++) {
					const double *src = bz.pw + 4 * (jj * (p + 1) + ii);
					double *dst = t->hw + 4 * (ii * (q + 1) + jj);
					for (k = 0; k < 4; k++)
						dst[k] = src[k];
					px_aabb_extend(&t->pc.box,
						       px_v3(src[0] / src[3], src[1] / src[3],
							     src[2] / src[3]));
				}
			{
				/* Axes along the averaged u and v edges of the net. */
				const double *h = t->hw;
				int c00 = 0, c10 = p * (q + 1), c01 = q, c11 = p * (q + 1) + q;
				px_vec3 du = px_v3_add(px_v3_sub(net_point(h, c10), net_point(h, c00)),
						       px_v3_sub(net_point(h, c11), net_point(h, c01)));
				px_vec3 dv = px_v3_add(px_v3_sub(net_point(h, c01), net_point(h, c00)),
						       px_v3_sub(net_point(h, c11), net_point(h, c10)));
				t->pc.obb = net_obb(h, (p + 1) * (q + 1), du, dv);
			}
			ext = px_aabb_diagonal(&t->pc.box);
			t->pc.ns = len > 0.0 ? clamp_count(ext / (so.sample_tol * len) + 1.0, 2, 4) : 2;
			t->pc.nt = t->pc.ns;
			bl->n_samples += (long)t->pc.ns * t->pc.nt;
		}
	info->n_pieces = bl->n - info->first_piece;

	/* Boundary curves: domain edges that do not collapse to a point,
	 * and interior C0 creases in both directions. */
	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	pwl = 4 * (size_t)(s->n_ctrl[0] > s->n_ctrl[1] ? s->n_ctrl[0] : s->n_ctrl[1]);
	pw = malloc(pwl * sizeof(double));
	if (!pw) {
		rc = PX_E_NOMEM;
		goto out;
	}
	first_boundary = bl->n;
	for (e = 0; e < 4; e++) {
		/* edge: 0 u = a, 1 u = b, 2 v = c, 3 v = d */
		struct px_nurbs_curve iso;
		struct px_dist_entity_info ci;
		double t = e == 0 ? a : (e == 1 ? b : (e == 2 ? c : d));
		dir = e < 2 ? 1 : 0; /* the curve runs along the other direction */
		if (px_nurbs_surf_edge_collapsed(s, e, 1e-12 * (1.0 + diag))) {
			info->n_collapsed++;
			continue;
		}
		rc = px_nurbs_surf_iso_curve(s, dir, t, pw, pwl, &iso);
		if (rc)
			goto out;
		memset(&ci, 0, sizeof(ci));
		rc = add_curve_pieces(bl, &iso, &so, &ci, ent, dir, t, len);
		if (rc)
			goto out;
	}
	for (dir = 0; dir < 2; dir++) {
		int nb = px_nurbs_surf_breaks(s, dir, brk, 64), k;
		if (nb > 64) {
			rc = PX_E_NOSPC;
			goto out;
		}
		for (k = 0; k < nb; k++) {
			/* A crease at u = brk runs along v. */
			struct px_nurbs_curve iso;
			struct px_dist_entity_info ci;
			rc = px_nurbs_surf_iso_curve(s, 1 - dir, brk[k], pw, pwl, &iso);
			if (rc)
				goto out;
			memset(&ci, 0, sizeof(ci));
			rc = add_curve_pieces(bl, &iso, &so, &ci, ent, 1 - dir, brk[k], len);
			if (rc)
				goto out;
		}
	}
	info->n_boundary_pieces = bl->n - first_boundary;
out:
	free(work);
	free(pw);
	free(cu.u);
	free(cv.u);
	return rc;
}

static void cell_range(const struct px_dist_model *m, px_aabb b, int lo[3],
		       int hi[3])
{
	const double mn[3] = {b.min.x, b.min.y, b.min.z};
	const double mx[3] = {b.max.x, b.max.y, b.max.z};
	const double g0[3] = {m->bounds.min.x, m->bounds.min.y, m->bounds.min.z};
	const int n[3] = {m->nx, m->ny, m->nz};
	int d;
	for (d = 0; d < 3; d++) {
		double l = floor((mn[d] - g0[d]) * m->inv_h);
		double h = floor((mx[d] - g0[d]) * m->inv_h);
		lo[d] = (int)fmax(0.0, fmin(l, n[d] - 1));
		hi[d] = (int)fmax(0.0, fmin(h, n[d] - 1));
	}
}

static long cell_index(const struct px_dist_model *m, int i, int j, int k)
{
	return ((long)k * m->ny + j) * m->nx + i;
}

/*
 * Chebyshev distance transform of the occupied cells by breadth-first
 * search over the 26-neighbourhood (setup only).
 */
static int empty_radius(struct px_dist_model *m)
{
	long *queue = malloc((size_t)m->n_cells * sizeof(long)), head = 0,
	     tail = 0, c;
	if (!queue)
		return PX_E_NOMEM;
	for (c = 0; c < m->n_cells; c++) {
		if (m->cell_count[c] > 0) {
			m->cell_empty_r[c] = 0;
			queue[tail++] = c;
		} else {
			m->cell_empty_r[c] = UINT16_MAX;
		}
	}
	while (head < tail) {
		long cur = queue[head++];
		int x = (int)(cur % m->nx), y = (int)((cur / m->nx) % m->ny),
		    z = (int)(cur / ((long)m->nx * m->ny)), dx, dy, dz;
		uint16_t r = m->cell_empty_r[cur];
		for (dz = -1; dz <= 1; dz++)
			for (dy = -1; dy <= 1; dy++)
				for (dx = -1; dx <= 1; dx++) {
					long n;
					if (x + dx < 0 || x + dx >= m->nx ||
					    y + dy < 0 || y + dy >= m->ny ||
					    z + dz < 0 || z + dz >= m->nz)
						continue;
					n = cell_index(m, x + dx, y + dy, z + dz);
					if (m->cell_empty_r[n] != UINT16_MAX)
						continue;
					m->cell_empty_r[n] =
						r < UINT16_MAX - 1 ? r + 1 : r;
					queue[tail++] = n;
				}
	}
	free(queue);
	return PX_OK;
}

static void free_builder(struct builder *bl)
{
	int i;
	for (i = 0; i < bl->n; i++)
		free(bl->tp[i].hw);
	free(bl->tp);
}

int px_dist_model_create(const struct px_nurbs_curve *curves, int n_curves,
			 const struct px_nurbs_surf *surfs, int n_surfs,
			 const struct px_dist_opts *opts,
			 struct px_dist_model **out)
{
	struct px_dist_opts o;
	struct px_dist_entity_info *ent = NULL;
	struct builder bl;
	struct px_dist_model *m = NULL, hdr;
	struct px_recog_shape *shapes = NULL;
	int e, i, rc = PX_OK, n_ent, n_cp = 0, n_sp = 0;
	size_t bytes, sp_doubles = 0, shape_doubles = 0;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (n_curves < 0 || n_surfs < 0 || n_curves + n_surfs < 1 ||
	    (n_curves && !curves) || (n_surfs && !surfs))
		return PX_E_INVAL;
	if (opts)
		o = *opts;
	else
		px_dist_opts_default(&o);
	if (o.sample_tol <= 0.0 || o.sample_tol > 1.0 || o.cell_cap < 1 ||
	    o.max_cells < 1 || o.max_pieces_per_entity < 1 ||
	    o.decomp_tol < 0.0 || o.decomp_tol > 1.0 || o.jitter < 0.0 ||
	    o.jitter >= 1.0)
		return PX_E_INVAL;
	n_ent = n_curves + n_surfs;
	ent = calloc((size_t)n_ent, sizeof(*ent));
	if (!ent)
		return PX_E_NOMEM;
	memset(&bl, 0, sizeof(bl));
	bl.sample_tol = o.sample_tol;

	for (e = 0; e < n_curves && !rc; e++) {
		ent[e].kind = PX_DIST_CURVE;
		ent[e].first_piece = bl.n;
		rc = add_curve_pieces(&bl, &curves[e], &o, &ent[e], e, -1, 0.0, 0.0);
		ent[e].n_pieces = bl.n - ent[e].first_piece;
	}
	for (e = 0; e < n_surfs && !rc; e++)
		rc = add_surface(&bl, &surfs[e], &o, &ent[n_curves + e], n_curves + e);
	if (rc)
		goto fail;
	/* Knowledge step (paper section 6, step 1): entities that are
	 * exactly a primitive are answered in closed form; the bound on how
	 * far the entity is from the primitive must be far inside the
	 * accuracy promised (1e-9 of the model size). */
	shapes = calloc((size_t)n_ent, sizeof(*shapes));
	if (!shapes) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	for (e = 0; e < n_ent; e++) {
		struct px_recog_shape *sh = &shapes[e];
		int got = e < n_curves ? px_recog_curve(&curves[e], 0.0, sh)
				       : px_recog_surf(&surfs[e - n_curves], 0.0, sh);
		if (got != 1 || sh->kind == PX_RECOG_PLANE ||
		    !(sh->hausdorff <= 1e-11 * (sh->size > 0.0 ? sh->size : 1.0))) {
			memset(sh, 0, sizeof(*sh));
			continue;
		}
		ent[e].shape = sh->kind;
		ent[e].hausdorff = sh->hausdorff;
		shape_doubles += e < n_curves
					 ? (size_t)curves[e].n_knots + 4 * (size_t)curves[e].n_ctrl
					 : (size_t)surfs[e - n_curves].n_knots[0] +
						   surfs[e - n_curves].n_knots[1] +
						   4 * (size_t)surfs[e - n_curves].n_ctrl[0] *
							   surfs[e - n_curves].n_ctrl[1];
	}
	for (i = 0; i < bl.n; i++) {
		if (bl.tp[i].pc.kind == PK_CURVE) {
			n_cp++;
		} else {
			n_sp++;
			sp_doubles += px_spiece_doubles_hw(bl.tp[i].p, bl.tp[i].q,
							   (const double(*)[4])bl.tp[i].hw);
		}
	}

	/* Grid geometry (paper section 6): cell size from the finest
	 * entity's piece count along the longest extent. */
	memset(&hdr, 0, sizeof(hdr));
	hdr.bounds = px_aabb_empty();
	for (i = 0; i < bl.n; i++)
		hdr.bounds = px_aabb_union(&hdr.bounds, &bl.tp[i].pc.box);
	{
		px_vec3 ext = px_v3_sub(hdr.bounds.max, hdr.bounds.min);
		double mx = fmax(ext.x, fmax(ext.y, ext.z));
		int per = 1;
		long cell_budget = bl.n / 2;
		for (e = 0; e < n_ent; e++)
			per = ent[e].n_pieces > per ? ent[e].n_pieces : per;
		if (!(mx > 0.0))
			mx = 1.0;
		hdr.h = mx / per;
		/* The paper's cell size suits planar curves; a space curve,
		 * a surface or a large model would get mostly empty cells
		 * that every wave has to cross, so the cells also stay within
		 * a budget proportional to the pieces (and the memory bound).
		 * A cell costs a wave more than a piece in it does (shell
		 * bookkeeping against one box test), so about two pieces per
		 * cell measured fastest: callgrind on a cubic curve, 6,600
		 * instructions per query at four cells per piece, 5,300 at
		 * one cell per two pieces. */
		if (cell_budget < 8)
			cell_budget = 8;
		if (cell_budget > o.max_cells)
			cell_budget = o.max_cells;
		for (;;) {
			hdr.nx = (int)fmax(1.0, ceil(ext.x / hdr.h));
			hdr.ny = (int)fmax(1.0, ceil(ext.y / hdr.h));
			hdr.nz = (int)fmax(1.0, ceil(ext.z / hdr.h));
			hdr.n_cells = (long)hdr.nx * hdr.ny * hdr.nz;
			if (hdr.n_cells <= cell_budget)
				break;
			hdr.h *= 1.1;
		}
		hdr.inv_h = 1.0 / hdr.h;
	}
	hdr.cap = o.cell_cap;
	/* Count references per cell to size the spill table exactly. */
	{
		long *cnt = calloc((size_t)hdr.n_cells, sizeof(long));
		long c;
		if (!cnt) {
			rc = PX_E_NOMEM;
			goto fail;
		}
		for (i = 0; i < bl.n; i++) {
			int lo[3], hi[3], x, y, z;
			cell_range(&hdr, bl.tp[i].pc.box, lo, hi);
			for (z = lo[2]; z <= hi[2]; z++)
				for (y = lo[1]; y <= hi[1]; y++)
					for (x = lo[0]; x <= hi[0]; x++)
						cnt[cell_index(&hdr, x, y, z)]++;
		}
		hdr.n_spill = 0;
		for (c = 0; c < hdr.n_cells; c++)
			if (cnt[c] > hdr.cap)
				hdr.n_spill += cnt[c] - hdr.cap;
		free(cnt);
	}

	/* One block for everything the queries touch. */
#define ALIGNED(x) (((x) + 63) & ~(size_t)63)
	bytes = ALIGNED(sizeof(*m)) + ALIGNED((size_t)n_ent * sizeof(*ent)) +
		ALIGNED((size_t)n_ent * sizeof(struct px_recog_shape)) +
		ALIGNED(shape_doubles * sizeof(double)) +
		ALIGNED((size_t)n_ent * sizeof(uint32_t)) +
		ALIGNED((size_t)bl.n * sizeof(struct piece)) +
		ALIGNED((size_t)n_cp * sizeof(struct px_cpiece)) +
		ALIGNED((size_t)n_sp * sizeof(struct px_spiece)) +
		ALIGNED(sp_doubles * sizeof(double)) +
		ALIGNED((size_t)bl.n_samples * sizeof(px_vec3)) +
		ALIGNED((size_t)hdr.n_cells * sizeof(int)) * 2 +
		ALIGNED((size_t)hdr.n_cells * sizeof(uint16_t)) +
		ALIGNED((size_t)hdr.n_cells * (size_t)hdr.cap * sizeof(int)) +
		ALIGNED((size_t)(hdr.n_spill + 1) * sizeof(int)) +
		ALIGNED((size_t)bl.n * sizeof(uint32_t)) +
		ALIGNED((size_t)bl.n * sizeof(struct cand)) + 64 * 16;
	{
		struct px_arena ar;
		rc = px_arena_init_alloc(&ar, bytes);
		if (rc)
			goto fail;
		m = px_arena_alloc(&ar, sizeof(*m), 64);
		*m = hdr;
		m->arena = ar;
	}
#define TAKE(ptr, n) \
	((ptr) = px_arena_calloc(&m->arena, (size_t)(n), sizeof(*(ptr)), 64))
	m->opts = o;
	m->n_ent = n_ent;
	m->n_pieces = bl.n;
	m->n_cp = n_cp;
	m->n_sp = n_sp;
	m->n_samples = (int)bl.n_samples;
	m->ws.n_pieces = bl.n;
	m->ws.n_ent = n_ent;
	{
		double *spmem = NULL, *shmem = NULL;
		if (!TAKE(m->ent, n_ent) || !TAKE(m->pieces, bl.n) ||
		    (n_cp && !TAKE(m->cp, n_cp)) || (n_sp && !TAKE(m->spc, n_sp)) ||
		    (sp_doubles && !TAKE(spmem, sp_doubles)) ||
		    !TAKE(m->samples, bl.n_samples) ||
		    !TAKE(m->cell_count, m->n_cells) ||
		    !TAKE(m->cell_spill, m->n_cells) ||
		    !TAKE(m->cell_empty_r, m->n_cells) ||
		    !TAKE(m->cell_slot, m->n_cells * m->cap) ||
		    !TAKE(m->spill, m->n_spill + 1) || !TAKE(m->ws.stamp, bl.n) ||
		    !TAKE(m->ws.cand, bl.n) || !TAKE(m->shape, n_ent) ||
		    !TAKE(m->ws.ent_stamp, n_ent) ||
		    (shape_doubles && !TAKE(shmem, shape_doubles))) {
			rc = PX_E_NOMEM; /* the sizing above is wrong: a bug */
			goto fail;
		}
#undef TAKE
		memcpy(m->ent, ent, (size_t)n_ent * sizeof(*ent));
		memcpy(m->shape, shapes, (size_t)n_ent * sizeof(*shapes));
		/* The shapes view the entity's arrays (for parameter
		 * inversion): point them at copies the model owns. */
		for (e = 0; e < n_ent; e++) {
			struct px_recog_shape *sh = &m->shape[e];
			if (sh->kind == PX_RECOG_NONE)
				continue;
			if (e < n_curves) {
				const struct px_nurbs_curve *c = &curves[e];
				memcpy(shmem, c->knots, (size_t)c->n_knots * sizeof(double));
				sh->curve.knots = shmem;
				shmem += c->n_knots;
				memcpy(shmem, c->pw, 4 * (size_t)c->n_ctrl * sizeof(double));
				sh->curve.pw = shmem;
				shmem += 4 * (size_t)c->n_ctrl;
			} else {
				const struct px_nurbs_surf *sf = &surfs[e - n_curves];
				size_t npw = 4 * (size_t)sf->n_ctrl[0] * sf->n_ctrl[1];
				int d;
				for (d = 0; d < 2; d++) {
					memcpy(shmem, sf->knots[d],
					       (size_t)sf->n_knots[d] * sizeof(double));
					sh->surf.knots[d] = shmem;
					shmem += sf->n_knots[d];
				}
				memcpy(shmem, sf->pw, npw * sizeof(double));
				sh->surf.pw = shmem;
				shmem += npw;
			}
		}
		{
			int ic = 0, is = 0, smp = 0;
			for (i = 0; i < bl.n; i++) {
				struct tmp_piece *t = &bl.tp[i];
				struct piece *pc = &m->pieces[i];
				int a, b;
				*pc = t->pc;
				pc->sample_start = smp;
				if (t->pc.kind == PK_CURVE) {
					pc->idx = ic;
					m->cp[ic] = t->cp;
					for (a = 0; a < pc->ns; a++)
						m->samples[smp++] = px_cpiece_eval(
							&m->cp[ic], (double)a / (pc->ns - 1), NULL);
					ic++;
				} else {
					pc->idx = is;
					rc = px_spiece_init(&m->spc[is], t->p, t->q,
							    (const double(*)[4])t->hw,
							    t->r[0], t->r[1], t->r[2], t->r[3],
							    spmem);
					if (rc)
						goto fail;
					spmem += px_spiece_doubles_hw(t->p, t->q,
								      (const double(*)[4])t->hw);
					for (a = 0; a < pc->ns; a++)
						for (b = 0; b < pc->nt; b++)
							m->samples[smp++] = px_spiece_eval(
								&m->spc[is], (double)a / (pc->ns - 1),
								(double)b / (pc->nt - 1), NULL, NULL,
								NULL, NULL, NULL);
					is++;
				}
			}
		}
	}
	/* Bin: first cap references in the cell, the rest in the spill
	 * table, laid out cell by cell. */
	{
		long c, next = 0;
		int *spill_count = calloc((size_t)m->n_cells, sizeof(int));
		if (!spill_count) {
			rc = PX_E_NOMEM;
			goto fail;
		}
		for (i = 0; i < bl.n; i++) {
			int lo[3], hi[3], x, y, z;
			cell_range(m, m->pieces[i].box, lo, hi);
			for (z = lo[2]; z <= hi[2]; z++)
				for (y = lo[1]; y <= hi[1]; y++)
					for (x = lo[0]; x <= hi[0]; x++)
						spill_count[cell_index(m, x, y, z)]++;
		}
		for (c = 0; c < m->n_cells; c++) {
			m->cell_spill[c] = (int)next;
			if (spill_count[c] > m->cap)
				next += spill_count[c] - m->cap;
		}
		free(spill_count);
		for (i = 0; i < bl.n; i++) {
			int lo[3], hi[3], x, y, z;
			cell_range(m, m->pieces[i].box, lo, hi);
			for (z = lo[2]; z <= hi[2]; z++)
				for (y = lo[1]; y <= hi[1]; y++)
					for (x = lo[0]; x <= hi[0]; x++) {
						long ci = cell_index(m, x, y, z);
						int k = m->cell_count[ci]++;
						if (k < m->cap)
							m->cell_slot[ci * m->cap + k] = i;
						else
							m->spill[m->cell_spill[ci] + k - m->cap] = i;
					}
		}
	}
	rc = empty_radius(m);
	if (rc)
		goto fail;
	free_builder(&bl);
	free(ent);
	free(shapes);
	*out = m;
	return PX_OK;
fail:
	if (m)
		px_arena_fini(&m->arena);
	free_builder(&bl);
	free(ent);
	free(shapes);
	return rc;
}

void px_dist_model_free(struct px_dist_model *m)
{
	struct px_arena a;
	if (!m)
		return;
	/* The model lives inside its own arena. */
	a = m->arena;
	px_arena_fini(&a);
}

void px_dist_model_info(const struct px_dist_model *m, struct px_dist_info *info)
{
	memset(info, 0, sizeof(*info));
	if (!m)
		return;
	info->n_entities = m->n_ent;
	info->n_pieces = m->n_pieces;
	info->n_curve_pieces = m->n_cp;
	info->n_patches = m->n_sp;
	info->n_samples = m->n_samples;
	info->grid[0] = m->nx;
	info->grid[1] = m->ny;
	info->grid[2] = m->nz;
	info->cell_size = m->h;
	info->cells = m->n_cells;
	info->spill = m->n_spill;
	info->bytes = px_arena_capacity(&m->arena);
	info->bounds = m->bounds;
}

int px_dist_entity_info(const struct px_dist_model *m, int entity,
			struct px_dist_entity_info *info)
{
	if (!m || !info || entity < 0 || entity >= m->n_ent)
		return PX_E_RANGE;
	*info = m->ent[entity];
	return PX_OK;
}

/* ---- query ---------------------------------------------------------------- */

/*
 * Squared distance from p to the part of the grid outside the cell block
 * [lo, hi] (inclusive indices): the minimum over the six slabs beyond the
 * block's faces, each clipped to the grid. INFINITY when the block covers
 * the grid. Exact for p inside or outside the grid.
 */
static double outside_lb2(const struct px_dist_model *m, px_vec3 p,
			  const int lo[3], const int hi[3])
{
	const int n[3] = {m->nx, m->ny, m->nz};
	const double g0[3] = {m->bounds.min.x, m->bounds.min.y, m->bounds.min.z};
	double best = INFINITY;
	int d;
	for (d = 0; d < 3; d++) {
		px_aabb slab;
		double *mn = d == 0 ? &slab.min.x : (d == 1 ? &slab.min.y : &slab.min.z);
		double *mx = d == 0 ? &slab.max.x : (d == 1 ? &slab.max.y : &slab.max.z);
		if (lo[d] > 0) {
			slab = m->bounds;
			*mx = g0[d] + lo[d] * m->h;
			double b2 = box_d2(&slab, p);
			best = b2 < best ? b2 : best;
		}
		if (hi[d] < n[d] - 1) {
			double b2;
			slab = m->bounds;
			*mn = g0[d] + (hi[d] + 1) * m->h;
			b2 = box_d2(&slab, p);
			best = b2 < best ? b2 : best;
		}
	}
	return best;
}

/* Cell index along one axis for a scaled coordinate, clamped to the
 * grid; comparisons first so that far points never overflow the int. */
static inline int clamp_cell(double v, int n)
{
	if (!(v >= 0.0))
		return 0;
	if (v >= (double)(n - 1))
		return n - 1;
	return (int)v;
}

struct qstate {
	double best;  /* squared upper bound */
	int best_sample; /* global sample index */
	int best_piece;
	int n_cand;
	int cells;
};

/* Inline: called for every piece of every visited cell. */
static inline void visit_piece(const struct px_dist_model *m,
			       struct px_dist_ws *ws, px_vec3 p, int id,
			       struct qstate *q)
{
	const struct piece *pc = &m->pieces[id];
	double lb, near_d2 = INFINITY;
	int s, e, near = 0;

	if (ws->stamp[id] == ws->epoch)
		return;
	ws->stamp[id] = ws->epoch;
	lb = box_d2(&pc->box, p);
	if (lb >= q->best)
		return;
	/* Branch-free scan (conditional moves): which sample of a random
	 * query's piece is nearest is unpredictable. */
	for (s = pc->sample_start, e = s + pc->ns * pc->nt; s < e; s++) {
		double d2 = px_v3_dist2(m->samples[s], p);
		int nearer = d2 < near_d2;
		near_d2 = nearer ? d2 : near_d2;
		near = nearer ? s : near;
	}
	if (near_d2 < q->best) {
		q->best = near_d2;
		q->best_sample = near;
		q->best_piece = id;
	}
	ws->cand[q->n_cand].lb = lb;
	ws->cand[q->n_cand].piece = id;
	q->n_cand++;
}

static void visit_cell(const struct px_dist_model *m, struct px_dist_ws *ws,
		       px_vec3 p, int x, int y, int z, struct qstate *q)
{
	long ci = cell_index(m, x, y, z);
	int k, n = m->cell_count[ci];
	double dx, dy, dz, lo;

	if (n == 0)
		return;
	/* A cell farther than the best so far holds nothing useful: any
	 * piece that could be nearer is also registered in a nearer cell
	 * (the one holding its box's nearest point). */
	lo = m->bounds.min.x + x * m->h;
	dx = gap1(p.x, lo, lo + m->h);
	lo = m->bounds.min.y + y * m->h;
	dy = gap1(p.y, lo, lo + m->h);
	lo = m->bounds.min.z + z * m->h;
	dz = gap1(p.z, lo, lo + m->h);
	if (dx * dx + dy * dy + dz * dz >= q->best)
		return;
	q->cells++;
	for (k = 0; k < n && k < m->cap; k++)
		visit_piece(m, ws, p, m->cell_slot[ci * m->cap + k], q);
	for (k = m->cap; k < n; k++)
		visit_piece(m, ws, p, m->spill[m->cell_spill[ci] + k - m->cap], q);
}

/* Heap sort by lower bound: bounded, in place, no allocation (the C
 * library's qsort may allocate). */
static void sift(struct cand *c, int i, int n)
{
	for (;;) {
		int l = 2 * i + 1, big = i;
		struct cand t;
		if (l < n && c[l].lb > c[big].lb)
			big = l;
		if (l + 1 < n && c[l + 1].lb > c[big].lb)
			big = l + 1;
		if (big == i)
			return;
		t = c[i];
		c[i] = c[big];
		c[big] = t;
		i = big;
	}
}

static void sort_cand(struct cand *c, int n)
{
	int i;
	for (i = n / 2 - 1; i >= 0; i--)
		sift(c, i, n);
	for (i = n - 1; i > 0; i--) {
		struct cand t = c[0];
		c[0] = c[i];
		c[i] = t;
		sift(c, 0, i);
	}
}

/* Global (u, v) of a sample: its piece's parameters at the sample's
 * place in the piece's sample grid. */
static void sample_params(const struct px_dist_model *m, int id, int s,
			  double *u, double *v)
{
	const struct piece *pc = &m->pieces[id];
	int k = s - pc->sample_start;
	if (pc->kind == PK_PATCH) {
		const struct px_spiece *sp = &m->spc[pc->idx];
		double a = (double)(k / pc->nt) / (pc->ns - 1);
		double b = (double)(k % pc->nt) / (pc->nt - 1);
		*u = sp->u0_ + a * (sp->u1_ - sp->u0_);
		*v = sp->v0_ + b * (sp->v1_ - sp->v0_);
	} else {
		const struct px_cpiece *cp = &m->cp[pc->idx];
		double t = cp->u0_ + (double)k / (pc->ns - 1) * (cp->u1_ - cp->u0_);
		if (pc->iso_dir == 1) {
			*u = pc->iso_t;
			*v = t;
		} else if (pc->iso_dir == 0) {
			*u = t;
			*v = pc->iso_t;
		} else {
			*u = t;
			*v = 0.0;
		}
	}
}

int px_dist_query(struct px_dist_model *m, px_vec3 p, struct px_dist_result *r)
{
	if (!m)
		return PX_E_INVAL;
	return px_dist_query_ws(m, &m->ws, p, r);
}

int px_dist_ws_create(const struct px_dist_model *m, struct px_dist_ws **out)
{
	struct px_dist_ws *ws;
	size_t n;

	if (!m || !out)
		return PX_E_INVAL;
	n = (size_t)m->n_pieces;
	ws = calloc(1, sizeof(*ws) + n * (sizeof(uint32_t) + sizeof(struct cand)) +
			       (size_t)m->n_ent * sizeof(uint32_t) + 16);
	if (!ws)
		return PX_E_NOMEM;
	/* One block: candidates first (16-byte aligned), then stamps. */
	ws->cand = (struct cand *)(void *)(((uintptr_t)(ws + 1) + 15) & ~(uintptr_t)15);
	ws->stamp = (uint32_t *)(void *)(ws->cand + n);
	ws->ent_stamp = ws->stamp + n;
	ws->n_pieces = m->n_pieces;
	ws->n_ent = m->n_ent;
	ws->owned = 1;
	*out = ws;
	return PX_OK;
}

void px_dist_ws_free(struct px_dist_ws *ws)
{
	if (ws && ws->owned)
		free(ws);
}

int px_dist_query_ws(const struct px_dist_model *m, struct px_dist_ws *ws,
		     px_vec3 p, struct px_dist_result *r)
{
	struct qstate q;
	int c[3], k, kmax, i, sorted;
	double gap = 0.0, best;

	if (!m || !ws || !r || ws->n_pieces != m->n_pieces || ws->n_ent != m->n_ent)
		return PX_E_INVAL;
	if (!px_v3_isfinite(p))
		return PX_E_NAN;
	if (px__too_far(&m->bounds, p))
		return PX_E_RANGE; /* squared distances would overflow */
	if (++ws->epoch == 0) {
		/* Wrapped after 2^32 queries: clear once, then go on. */
		memset(ws->stamp, 0, (size_t)m->n_pieces * sizeof(uint32_t));
		memset(ws->ent_stamp, 0, (size_t)m->n_ent * sizeof(uint32_t));
		ws->epoch = 1;
	}
	memset(r, 0, sizeof(*r));
	r->certified = 1;
	q.best = INFINITY;
	q.best_piece = -1;
	q.best_sample = 0;
	q.n_cand = 0;
	q.cells = 0;

	/* The wave: shells of cells at Chebyshev distance k from the cell
	 * nearest to p. */
	c[0] = clamp_cell((p.x - m->bounds.min.x) * m->inv_h, m->nx);
	c[1] = clamp_cell((p.y - m->bounds.min.y) * m->inv_h, m->ny);
	c[2] = clamp_cell((p.z - m->bounds.min.z) * m->inv_h, m->nz);
	kmax = m->nx > m->ny ? m->nx : m->ny;
	kmax = kmax > m->nz ? kmax : m->nz;
	/* Shells nearer than the nearest occupied cell hold nothing. */
	k = m->cell_empty_r[cell_index(m, c[0], c[1], c[2])];
	for (; k <= kmax; k++) {
		int lo[3], hi[3], x, y, z;
		/* Everything not yet reached lies outside block k - 1. */
		if (k > 0) {
			for (i = 0; i < 3; i++) {
				lo[i] = c[i] - (k - 1);
				hi[i] = c[i] + (k - 1);
			}
			if (q.best <= outside_lb2(m, p, lo, hi))
				break;
		}
		for (z = c[2] - k; z <= c[2] + k; z++) {
			if (z < 0 || z >= m->nz)
				continue;
			for (y = c[1] - k; y <= c[1] + k; y++) {
				int rim;
				if (y < 0 || y >= m->ny)
					continue;
				rim = abs(z - c[2]) == k || abs(y - c[1]) == k;
				if (rim) {
					for (x = c[0] - k; x <= c[0] + k; x++)
						if (x >= 0 && x < m->nx)
							visit_cell(m, ws, p, x, y, z, &q);
				} else {
					if (c[0] - k >= 0)
						visit_cell(m, ws, p, c[0] - k, y, z, &q);
					if (k > 0 && c[0] + k < m->nx)
						visit_cell(m, ws, p, c[0] + k, y, z, &q);
				}
			}
		}
	}
	r->cells_visited = q.cells;
	if (q.best_piece < 0)
		/* The wave meets every piece, so only overflowing squared
		 * distances (a model spanning more than about 1e154) leave
		 * no best sample. */
		return PX_E_RANGE;

	/* Start from the best sample, a point on the model, so that an
	 * answer exists even if no solve improves on it. */
	best = q.best;
	r->point = m->samples[q.best_sample];
	r->piece = q.best_piece;
	sample_params(m, q.best_piece, q.best_sample, &r->u, &r->v);

	/* Exact solve of every piece that may still hold something closer.
	 * The piece holding the best sample goes first: its solve usually
	 * lands on the global minimum. Only the candidates whose bound
	 * still beats the best after it are sorted (nearest bound first):
	 * most fall out there, and sorting a handful costs little. */
	for (i = 0; i < q.n_cand; i++)
		if (ws->cand[i].piece == q.best_piece) {
			struct cand t = ws->cand[i];
			ws->cand[i] = ws->cand[0];
			ws->cand[0] = t;
			break;
		}
	sorted = q.n_cand <= 1;
	for (i = 0; i < q.n_cand; i++) {
		const struct cand *cd;
		const struct piece *pc;
		if (i == 1 && !sorted) {
			int j, n = 1;
			for (j = 1; j < q.n_cand; j++)
				if (ws->cand[j].lb < best)
					ws->cand[n++] = ws->cand[j];
			q.n_cand = n;
			sort_cand(ws->cand + 1, n - 1);
			sorted = 1;
			if (n <= 1)
				break;
		}
		cd = &ws->cand[i];
		pc = &m->pieces[cd->piece];
		/* Past the first, the list is sorted by lower bound. */
		if (i > 0 && cd->lb >= best)
			break;
		if (m->shape[pc->ent].kind != PX_RECOG_NONE) {
			struct px_recog_hit h;
			if (ws->ent_stamp[pc->ent] == ws->epoch)
				continue; /* the whole entity is answered */
			if (px_recog_closest(&m->shape[pc->ent], p, PX_RECOG_WANT_PARAMS,
					     &h) == PX_OK) {
				ws->ent_stamp[pc->ent] = ws->epoch;
				r->pieces_solved++;
				if (h.dist * h.dist < best) {
					best = h.dist * h.dist;
					r->point = h.point;
					r->u = h.u;
					r->v = h.v;
					r->piece = cd->piece;
				}
				continue;
			}
			/* No closed form for this query: solve the pieces. */
		}
		/* The oriented box can only drop a piece (the list order is
		 * by the axis-aligned bound, so go on to the next). */
		if (i > 0 && px_obb_dist2(&pc->obb, p) >= best)
			continue;
		r->pieces_solved++;
		if (pc->kind == PK_CURVE) {
			struct px_cpiece_hit hit;
			if (px_cpiece_closest(&m->cp[pc->idx], p, &best, &hit)) {
				r->point = hit.point;
				r->piece = cd->piece;
				if (pc->iso_dir == 1) {
					r->u = pc->iso_t;
					r->v = hit.u;
				} else if (pc->iso_dir == 0) {
					r->u = hit.u;
					r->v = pc->iso_t;
				} else {
					r->u = hit.u;
					r->v = 0.0;
				}
			}
			r->iters += hit.iters;
			if (!hit.certified) {
				r->certified = 0;
				gap = fmax(gap, hit.gap);
			}
		} else {
			struct px_spiece_hit hit;
			double hs = NAN, ht = NAN;
			if (cd->piece == q.best_piece) {
				/* Newton starts at the best pre-sample. */
				int ks = q.best_sample - pc->sample_start;
				hs = (double)(ks / pc->nt) / (pc->ns - 1);
				ht = (double)(ks % pc->nt) / (pc->nt - 1);
			}
			if (px_spiece_closest_hint(&m->spc[pc->idx], p, hs, ht, &best,
						   &hit)) {
				r->point = hit.point;
				r->piece = cd->piece;
				r->u = hit.u;
				r->v = hit.v;
			}
			r->iters += hit.iters;
			if (!hit.certified) {
				r->certified = 0;
				gap = fmax(gap, hit.gap);
			}
		}
	}
	r->dist = sqrt(best);
	if (!isfinite(r->dist))
		return PX_E_RANGE; /* overflow: see PX__MAX_QUERY_REACH */
	r->gap = gap;
	r->entity = m->pieces[r->piece].ent;
	r->kind = m->ent[r->entity].kind;
	{
		px_vec3 d = px_v3_sub(p, r->point);
		r->dir = r->dist > 0.0 ? px_v3_scale(d, 1.0 / r->dist)
				       : px_v3(0, 0, 0);
	}
	return PX_OK;
}

int px_dist_query_batch(struct px_dist_model *m, const px_vec3 *p, size_t n,
			struct px_dist_result *r)
{
	size_t i;
	if (!m || (!p && n) || (!r && n))
		return PX_E_INVAL;
	for (i = 0; i < n; i++) {
		int rc = px_dist_query(m, p[i], &r[i]);
		if (rc)
			return rc;
	}
	return PX_OK;
}
