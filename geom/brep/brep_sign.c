/*
 * brep_sign.c - signed distance of closed B-reps from their own faces.
 *
 * Setup decides whether answers can be signed and prepares what the
 * signing reads: per coedge a table from edge parameters to its loop
 * curve's parameters (so that an edge point's (u, v) on either face
 * comes from a few Gauss-Newton steps), and per vertex its
 * angle-weighted pseudo-normal: every face corner at the vertex adds its
 * outward unit normal times the corner's angle, measured in the tangent
 * plane from the outgoing loop tangent round the normal to the reversed
 * incoming one (a loop runs with its face on the left: outer loops
 * counter-clockwise, holes clockwise, as px_trim orients them). Where a
 * loop curve collapses to the vertex (a pole, an apex, a blend's
 * corner) the face has no tangent plane there: its fan of directions
 * round the vertex is swept instead, from the incoming edge backwards,
 * through points just inside the face along the collapsed curve, to the
 * outgoing edge, each step's angle weighting the unit normal there (as
 * px_model_nurbs.c does at poles).
 *
 * Signed only when every face is trimmed, every shell is closed and in
 * a solid, every edge is used by exactly two coedges of one shell that
 * run it in opposite directions once each face's orientation is applied
 * (so the faces agree on the outside), every coedge lies along its edge,
 * every vertex has a pseudo-normal, and a point beyond the box comes out
 * outside (faces given inwards would sign everything the wrong way).
 *
 * Query: at a face's interior foot point the face's outward normal; at
 * an edge the sum of its two faces' outward normals there (the equal
 * angle weights of an edge); at a vertex its pseudo-normal. For a point
 * whose closest point is that feature, these point towards it exactly
 * when it is outside (Baerentzen and Aanaes; the tangent cones of the
 * faces decide, as for a polyhedron).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"

px_vec3 px__brep_face_normal(const struct px_brep *b, int f, double u, double v)
{
	struct px_nurbs_surf_derivs d;
	px_vec3 n;
	double l;
	if (px_nurbs_surf_eval(&b->faces[f].surf, u, v, 1, &d) != PX_OK)
		return px_v3(0, 0, 0);
	n = px_v3_cross(d.su, d.sv);
	l = px_v3_norm(n);
	if (!(l > 0.0))
		return px_v3(0, 0, 0);
	return px_v3_scale(n, (b->faces[f].reversed ? -1.0 : 1.0) / l);
}

/* Loop curve parameter s of coedge c nearest to the 3D point x, by
 * Gauss-Newton on |S(c(s)) - x|^2 from s (bounded steps, clamped to the
 * curve's domain); *gap the distance left. @note RT-safe. */
static double refine_s(const struct px_brep *b, const struct brep_coedge *c,
		       px_vec3 x, double s, double *gap)
{
	const struct px_nurbs_surf *sf = &b->faces[c->face].surf;
	double t0, t1;
	px_vec3 cd[2];
	struct px_nurbs_surf_derivs d;
	int it;

	px_nurbs_curve_domain(&c->pc, &t0, &t1);
	for (it = 0; it < 12; it++) {
		px_vec3 tg, r;
		double h, ds;
		px_nurbs_curve_eval(&c->pc, s, 1, cd);
		px_nurbs_surf_eval(sf, cd[0].x, cd[0].y, 1, &d);
		tg = px_v3_add(px_v3_scale(d.su, cd[1].x), px_v3_scale(d.sv, cd[1].y));
		r = px_v3_sub(d.s, x);
		h = px_v3_dot(tg, tg);
		if (!(h > 0.0))
			break;
		ds = -px_v3_dot(r, tg) / h;
		ds = ds > 0.25 * (t1 - t0) ? 0.25 * (t1 - t0)
					   : (ds < -0.25 * (t1 - t0) ? -0.25 * (t1 - t0) : ds);
		s = s + ds < t0 ? t0 : (s + ds > t1 ? t1 : s + ds);
		if (fabs(ds) <= 1e-15 * (t1 - t0))
			break;
	}
	if (gap) {
		px_vec3 q = px_nurbs_curve_point(&c->pc, s);
		*gap = px_v3_dist(px_nurbs_surf_point(sf, q.x, q.y), x);
	}
	return s;
}

/* (u, v) on coedge c's face of the point x of its edge at parameter t. */
static void coedge_uv(const struct px_brep *b, const struct brep_coedge *c,
		      double t, px_vec3 x, double *u, double *v)
{
	const struct brep_edge *e = &b->edges[c->edge];
	double f = (t - e->t0) / (e->t1 - e->t0) * (BREP_MAP_N - 1), s;
	int j = f <= 0.0 ? 0 : (f >= BREP_MAP_N - 1 ? BREP_MAP_N - 2 : (int)f);
	double a = f - j;
	px_vec3 q;
	a = a < 0.0 ? 0.0 : (a > 1.0 ? 1.0 : a);
	s = c->s[j] + a * (c->s[j + 1] - c->s[j]);
	s = refine_s(b, c, x, s, NULL);
	q = px_nurbs_curve_point(&c->pc, s);
	*u = q.x;
	*v = q.y;
}

/* The coedge's edge -> loop curve parameter table: each edge sample's
 * nearest point of 257 on the loop curve's image, refined. 0 when the
 * loop curve does not run along the edge (within tol). */
static int map_coedge(const struct px_brep *b, struct brep_coedge *c, double tol)
{
	const struct brep_edge *e = &b->edges[c->edge];
	const struct px_nurbs_surf *sf = &b->faces[c->face].surf;
	px_vec3 img[257];
	double t0, t1;
	int i, j;

	px_nurbs_curve_domain(&c->pc, &t0, &t1);
	for (i = 0; i <= 256; i++) {
		px_vec3 q = px_nurbs_curve_point(&c->pc, t0 + (t1 - t0) * i / 256.0);
		img[i] = px_nurbs_surf_point(sf, q.x, q.y);
	}
	for (j = 0; j < BREP_MAP_N; j++) {
		double t = e->t0 + (e->t1 - e->t0) * j / (BREP_MAP_N - 1), best = INFINITY, gap;
		px_vec3 x = px_nurbs_curve_point(&e->c, t);
		int bi = 0;
		for (i = 0; i <= 256; i++) {
			double d2 = px_v3_dist2(img[i], x);
			if (d2 < best) {
				best = d2;
				bi = i;
			}
		}
		c->t[j] = t;
		c->s[j] = refine_s(b, c, x, t0 + (t1 - t0) * bi / 256.0, &gap);
		if (!(gap <= tol))
			return 0;
	}
	c->mapped = 1;
	return 1;
}

/* 3D unit tangent of coedge c at loop curve parameter s, in the
 * direction its face's outward normal induces (loop orientation, then
 * the face's reversal). */
static px_vec3 induced_tangent(const struct px_brep *b,
			       const struct brep_coedge *c, double s)
{
	const struct brep_face *f = &b->faces[c->face];
	struct px_nurbs_surf_derivs d;
	px_vec3 cd[2], t;
	double sg = c->dir * (px_trim_loop_reversed(f->trim, c->loop) == 1 ? -1.0 : 1.0) *
		    (f->reversed ? -1.0 : 1.0);
	px_nurbs_curve_eval(&c->pc, s, 1, cd);
	px_nurbs_surf_eval(&f->surf, cd[0].x, cd[0].y, 1, &d);
	t = px_v3_add(px_v3_scale(d.su, cd[1].x), px_v3_scale(d.sv, cd[1].y));
	return px_v3_scale(t, sg / (px_v3_norm(t) > 0.0 ? px_v3_norm(t) : 1.0));
}

/* End (end != 0) or start of coedge c in the given loop direction: its
 * (u, v) point and its (u, v) tangent along that direction. */
static void coedge_end(const struct brep_coedge *c, int end, px_vec3 *p,
		       px_vec3 *tg)
{
	double t0, t1, s;
	px_vec3 cd[2];
	px_nurbs_curve_domain(&c->pc, &t0, &t1);
	s = (end != 0) == (c->dir > 0) ? t1 : t0;
	px_nurbs_curve_eval_side(&c->pc, s, s == t1 ? -1 : 1, 1, cd);
	*p = cd[0];
	*tg = px_v3_scale(cd[1], (double)c->dir);
}

/* The vertex of the corner between coedges i and j (the end of i) at the
 * 3D point x: the end vertex of either edge nearest to x, or -1. */
static int corner_vertex(const struct px_brep *b, int i, int j, px_vec3 x)
{
	int cand[4], n = 0, k, best = -1;
	double bd = INFINITY;
	if (b->co[i].edge >= 0) {
		cand[n++] = b->edges[b->co[i].edge].v0;
		cand[n++] = b->edges[b->co[i].edge].v1;
	}
	if (b->co[j].edge >= 0) {
		cand[n++] = b->edges[b->co[j].edge].v0;
		cand[n++] = b->edges[b->co[j].edge].v1;
	}
	for (k = 0; k < n; k++)
		if (cand[k] >= 0 && px_v3_dist(b->verts[cand[k]], x) < bd) {
			bd = px_v3_dist(b->verts[cand[k]], x);
			best = cand[k];
		}
	return best;
}

/* The coedge after i in its loop (the loop's first after its last). */
static int next_coedge(const struct px_brep *b, int i)
{
	const struct brep_coedge *c = &b->co[i];
	int j = i + 1;
	if (j < b->n_co && b->co[j].face == c->face && b->co[j].loop == c->loop)
		return j;
	for (j = i; j > 0 && b->co[j - 1].face == c->face && b->co[j - 1].loop == c->loop;
	     j--)
		;
	return j;
}

/* 3D unit direction of the (u, v) tangent t at the surface derivatives
 * d (zero when it has none). */
static px_vec3 dir3(const struct px_nurbs_surf_derivs *d, px_vec3 t)
{
	px_vec3 r = px_v3_add(px_v3_scale(d->su, t.x), px_v3_scale(d->sv, t.y));
	double l = px_v3_norm(r);
	return l > 0.0 ? px_v3_scale(r, 1.0 / l) : px_v3(0, 0, 0);
}

#define BREP_FAN 32
#define BREP_FAN_DELTA 1e-5 /* inward offset, fraction of the domain */

/*
 * The fan of face f round vertex x where loop curve k (coedge ic, image
 * x) collapses: incoming coedge ia ends there, outgoing ib starts. Adds
 * the angle-weighted outward normals to *acc; 0 when a direction or
 * normal is missing.
 */
static int pole_fan(const struct px_brep *b, int ia, int ic, int ib, px_vec3 x,
		    px_vec3 *acc)
{
	const struct brep_coedge *c = &b->co[ic];
	const struct brep_face *f = &b->faces[c->face];
	double sg = f->reversed ? -1.0 : 1.0, a0, a1, b0, b1, t0, t1, del;
	double lr = px_trim_loop_reversed(f->trim, c->loop) == 1 ? -1.0 : 1.0;
	struct px_nurbs_surf_derivs d;
	px_vec3 p, ta, tb, prev, prev_n = px_v3(0, 0, 0);
	int k;

	px_nurbs_surf_domain(&f->surf, &a0, &a1, &b0, &b1);
	del = BREP_FAN_DELTA * fmax(a1 - a0, b1 - b0);
	coedge_end(&b->co[ia], 1, &p, &ta);
	px_nurbs_surf_eval(&f->surf, p.x, p.y, 1, &d);
	prev = px_v3_neg(dir3(&d, ta));
	coedge_end(&b->co[ib], 0, &p, &tb);
	px_nurbs_surf_eval(&f->surf, p.x, p.y, 1, &d);
	tb = dir3(&d, tb);
	if (px_v3_norm(prev) == 0.0 || px_v3_norm(tb) == 0.0)
		return 0;
	px_nurbs_curve_domain(&c->pc, &t0, &t1);
	for (k = 0; k <= BREP_FAN + 1; k++) {
		px_vec3 q, n;
		if (k <= BREP_FAN) {
			/* Along the collapsed curve in the loop's direction,
			 * offset to its left (into the face). */
			double s = c->dir > 0 ? t0 + (t1 - t0) * (k + 0.5) / (BREP_FAN + 1)
					      : t1 - (t1 - t0) * (k + 0.5) / (BREP_FAN + 1);
			px_vec3 cd[2], lt;
			double l;
			px_nurbs_curve_eval(&c->pc, s, 1, cd);
			lt = px_v3_scale(cd[1], c->dir * lr);
			l = hypot(lt.x, lt.y);
			if (!(l > 0.0))
				return 0;
			px_nurbs_surf_eval(&f->surf, cd[0].x - del * lt.y / l * lr,
					   cd[0].y + del * lt.x / l * lr, 1, &d);
			q = px_v3_sub(d.s, x);
			n = px_v3_cross(d.su, d.sv);
			if (!(px_v3_norm(q) > 0.0 && px_v3_norm(n) > 0.0))
				return 0;
			q = px_v3_scale(q, 1.0 / px_v3_norm(q));
			n = px_v3_scale(n, sg / px_v3_norm(n));
		} else {
			q = tb;
			n = prev_n;
		}
		if (k == 0)
			prev_n = n;
		*acc = px_v3_madd(*acc, k == 0 ? n : (k <= BREP_FAN ? px_v3_scale(px_v3_add(n, prev_n), 0.5) : prev_n),
				  atan2(px_v3_norm(px_v3_cross(prev, q)), px_v3_dot(prev, q)));
		prev = q;
		prev_n = n;
	}
	return 1;
}

/* Every face corner's angle times its outward normal into its vertex's
 * pseudo-normal; bad[v] set where a corner has no tangent or normal. */
static void corners(struct px_brep *b, unsigned char *bad)
{
	int i;
	for (i = 0; i < b->n_co; i++) {
		const struct brep_coedge *c = &b->co[i];
		const struct brep_face *f = &b->faces[c->face];
		int j = next_coedge(b, i), lr, v;
		px_vec3 p, q, a, bt, in, out, m, n3;
		struct px_nurbs_surf_derivs d;
		double th, l1, l2, lm;
		if (c->edge < 0)
			continue; /* the fan of the curve before it */
		if (b->co[j].edge < 0) {
			int jn = next_coedge(b, j);
			coedge_end(c, 1, &p, &a);
			px_nurbs_surf_eval(&f->surf, p.x, p.y, 1, &d);
			v = corner_vertex(b, i, jn, d.s);
			if (v >= 0 && (b->co[jn].edge < 0 ||
				       !pole_fan(b, i, j, jn, b->verts[v], &b->vnormal[v])))
				bad[v] = 1;
			continue;
		}
		coedge_end(c, 1, &p, &a);
		coedge_end(&b->co[j], 0, &q, &bt);
		lr = px_trim_loop_reversed(f->trim, c->loop) == 1;
		px_nurbs_surf_eval(&f->surf, p.x, p.y, 1, &d);
		v = corner_vertex(b, i, j, d.s);
		if (v < 0)
			continue;
		in = lr ? px_v3_neg(bt) : a;
		out = lr ? px_v3_neg(a) : bt;
		in = px_v3_add(px_v3_scale(d.su, in.x), px_v3_scale(d.sv, in.y));
		out = px_v3_add(px_v3_scale(d.su, out.x), px_v3_scale(d.sv, out.y));
		m = px_v3_cross(d.su, d.sv);
		l1 = px_v3_norm(in);
		l2 = px_v3_norm(out);
		lm = px_v3_norm(m);
		if (!(l1 > 0.0 && l2 > 0.0 && lm > 0.0)) {
			bad[v] = 1;
			continue;
		}
		in = px_v3_scale(in, -1.0 / l1);
		out = px_v3_scale(out, 1.0 / l2);
		m = px_v3_scale(m, 1.0 / lm);
		th = atan2(px_v3_dot(m, px_v3_cross(out, in)), px_v3_dot(out, in));
		if (th <= 0.0)
			th += 2.0 * M_PI;
		n3 = px_v3_scale(m, f->reversed ? -1.0 : 1.0);
		b->vnormal[v] = px_v3_madd(b->vnormal[v], n3, th);
	}
}

/* The topology checks; 0 with b->why set when one fails. */
static int check_closed(struct px_brep *b)
{
	int i;
	if (b->n_shells < 1 || b->n_solids < 1) {
		snprintf(b->why, sizeof(b->why), "no shells or solids: open");
		return 0;
	}
	for (i = 0; i < b->n_shells; i++)
		if (!b->shell_closed[i] || b->shell_solid[i] < 0) {
			snprintf(b->why, sizeof(b->why), "shell %d is %s", i,
				 !b->shell_closed[i] ? "open" : "in no solid");
			return 0;
		}
	for (i = 0; i < b->n_faces; i++)
		if (!b->faces[i].trim) {
			snprintf(b->why, sizeof(b->why),
				 "face %d has no loops (its edges are unknown)", i);
			return 0;
		}
	for (i = 0; i < b->n_pts; i++)
		if (!b->pts[i].collapsed || b->pts[i].vertex < 0) {
			if (b->pts[i].collapsed)
				snprintf(b->why, sizeof(b->why),
					 "a loop curve collapses to a point that is no "
					 "vertex");
			else
				snprintf(b->why, sizeof(b->why),
					 "vertex %d is on no edge", b->pts[i].vertex);
			return 0;
		}
	return 1;
}

/* Every edge used twice, within one shell, in opposite directions. */
static int check_edges(struct px_brep *b, double tol)
{
	int e, k;
	for (e = 0; e < b->n_edges; e++) {
		const struct brep_edge *be = &b->edges[e];
		px_vec3 tg[2];
		double tm = 0.5 * (be->t0 + be->t1);
		px_vec3 x = px_nurbs_curve_point(&be->c, tm);
		if (be->uses != 2 ||
		    b->faces[b->co[be->co[0]].face].shell != b->faces[b->co[be->co[1]].face].shell) {
			snprintf(b->why, sizeof(b->why),
				 "edge %d is used by %d loop curves%s", e, be->uses,
				 be->uses == 2 ? " of different shells" : "");
			return 0;
		}
		for (k = 0; k < 2; k++) {
			struct brep_coedge *c = &b->co[be->co[k]];
			if (!map_coedge(b, c, tol)) {
				snprintf(b->why, sizeof(b->why),
					 "face %d loop %d curve %d does not run along "
					 "edge %d",
					 c->face, c->loop, c->curve, e);
				return 0;
			}
			tg[k] = induced_tangent(b, c,
						refine_s(b, c, x, c->s[BREP_MAP_N / 2], NULL));
		}
		if (!(px_v3_dot(tg[0], tg[1]) < -0.5)) {
			snprintf(b->why, sizeof(b->why),
				 "the faces of edge %d (faces %d and %d) disagree on "
				 "the outside",
				 e, b->co[be->co[0]].face, b->co[be->co[1]].face);
			return 0;
		}
	}
	return 1;
}

static int shape_signs(struct px_brep *b);

int px__brep_sign_setup(struct px_brep *b)
{
	unsigned char *bad;
	int i, far_sign;
	double tol = 1e-6 * (b->size > 0.0 ? b->size : 1.0);
	struct px_dist_result d;
	px_vec3 far;

	b->closed = 0;
	if (!check_closed(b))
		return PX_OK;
	if (!check_edges(b, tol))
		return PX_OK;
	if (shape_signs(b) != PX_OK)
		return PX_E_NOMEM;
	b->vnormal = calloc((size_t)b->n_vertices + 1, sizeof(*b->vnormal));
	bad = calloc((size_t)b->n_vertices + 1, 1);
	if (!b->vnormal || !bad) {
		free(bad);
		return PX_E_NOMEM;
	}
	b->bytes += ((size_t)b->n_vertices + 1) * sizeof(*b->vnormal);
	corners(b, bad);
	for (i = 0; i < b->n_vertices; i++)
		if (bad[i] || !(px_v3_norm(b->vnormal[i]) > 0.0)) {
			snprintf(b->why, sizeof(b->why),
				 "vertex %d has no pseudo-normal (a degenerate "
				 "corner)",
				 i);
			free(bad);
			return PX_OK;
		}
	free(bad);
	/* Beyond the box: must be outside. */
	far = px_v3_add(b->box.max, px_v3(0.5 * b->size + 1e-3, 0.31 * b->size,
					  0.17 * b->size));
	if (px__brep_closest(b, 0, far, &d) != PX_OK) {
		snprintf(b->why, sizeof(b->why), "the orientation check failed");
		return PX_OK;
	}
	b->closed = 1;
	far_sign = px__brep_sign(b, far, &d);
	if (far_sign < 0) {
		b->closed = 0;
		snprintf(b->why, sizeof(b->why),
			 "the faces are oriented inwards (a point beyond the box "
			 "comes out inside)");
		return PX_OK;
	}
	snprintf(b->why, sizeof(b->why), "closed and consistently oriented");
	return PX_OK;
}

/* Vertex of edge answer d when its foot is an end of the edge, else -1. */
static int edge_vertex(const struct px_brep *b, const struct px_dist_result *d)
{
	const struct brep_edge *e = &b->edges[d->entity];
	if (e->v0 >= 0 && (d->u <= e->t0 ||
			   px_v3_dist2(d->point, b->verts[e->v0]) == 0.0))
		return e->v0;
	if (e->v1 >= 0 && (d->u >= e->t1 ||
			   px_v3_dist2(d->point, b->verts[e->v1]) == 0.0))
		return e->v1;
	return -1;
}

/*
 * Unit normal at (or, off it, nearest to) x of the closed-form shape
 * of a face (a parallelogram or a surface of revolution, px_recog.h):
 * the profile's normal in x's meridian half-plane. Zero where that is
 * not defined (x on the axis, at an arc's centre, another kind).
 * @note RT-safe.
 */
static px_vec3 shape_normal(const struct px_recog_shape *sh, px_vec3 x)
{
	const struct px_recog_rev *rv = &sh->rev;
	px_vec3 w, er, n;
	double h, rho, l;

	switch (sh->kind) {
	case PX_RECOG_PARALLELOGRAM:
		n = sh->quad.normal;
		break;
	case PX_RECOG_CYLINDER:
	case PX_RECOG_CONE:
	case PX_RECOG_ANNULUS:
	case PX_RECOG_SPHERE:
	case PX_RECOG_TORUS:
		w = px_v3_sub(x, rv->origin);
		h = px_v3_dot(rv->axis, w);
		er = px_v3_madd(w, rv->axis, -h);
		rho = px_v3_norm(er);
		/* So near the axis the radial direction is rounding noise. */
		if (!(rho > 1e-9 * px_v3_norm(w)))
			return px_v3(0, 0, 0);
		er = px_v3_scale(er, 1.0 / rho);
		if (rv->profile_is_arc) /* from the arc's centre (h, rho) */
			n = px_v3_madd(px_v3_scale(rv->axis, h - rv->parc.center.x), er,
				       rho - rv->parc.center.y);
		else /* across the segment's direction (dh, drho) */
			n = px_v3_madd(px_v3_scale(rv->axis, -rv->pseg.dir.y), er,
				       rv->pseg.dir.x);
		break;
	default:
		return px_v3(0, 0, 0);
	}
	l = px_v3_norm(n);
	return l > 0.0 ? px_v3_scale(n, 1.0 / l) : px_v3(0, 0, 0);
}

/* Outward unit normal of face f at its point x from the face's closed
 * form, or zero when it has none (then the surface is evaluated). */
static px_vec3 fast_normal(const struct px_brep *b, int f, px_vec3 x)
{
	if (!b->fsign || !b->fsign[f])
		return px_v3(0, 0, 0);
	return px_v3_scale(shape_normal(&b->dm->shape[b->n_edges + f], x),
			   (double)b->fsign[f]);
}

/*
 * Per face with a closed form: +1 / -1 when the shape's normal is the
 * outward normal / its opposite, checked on a 3 x 3 set of interior
 * parameters (the sign is the same all over a regular patch: both are
 * continuous unit normal fields), 0 when a sample disagrees or is
 * degenerate (then queries evaluate the surface). PX_OK or PX_E_NOMEM.
 */
static int shape_signs(struct px_brep *b)
{
	int f, i, j;
	b->fsign = calloc((size_t)b->n_faces + 1, 1);
	if (!b->fsign)
		return PX_E_NOMEM;
	b->bytes += (size_t)b->n_faces + 1;
	for (f = 0; f < b->n_faces; f++) {
		const struct px_recog_shape *sh = &b->dm->shape[b->n_edges + f];
		double u0, u1, v0, v1;
		int sg = 0, ok = sh->kind != PX_RECOG_NONE;
		px_nurbs_surf_domain(&b->faces[f].surf, &u0, &u1, &v0, &v1);
		for (i = 1; i <= 3 && ok; i++)
			for (j = 1; j <= 3 && ok; j++) {
				double u = u0 + (u1 - u0) * i / 4.0, v = v0 + (v1 - v0) * j / 4.0;
				px_vec3 no = px__brep_face_normal(b, f, u, v);
				px_vec3 ns = shape_normal(
					sh, px_nurbs_surf_point(&b->faces[f].surf, u, v));
				double c = px_v3_dot(no, ns);
				int s = c > 0.99 ? 1 : (c < -0.99 ? -1 : 0);
				if (!s || (sg && s != sg))
					ok = 0;
				sg = s;
			}
		b->fsign[f] = (signed char)(ok ? sg : 0);
	}
	return PX_OK;
}

int px__brep_sign(const struct px_brep *b, px_vec3 p,
		  const struct px_dist_result *d)
{
	px_vec3 dir = px_v3_sub(p, d->point), n = px_v3(0, 0, 0);
	int k;

	if (d->kind == PX_DIST_SURFACE) {
		int f = d->entity - b->n_edges;
		n = fast_normal(b, f, d->point);
		if (px_v3_dot(n, n) == 0.0)
			n = px__brep_face_normal(b, f, d->u, d->v);
	} else if (d->kind == PX_DIST_CURVE) {
		int v = edge_vertex(b, d);
		if (v >= 0) {
			n = b->vnormal[v];
		} else {
			const struct brep_edge *e = &b->edges[d->entity];
			for (k = 0; k < e->n_co; k++) {
				const struct brep_coedge *c = &b->co[e->co[k]];
				px_vec3 nf = fast_normal(b, c->face, d->point);
				double u, v2;
				if (px_v3_dot(nf, nf) == 0.0) {
					coedge_uv(b, c, d->u, d->point, &u, &v2);
					nf = px__brep_face_normal(b, c->face, u, v2);
				}
				n = px_v3_add(n, nf);
			}
		}
	} else if (b->pts[d->entity].vertex >= 0) {
		n = b->vnormal[b->pts[d->entity].vertex];
	}
	return px_v3_dot(dir, n) < 0.0 ? -1 : 1;
}
