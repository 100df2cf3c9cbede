/*
 * px_dist.c - the global query of the distance core: a wave of grid
 * shells around the point collects candidate pieces by their boxes and
 * pre-samples, then the candidates are solved exactly (closed-form
 * shapes, certified curve and surface pieces) nearest bound first. The
 * model is built by dist_build.c.
 */
#include "px_dist.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dist_internal.h"

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

/* ---- query ---------------------------------------------------------------- */

/*
 * Squared distance from p to the part of the grid outside the cell block
 * [lo, hi] (inclusive indices): the minimum over the six slabs beyond the
 * block's faces, each clipped to the grid. INFINITY when the block covers
 * the grid. Exact for p inside or outside the grid.
 */
static inline __attribute__((always_inline)) double
outside_lb2(const struct px_dist_model *m, px_vec3 p, const int lo[3],
	    const int hi[3])
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
	int best_sample; /* global sample index; -1: a closed-form answer */
	int best_piece;
	px_vec3 best_point; /* the closed-form answer: point, parameters */
	double best_u, best_v;
	int best_params; /* 0: the parameters are still to be computed */
	int n_cand;
	int cells;
	int shapes; /* closed forms evaluated */
};

/*
 * 1 when (u, v) lies on the edge of the surface's parameter domain (to
 * 1e-13 of its extent, the trimmed domains' boundary tolerance): a
 * closed-form answer there says the surface has no interior minimum (it
 * has but its global one), so the nearest point of a trimmed part of it
 * is on the part's boundary, without asking the domain (whose loops
 * often run along that edge, where its test is dearest).
 */
static inline int on_domain_edge(const struct px_recog_shape *sh, double u,
				 double v)
{
	double eu = 1e-13 * (sh->dom[1] - sh->dom[0]);
	double ev = 1e-13 * (sh->dom[3] - sh->dom[2]);
	return u <= sh->dom[0] + eu || u >= sh->dom[1] - eu ||
	       v <= sh->dom[2] + ev || v >= sh->dom[3] - ev;
}

/* 1 when the direction (x, y) of length r lies in the wedge w of a turn
 * (struct px__shape_fast): its angle from the middle is at most half
 * the sweep. */
static inline int in_wedge(double x, double y, double r, const double w[3])
{
	return x * w[0] + y * w[1] >= r * w[2];
}

/* Squared distance from p to the arc a of wedge w and end points e0, e1
 * (the arc_closest() of px_recog.c without its angles). */
static inline double arc_d2(const struct px_recog_arc *a, const double w[3],
			    px_vec3 e0, px_vec3 e1, px_vec3 p)
{
	px_vec3 d = px_v3_sub(p, a->center);
	double h = px_v3_dot(a->normal, d), x = px_v3_dot(a->e0, d),
	       y = px_v3_dot(a->e1, d), r = sqrt(x * x + y * y), d0, d1;
	if (in_wedge(x, y, r, w))
		return h * h + (r - a->radius) * (r - a->radius);
	/* Outside the sweep the nearer end point answers. */
	d0 = px_v3_dist2(p, e0);
	d1 = px_v3_dist2(p, e1);
	return d0 < d1 ? d0 : d1;
}

/*
 * The squared distance from p to a closed-form shape to rounding,
 * without angle functions (px__shape_fast), or for a parallelogram
 * whose sides are not square the squared distance to its plane: a bound
 * the wave prunes with, far cheaper than px_recog_closest(). A surface
 * of revolution: p's meridian coordinates (h, rho), or where p's angle
 * is outside the sweep, those of its projection on the nearer end
 * meridian plus the squared distance to that plane; then the profile's
 * nearest point.
 */
static inline double shape_lb2(const struct px_recog_shape *sh,
			       const struct px__shape_fast *f, px_vec3 p)
{
	const struct px_recog_rev *rv = &sh->rev;
	px_vec3 w;
	double a, b, c, x, y, r, extra = 0.0;

	switch (sh->kind) {
	case PX_RECOG_ARC:
		return arc_d2(&sh->arc, f->wedge, f->a0, f->a1, p);
	case PX_RECOG_SEGMENT:
		w = px_v3_sub(p, sh->seg.p0);
		c = px_v3_dot(w, sh->seg.dir);
		c = c < 0.0 ? 0.0 : (c > sh->seg.len ? sh->seg.len : c);
		return px_v3_dist2(w, px_v3_scale(sh->seg.dir, c));
	case PX_RECOG_PARALLELOGRAM:
		w = px_v3_sub(p, sh->quad.origin);
		a = px_v3_dot(sh->quad.normal, w);
		a = a * a / px_v3_dot(sh->quad.normal, sh->quad.normal);
		/* Square sides: the in-plane excess beyond the sides adds. */
		x = px_v3_dot(sh->quad.f1, w);
		y = px_v3_dot(sh->quad.f2, w);
		b = gap1(x, sh->quad.x0 < sh->quad.x1 ? sh->quad.x0 : sh->quad.x1,
			 sh->quad.x0 < sh->quad.x1 ? sh->quad.x1 : sh->quad.x0);
		c = gap1(y, sh->quad.y0 < sh->quad.y1 ? sh->quad.y0 : sh->quad.y1,
			 sh->quad.y0 < sh->quad.y1 ? sh->quad.y1 : sh->quad.y0);
		return a + b * b * f->side2[0] + c * c * f->side2[1];
	case PX_RECOG_CYLINDER:
	case PX_RECOG_CONE:
	case PX_RECOG_ANNULUS:
	case PX_RECOG_SPHERE:
	case PX_RECOG_TORUS:
		w = px_v3_sub(p, rv->origin);
		a = px_v3_dot(rv->axis, w);
		x = px_v3_dot(rv->e0, w);
		y = px_v3_dot(rv->e1, w);
		r = sqrt(x * x + y * y);
		b = r;
		if (!in_wedge(x, y, r, f->wedge)) {
			double b1 = x * f->end[0] + y * f->end[1];
			b = x > b1 ? x : b1;
			extra = r * r - b * b;
			extra = extra > 0.0 ? extra : 0.0;
		}
		if (rv->profile_is_arc)
			return extra + arc_d2(&rv->parc, f->pwedge, f->a0, f->a1,
					      px_v3(a, b, 0.0));
		return extra + px__dist_pseg_d2(&rv->pseg, a, b);
	default:
		return 0.0;
	}
}

/*
 * A PK_SHAPE item (trimmed models, dist_build.c: add_shape_items()):
 * its entity in closed form, once per query. The answer is exact, so it
 * is the wave's upper bound at once and nothing is left to solve; on a
 * trimmed surface an answer outside the domain means the nearest point
 * is on the domain's boundary, which other entities answer. Out of line:
 * untrimmed models never come here.
 */
static __attribute__((noinline)) void
visit_shape(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	    const struct piece *pc, struct qstate *q)
{
	const struct px__dist_trim *tr = m->trim ? &m->trim[pc->ent] : NULL;
	struct px_recog_hit h;
	double d2;
	int trimmed;

	if (ws->ent_stamp[pc->ent] == ws->epoch)
		return;
	ws->ent_stamp[pc->ent] = ws->epoch;
	q->shapes++;
	/* The parameters only where the domain asks for them. */
	trimmed = tr && tr->inside;
	if (px_recog_closest(&m->shape[pc->ent], p, trimmed ? PX_RECOG_WANT_PARAMS : 0,
			     &h) != PX_OK)
		return; /* only an unrecognised kind refuses: never made an item */
	d2 = h.dist * h.dist;
	if (d2 >= q->best)
		return;
	if (trimmed && (on_domain_edge(&m->shape[pc->ent], h.u, h.v) ||
			!tr->inside(tr->ctx, h.u, h.v)))
		return;
	q->best_params = trimmed;
	q->best = d2;
	q->best_sample = -1;
	q->best_piece = pc->idx;
	q->best_point = h.point;
	q->best_u = h.u;
	q->best_v = h.v;
}

/* A PK_SHAPE item met: solved when its closed form's bound (with a
 * rounding margin, so that it only skips what is clearly farther) can
 * still beat the best. q->best only falls, so an item skipped once can
 * never win. */
static __attribute__((noinline)) void
meet_shape(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	   const struct piece *pc, struct qstate *q)
{
	if (ws->ent_stamp[pc->ent] != ws->epoch &&
	    shape_lb2(&m->shape[pc->ent], &m->sfast[pc->ent], p) * (1.0 - 1e-9) <
		    q->best)
		visit_shape(m, ws, p, pc, q);
}

/*
 * Models with few PK_SHAPE items (dist_build.c: SCAN_ITEMS): all of
 * them by their boxes' bounds, the nearest box's item first, then the
 * items whose bound beats its answer, nearest first, until the bound
 * reaches the best. A big face's box spans many cells, so the wave
 * would meet it from many of them and far from its nearest point; a
 * scan of a few dozen boxes costs less than the wave's shells. These
 * items are not in the grid, which holds the model's other pieces. The
 * bounds sit at the far end of the candidate list, which has room for
 * every piece.
 */
typedef double sb_v2 __attribute__((vector_size(16)));
typedef long long sb_i2 __attribute__((vector_size(16)));

static __attribute__((noinline)) void
scan_shapes(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	    struct qstate *q)
{
	int n = m->n_shape_items, first = m->n_pieces - n, i, k = 0, near = 0;
	struct cand *h = ws->cand + first;
	double near_lb, lbs[PX__DIST_SCAN_ITEMS + 1];
	const sb_v2 px = {p.x, p.x}, py = {p.y, p.y}, pz = {p.z, p.z}, zero = {0.0, 0.0};
	sb_v2 least = {INFINITY, INFINITY};
	const sb_i2 mag = {INT64_MAX, INT64_MAX};
	/* Two boxes at a time: lane by lane the scalar bound's operations
	 * (|p - c| - e clamped at 0, squares summed in the same order), so
	 * the same values bit for bit. */
	for (i = 0; 2 * i < n; i++) {
		const struct px__dist_sbox *b = &m->shape_box[i];
		sb_v2 c, e, dx, dy, dz, lb;
		memcpy(&c, b->c[0], sizeof(c));
		memcpy(&e, b->e[0], sizeof(e));
		dx = (sb_v2)((sb_i2)(px - c) & mag) - e;
		memcpy(&c, b->c[1], sizeof(c));
		memcpy(&e, b->e[1], sizeof(e));
		dy = (sb_v2)((sb_i2)(py - c) & mag) - e;
		memcpy(&c, b->c[2], sizeof(c));
		memcpy(&e, b->e[2], sizeof(e));
		dz = (sb_v2)((sb_i2)(pz - c) & mag) - e;
		dx = (sb_v2)((sb_i2)dx & (dx > zero));
		dy = (sb_v2)((sb_i2)dy & (dy > zero));
		dz = (sb_v2)((sb_i2)dz & (dz > zero));
		lb = dx * dx + dy * dy + dz * dz;
		memcpy(lbs + 2 * i, &lb, sizeof(lb));
		least = (sb_v2)(((sb_i2)lb & (lb < least)) | ((sb_i2)least & ~(lb < least)));
	}
	/* The first of the nearest boxes. */
	near_lb = least[0] < least[1] ? least[0] : least[1];
	while (near < n - 1 && lbs[near] != near_lb)
		near++;
	/* The nearest box's item first: its answer leaves few to order. */
	meet_shape(m, ws, p, &m->pieces[first + near], q);
	for (i = 0; i < n; i++)
		if (lbs[i] < q->best && i != near) {
			h[k].lb = lbs[i];
			h[k++].piece = first + i;
		}
	/* Nearest first by selection: usually one or two are taken. */
	while (k > 0) {
		int lo = 0, id;
		for (i = 1; i < k; i++)
			lo = h[i].lb < h[lo].lb ? i : lo;
		if (h[lo].lb >= q->best)
			break;
		id = h[lo].piece;
		h[lo] = h[--k];
		meet_shape(m, ws, p, &m->pieces[id], q);
	}
}

/* Inline: called for every piece of every visited cell. shapes: the
 * model has PK_SHAPE items (a constant in each specialised wave). */
static inline __attribute__((always_inline)) void
visit_piece(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	    int id, struct qstate *q, const int shapes)
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
	if (shapes && pc->kind == PK_SHAPE) {
		meet_shape(m, ws, p, pc, q);
		return;
	}
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

static inline __attribute__((always_inline)) void
visit_cell_k(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	     int x, int y, int z, struct qstate *q, const int shapes)
{
	long ci = px__dist_cell_index(m, x, y, z);
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
		visit_piece(m, ws, p, m->cell_slot[ci * m->cap + k], q, shapes);
	for (k = m->cap; k < n; k++)
		visit_piece(m, ws, p, m->spill[m->cell_spill[ci] + k - m->cap], q,
			    shapes);
}

static void visit_cell(const struct px_dist_model *m, struct px_dist_ws *ws,
		       px_vec3 p, int x, int y, int z, struct qstate *q)
{
	visit_cell_k(m, ws, p, x, y, z, q, 0);
}

static void visit_cell_shapes(const struct px_dist_model *m,
			      struct px_dist_ws *ws, px_vec3 p, int x, int y,
			      int z, struct qstate *q)
{
	visit_cell_k(m, ws, p, x, y, z, q, 1);
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
	ws->bound2 = INFINITY;
	*out = ws;
	return PX_OK;
}

void px_dist_ws_free(struct px_dist_ws *ws)
{
	if (ws && ws->owned)
		free(ws);
}

/* The wave: shells of cells at Chebyshev distance k from the cell
 * nearest to p, until everything not yet reached is farther than the
 * best sample (or closed-form answer). */
static inline __attribute__((always_inline)) void
wave_k(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
       struct qstate *q, const int shapes)
{
	int c[3], k, kmax, i;

	c[0] = clamp_cell((p.x - m->bounds.min.x) * m->inv_h, m->nx);
	c[1] = clamp_cell((p.y - m->bounds.min.y) * m->inv_h, m->ny);
	c[2] = clamp_cell((p.z - m->bounds.min.z) * m->inv_h, m->nz);
	kmax = m->nx > m->ny ? m->nx : m->ny;
	kmax = kmax > m->nz ? kmax : m->nz;
	/* Shells nearer than the nearest occupied cell hold nothing. */
	k = m->cell_empty_r[px__dist_cell_index(m, c[0], c[1], c[2])];
	for (; k <= kmax; k++) {
		int lo[3], hi[3], x, y, z;
		/* Everything not yet reached lies outside block k - 1. */
		if (k > 0) {
			for (i = 0; i < 3; i++) {
				lo[i] = c[i] - (k - 1);
				hi[i] = c[i] + (k - 1);
			}
			if (q->best <= outside_lb2(m, p, lo, hi))
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
							(shapes ? visit_cell_shapes : visit_cell)(
								m, ws, p, x, y, z, q);
				} else {
					if (c[0] - k >= 0)
						(shapes ? visit_cell_shapes : visit_cell)(
							m, ws, p, c[0] - k, y, z, q);
					if (k > 0 && c[0] + k < m->nx)
						(shapes ? visit_cell_shapes : visit_cell)(
							m, ws, p, c[0] + k, y, z, q);
				}
			}
		}
	}
}

/* The wave specialised once per model kind, so that models without
 * PK_SHAPE items pay nothing for them. */
static void wave(const struct px_dist_model *m, struct px_dist_ws *ws,
		 px_vec3 p, struct qstate *q)
{
	wave_k(m, ws, p, q, 0);
}

static __attribute__((noinline)) void
wave_shapes(const struct px_dist_model *m, struct px_dist_ws *ws, px_vec3 p,
	    struct qstate *q)
{
	if (!m->shape_box) {
		wave_k(m, ws, p, q, 1);
		return;
	}
	/* The scanned items are not in the grid. */
	scan_shapes(m, ws, p, q);
	if (m->wave_pieces)
		wave_k(m, ws, p, q, 0);
}

/* What the solves of one query carry from candidate to candidate. */
struct solve {
	double best; /* squared distance of the answer so far */
	double gap;  /* largest uncertified gap */
};

/* A piece's uncertified result widens the query's gap. */
static inline void note_cert(struct px_dist_result *r, struct solve *sv,
			     int certified, double gap)
{
	if (!certified) {
		r->certified = 0;
		sv->gap = fmax(sv->gap, gap);
	}
}

/* The entity of piece cd in closed form. 1 when that answers the whole
 * entity (now or earlier in this query), 0 when its pieces must be
 * solved. */
static inline int solve_shape(const struct px_dist_model *m,
			      struct px_dist_ws *ws, px_vec3 p,
			      const struct cand *cd, const struct piece *pc,
			      struct solve *sv, struct px_dist_result *r)
{
	struct px_recog_hit h;
	if (ws->ent_stamp[pc->ent] == ws->epoch)
		return 1; /* the whole entity is answered */
	if (px_recog_closest(&m->shape[pc->ent], p, PX_RECOG_WANT_PARAMS, &h) !=
	    PX_OK)
		return 0; /* no closed form for this query */
	/* A trimmed surface: the whole surface's minimum answers its trimmed
	 * part when it lies inside the domain, else the pieces do; when it
	 * is no nearer than the best, nothing on the part is either. */
	if (m->trim && m->trim[pc->ent].inside && h.dist * h.dist < sv->best &&
	    !m->trim[pc->ent].inside(m->trim[pc->ent].ctx, h.u, h.v))
		return 0;
	ws->ent_stamp[pc->ent] = ws->epoch;
	r->pieces_solved++;
	if (h.dist * h.dist < sv->best) {
		sv->best = h.dist * h.dist;
		r->point = h.point;
		r->u = h.u;
		r->v = h.v;
		r->piece = cd->piece;
	}
	return 1;
}

static inline void solve_curve(const struct px_dist_model *m, px_vec3 p,
			       const struct cand *cd, const struct piece *pc,
			       struct solve *sv, struct px_dist_result *r)
{
	struct px_cpiece_hit hit;
	if (px_cpiece_closest(&m->cp[pc->idx], p, &sv->best, &hit)) {
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
	note_cert(r, sv, hit.certified, hit.gap);
}

static inline void solve_patch(const struct px_dist_model *m, px_vec3 p,
			       const struct cand *cd, const struct piece *pc,
			       const struct qstate *q, struct solve *sv,
			       struct px_dist_result *r)
{
	struct px_spiece_hit hit;
	double hs = NAN, ht = NAN;
	if (cd->piece == q->best_piece) {
		/* Newton starts at the best pre-sample. */
		int ks = q->best_sample - pc->sample_start;
		hs = (double)(ks / pc->nt) / (pc->ns - 1);
		ht = (double)(ks % pc->nt) / (pc->nt - 1);
	}
	if (px_spiece_closest_hint(&m->spc[pc->idx], p, hs, ht, &sv->best, &hit)) {
		r->point = hit.point;
		r->piece = cd->piece;
		r->u = hit.u;
		r->v = hit.v;
	}
	r->iters += hit.iters;
	note_cert(r, sv, hit.certified, hit.gap);
}

/* A piece of a trimmed surface that a loop crosses: its solver keeps
 * only minima inside the domain (no pre-samples, so no Newton hint).
 * Out of line: untrimmed models never come here. */
static __attribute__((noinline)) void
solve_crossed(const struct px_dist_model *m, px_vec3 p, const struct cand *cd,
	      const struct piece *pc, struct solve *sv, struct px_dist_result *r)
{
	const struct px__uv_filter f = {m->trim[pc->ent].inside, m->trim[pc->ent].ctx,
					pc->iso_dir, pc->iso_t};
	int got, iters, certified;
	double gap, u, v = 0.0;
	px_vec3 pt;
	if (pc->kind == PK_CURVE) {
		struct px_cpiece_hit h;
		got = px__cpiece_closest_in(&m->cp[pc->idx], p, &f, &sv->best, &h);
		iters = h.iters, certified = h.certified, gap = h.gap;
		pt = h.point;
		u = pc->iso_dir == 1 ? pc->iso_t : h.u;
		v = pc->iso_dir == 1 ? h.u : pc->iso_t;
	} else {
		struct px_spiece_hit h;
		got = px__spiece_closest_in(&m->spc[pc->idx], p, NAN, NAN, &f, &sv->best,
					    &h);
		iters = h.iters, certified = h.certified, gap = h.gap;
		pt = h.point, u = h.u, v = h.v;
	}
	if (got) {
		r->point = pt;
		r->piece = cd->piece;
		r->u = u;
		r->v = v;
	}
	r->iters += iters;
	note_cert(r, sv, certified, gap);
}

/*
 * Exact solve of every piece that may still hold something closer. The
 * piece holding the best sample goes first: its solve usually lands on
 * the global minimum. Only the candidates whose bound still beats the
 * best after it are sorted (nearest bound first): most fall out there,
 * and sorting a handful costs little.
 */
static inline __attribute__((always_inline)) void
solve_candidates(const struct px_dist_model *m, struct px_dist_ws *ws,
		 px_vec3 p, struct qstate *q, struct solve *sv,
		 struct px_dist_result *r, const int shapes)
{
	/* A closed-form best (models with PK_SHAPE items) is already the
	 * answer of its entity: then every candidate waits for the sort. */
	const int head = !shapes || q->best_sample >= 0;
	int i, sorted;
	for (i = 0; i < q->n_cand && head; i++)
		if (ws->cand[i].piece == q->best_piece) {
			struct cand t = ws->cand[i];
			ws->cand[i] = ws->cand[0];
			ws->cand[0] = t;
			break;
		}
	sorted = q->n_cand <= head;
	for (i = 0; i < q->n_cand; i++) {
		const struct cand *cd;
		const struct piece *pc;
		if (i == head && !sorted) {
			int j, n = head;
			for (j = head; j < q->n_cand; j++)
				if (ws->cand[j].lb < sv->best)
					ws->cand[n++] = ws->cand[j];
			q->n_cand = n;
			sort_cand(ws->cand + head, n - head);
			sorted = 1;
			if (n <= i)
				break;
		}
		cd = &ws->cand[i];
		pc = &m->pieces[cd->piece];
		/* Past the head, the list is sorted by lower bound. */
		if (i >= head && cd->lb >= sv->best)
			break;
		if (m->shape[pc->ent].kind != PX_RECOG_NONE &&
		    solve_shape(m, ws, p, cd, pc, sv, r))
			continue;
		/* The oriented box can only drop a piece (the list order is
		 * by the axis-aligned bound, so go on to the next). */
		if (i >= head && px_obb_dist2(&pc->obb, p) >= sv->best)
			continue;
		r->pieces_solved++;
		if (pc->trim == PIECE_CROSSED)
			solve_crossed(m, p, cd, pc, sv, r);
		else if (pc->kind == PK_CURVE)
			solve_curve(m, p, cd, pc, sv, r);
		else
			solve_patch(m, p, cd, pc, q, sv, r);
	}
}

int px_dist_query_ws(const struct px_dist_model *m, struct px_dist_ws *ws,
		     px_vec3 p, struct px_dist_result *r)
{
	struct qstate q;
	struct solve sv;

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
	/* INFINITY but inside px__dist_query_below() */
	q.best = ws->bound2;
	q.best_piece = -1;
	q.best_sample = 0;
	q.n_cand = 0;
	q.cells = 0;
	q.shapes = 0;
	q.best_params = 1;
	if (m->n_shape_items)
		wave_shapes(m, ws, p, &q);
	else
		wave(m, ws, p, &q);
	r->cells_visited = q.cells;
	r->pieces_solved = q.shapes;
	if (q.best_piece < 0 && q.best == INFINITY)
		/* The wave meets every piece, so only overflowing squared
		 * distances (a model spanning more than about 1e154) leave
		 * no best sample. */
		return PX_E_RANGE;

	/* Start from the best sample, a point on the model, so that an
	 * answer exists even if no solve improves on it. */
	sv.best = q.best;
	sv.gap = 0.0;
	r->piece = q.best_piece;
	if (q.best_piece < 0) {
		/* below a bound: only a solve can answer */
	} else if (q.best_sample >= 0) {
		r->point = m->samples[q.best_sample];
		sample_params(m, q.best_piece, q.best_sample, &r->u, &r->v);
	} else {
		struct px_recog_hit h;
		r->point = q.best_point;
		r->u = q.best_u;
		r->v = q.best_v;
		/* The same point again, now with its parameters. */
		if (!q.best_params &&
		    px_recog_closest(&m->shape[m->pieces[q.best_piece].ent], p,
				     PX_RECOG_WANT_PARAMS, &h) == PX_OK) {
			r->u = h.u;
			r->v = h.v;
		}
	}
	if (m->n_shape_items)
		solve_candidates(m, ws, p, &q, &sv, r, 1);
	else
		solve_candidates(m, ws, p, &q, &sv, r, 0);
	r->dist = sqrt(sv.best);
	if (!isfinite(r->dist))
		return PX_E_RANGE; /* overflow: see PX__MAX_QUERY_REACH */
	r->gap = sv.gap;
	if (r->piece < 0)
		return 1;
	r->entity = m->pieces[r->piece].ent;
	r->kind = m->ent[r->entity].kind;
	{
		px_vec3 d = px_v3_sub(p, r->point);
		r->dir = r->dist > 0.0 ? px_v3_scale(d, 1.0 / r->dist)
				       : px_v3(0, 0, 0);
	}
	return PX_OK;
}

int px__dist_query_below(const struct px_dist_model *m, struct px_dist_ws *ws,
			 px_vec3 p, double bound2, struct px_dist_result *r)
{
	int rc;
	if (!ws)
		return PX_E_INVAL;
	ws->bound2 = bound2;
	rc = px_dist_query_ws(m, ws, p, r);
	ws->bound2 = INFINITY;
	return rc;
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
