/*
 * dist_build.c - setup of the distance core (px_dist_model_create()):
 * entities cut into pieces (dist_decomp.c), each piece's boxes and
 * samples, the knowledge step's closed-form shapes, and the grid that
 * the query's wave walks, all in one arena block.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "dist_internal.h"

void px_dist_opts_default(struct px_dist_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->sample_tol = 0.01;
	o->cell_cap = PX_DIST_CELL_CAP_DEFAULT;
	o->max_cells = 1L << 18;
	o->max_pieces_per_entity = 4096;
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
	struct px__dist_cuts d = {0};
	double *work;
	size_t wl = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
	int i, rc;

	if (c->degree < 1 || c->degree > PX_CPIECE_MAX_DEGREE)
		return PX_E_RANGE;
	rc = px__dist_decompose(c, o, info, &d);
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

/* One patch from the Bezier net bz of the rectangle r (u0, u1, v0, v1)
 * of entity ent; len the entity's length the sample spacing refers to. */
static int add_patch(struct builder *bl, const struct px_nurbs_surf *bz,
		     const double r[4], int ent, double len, double sample_tol)
{
	struct tmp_piece *t;
	int p = bz->degree[0], q = bz->degree[1], ii, jj, k;
	double ext;

	t = new_piece(bl);
	if (!t)
		return PX_E_NOMEM;
	t->hw = malloc((size_t)(p + 1) * (q + 1) * 4 * sizeof(double));
	if (!t->hw)
		return PX_E_NOMEM;
	t->p = p;
	t->q = q;
	for (k = 0; k < 4; k++)
		t->r[k] = r[k];
	t->pc.kind = PK_PATCH;
	t->pc.ent = ent;
	t->pc.iso_dir = -1;
	t->pc.box = px_aabb_empty();
	/* The extracted net has u fastest; patches want i (along u) as the
	 * slow index. */
	for (ii = 0; ii <= p; ii++)
		for (jj = 0; jj <= q; jj++) {
			const double *src = bz->pw + 4 * (jj * (p + 1) + ii);
			double *dst = t->hw + 4 * (ii * (q + 1) + jj);
			for (k = 0; k < 4; k++)
				dst[k] = src[k];
			px_aabb_extend(&t->pc.box, px_v3(src[0] / src[3], src[1] / src[3],
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
	t->pc.ns = len > 0.0 ? clamp_count(ext / (sample_tol * len) + 1.0, 2, 4) : 2;
	t->pc.nt = t->pc.ns;
	bl->n_samples += (long)t->pc.ns * t->pc.nt;
	return PX_OK;
}

/* Patches: every cell of the cut grid cu x cv lies in one knot
 * rectangle. */
static int add_patches(struct builder *bl, const struct px_nurbs_surf *s,
		       const struct px__dist_cuts *cu,
		       const struct px__dist_cuts *cv, int ent, double len,
		       double sample_tol)
{
	size_t wl = PX_NURBS_SURF_WORK_LEN(s->degree[0], s->degree[1],
					   s->n_ctrl[0], s->n_ctrl[1]);
	double *work = malloc(wl * sizeof(double));
	int i, j, rc = PX_OK;

	if (!work)
		return PX_E_NOMEM;
	for (i = 0; i + 1 < cu->n && !rc; i++)
		for (j = 0; j + 1 < cv->n && !rc; j++) {
			struct px_nurbs_surf bz;
			const double r[4] = {cu->u[i], cu->u[i + 1], cv->u[j],
					     cv->u[j + 1]};
			rc = px_nurbs_surf_extract_work(s, r[0], r[1], r[2], r[3],
							work, wl, &bz);
			if (!rc && (bz.n_ctrl[0] != s->degree[0] + 1 ||
				    bz.n_ctrl[1] != s->degree[1] + 1))
				rc = PX_E_STATE;
			if (!rc)
				rc = add_patch(bl, &bz, r, ent, len, sample_tol);
		}
	free(work);
	return rc;
}

/* Curve pieces along the iso-curve of s at parameter t of direction 1 -
 * dir (the curve runs along dir), through pw (pwl doubles). */
static int add_iso_pieces(struct builder *bl, const struct px_nurbs_surf *s,
			  int dir, double t, double *pw, size_t pwl,
			  const struct px_dist_opts *so, int ent, double len)
{
	struct px_nurbs_curve iso;
	struct px_dist_entity_info ci;
	int rc = px_nurbs_surf_iso_curve(s, dir, t, pw, pwl, &iso);
	if (rc)
		return rc;
	memset(&ci, 0, sizeof(ci));
	return add_curve_pieces(bl, &iso, so, &ci, ent, dir, t, len);
}

/* Boundary curves: domain edges that do not collapse to a point, and
 * interior C0 creases in both directions. */
static int add_boundaries(struct builder *bl, const struct px_nurbs_surf *s,
			  const struct px_dist_opts *so,
			  struct px_dist_entity_info *info, int ent, double len,
			  double diag)
{
	double a, b, c, d, brk[64], *pw;
	size_t pwl = 4 * (size_t)(s->n_ctrl[0] > s->n_ctrl[1] ? s->n_ctrl[0]
							       : s->n_ctrl[1]);
	int e, dir, k, nb, rc = PX_OK;

	px_nurbs_surf_domain(s, &a, &b, &c, &d);
	pw = malloc(pwl * sizeof(double));
	if (!pw)
		return PX_E_NOMEM;
	for (e = 0; e < 4 && !rc; e++) {
		/* edge: 0 u = a, 1 u = b, 2 v = c, 3 v = d; the curve runs
		 * along the other direction */
		double t = e == 0 ? a : (e == 1 ? b : (e == 2 ? c : d));
		if (px_nurbs_surf_edge_collapsed(s, e, 1e-12 * (1.0 + diag))) {
			info->n_collapsed++;
			continue;
		}
		rc = add_iso_pieces(bl, s, e < 2 ? 1 : 0, t, pw, pwl, so, ent, len);
	}
	for (dir = 0; dir < 2 && !rc; dir++) {
		/* A crease at u = brk runs along v. */
		nb = px_nurbs_surf_breaks(s, dir, brk, 64);
		if (nb > 64)
			rc = PX_E_NOSPC;
		for (k = 0; k < nb && !rc; k++)
			rc = add_iso_pieces(bl, s, 1 - dir, brk[k], pw, pwl, so, ent,
					    len);
	}
	free(pw);
	return rc;
}

static int add_surface(struct builder *bl, const struct px_nurbs_surf *s,
		       const struct px_dist_opts *o,
		       struct px_dist_entity_info *info, int ent)
{
	struct px_dist_opts so = *o;
	struct px__dist_cuts cu = {0}, cv = {0};
	double len_u = 0.0, len_v = 0.0, len, diag;
	int rc, first_boundary;
	px_aabb hull = px_nurbs_surf_aabb(s);

	if (s->degree[0] < 1 || s->degree[1] < 1 ||
	    s->degree[0] > PX_SPIECE_MAX_DEGREE ||
	    s->degree[1] > PX_SPIECE_MAX_DEGREE)
		return PX_E_RANGE;
	info->kind = PX_DIST_SURFACE;
	info->pf = px__dist_surf_pf(s);
	/* Memory grows with the square of the count: surfaces stop at the
	 * paper's 10 % (see pf_table()). */
	px__dist_decomp_settings(info, 0.1, o);
	so.decomp_tol = info->tol;
	so.jitter = info->jitter;
	rc = px__dist_surf_cuts(s, 0, &so, &len_u, &cu);
	if (!rc)
		rc = px__dist_surf_cuts(s, 1, &so, &len_v, &cv);
	if (!rc && (long)(cu.n - 1) * (cv.n - 1) > o->max_pieces_per_entity)
		rc = PX_E_NOSPC;
	if (rc)
		goto out;
	len = len_u > len_v ? len_u : len_v;
	info->arc_length = len;
	diag = px_aabb_diagonal(&hull);
	info->closed = (px_nurbs_surf_closed(s, 0, 1e-12 * (1.0 + diag)) ? 1 : 0) |
		       (px_nurbs_surf_closed(s, 1, 1e-12 * (1.0 + diag)) ? 2 : 0);
	info->n_breaks = px_nurbs_surf_breaks(s, 0, NULL, 0) +
			 px_nurbs_surf_breaks(s, 1, NULL, 0);
	info->first_piece = bl->n;
	rc = add_patches(bl, s, &cu, &cv, ent, len, so.sample_tol);
	if (rc)
		goto out;
	info->n_pieces = bl->n - info->first_piece;
	first_boundary = bl->n;
	rc = add_boundaries(bl, s, &so, info, ent, len, diag);
	if (!rc)
		info->n_boundary_pieces = bl->n - first_boundary;
out:
	free(cu.u);
	free(cv.u);
	return rc;
}

/* Pieces the grid holds (the others are outside a trimmed domain or
 * stand behind their entity's PK_SHAPE item). */
static int binned(const struct piece *pc)
{
	return pc->trim != PIECE_PRUNED && pc->trim != PIECE_SHAPE;
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
					n = px__dist_cell_index(m, x + dx, y + dy, z + dz);
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

/* The options with defaults for NULL; PX_E_INVAL when out of range. */
static int check_opts(const struct px_dist_opts *opts, struct px_dist_opts *o)
{
	if (opts)
		*o = *opts;
	else
		px_dist_opts_default(o);
	if (o->sample_tol <= 0.0 || o->sample_tol > 1.0 || o->cell_cap < 1 ||
	    o->max_cells < 1 || o->max_pieces_per_entity < 1 ||
	    o->decomp_tol < 0.0 || o->decomp_tol > 1.0 || o->jitter < 0.0 ||
	    o->jitter >= 1.0)
		return PX_E_INVAL;
	return PX_OK;
}

/* The pieces of every entity, curves first, into bl; their infos into
 * ent. */
static int add_entities(struct builder *bl, const struct px_nurbs_curve *curves,
			int n_curves, const struct px_nurbs_surf *surfs,
			int n_surfs, const struct px_dist_opts *o,
			struct px_dist_entity_info *ent)
{
	int e, rc = PX_OK;
	for (e = 0; e < n_curves && !rc; e++) {
		ent[e].kind = PX_DIST_CURVE;
		ent[e].first_piece = bl->n;
		rc = add_curve_pieces(bl, &curves[e], o, &ent[e], e, -1, 0.0, 0.0);
		ent[e].n_pieces = bl->n - ent[e].first_piece;
	}
	for (e = 0; e < n_surfs && !rc; e++)
		rc = add_surface(bl, &surfs[e], o, &ent[n_curves + e], n_curves + e);
	return rc;
}

/* What the model's block holds besides the pieces and the grid. */
struct layout {
	int n_curves, n_ent, n_cp, n_sp;
	int trimmed; /* the model keeps per-entity trimmed domains */
	size_t sp_doubles;    /* the patches' tensors */
	size_t shape_doubles; /* the closed-form shapes' copies of their arrays */
};

/*
 * Knowledge step (paper section 6, step 1): entities that are exactly a
 * primitive are answered in closed form; the bound on how far the
 * entity is from the primitive must be far inside the accuracy promised
 * (1e-9 of the model size). The others' shapes stay zero (NONE).
 */
static void recognize(const struct px_nurbs_curve *curves,
		      const struct px_nurbs_surf *surfs,
		      struct px_dist_entity_info *ent,
		      struct px_recog_shape *shapes, struct layout *ly)
{
	int e, n_curves = ly->n_curves;
	for (e = 0; e < ly->n_ent; e++) {
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
		ly->shape_doubles += e < n_curves
					     ? (size_t)curves[e].n_knots + 4 * (size_t)curves[e].n_ctrl
					     : (size_t)surfs[e - n_curves].n_knots[0] +
						       surfs[e - n_curves].n_knots[1] +
						       4 * (size_t)surfs[e - n_curves].n_ctrl[0] *
							       surfs[e - n_curves].n_ctrl[1];
	}
}

static void count_pieces(const struct builder *bl, struct layout *ly)
{
	int i;
	for (i = 0; i < bl->n; i++) {
		if (bl->tp[i].pc.kind == PK_SHAPE)
			continue;
		if (bl->tp[i].pc.kind == PK_CURVE) {
			ly->n_cp++;
		} else {
			ly->n_sp++;
			ly->sp_doubles += px_spiece_doubles_hw(bl->tp[i].p, bl->tp[i].q,
							       (const double(*)[4])bl->tp[i].hw);
		}
	}
}

/* A PK_SHAPE item counts as this many pieces in the cell budget: it
 * stands for a whole face or edge, whose box spans many cells; finer
 * cells let the wave meet the nearest faces first, so it answers fewer
 * in closed form (on CAD parts 8 beat both 2 and 32 under callgrind). */
#define SHAPE_ITEM_WEIGHT 8

/* On CAD parts of a few dozen faces the scan of PX__DIST_SCAN_ITEMS
 * boxes costs a fraction of the wave's shells. */
#define SCAN_ITEMS PX__DIST_SCAN_ITEMS

/* Grid geometry (paper section 6) into hdr: bounds, cell size from the
 * finest entity's piece count along the longest extent, cell counts. */
static void grid_geometry(struct px_dist_model *hdr, const struct builder *bl,
			  const struct px_dist_entity_info *ent, int n_ent,
			  long max_cells)
{
	px_vec3 ext;
	double mx;
	int i, e, per = 1;
	long cell_budget = 0;

	hdr->bounds = px_aabb_empty();
	for (i = 0; i < bl->n; i++) {
		hdr->bounds = px_aabb_union(&hdr->bounds, &bl->tp[i].pc.box);
		if (bl->tp[i].pc.kind == PK_SHAPE)
			cell_budget += bl->tp[i].pc.trim != PIECE_SHAPE ? SHAPE_ITEM_WEIGHT : 0;
		else
			cell_budget += bl->tp[i].pc.trim != PIECE_SHAPE;
	}
	cell_budget /= 2;
	ext = px_v3_sub(hdr->bounds.max, hdr->bounds.min);
	mx = fmax(ext.x, fmax(ext.y, ext.z));
	for (e = 0; e < n_ent; e++)
		per = ent[e].n_pieces > per ? ent[e].n_pieces : per;
	if (!(mx > 0.0))
		mx = 1.0;
	hdr->h = mx / per;
	/* The paper's cell size suits planar curves; a space curve, a
	 * surface or a large model would get mostly empty cells that every
	 * wave has to cross, so the cells also stay within a budget
	 * proportional to the pieces (and the memory bound). A cell costs a
	 * wave more than a piece in it does (shell bookkeeping against one
	 * box test), so about two pieces per cell measured fastest on a
	 * cubic curve (instruction counts under callgrind, against four
	 * cells per piece). */
	if (cell_budget < 8)
		cell_budget = 8;
	if (cell_budget > max_cells)
		cell_budget = max_cells;
	for (;;) {
		hdr->nx = (int)fmax(1.0, ceil(ext.x / hdr->h));
		hdr->ny = (int)fmax(1.0, ceil(ext.y / hdr->h));
		hdr->nz = (int)fmax(1.0, ceil(ext.z / hdr->h));
		hdr->n_cells = (long)hdr->nx * hdr->ny * hdr->nz;
		if (hdr->n_cells <= cell_budget)
			break;
		hdr->h *= 1.1;
	}
	hdr->inv_h = 1.0 / hdr->h;
}

/* References per cell of the pieces' boxes (calloc'd, n_cells), and the
 * spill table's size into hdr: every reference past the first cap of a
 * cell. NULL when out of memory. */
static long *count_refs(struct px_dist_model *hdr, const struct builder *bl)
{
	long *cnt = calloc((size_t)hdr->n_cells, sizeof(long)), c;
	int i;
	if (!cnt)
		return NULL;
	for (i = 0; i < bl->n; i++) {
		int lo[3], hi[3], x, y, z;
		if (!binned(&bl->tp[i].pc))
			continue;
		cell_range(hdr, bl->tp[i].pc.box, lo, hi);
		for (z = lo[2]; z <= hi[2]; z++)
			for (y = lo[1]; y <= hi[1]; y++)
				for (x = lo[0]; x <= hi[0]; x++)
					cnt[px__dist_cell_index(hdr, x, y, z)]++;
	}
	hdr->n_spill = 0;
	for (c = 0; c < hdr->n_cells; c++)
		if (cnt[c] > hdr->cap)
			hdr->n_spill += cnt[c] - hdr->cap;
	return cnt;
}

#define ALIGNED(x) (((x) + 63) & ~(size_t)63)

/* Bytes of the one block holding everything the queries touch. */
static size_t model_bytes(const struct px_dist_model *hdr,
			  const struct builder *bl, const struct layout *ly)
{
	size_t n_ent = (size_t)ly->n_ent, n = (size_t)bl->n;
	return ALIGNED(sizeof(*hdr)) +
	       ALIGNED(n_ent * sizeof(struct px_dist_entity_info)) +
	       ALIGNED(n_ent * sizeof(struct px_recog_shape)) +
	       ALIGNED(n_ent * sizeof(struct px__shape_fast)) +
	       ALIGNED(n * sizeof(struct px__dist_sbox)) +
	       (ly->trimmed ? ALIGNED(n_ent * sizeof(struct px__dist_trim)) : 0) +
	       ALIGNED(ly->shape_doubles * sizeof(double)) +
	       ALIGNED(n_ent * sizeof(uint32_t)) +
	       ALIGNED(n * sizeof(struct piece)) +
	       ALIGNED((size_t)ly->n_cp * sizeof(struct px_cpiece)) +
	       ALIGNED((size_t)ly->n_sp * sizeof(struct px_spiece)) +
	       ALIGNED(ly->sp_doubles * sizeof(double)) +
	       ALIGNED((size_t)bl->n_samples * sizeof(px_vec3)) +
	       ALIGNED((size_t)hdr->n_cells * sizeof(int)) * 2 +
	       ALIGNED((size_t)hdr->n_cells * sizeof(uint16_t)) +
	       ALIGNED((size_t)hdr->n_cells * (size_t)hdr->cap * sizeof(int)) +
	       ALIGNED((size_t)(hdr->n_spill + 1) * sizeof(int)) +
	       ALIGNED(n * sizeof(uint32_t)) + ALIGNED(n * sizeof(struct cand)) +
	       64 * 16;
}

/*
 * The model in its own arena (*out, set also when a later step fails, so
 * that the caller frees it), with hdr's grid, the counts and every array
 * taken from the block; *spmem and *shmem the patches' and the shapes'
 * doubles.
 */
static int model_alloc(const struct px_dist_model *hdr, const struct builder *bl,
		       const struct layout *ly, const struct px_dist_opts *o,
		       struct px_dist_model **out, double **spmem, double **shmem)
{
	struct px_arena ar;
	struct px_dist_model *m;
	int n_ent = ly->n_ent, rc;

	rc = px_arena_init_alloc(&ar, model_bytes(hdr, bl, ly));
	if (rc)
		return rc;
	m = px_arena_alloc(&ar, sizeof(*m), 64);
	*m = *hdr;
	m->arena = ar;
	*out = m;
#define TAKE(ptr, n) \
	((ptr) = px_arena_calloc(&m->arena, (size_t)(n), sizeof(*(ptr)), 64))
	m->opts = *o;
	m->n_ent = n_ent;
	m->n_pieces = bl->n;
	m->n_cp = ly->n_cp;
	m->n_sp = ly->n_sp;
	m->n_samples = (int)bl->n_samples;
	m->ws.n_pieces = bl->n;
	m->ws.bound2 = INFINITY;
	m->ws.n_ent = n_ent;
	*spmem = NULL;
	*shmem = NULL;
	if (!TAKE(m->ent, n_ent) || !TAKE(m->pieces, bl->n) ||
	    (ly->n_cp && !TAKE(m->cp, ly->n_cp)) ||
	    (ly->n_sp && !TAKE(m->spc, ly->n_sp)) ||
	    (ly->sp_doubles && !TAKE(*spmem, ly->sp_doubles)) ||
	    !TAKE(m->samples, bl->n_samples) ||
	    !TAKE(m->cell_count, m->n_cells) ||
	    !TAKE(m->cell_spill, m->n_cells) ||
	    !TAKE(m->cell_empty_r, m->n_cells) ||
	    !TAKE(m->cell_slot, m->n_cells * m->cap) ||
	    !TAKE(m->spill, m->n_spill + 1) || !TAKE(m->ws.stamp, bl->n) ||
	    !TAKE(m->ws.cand, bl->n) || !TAKE(m->shape, n_ent) ||
	    !TAKE(m->sfast, n_ent) ||
	    !TAKE(m->ws.ent_stamp, n_ent) ||
	    (ly->shape_doubles && !TAKE(*shmem, ly->shape_doubles)) ||
	    (ly->trimmed && !TAKE(m->trim, n_ent)))
		return PX_E_NOMEM; /* the sizing above is wrong: a bug */
#undef TAKE
	return PX_OK;
}

/* Box b as centre and half extents, the extents widened by a few ulp
 * of the coordinates (so |x - c| - e never exceeds the gap to b). */
/* Item i's lane of the scanned boxes o (struct px__dist_sbox); b NULL
 * for the padding lane. */
static void sbox(const px_aabb *b, struct px__dist_sbox *o, int i)
{
	int d, l = i & 1;
	o += i / 2;
	for (d = 0; d < 3; d++) {
		const double lo = b ? (&b->min.x)[d] : 0.0, hi = b ? (&b->max.x)[d] : 0.0;
		o->c[d][l] = b ? 0.5 * (lo + hi) : INFINITY;
		o->e[d][l] = 0.5 * (hi - lo) + 4.0 * DBL_EPSILON * (fabs(lo) + fabs(hi));
	}
}

/* The wedge of a turn of the given sweep into w (px__shape_fast). */
static void wedge(double sweep, double w[3])
{
	w[0] = cos(0.5 * sweep);
	w[1] = sin(0.5 * sweep);
	w[2] = sweep >= 2.0 * M_PI ? -2.0 : cos(0.5 * sweep);
}

static px_vec3 arc_end(const struct px_recog_arc *a, double f)
{
	return px_v3_add(a->center, px_v3_add(px_v3_scale(a->e0, a->radius * cos(f)),
					      px_v3_scale(a->e1, a->radius * sin(f))));
}

/* Every shape's px__shape_fast. */
static void fill_fast(struct px_dist_model *m)
{
	int e;
	for (e = 0; e < m->n_ent; e++) {
		const struct px_recog_shape *sh = &m->shape[e];
		struct px__shape_fast *f = &m->sfast[e];
		const struct px_recog_arc *a = sh->kind == PX_RECOG_ARC ? &sh->arc
									: &sh->rev.parc;
		wedge(sh->kind == PX_RECOG_ARC ? sh->arc.sweep : sh->rev.sweep, f->wedge);
		f->end[0] = cos(sh->rev.sweep);
		f->end[1] = sin(sh->rev.sweep);
		wedge(sh->rev.parc.sweep, f->pwedge);
		f->a0 = arc_end(a, 0.0);
		f->a1 = arc_end(a, a->sweep);
		if (sh->kind == PX_RECOG_PARALLELOGRAM) {
			const struct px_recog_quad *qd = &sh->quad;
			double l1 = px_v3_dot(qd->e1, qd->e1), l2 = px_v3_dot(qd->e2, qd->e2);
			/* Square to rounding: the bound's error stays far below
			 * the pruning margin (1e-9). */
			if (fabs(px_v3_dot(qd->e1, qd->e2)) <= 1e-14 * sqrt(l1 * l2)) {
				f->side2[0] = l1;
				f->side2[1] = l2;
			}
		}
	}
}

/* The shapes view the entity's arrays (for parameter inversion): point
 * them at copies the model owns, in shmem. */
static void copy_shape_arrays(struct px_dist_model *m,
			      const struct px_nurbs_curve *curves, int n_curves,
			      const struct px_nurbs_surf *surfs, double *shmem)
{
	int e;
	for (e = 0; e < m->n_ent; e++) {
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
}

/* The pieces into the model: curve pieces copied, patches prepared in
 * spmem, and every piece's pre-samples. */
static int fill_pieces(struct px_dist_model *m, const struct builder *bl,
		       double *spmem)
{
	int i, rc, ic = 0, is = 0, smp = 0;
	for (i = 0; i < bl->n; i++) {
		const struct tmp_piece *t = &bl->tp[i];
		struct piece *pc = &m->pieces[i];
		int a, b;
		*pc = t->pc;
		pc->sample_start = smp;
		if (t->pc.kind == PK_SHAPE)
			continue;
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
					    (const double(*)[4])t->hw, t->r[0],
					    t->r[1], t->r[2], t->r[3], spmem);
			if (rc)
				return rc;
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
	return PX_OK;
}

/* Bin the pieces: first cap references in the cell, the rest in the
 * spill table, laid out cell by cell (refs: count_refs()). */
static void bin_pieces(struct px_dist_model *m, const long *refs)
{
	long c, next = 0;
	int i;
	for (c = 0; c < m->n_cells; c++) {
		m->cell_spill[c] = (int)next;
		if (refs[c] > m->cap)
			next += refs[c] - m->cap;
	}
	for (i = 0; i < m->n_pieces; i++) {
		int lo[3], hi[3], x, y, z;
		if (!binned(&m->pieces[i]))
			continue;
		cell_range(m, m->pieces[i].box, lo, hi);
		for (z = lo[2]; z <= hi[2]; z++)
			for (y = lo[1]; y <= hi[1]; y++)
				for (x = lo[0]; x <= hi[0]; x++) {
					long ci = px__dist_cell_index(m, x, y, z);
					int k = m->cell_count[ci]++;
					if (k < m->cap)
						m->cell_slot[ci * m->cap + k] = i;
					else
						m->spill[m->cell_spill[ci] + k - m->cap] = i;
				}
	}
}

/*
 * Trimmed surfaces (px__dist_model_create_trimmed()): every piece of
 * surface e is classified against its domain once, so that queries pay
 * nothing for it. Domain edges go (the surface's edge points are never
 * strictly inside its trimmed domain; the trimming edges are the
 * caller's curves); patches and creases wholly outside are pruned,
 * crossed ones lose their samples and are solved with the filter.
 */
static void apply_trims(struct builder *bl, const struct px_nurbs_surf *surfs,
			const struct px__dist_trim *trims, int n_curves)
{
	int i;
	for (i = 0; i < bl->n; i++) {
		struct tmp_piece *t = &bl->tp[i];
		const struct px__dist_trim *tr;
		double a, b, c, d, box[4];
		int cls;
		if (t->pc.ent < n_curves)
			continue;
		tr = &trims[t->pc.ent - n_curves];
		if (!tr->inside)
			continue;
		px_nurbs_surf_domain(&surfs[t->pc.ent - n_curves], &a, &b, &c, &d);
		if (t->pc.kind == PK_PATCH) {
			memcpy(box, t->r, sizeof(box));
		} else if ((t->pc.iso_dir == 1 && (t->pc.iso_t == a || t->pc.iso_t == b)) ||
			   (t->pc.iso_dir == 0 && (t->pc.iso_t == c || t->pc.iso_t == d))) {
			t->pc.trim = PIECE_PRUNED;
		} else if (t->pc.iso_dir == 1) {
			box[0] = box[1] = t->pc.iso_t;
			box[2] = t->cp.u0_;
			box[3] = t->cp.u1_;
		} else {
			box[0] = t->cp.u0_;
			box[1] = t->cp.u1_;
			box[2] = box[3] = t->pc.iso_t;
		}
		if (t->pc.trim != PIECE_PRUNED) {
			cls = tr->classify(tr->ctx, box[0], box[1], box[2], box[3]);
			t->pc.trim = cls == 1 ? PIECE_WHOLE
					      : (cls == 0 ? PIECE_PRUNED : PIECE_CROSSED);
		}
		if (t->pc.trim != PIECE_WHOLE) {
			bl->n_samples -= (long)t->pc.ns * t->pc.nt;
			t->pc.ns = 0;
			t->pc.nt = 0;
		}
	}
}

/*
 * Trimmed models: an entity the closed form answers whole goes into the
 * grid as one PK_SHAPE item with the box of its pieces that are not
 * pruned; those pieces stay in the model (results name the first),
 * unbinned and without samples. Answered whole: a curve, an untrimmed
 * surface, or a trimmed one whose domain boundary lies on the caller's
 * curves (px__dist_trim.edged). Every recognised surface (parallelogram,
 * cylinder, cone, annulus, sphere, torus patch) has no interior local
 * minimum of the distance but its global minimum: in the angle about
 * the axis the distance is least at the query's angle and greatest
 * opposite, and along the profile (a segment or an arc) it has one
 * minimum; a query on the axis or at the centre makes a set of equal
 * minima, connected, so it reaches the domain's boundary if it meets
 * the domain. So when the closed form's point is not inside the domain,
 * the nearest point of the trimmed surface is on its boundary, which
 * the curves answer.
 */
static int add_shape_items(struct builder *bl,
			   const struct px_dist_entity_info *ent,
			   const struct px_recog_shape *shapes,
			   const struct px__dist_trim *trims, int n_curves,
			   int n_ent)
{
	int e, i;
	for (e = 0; e < n_ent; e++) {
		const struct px_dist_entity_info *in = &ent[e];
		int lo = in->first_piece, hi = lo + in->n_pieces + in->n_boundary_pieces;
		struct tmp_piece *t;
		px_aabb box = px_aabb_empty();
		const struct px__dist_trim *tr = e >= n_curves ? &trims[e - n_curves] : NULL;
		if (shapes[e].kind == PX_RECOG_NONE || (tr && tr->inside && !tr->edged))
			continue;
		for (i = lo; i < hi; i++)
			if (bl->tp[i].pc.trim != PIECE_PRUNED)
				box = px_aabb_union(&box, &bl->tp[i].pc.box);
		if (px_aabb_is_empty(&box))
			continue; /* nothing of it is in the domain */
		for (i = lo; i < hi; i++) {
			struct tmp_piece *f = &bl->tp[i];
			if (f->pc.trim == PIECE_WHOLE)
				bl->n_samples -= (long)f->pc.ns * f->pc.nt;
			f->pc.trim = PIECE_SHAPE;
			f->pc.ns = f->pc.nt = 0;
		}
		t = new_piece(bl);
		if (!t)
			return PX_E_NOMEM;
		t->pc.kind = PK_SHAPE;
		t->pc.ent = e;
		t->pc.idx = lo;
		t->pc.iso_dir = -1;
		t->pc.box = box;
		t->pc.trim = PIECE_WHOLE;
	}
	return PX_OK;
}

int px_dist_model_create(const struct px_nurbs_curve *curves, int n_curves,
			 const struct px_nurbs_surf *surfs, int n_surfs,
			 const struct px_dist_opts *opts,
			 struct px_dist_model **out)
{
	return px__dist_model_create_trimmed(curves, n_curves, surfs, n_surfs,
					     NULL, opts, out);
}

int px__dist_model_create_trimmed(const struct px_nurbs_curve *curves,
				  int n_curves, const struct px_nurbs_surf *surfs,
				  int n_surfs, const struct px__dist_trim *trims,
				  const struct px_dist_opts *opts,
				  struct px_dist_model **out)
{
	struct px_dist_opts o;
	struct px_dist_entity_info *ent = NULL;
	struct builder bl;
	struct px_dist_model *m = NULL, hdr;
	struct px_recog_shape *shapes = NULL;
	struct layout ly;
	long *refs = NULL;
	double *spmem, *shmem;
	int rc, i, hdr_shape_items = 0;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (n_curves < 0 || n_surfs < 0 || n_curves + n_surfs < 1 ||
	    (n_curves && !curves) || (n_surfs && !surfs))
		return PX_E_INVAL;
	rc = check_opts(opts, &o);
	if (rc)
		return rc;
	memset(&ly, 0, sizeof(ly));
	ly.n_curves = n_curves;
	ly.n_ent = n_curves + n_surfs;
	ent = calloc((size_t)ly.n_ent, sizeof(*ent));
	if (!ent)
		return PX_E_NOMEM;
	memset(&bl, 0, sizeof(bl));
	bl.sample_tol = o.sample_tol;
	rc = add_entities(&bl, curves, n_curves, surfs, n_surfs, &o, ent);
	if (rc)
		goto fail;
	if (trims) {
		apply_trims(&bl, surfs, trims, n_curves);
		ly.trimmed = 1;
	}
	shapes = calloc((size_t)ly.n_ent, sizeof(*shapes));
	if (!shapes) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	recognize(curves, surfs, ent, shapes, &ly);
	if (trims) {
		int n0 = bl.n;
		rc = add_shape_items(&bl, ent, shapes, trims, n_curves, ly.n_ent);
		if (rc)
			goto fail;
		hdr_shape_items = bl.n - n0;
		if (hdr_shape_items <= SCAN_ITEMS)
			for (i = n0; i < bl.n; i++)
				bl.tp[i].pc.trim = PIECE_SHAPE; /* scanned, not binned */
	}
	count_pieces(&bl, &ly);
	memset(&hdr, 0, sizeof(hdr));
	grid_geometry(&hdr, &bl, ent, ly.n_ent, o.max_cells);
	hdr.cap = o.cell_cap;
	refs = count_refs(&hdr, &bl);
	if (!refs) {
		rc = PX_E_NOMEM;
		goto fail;
	}
	rc = model_alloc(&hdr, &bl, &ly, &o, &m, &spmem, &shmem);
	if (rc)
		goto fail;
	m->n_shape_items = hdr_shape_items;
	for (i = 0; i < bl.n; i++)
		m->wave_pieces += binned(&bl.tp[i].pc);
	if (hdr_shape_items && hdr_shape_items <= SCAN_ITEMS) {
		m->shape_box = px_arena_calloc(&m->arena, (size_t)(hdr_shape_items + 1) / 2,
					       sizeof(*m->shape_box), 64);
		if (!m->shape_box) {
			rc = PX_E_NOMEM; /* the sizing is wrong: a bug */
			goto fail;
		}
		for (i = 0; i < hdr_shape_items; i++)
			sbox(&bl.tp[bl.n - hdr_shape_items + i].pc.box, m->shape_box, i);
		if (hdr_shape_items & 1)
			sbox(NULL, m->shape_box, hdr_shape_items);
	}
	memcpy(m->ent, ent, (size_t)ly.n_ent * sizeof(*ent));
	memcpy(m->shape, shapes, (size_t)ly.n_ent * sizeof(*shapes));
	fill_fast(m);
	copy_shape_arrays(m, curves, n_curves, surfs, shmem);
	if (trims) {
		int e;
		for (e = 0; e < n_surfs; e++)
			m->trim[n_curves + e] = trims[e];
	}
	rc = fill_pieces(m, &bl, spmem);
	if (rc)
		goto fail;
	bin_pieces(m, refs);
	rc = empty_radius(m);
	if (rc)
		goto fail;
	free_builder(&bl);
	free(ent);
	free(shapes);
	free(refs);
	*out = m;
	return PX_OK;
fail:
	if (m)
		px_arena_fini(&m->arena);
	free_builder(&bl);
	free(ent);
	free(shapes);
	free(refs);
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
