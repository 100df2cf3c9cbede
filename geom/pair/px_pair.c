/*
 * px_pair.c - model-to-model distance by alternating projections.
 */
#include <math.h>
#include <string.h>

#include "mesh_internal.h"
#include "px_mesh.h"
#include "px_pair.h"
#include "pair_internal.h"
#include "px_prim.h"

/* ---- exact convex distance: GJK ---------------------------------------------
 *
 * Gilbert, Johnson and Keerthi (1988) on the Minkowski difference A - B
 * through the models' support functions. The simplex (at most 4
 * points, each with the support points of A and B that made it) is
 * reduced to the face, edge or vertex nearest the origin by the exact
 * point-triangle routine of the mesh module, whose barycentric weights
 * also give the witness points. Stops when the support point in the
 * direction of the origin gains less than a relative 1e-10 of |v|^2 (the
 * classic bound |v|^2 - v.w <= eps |v|^2: the true distance is within
 * that of |v|; 1e-10 of |v|^2 is 5e-11 of the distance), or when the
 * origin is inside (intersection).
 */

#define GJK_MAX_ITERS 128
#define GJK_REL 1e-10

struct gjk_vert {
	px_vec3 w, a, b; /* w = a - b */
};

/* Closest point of the simplex to the origin; keeps only the vertices
 * that carry it. Returns 1 when the origin is inside a full simplex. */
static int gjk_reduce(struct gjk_vert *S, int *n, px_vec3 *v, px_vec3 *pa,
		      px_vec3 *pb)
{
	px_vec3 o = px_v3(0, 0, 0), q;
	double lam[4] = {1, 0, 0, 0};
	int keep[4] = {1, 0, 0, 0}, i, m;

	if (*n == 1) {
		q = S[0].w;
	} else if (*n == 2) {
		px_vec3 d = px_v3_sub(S[1].w, S[0].w);
		double l2 = px_v3_norm2(d), t = 0.0;
		if (l2 > 0.0) {
			t = -px_v3_dot(S[0].w, d) / l2;
			t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
		}
		lam[0] = 1.0 - t;
		lam[1] = t;
		keep[0] = t < 1.0;
		keep[1] = t > 0.0;
		q = px_v3_madd(S[0].w, d, t);
	} else if (*n == 3) {
		int f, sub;
		double u, w;
		px_tri_closest(o, S[0].w, S[1].w, S[2].w, &q, &f, &sub, &u, &w);
		lam[0] = 1.0 - u - w;
		lam[1] = u;
		lam[2] = w;
		keep[0] = keep[1] = keep[2] = 0;
		if (f == PX_FEATURE_FACE) {
			keep[0] = keep[1] = keep[2] = 1;
		} else if (f == PX_FEATURE_EDGE) {
			keep[sub] = keep[(sub + 1) % 3] = 1;
		} else {
			keep[sub] = 1;
		}
	} else {
		/* tetrahedron: origin inside, or the nearest of its faces */
		static const int F[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
		double vol = px_v3_dot(px_v3_sub(S[1].w, S[0].w),
				       px_v3_cross(px_v3_sub(S[2].w, S[0].w),
						   px_v3_sub(S[3].w, S[0].w)));
		double best = INFINITY, L = 0.0;
		int inside, k, j;
		for (k = 0; k < 4; k++)
			for (j = k + 1; j < 4; j++)
				L = fmax(L, px_v3_dist(S[k].w, S[j].w));
		/* a flat simplex (relative volume below 1e-9) never holds the
		 * origin: its weights would be rounding noise */
		inside = fabs(vol) > 1e-9 * L * L * L;
		for (k = 0; k < 4 && inside; k++) {
			const px_vec3 A = S[F[k][0]].w, B = S[F[k][1]].w, C = S[F[k][2]].w;
			double s = px_v3_dot(px_v3_neg(A),
					     px_v3_cross(px_v3_sub(B, A), px_v3_sub(C, A)));
			/* origin on the inner side of every face (same sign as
			 * the opposite vertex) */
			double so = px_v3_dot(px_v3_sub(S[k].w, A),
					      px_v3_cross(px_v3_sub(B, A), px_v3_sub(C, A)));
			/* s / so is the origin's barycentric weight of vertex
			 * k: inside only with every weight clearly positive,
			 * so that a nearly flat simplex (common on smooth
			 * shapes) never claims the origin by rounding; a
			 * touching pair then ends through |v| -> 0 instead. */
			if (!(so != 0.0 && s / so > 1e-9))
				inside = 0;
		}
		if (inside) {
			/* the origin's weights give a common point of both
			 * (the witnesses of the overlap) */
			double tot = 0.0;
			for (k = 0; k < 4; k++) {
				const px_vec3 A = S[F[k][0]].w, B = S[F[k][1]].w, C = S[F[k][2]].w;
				px_vec3 nk = px_v3_cross(px_v3_sub(B, A), px_v3_sub(C, A));
				lam[k] = px_v3_dot(px_v3_neg(A), nk) / px_v3_dot(px_v3_sub(S[k].w, A), nk);
				tot += lam[k];
			}
			*pa = px_v3(0, 0, 0);
			*pb = px_v3(0, 0, 0);
			for (k = 0; k < 4; k++) {
				*pa = px_v3_madd(*pa, S[k].a, lam[k] / tot);
				*pb = px_v3_madd(*pb, S[k].b, lam[k] / tot);
			}
			return 1;
		}
		for (k = 0; k < 4; k++) {
			int f, sub;
			double u, w, d2;
			px_vec3 qq;
			const int *t = F[k];
			d2 = px_tri_closest(o, S[t[0]].w, S[t[1]].w, S[t[2]].w, &qq, &f, &sub,
					    &u, &w);
			if (d2 < best) {
				double l3[3] = {1.0 - u - w, u, w};
				int k3[3] = {0, 0, 0};
				best = d2;
				q = qq;
				if (f == PX_FEATURE_FACE)
					k3[0] = k3[1] = k3[2] = 1;
				else if (f == PX_FEATURE_EDGE)
					k3[sub] = k3[(sub + 1) % 3] = 1;
				else
					k3[sub] = 1;
				for (j = 0; j < 4; j++) {
					lam[j] = 0.0;
					keep[j] = 0;
				}
				for (j = 0; j < 3; j++) {
					lam[t[j]] = l3[j];
					keep[t[j]] = k3[j];
				}
			}
		}
	}
	*pa = px_v3(0, 0, 0);
	*pb = px_v3(0, 0, 0);
	for (i = 0; i < *n; i++) {
		*pa = px_v3_madd(*pa, S[i].a, lam[i]);
		*pb = px_v3_madd(*pb, S[i].b, lam[i]);
	}
	for (i = 0, m = 0; i < *n; i++)
		if (keep[i])
			S[m++] = S[i];
	if (m == 0) { /* cannot happen; keep the nearest vertex */
		m = 1;
	}
	*n = m;
	*v = q;
	return 0;
}

/* Returns 1 with the distance and witness points, 0 when intersecting,
 * negative when a model has no support function. */
/* A convex shape for GJK: a model with a support function, or a
 * triangle (world-frame vertices) of a mesh. */
struct shp {
	const struct px_model *m;
	const px_vec3 *v; /* 3 vertices, or NULL for m */
};

static int shp_support(const struct shp *s, px_vec3 d, px_vec3 *out)
{
	if (s->v) {
		double h0 = px_v3_dot(s->v[0], d), h1 = px_v3_dot(s->v[1], d),
		       h2 = px_v3_dot(s->v[2], d);
		*out = h0 >= h1 ? (h0 >= h2 ? s->v[0] : s->v[2])
				: (h1 >= h2 ? s->v[1] : s->v[2]);
		return PX_OK;
	}
	return px_model_support(s->m, d, out);
}

static px_vec3 shp_centre(const struct shp *s)
{
	if (s->v)
		return px_v3_scale(px_v3_add(s->v[0], px_v3_add(s->v[1], s->v[2])), 1.0 / 3.0);
	return px_model_pose(s->m).t;
}

/* *vout (may be NULL): the point of A - B nearest the origin found;
 * *lower (may be NULL): the best lower bound of the distance seen (the
 * support plane's distance v . w / |v|), which certifies *dist. */
static int gjk(const struct shp *a, const struct shp *b, double *dist,
	       px_vec3 *pa, px_vec3 *pb, int *iters, struct gjk_vert S[4],
	       int *n_out, px_vec3 *vout, double *lower)
{
	px_vec3 v, sa, sb;
	int n = 1, it, rc;
	double lb = 0.0;

	v = px_v3_sub(shp_centre(a), shp_centre(b));
	if (px_v3_norm2(v) == 0.0)
		v = px_v3(1, 0, 0);
	if ((rc = shp_support(a, px_v3_neg(v), &sa)) < 0 ||
	    (rc = shp_support(b, v, &sb)) < 0)
		return rc;
	S[0].a = sa;
	S[0].b = sb;
	S[0].w = px_v3_sub(sa, sb);
	*pa = sa;
	*pb = sb;
	v = S[0].w;
	for (it = 0; it < GJK_MAX_ITERS; it++) {
		struct gjk_vert nw;
		double vv = px_v3_norm2(v), vw;
		int k, dup = 0;
		if (vv == 0.0)
			break;
		shp_support(a, px_v3_neg(v), &nw.a);
		shp_support(b, v, &nw.b);
		nw.w = px_v3_sub(nw.a, nw.b);
		vw = px_v3_dot(v, nw.w);
		if (vw / sqrt(vv) > lb)
			lb = vw / sqrt(vv);
		if (vv - vw <= GJK_REL * vv)
			break;
		for (k = 0; k < n; k++)
			if (S[k].w.x == nw.w.x && S[k].w.y == nw.w.y && S[k].w.z == nw.w.z)
				dup = 1;
		if (dup)
			break;
		S[n++] = nw;
		if (gjk_reduce(S, &n, &v, pa, pb)) {
			*iters = it + 1;
			*n_out = n;
			return 0;
		}
		/* no progress: rounding has taken over */
		if (px_v3_norm2(v) >= vv)
			break;
	}
	*iters = it;
	*n_out = n;
	*dist = px_v3_norm(v);
	if (vout)
		*vout = v;
	if (lower)
		*lower = lb;
	if (*dist <= 1e-15 * (1.0 + px_v3_norm(*pa)))
		return 0;
	return 1;
}

/* ---- exact convex penetration: EPA ------------------------------------------
 *
 * Expanding polytope (van den Bergen 2001): when GJK ends with the origin
 * inside A - B, the depth is the distance from the origin to the boundary
 * of A - B, and translating B by depth * n (n the boundary normal there)
 * separates the pair. The polytope starts as GJK's last simplex (blown up
 * to a tetrahedron when the origin lies on a face, edge or vertex of it),
 * always encloses the origin and lies inside A - B; each step takes the
 * face nearest the origin, adds the support point along its normal, and
 * replaces the faces that point sees by a fan from its horizon. The
 * nearest face's distance is a lower bound of the depth and the support
 * value along its normal an upper bound; the loop stops when they agree
 * within a relative 1e-9 (curved shapes may run out of the fixed buffers
 * first: then the upper bound is returned and the result is flagged).
 * Fixed arrays on the stack: no allocation.
 */

#define EPA_MAX_V 64
#define EPA_MAX_F 160
#define EPA_MAX_E 96
#define EPA_REL 1e-9

struct epa_face {
	int v[3];
	px_vec3 n; /* unit outward normal */
	double d;  /* n . v0: distance of the plane from the origin */
	int alive;
};

static int epa_face_make(const struct gjk_vert *V, struct epa_face *f, int a,
			 int b, int c)
{
	px_vec3 n = px_v3_cross(px_v3_sub(V[b].w, V[a].w), px_v3_sub(V[c].w, V[a].w));
	double l = px_v3_norm(n);
	f->v[0] = a;
	f->v[1] = b;
	f->v[2] = c;
	f->alive = 1;
	if (!(l > 0.0)) {
		/* a sliver: never the nearest, still part of the hull */
		f->n = px_v3(0, 0, 0);
		f->d = INFINITY;
		return 0;
	}
	f->n = px_v3_scale(n, 1.0 / l);
	f->d = px_v3_dot(f->n, V[a].w);
	return 1;
}

/* Grow a simplex that holds the origin (GJK ended on it) to a tetrahedron
 * by support points along directions off its affine hull. */
static int epa_blowup(const struct px_model *a, const struct px_model *b,
		      struct gjk_vert *V, int *n, double scale)
{
	static const px_vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
					{0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
	double eps = 1e-9 * scale;
	while (*n < 4) {
		px_vec3 dirs[6];
		int nd = 0, k, added = 0;
		if (*n == 1) {
			for (k = 0; k < 6; k++)
				dirs[nd++] = axes[k];
		} else if (*n == 2) {
			px_vec3 e = px_v3_sub(V[1].w, V[0].w), u, w;
			int ax = fabs(e.x) < fabs(e.y) ? (fabs(e.x) < fabs(e.z) ? 0 : 2)
						       : (fabs(e.y) < fabs(e.z) ? 1 : 2);
			u = px_v3_cross(e, axes[2 * ax]);
			w = px_v3_cross(e, u);
			dirs[nd++] = u;
			dirs[nd++] = px_v3_neg(u);
			dirs[nd++] = w;
			dirs[nd++] = px_v3_neg(w);
		} else {
			px_vec3 nn = px_v3_cross(px_v3_sub(V[1].w, V[0].w),
						 px_v3_sub(V[2].w, V[0].w));
			dirs[nd++] = nn;
			dirs[nd++] = px_v3_neg(nn);
		}
		for (k = 0; k < nd && !added; k++) {
			struct gjk_vert g;
			double off;
			if (px_v3_norm2(dirs[k]) == 0.0)
				continue;
			px_model_support(a, dirs[k], &g.a);
			px_model_support(b, px_v3_neg(dirs[k]), &g.b);
			g.w = px_v3_sub(g.a, g.b);
			/* distance of g.w from the current affine hull */
			if (*n == 1) {
				off = px_v3_dist(g.w, V[0].w);
			} else if (*n == 2) {
				px_vec3 e = px_v3_sub(V[1].w, V[0].w);
				off = px_v3_norm(px_v3_cross(e, px_v3_sub(g.w, V[0].w))) /
				      fmax(px_v3_norm(e), 1e-300);
			} else {
				px_vec3 nn = px_v3_cross(px_v3_sub(V[1].w, V[0].w),
							 px_v3_sub(V[2].w, V[0].w));
				off = fabs(px_v3_dot(nn, px_v3_sub(g.w, V[0].w))) /
				      fmax(px_v3_norm(nn), 1e-300);
			}
			if (off > eps) {
				V[(*n)++] = g;
				added = 1;
			}
		}
		if (!added)
			return 0; /* A - B is flat here: no depth */
	}
	return 1;
}

/* Depth, normal (translate B by depth * normal to separate) and the
 * witness points (pa - pb = depth * normal). Returns 1 converged, 0 when
 * the buffers ran out (upper bound returned), -1 when no polytope could
 * be built (flat Minkowski difference: depth 0). */
static int epa(const struct px_model *a, const struct px_model *b,
	       const struct gjk_vert *S, int ns, double *depth, px_vec3 *normal,
	       px_vec3 *pa, px_vec3 *pb, int *iters)
{
	struct gjk_vert V[EPA_MAX_V];
	struct epa_face F[EPA_MAX_F];
	int E[EPA_MAX_E][2];
	int nv = ns, nf = 0, it, k, i, best = -1, conv = 0;
	double scale = 0.0, upper = INFINITY;
	px_vec3 up_n = px_v3(0, 0, 1);

	for (k = 0; k < ns; k++) {
		V[k] = S[k];
		scale = fmax(scale, px_v3_norm(S[k].w));
	}
	scale = fmax(scale, 1e-300);
	if (!epa_blowup(a, b, V, &nv, scale))
		return -1;
	{
		/* outward winding: each face away from the opposite vertex */
		static const int T[4][4] = {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}};
		for (k = 0; k < 4; k++) {
			int x = T[k][0], y = T[k][1], z = T[k][2], o = T[k][3];
			px_vec3 n = px_v3_cross(px_v3_sub(V[y].w, V[x].w),
						px_v3_sub(V[z].w, V[x].w));
			if (px_v3_dot(n, px_v3_sub(V[o].w, V[x].w)) > 0.0) {
				int t = y;
				y = z;
				z = t;
			}
			epa_face_make(V, &F[nf++], x, y, z);
		}
	}
	for (it = 0; it < 4 * EPA_MAX_V; it++) {
		struct gjk_vert w;
		double h;
		int ne = 0, slot;
		best = -1;
		for (k = 0; k < nf; k++)
			if (F[k].alive && (best < 0 || F[k].d < F[best].d))
				best = k;
		if (best < 0 || !isfinite(F[best].d))
			return -1;
		px_model_support(a, F[best].n, &w.a);
		px_model_support(b, px_v3_neg(F[best].n), &w.b);
		w.w = px_v3_sub(w.a, w.b);
		h = px_v3_dot(F[best].n, w.w);
		if (h < upper) {
			upper = h;
			up_n = F[best].n;
		}
		if (h - F[best].d <= EPA_REL * fmax(F[best].d, 1e-6 * scale)) {
			conv = 1;
			break;
		}
		if (nv >= EPA_MAX_V)
			break;
		/* faces seen from w: removed, their boundary is the horizon */
		for (k = 0; k < nf; k++) {
			if (!F[k].alive)
				continue;
			if (k != best &&
			    !(isfinite(F[k].d) &&
			      px_v3_dot(F[k].n, px_v3_sub(w.w, V[F[k].v[0]].w)) > 1e-12 * scale) &&
			    !(!isfinite(F[k].d) &&
			      px_v3_dot(px_v3_cross(px_v3_sub(V[F[k].v[1]].w, V[F[k].v[0]].w),
						    px_v3_sub(V[F[k].v[2]].w, V[F[k].v[0]].w)),
					px_v3_sub(w.w, V[F[k].v[0]].w)) > 0.0))
				continue;
			F[k].alive = 0;
			for (i = 0; i < 3; i++) {
				int x = F[k].v[i], y = F[k].v[(i + 1) % 3], j, found = -1;
				for (j = 0; j < ne; j++)
					if (E[j][0] == y && E[j][1] == x)
						found = j;
				if (found >= 0) {
					E[found][0] = E[ne - 1][0];
					E[found][1] = E[ne - 1][1];
					ne--;
				} else if (ne < EPA_MAX_E) {
					E[ne][0] = x;
					E[ne][1] = y;
					ne++;
				} else {
					goto out; /* horizon too long for the buffer */
				}
			}
		}
		V[nv] = w;
		slot = 0;
		for (i = 0; i < ne; i++) {
			while (slot < nf && F[slot].alive)
				slot++;
			if (slot == nf) {
				if (nf == EPA_MAX_F)
					goto out;
				nf++;
			}
			epa_face_make(V, &F[slot], E[i][0], E[i][1], nv);
		}
		nv++;
	}
out:
	*iters += it;
	{
		/* witness points from the nearest face when converged, else
		 * from the best upper bound's direction */
		px_vec3 q;
		double u = 0, v = 0;
		int f, sub;
		if (conv) {
			/* A flat part of A - B is cut into coplanar faces that
			 * tie on distance; the witnesses come from the one that
			 * holds the foot of the origin (else they fall off the
			 * surfaces: the foot's weights are then those of
			 * another face's edge). */
			const struct epa_face *fb = &F[best];
			px_vec3 foot = px_v3_scale(fb->n, fb->d);
			double gap = INFINITY;
			int pick = best;
			/* the nearest face itself passes the test, so pick and
			 * its weights u, v are always set here */
			for (k = 0; k < nf; k++) {
				double g, uk, vk;
				if (!F[k].alive || !isfinite(F[k].d) ||
				    F[k].d - fb->d > EPA_REL * fmax(fb->d, 1e-6 * scale) ||
				    px_v3_dot(F[k].n, fb->n) < 1.0 - 1e-9)
					continue;
				g = px_tri_closest(foot, V[F[k].v[0]].w, V[F[k].v[1]].w,
						   V[F[k].v[2]].w, &q, &f, &sub, &uk, &vk);
				if (g < gap) {
					gap = g;
					pick = k;
					u = uk;
					v = vk;
				}
			}
			*depth = fb->d;
			*normal = fb->n;
			/* the same weights on both sides: each support point
			 * lies on its model's supporting plane (to the
			 * tolerance), so both witnesses lie on the surfaces */
			*pa = px_v3_add(px_v3_scale(V[F[pick].v[0]].a, 1.0 - u - v),
					px_v3_add(px_v3_scale(V[F[pick].v[1]].a, u),
						  px_v3_scale(V[F[pick].v[2]].a, v)));
			*pb = px_v3_add(px_v3_scale(V[F[pick].v[0]].b, 1.0 - u - v),
					px_v3_add(px_v3_scale(V[F[pick].v[1]].b, u),
						  px_v3_scale(V[F[pick].v[2]].b, v)));
			{
				/* the weights' point misses the foot by the
				 * rounding of a curved hull (up to ~1e-7 of the
				 * size): half the miss to each side, so that
				 * pa - pb = depth * normal holds exactly */
				px_vec3 miss = px_v3_scale(px_v3_sub(foot, px_v3_sub(*pa, *pb)), 0.5);
				*pa = px_v3_add(*pa, miss);
				*pb = px_v3_sub(*pb, miss);
			}
			return 1;
		}
		px_model_support(a, up_n, pa);
		*depth = upper;
		*normal = up_n;
		*pb = px_v3_madd(*pa, up_n, -upper);
		return 0;
	}
}

/* ---- approximate penetration: deepest point ---------------------------------
 *
 * For closed models without an exact method: the point of x's surface
 * deepest inside y (most negative signed distance to y), by projected
 * descent from a start on x: step against y's distance gradient,
 * project back onto x, keep the step when it went deeper (the step
 * grows after a success and halves after a failure). A local search:
 * results are flagged approximate. Returns 1 with *d (< 0) and the
 * points when a point of x inside y was found, 0 when none, or an error.
 */
#define DEEP_ITERS 40

static int deepest(const struct px_model *x, const struct px_model *y,
		   px_vec3 start, double scale, double *d, px_vec3 *px_,
		   px_vec3 *qy, px_vec3 *dir, int *iters)
{
	struct px_model_result rx, ry, t;
	double step;
	int it, rc;

	if ((rc = px_model_query(x, start, &rx)) < 0)
		return rc;
	if ((rc = px_model_query(y, rx.point, &ry)) < 0)
		return rc;
	*iters += 2;
	if (!ry.is_signed || !(ry.distance < 0.0))
		return 0;
	step = fmax(-ry.distance, 1e-3 * scale);
	for (it = 0; it < DEEP_ITERS && step > 1e-5 * scale; it++) {
		px_vec3 target = px_v3_madd(rx.point, ry.direction, -step);
		struct px_model_result nx;
		if ((rc = px_model_query(x, target, &nx)) < 0)
			return rc;
		if ((rc = px_model_query(y, nx.point, &t)) < 0)
			return rc;
		*iters += 2;
		if (t.is_signed && t.distance < ry.distance - 1e-12 * scale) {
			rx = nx;
			ry = t;
			step *= 1.5;
		} else {
			step *= 0.5;
		}
	}
	*d = ry.distance;
	*px_ = rx.point;
	*qy = ry.point;
	*dir = ry.direction;
	return 1;
}

struct run {
	double d;
	px_vec3 pa, pb;
	int ia, ib;
	int iters;
	int converged;
	int intersecting;
};

/*
 * One start. seed is a point to project onto A first (any point: a box
 * corner, last cycle's pair), so every pair compared is (a point of A,
 * the point of B closest to it) or the reverse, real surface points.
 */
static int run_start(const struct px_model *a, const struct px_model *b,
		     px_vec3 seed, int max_iters, double tol, double rel,
		     struct run *o)
{
	struct px_model_result ra, rb;
	double prev = INFINITY;
	int it, rc;

	o->iters = 0;
	o->converged = 0;
	o->intersecting = 0;
	o->d = INFINITY;
	rc = px_model_query(a, seed, &ra);
	if (rc < 0)
		return rc;
	o->iters++;
	for (it = 0; it < max_iters; it++) {
		double d;
		rc = px_model_query(b, ra.point, &rb);
		if (rc < 0)
			return rc;
		o->iters++;
		d = fabs(rb.distance);
		if (d < o->d) {
			o->d = d;
			o->pa = ra.point;
			o->pb = rb.point;
			o->ia = ra.index;
			o->ib = rb.index;
		}
		if ((rb.is_signed && rb.distance <= 0.0) || d == 0.0) {
			/* a point of A inside or on B */
			o->d = 0.0;
			o->pa = ra.point;
			o->pb = rb.point;
			o->ia = ra.index;
			o->ib = rb.index;
			o->intersecting = 1;
			o->converged = 1;
			return 0;
		}
		rc = px_model_query(a, rb.point, &ra);
		if (rc < 0)
			return rc;
		o->iters++;
		d = fabs(ra.distance);
		if ((ra.is_signed && ra.distance <= 0.0) || d == 0.0) {
			o->d = 0.0;
			o->pa = ra.point;
			o->pb = rb.point;
			o->ia = ra.index;
			o->ib = rb.index;
			o->intersecting = 1;
			o->converged = 1;
			return 0;
		}
		if (d < o->d) {
			o->d = d;
			o->pa = ra.point;
			o->pb = rb.point;
			o->ia = ra.index;
			o->ib = rb.index;
		}
		/* each projection can only lower the distance; stop when it
		 * no longer does by more than tol */
		if (prev - o->d <= tol + rel * o->d) {
			o->converged = 1;
			return 0;
		}
		prev = o->d;
	}
	return 0;
}

#define REFINE_CAP 16

/*
 * Neighbourhood step on side x: every feature of x within the current
 * distance of x's point (as many as REFINE_CAP allows, shrinking the
 * radius otherwise), each taken at its point nearest y's point and
 * projected onto y. Discrete models (clouds, fine meshes) have many
 * shallow local minima next to the global one; this jumps over them.
 * Every pair tried is a real pair, so the distance can only drop.
 * Returns 1 when it improved, 0 when not, a negative error.
 */
static int refine_side(const struct px_model *x, const struct px_model *y,
		       px_vec3 *px, px_vec3 *py, int *ix, int *iy, double *d,
		       int *iters)
{
	const struct px_model_ops *o = px_model_get_ops(x);
	const void *impl = px_model_impl(x);
	px_pose P = px_model_pose(x);
	struct px_model_query q;
	int idx[REFINE_CAP], n = PX_E_NOSPC, k, tries, improved = 0;
	double R = *d;
	px_vec3 c;

	if (!o->collect || !o->closest_among || !(R > 0.0))
		return 0;
	c = px_pose_inverse_transform_point(P, *px);
	for (tries = 0; tries < 8 && n == PX_E_NOSPC; tries++) {
		n = o->collect(impl, c, R, idx, REFINE_CAP);
		if (n == PX_E_NOSPC)
			R *= 0.5;
	}
	if (n < 0)
		return n == PX_E_NOSPC ? 0 : n;
	q.p = px_pose_inverse_transform_point(P, *py);
	q.max_dist = INFINITY;
	q.hint = -1;
	q.flags = PX_QUERY_UNSIGNED;
	for (k = 0; k < n; k++) {
		struct px_model_result rx, ry;
		px_vec3 xw;
		int rc = o->closest_among(impl, &q, &idx[k], 1, &rx);
		if (rc < 0)
			return rc;
		if (rc == 0)
			continue;
		xw = px_pose_transform_point(P, rx.point);
		rc = px_model_query_ex(y, xw, INFINITY, -1, PX_QUERY_UNSIGNED, &ry);
		if (rc < 0)
			return rc;
		(*iters)++;
		if (ry.distance < *d) {
			*d = ry.distance;
			*px = xw;
			*py = ry.point;
			*ix = rx.index;
			*iy = ry.index;
			improved = 1;
		}
	}
	return improved;
}

static int finite_box(const px_aabb *b)
{
	return !px_aabb_is_empty(b) && px_v3_isfinite(b->min) &&
	       px_v3_isfinite(b->max);
}

/* Seed k: 0 = closest point of A's box to B's box (alternating between
 * the two convex boxes), then B's box corners and face centres, then
 * A's (each later projected onto A by run_start). */
static int seed_point(const struct px_model *a, const struct px_model *b,
		      int k, px_vec3 *out)
{
	px_aabb la = px_model_local_aabb(a), lb = px_model_local_aabb(b);
	int fa = finite_box(&la), fb = finite_box(&lb);
	px_obb A, B;

	if (fa)
		A = px_model_world_obb(a);
	if (fb)
		B = px_model_world_obb(b);
	if (k == 0) {
		if (fa && fb) {
			px_vec3 x = A.center, y;
			int i;
			for (i = 0; i < 16; i++) {
				y = px_obb_closest_point(&B, x);
				x = px_obb_closest_point(&A, y);
			}
			*out = x;
		} else if (fb) {
			*out = B.center;
		} else if (fa) {
			*out = A.center;
		} else {
			*out = px_model_pose(b).t;
		}
		return 1;
	}
	k--;
	if (fb) {
		if (k < 8) {
			*out = px_obb_corner(&B, k);
			return 1;
		}
		if (k < 14) {
			int ax = (k - 8) / 2;
			double s = (k - 8) % 2 ? 1.0 : -1.0;
			*out = px_v3_madd(B.center, B.axis[ax],
					  s * px_v3_comp(B.half, ax));
			return 1;
		}
		k -= 14;
	}
	if (fa) {
		if (k < 8) {
			*out = px_obb_corner(&A, k);
			return 1;
		}
		if (k < 14) {
			int ax = (k - 8) / 2;
			double s = (k - 8) % 2 ? 1.0 : -1.0;
			*out = px_v3_madd(A.center, A.axis[ax],
					  s * px_v3_comp(A.half, ax));
			return 1;
		}
	}
	return 0;
}

/* ---- exact paths for meshes ------------------------------------------------ */

/* World-frame vertices of triangle t of mesh m (seeds for the depth
 * search). */
static void tri_world(const struct px_model *m, int t, px_vec3 v[3])
{
	int k;
	if (t < 0 || px_mesh_triangle(m, (size_t)t, v) != PX_OK) {
		v[0] = v[1] = v[2] = px_model_pose(m).t;
		return;
	}
	for (k = 0; k < 3; k++)
		v[k] = px_pose_transform_point(px_model_pose(m), v[k]);
}

/*
 * The surfaces are apart (best->d > 0), yet a closed model may hold the
 * other whole: then the other's closest point lies inside it, which its
 * signed distance tells. Marks best intersecting (that point as the
 * overlap) and returns 1, else 0, or an error.
 */
static int contained(const struct px_model *a, const struct px_model *b,
		     struct run *best, int *total)
{
	int side, rc;
	for (side = 0; side < 2; side++) {
		const struct px_model *x = side ? b : a;
		px_vec3 p = side ? best->pa : best->pb; /* a point of the other */
		struct px_model_result q;
		if (!(px_model_caps(x) & PX_MODEL_CAP_SIGNED))
			continue;
		if ((rc = px_model_query(x, p, &q)) < 0)
			return rc;
		(*total)++;
		if (q.is_signed && q.distance < 0.0) {
			best->intersecting = 1;
			best->d = 0.0;
			if (side)
				best->pb = q.point;
			else
				best->pa = q.point;
			return 1;
		}
	}
	return 0;
}

/* Mesh against a convex model with a support function: each triangle
 * is itself convex, so GJK between the two is exact. */
struct tv_ctx {
	const struct px_model *o;
	int capsule;        /* o is a capsule: axis c0-c1, radius cr */
	px_vec3 c0, c1;
	double cr;
	double best;
	px_vec3 pt, po; /* on the triangle, on o */
	px_vec3 tv[3];
	int tri;
	int iters;
};

static int tri_vs_convex(void *ctx, const px_vec3 v[3], int index, double *d)
{
	struct tv_ctx *c = ctx;
	struct shp T = {NULL, v}, O = {c->o, NULL};
	struct gjk_vert S[4];
	double dist = 0.0;
	px_vec3 pt = v[0], po = v[0];
	int its = 0, ns = 0, g;

	if (c->capsule) {
		/* closed form: the axis segment against the triangle */
		double s, d2 = px__seg_tri(c->c0, c->c1, v, &s, &pt);
		px_vec3 a = px_v3_lerp(c->c0, c->c1, s);
		dist = sqrt(d2) - c->cr;
		if (dist <= 0.0) {
			dist = 0.0;
			po = pt; /* the triangle point is in the capsule */
		} else {
			po = px_v3_madd(a, px_v3_sub(pt, a), c->cr / sqrt(d2));
		}
		its = 1;
		g = 1;
	} else {
		g = gjk(&T, &O, &dist, &pt, &po, &its, S, &ns, NULL, NULL);
	}
	c->iters += its;
	if (g < 0)
		return g;
	if (g == 0)
		dist = 0.0;
	if (dist < c->best) {
		c->best = dist;
		c->pt = pt;
		c->po = po;
		c->tv[0] = v[0];
		c->tv[1] = v[1];
		c->tv[2] = v[2];
		c->tri = index;
	}
	/* GJK out of iterations: only an upper bound, which the search
	 * must not take as exact */
	*d = its >= GJK_MAX_ITERS ? INFINITY : dist;
	return 0;
}

/*
 * Mesh against a point cloud (radius 0, with the cache operations),
 * exact per triangle: a piece S of the triangle (centroid g, radius r)
 * is at least d(g) - r from the cloud, d(g) being the cloud's exact
 * nearest-point distance; pieces not bounded out collect the cloud
 * points within best + r of g (every point closer than best to S is
 * among them) and measure them exactly against the whole triangle.
 * When there are too many such points the piece is split in four
 * (midpoint subdivision, up to TP_DEPTH levels): near the answer g's
 * nearest point is about best away, so the ball holds only the points
 * of a thin shell, and few.
 */
#define TP_CAP 64
#define TP_DEPTH 5

struct tp_ctx {
	const struct px_model *c;
	double best;
	px_vec3 pt, pc; /* on the triangle, the cloud point */
	int tri, pidx;
	int iters, budget;
	int idx[TP_CAP];
};

static void tp_take(struct tp_ctx *c, const px_vec3 v[3], int index, px_vec3 x,
		    int pidx, double *found)
{
	px_vec3 qt;
	double dd = sqrt(px_tri_closest(x, v[0], v[1], v[2], &qt, NULL, NULL, NULL, NULL));
	if (dd < *found)
		*found = dd;
	if (dd < c->best) {
		c->best = dd;
		c->pt = qt;
		c->pc = x;
		c->tri = index;
		c->pidx = pidx;
	}
}

static int tri_vs_points(void *ctx, const px_vec3 v[3], int index, double *d)
{
	struct tp_ctx *c = ctx;
	const struct px_model_ops *o = px_model_get_ops(c->c);
	const void *impl = px_model_impl(c->c);
	px_pose P = px_model_pose(c->c);
	struct {
		px_vec3 v[3];
		int depth;
	} st[3 * TP_DEPTH + 2];
	double found = INFINITY;
	int sp = 1, unsure = 0, k, rc;

	st[0].v[0] = v[0];
	st[0].v[1] = v[1];
	st[0].v[2] = v[2];
	st[0].depth = 0;
	while (sp > 0) {
		const px_vec3 *S;
		px_vec3 g, gl;
		struct px_model_result nr;
		struct px_model_query q;
		double r;
		int n, dep;
		sp--;
		S = st[sp].v;
		dep = st[sp].depth;
		g = px_v3_scale(px_v3_add(S[0], px_v3_add(S[1], S[2])), 1.0 / 3.0);
		r = fmax(px_v3_dist(g, S[0]), fmax(px_v3_dist(g, S[1]), px_v3_dist(g, S[2])));
		if (c->iters >= c->budget) {
			unsure = 1;
			break;
		}
		gl = px_pose_inverse_transform_point(P, g);
		q.p = gl;
		q.max_dist = INFINITY;
		q.hint = -1;
		q.flags = PX_QUERY_UNSIGNED;
		if ((rc = o->closest(impl, &q, &nr)) < 0)
			return rc;
		c->iters++;
		if (rc == 0)
			continue;
		/* the nearest point is itself a candidate pair */
		tp_take(c, v, index, px_pose_transform_point(P, nr.point), nr.index, &found);
		if (nr.distance - r >= c->best * (1.0 - 1e-12))
			continue;
		n = o->collect(impl, gl, (c->best + r) * (1.0 + 1e-12), c->idx, TP_CAP);
		if (n == PX_E_NOSPC) {
			if (dep >= TP_DEPTH || sp + 4 > (int)(sizeof(st) / sizeof(st[0]))) {
				unsure = 1;
				continue;
			}
			{
				px_vec3 a = S[0], b = S[1], cc = S[2];
				px_vec3 ab = px_v3_scale(px_v3_add(a, b), 0.5);
				px_vec3 bc = px_v3_scale(px_v3_add(b, cc), 0.5);
				px_vec3 ca = px_v3_scale(px_v3_add(cc, a), 0.5);
				px_vec3 T4[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, cc}, {ab, bc, ca}};
				int j;
				for (j = 0; j < 4; j++) {
					st[sp].v[0] = T4[j][0];
					st[sp].v[1] = T4[j][1];
					st[sp].v[2] = T4[j][2];
					st[sp].depth = dep + 1;
					sp++;
				}
			}
			continue;
		}
		if (n < 0)
			return n;
		for (k = 0; k < n; k++) {
			struct px_model_result pr;
			rc = o->closest_among(impl, &q, &c->idx[k], 1, &pr);
			if (rc < 0)
				return rc;
			if (rc > 0)
				tp_take(c, v, index, px_pose_transform_point(P, pr.point), pr.index,
					&found);
		}
	}
	/* the triangle is at least c->best away unless something closer
	 * was measured */
	*d = unsure ? INFINITY : fmin(found, c->best);
	return 0;
}

#define MESH_CLOUD_QUERIES 1024

#define MESH_CONVEX_QUERIES 4096

/*
 * Exact distance of mesh m to convex model o (support function): the
 * mesh hierarchy bounded from below by o's point queries
 * (px__mesh_vs_model), each remaining triangle measured by GJK. The
 * start bound is the triangle of hint (last cycle's) or of the mesh
 * point nearest o's origin. Fills best (points polished by two exact
 * projections) and returns 1 when proven global, 0 when the query
 * budget ran out (best is then only the best found), or an error.
 */
static int mesh_vs_convex(const struct px_model *m, const struct px_model *o,
			  int hint, struct run *best, int *total)
{
	struct tv_ctx c;
	int rc, exact, queries = 0, bt = -1, j;
	double bd;
	px_vec3 v[3];
	double dd;

	memset(&c, 0, sizeof(c));
	c.o = o;
	c.capsule = px__capsule_axis(o, &c.c0, &c.c1, &c.cr);
	c.best = INFINITY;
	c.tri = -1;
	if (hint < 0 || (size_t)hint >= px_mesh_triangle_count(m)) {
		struct px_model_result q;
		if ((rc = px_model_query_ex(m, px_model_pose(o).t, INFINITY, -1,
					    PX_QUERY_UNSIGNED, &q)) < 0)
			return rc;
		(*total)++;
		hint = q.index;
	}
	tri_world(m, hint, v);
	if ((rc = tri_vs_convex(&c, v, hint, &dd)) < 0)
		return rc;
	bd = c.best;
	bt = c.tri;
	exact = px__mesh_vs_model(m, o, tri_vs_convex, &c, MESH_CONVEX_QUERIES, &bd, &bt,
				  &queries);
	*total += queries + c.iters;
	if (exact < 0)
		return exact;
	best->converged = 1;
	best->intersecting = c.best == 0.0;
	best->d = c.best;
	best->pa = c.pt;
	/* overlapping: GJK's common point, on the triangle and in o */
	best->pb = best->intersecting ? c.pt : c.po;
	best->ia = c.tri;
	best->ib = -1;
	for (j = 0; j < 2 && !best->intersecting; j++) {
		/* GJK's witness on o is a convex combination of support
		 * points, a chord point just inside a curved o: two exact
		 * projections put the pair on the surfaces (the triangle's
		 * witness is on it already; both sets are convex, so this
		 * converges to the true pair) */
		struct px_model_result q;
		px_vec3 pt;
		if ((rc = px_model_query(o, best->pa, &q)) < 0)
			return rc;
		(*total)++;
		if (q.is_signed && q.distance <= 0.0) {
			best->intersecting = 1;
			best->d = 0.0;
			best->pb = best->pa;
			break;
		}
		px_tri_closest(q.point, c.tv[0], c.tv[1], c.tv[2], &pt, NULL, NULL, NULL, NULL);
		best->ib = q.index;
		best->pb = q.point;
		best->pa = pt;
		best->d = px_v3_dist(pt, q.point);
	}
	return exact;
}

int px_pair_distance(const struct px_model *a, const struct px_model *b,
		     const struct px_pair_opts *opt, struct px_pair_result *res)
{
	int starts = opt && opt->starts ? opt->starts : 8;
	int max_iters = opt && opt->max_iters ? opt->max_iters : 64;
	double tol = opt && opt->tol > 0.0 ? opt->tol : 1e-12;
	double rel = opt && opt->rel_tol > 0.0 ? opt->rel_tol : 1e-9;
	int coherent = opt && opt->coherent && res && res->valid;
	struct run best, r;
	int k, n = 0, total = 0, rc, have = 0, nxs = 0, cert = 0, mesh_local;
	px_vec3 seed, xs[2][3];

	if (!a || !b || !res || starts < 1 || starts > PX_PAIR_MAX_STARTS ||
	    max_iters < 1 || !(tol >= 0.0))
		return PX_E_INVAL;
	res->depth = 0.0;
	res->depth_approx = 0;
	res->witness_gap = 0.0;

	/* Exact paths. A sphere against anything: one point query of its
	 * centre. Two convex models with support functions: GJK. */
	{
		struct px_prim pr;
		const struct px_model *sph = NULL, *oth = NULL;
		int swap = 0;
		if (px_prim_get(a, &pr) == PX_OK && pr.type == PX_PRIM_SPHERE) {
			sph = a;
			oth = b;
		} else if (px_prim_get(b, &pr) == PX_OK && pr.type == PX_PRIM_SPHERE) {
			sph = b;
			oth = a;
			swap = 1;
		}
		if (sph) {
			struct px_model_result q;
			px_vec3 c = px_model_pose(sph).t, ps, po;
			double d;
			rc = px_model_query(oth, c, &q);
			if (rc < 0)
				return rc;
			d = q.distance - pr.a;
			po = q.point;
			/* the sphere's point towards the other model */
			ps = px_v3_madd(c, q.direction, q.distance < 0.0 ? pr.a : -pr.a);
			if (q.distance == 0.0)
				ps = px_v3_madd(c, q.direction, -pr.a);
			res->intersecting = d <= 0.0;
			res->distance = d;
			if (d < 0.0) {
				/* the sphere's point deepest in the other model:
				 * moving the sphere by -d along direction frees it */
				ps = px_v3_madd(c, q.direction, -pr.a);
				res->depth = -d;
				res->depth_approx = !q.is_signed && q.distance == 0.0;
				res->normal = swap ? q.direction : px_v3_neg(q.direction);
			}
			res->point_a = swap ? po : ps;
			res->point_b = swap ? ps : po;
			res->index_a = swap ? q.index : 0;
			res->index_b = swap ? 0 : q.index;
			res->iterations = 1;
			res->starts = 0;
			res->converged = 1;
			res->local_only = !q.certified;
			goto done;
		}
	}
	/* capsule against capsule or box: closed forms (pair_internal.h) */
	rc = px__pair_closed(a, b, res);
	if (rc < 0)
		return rc;
	if (rc == 1)
		goto done;
	if ((px_model_caps(a) & PX_MODEL_CAP_CONVEX) &&
	    (px_model_caps(b) & PX_MODEL_CAP_CONVEX) &&
	    px_model_get_ops(a)->support && px_model_get_ops(b)->support) {
		double d = 0.0;
		px_vec3 pa, pb;
		struct gjk_vert S[4];
		struct shp sa = {a, NULL}, sb = {b, NULL};
		px_vec3 gv;
		double lower = 0.0;
		int its = 0, ns = 0,
		    g = gjk(&sa, &sb, &d, &pa, &pb, &its, S, &ns, &gv, &lower);
		if (g > 0) {
			/* GJK's witness points are convex combinations of
			 * support points, whose weights lose accuracy on the thin
			 * simplices of smooth shapes (then they can sit far from
			 * the contact though the distance |v| is right). Two
			 * starts: those points, and the supports along the
			 * separating direction v (the contact points themselves
			 * on strictly convex shapes); each is put on the
			 * surfaces by two exact projections (each step can only
			 * shorten the pair, both models being convex), and the
			 * shorter pair is kept. The distance is the lesser of
			 * |v| and that pair's, certified by GJK's support plane
			 * bound: converged = 0 when they differ by more than
			 * 1e-8 of the distance plus 1e-9 of the coordinates
			 * (a nanometre in a metre-sized scene). */
			struct px_model_result qa, qb, ka, kb;
			px_vec3 x = pa;
			double dq = INFINITY, ctol = 0.0;
			int j, s, nq = 0;
			memset(&qa, 0, sizeof(qa));
			memset(&qb, 0, sizeof(qb));
			for (s = 0; s < 2; s++) {
				if (s == 1) {
					/* the second start only where the first one's
					 * pair is longer than |v| (its queries are the
					 * cost of this path on a convex mesh) */
					if (!(dq - d > ctol))
						break;
					if ((rc = px_model_support(a, px_v3_neg(gv), &x)) < 0)
						return rc;
				}
				for (j = 0; j < 2; j++) {
					if ((rc = px_model_query(b, x, &kb)) < 0 ||
					    (rc = px_model_query(a, kb.point, &ka)) < 0)
						return rc;
					x = ka.point;
					nq += 2;
				}
				if (s == 0 || px_v3_dist(ka.point, kb.point) < dq) {
					dq = px_v3_dist(ka.point, kb.point);
					qa = ka;
					qb = kb;
				}
				ctol = 1e-8 * dq + 1e-9 * (1.0 + px_v3_norm(qa.point));
			}
			/* witnesses still longer than |v|: a few more rounds from
			 * the better start while they gain (slow near contact,
			 * where curved and flat parts meet; the distance itself
			 * is |v| either way) */
			for (j = 0; j < 4 && dq - d > ctol; j++) {
				double dn, gap = dq - d;
				if ((rc = px_model_query(b, qa.point, &kb)) < 0 ||
				    (rc = px_model_query(a, kb.point, &ka)) < 0)
					return rc;
				nq += 2;
				dn = px_v3_dist(ka.point, kb.point);
				if (!(dn < dq))
					break;
				dq = dn;
				qa = ka;
				qb = kb;
				if (dq - d > 0.75 * gap)
					break; /* stalled: less than a quarter gained */
			}
			pa = qa.point;
			pb = qb.point;
			res->intersecting = qb.is_signed && qb.distance <= 0.0;
			/* |v| is a point of A - B (an upper bound) and the
			 * support plane a lower one: the distance is |v| when
			 * they agree, whatever the witnesses' own gap */
			res->distance = res->intersecting ? 0.0 : fmin(d, dq);
			res->witness_gap = res->intersecting ? 0.0 : dq - res->distance;
			res->point_a = pa;
			res->point_b = pb;
			res->index_a = qa.index;
			res->index_b = qb.index;
			res->iterations = its + nq;
			res->starts = 0;
			res->converged = its < GJK_MAX_ITERS &&
					 (res->intersecting || res->distance - lower <= ctol);
			res->local_only = !res->converged;
			goto done;
		}
		if (g == 0) {
			double depth = 0.0;
			px_vec3 nrm;
			int e = epa(a, b, S, ns, &depth, &nrm, &pa, &pb, &its);
			res->intersecting = 1;
			res->distance = 0.0;
			if (e >= 0 && depth > 0.0) {
				res->depth = depth;
				res->distance = -depth;
				res->normal = nrm;
				res->depth_approx = e == 0;
			}
			res->point_a = pa;
			res->point_b = pb;
			res->index_a = res->index_b = -1;
			res->iterations = its;
			res->starts = 0;
			res->converged = 1;
			res->local_only = 0;
			goto done_n;
		}
	}
	memset(&best, 0, sizeof(best));
	best.d = INFINITY;
	/* two meshes, coherent and allowed local: last cycle's pair tracked
	 * by the projections, no exact proof (px_pair.h, local_ok) */
	mesh_local = coherent && opt->local_ok && px_mesh_triangle_count(a) > 0 &&
		     px_mesh_triangle_count(b) > 0;
	if (px_mesh_triangle_count(a) > 0 && px_mesh_triangle_count(b) > 0 && !mesh_local) {
		/* two meshes: exact, by both hierarchies at once */
		struct px__mesh_pair mp;
		rc = px__mesh_pair(a, b, coherent ? res->index_a : -1,
				   coherent ? res->index_b : -1, &mp);
		if (rc < 0)
			return rc;
		total = mp.nodes + mp.tri_tests;
		best.d = mp.distance;
		best.pa = mp.point_a;
		best.pb = mp.point_b;
		best.ia = mp.tri_a;
		best.ib = mp.tri_b;
		best.converged = 1;
		best.intersecting = mp.intersecting;
		if (!best.intersecting && (rc = contained(a, b, &best, &total)) < 0)
			return rc;
		if (best.intersecting) {
			tri_world(a, best.ia, xs[0]);
			tri_world(b, best.ib, xs[1]);
			nxs = 3;
			goto penetrate;
		}
		res->distance = best.d;
		res->point_a = best.pa;
		res->point_b = best.pb;
		res->index_a = best.ia;
		res->index_b = best.ib;
		res->iterations = total;
		res->starts = 0;
		res->converged = 1;
		res->intersecting = 0;
		res->local_only = !mp.certified;
		goto done;
	}
	{
		/* a mesh against a convex model with a support function:
		 * exact, by the mesh hierarchy and GJK per triangle */
		int ma = px_mesh_triangle_count(a) > 0 && px_model_get_ops(b)->support;
		int mb = !ma && px_mesh_triangle_count(b) > 0 && px_model_get_ops(a)->support;
		if ((ma || mb) && !mesh_local) {
			const struct px_model *m = ma ? a : b, *o = ma ? b : a;
			struct run mr;
			int ex, mt;
			memset(&mr, 0, sizeof(mr));
			ex = mesh_vs_convex(m, o, coherent ? (ma ? res->index_a : res->index_b) : -1,
					    &mr, &total);
			if (ex < 0)
				return ex;
			mt = mr.ia; /* the mesh's triangle */
			if (mb) {
				/* the pair was measured mesh first */
				px_vec3 t = mr.pa;
				int ti = mr.ia;
				mr.pa = mr.pb;
				mr.pb = t;
				mr.ia = mr.ib;
				mr.ib = ti;
			}
			best = mr;
			if (!best.intersecting && (rc = contained(a, b, &best, &total)) < 0)
				return rc;
			if (best.intersecting) {
				tri_world(m, mt, xs[ma ? 0 : 1]);
				xs[ma ? 1 : 0][0] = xs[ma ? 1 : 0][1] = xs[ma ? 1 : 0][2] =
					ma ? best.pb : best.pa;
				nxs = 3;
				goto penetrate;
			}
			if (ex == 1) {
				res->distance = best.d;
				res->point_a = best.pa;
				res->point_b = best.pb;
				res->index_a = best.ia;
				res->index_b = best.ib;
				res->iterations = total;
				res->starts = 0;
				res->converged = 1;
				res->intersecting = 0;
				res->local_only = 0;
				goto done;
			}
			/* budget out: projections may still do better */
			have = 1;
		}
	}
	for (k = coherent ? -1 : 0; n < starts; k++) {
		if (k == -1) {
			/* last pair, moved with the models */
			seed = px_pose_transform_point(px_model_pose(a), res->local_a);
		} else if (!seed_point(a, b, k, &seed)) {
			break;
		}
		if (!px_v3_isfinite(seed))
			continue;
		rc = run_start(a, b, seed, max_iters, tol, rel, &r);
		if (rc < 0)
			return rc;
		total += r.iters;
		n++;
		if (!have || r.d < best.d) {
			best = r;
			have = 1;
		}
		if (best.intersecting)
			break;
	}
	if (!have)
		return PX_E_DEGENERATE;
	/* neighbourhood steps on both sides, each success polished by a
	 * further round of projections */
	for (k = 0; k < (coherent && starts == 1 ? 0 : 2) && !best.intersecting &&
		    best.d > 0.0; k++) {
		int ia = best.ia, ib = best.ib, ra, rb;
		double d = best.d;
		px_vec3 pa = best.pa, pb = best.pb;
		ra = refine_side(a, b, &pa, &pb, &ia, &ib, &d, &total);
		if (ra < 0)
			return ra;
		rb = refine_side(b, a, &pb, &pa, &ib, &ia, &d, &total);
		if (rb < 0)
			return rb;
		if (!ra && !rb)
			break;
		best.d = d;
		best.pa = pa;
		best.pb = pb;
		best.ia = ia;
		best.ib = ib;
		rc = run_start(a, b, pa, max_iters, tol, rel, &r);
		if (rc < 0)
			return rc;
		total += r.iters;
		if (r.d < best.d || r.intersecting)
			best = r;
	}
	if (!best.intersecting && best.d > 0.0 &&
	    ((px_mesh_triangle_count(a) > 0 && px_model_kind(b) == PX_MODEL_CLOUD) ||
	     (px_mesh_triangle_count(b) > 0 && px_model_kind(a) == PX_MODEL_CLOUD))) {
		/* certify (or improve) a mesh / cloud answer exactly */
		int ma = px_mesh_triangle_count(a) > 0;
		const struct px_model *m = ma ? a : b, *c = ma ? b : a;
		const struct px_model_ops *co = px_model_get_ops(c);
		if (co->collect && co->closest_among) {
			struct tp_ctx tc;
			double bd = best.d;
			int bt = -1, queries = 0, ex;
			memset(&tc, 0, sizeof(tc));
			tc.c = c;
			tc.best = best.d;
			tc.tri = -1;
			tc.budget = MESH_CLOUD_QUERIES;
			ex = px__mesh_vs_model(m, c, tri_vs_points, &tc, MESH_CLOUD_QUERIES, &bd, &bt,
					       &queries);
			if (ex < 0)
				return ex;
			total += queries + tc.iters;
			if (tc.tri >= 0 && tc.best < best.d) {
				best.d = tc.best;
				best.pa = ma ? tc.pt : tc.pc;
				best.pb = ma ? tc.pc : tc.pt;
				best.ia = ma ? tc.tri : tc.pidx;
				best.ib = ma ? tc.pidx : tc.tri;
				best.intersecting = best.d == 0.0;
			}
			cert = ex == 1;
		}
	}
penetrate:
	res->distance = best.d;
	res->point_a = best.pa;
	res->point_b = best.pb;
	res->index_a = best.ia;
	res->index_b = best.ib;
	if (best.intersecting) {
		/* penetration: the deepest point of either model in the other,
		 * from the overlap found and from every seed */
		px_aabb ba = px_model_local_aabb(a), bb = px_model_local_aabb(b);
		double scale = fmax(finite_box(&ba) ? px_aabb_diagonal(&ba) : 0.0,
				    finite_box(&bb) ? px_aabb_diagonal(&bb) : 0.0);
		double dmin = 0.0;
		int side, j;
		scale = scale > 0.0 ? scale : 1.0;
		for (side = 0; side < 2; side++) {
			const struct px_model *x = side ? b : a, *y = side ? a : b;
			/* every seed costs up to 2 DEEP_ITERS + 2 point
			 * queries, and points deep inside a mesh are its most
			 * expensive queries (many triangles nearly equidistant):
			 * opt->starts trades time for the global hit rate */
			for (j = -1 - nxs; j < starts; j++) {
				px_vec3 st = side ? best.pb : best.pa, pxx, qy, dir;
				double dd;
				int g;
				if (j < -1)
					st = xs[side][-2 - j]; /* the contact triangles' corners */
				else if (j >= 0 && (!seed_point(x, y, j, &st) || !px_v3_isfinite(st)))
					break;
				g = deepest(x, y, st, scale, &dd, &pxx, &qy, &dir, &total);
				if (g < 0)
					return g;
				if (g == 0 || !(dd < dmin))
					continue;
				dmin = dd;
				/* pa - pb = depth * normal (see px_pair.h) */
				res->point_a = side ? qy : pxx;
				res->point_b = side ? pxx : qy;
				res->normal = side ? dir : px_v3_neg(dir);
			}
		}
		if (dmin < 0.0) {
			res->depth = -dmin;
			res->distance = dmin;
			res->depth_approx = 1;
		}
	}
	res->iterations = total;
	res->starts = n;
	res->converged = best.converged;
	res->intersecting = best.intersecting;
	res->local_only = !(best.intersecting || cert ||
			    (best.converged &&
			     (px_model_caps(a) & PX_MODEL_CAP_CONVEX) &&
			     (px_model_caps(b) & PX_MODEL_CAP_CONVEX)));
done:
	{
		/* apart: the way B moves away from A */
		px_vec3 dv = px_v3_sub(res->point_b, res->point_a);
		if (res->depth == 0.0 &&
		    px_v3_normalize(dv, px_v3(0, 0, 0), &res->normal) != PX_OK)
			res->normal = px_v3(0, 0, 0);
	}
done_n:
	res->local_a = px_pose_inverse_transform_point(px_model_pose(a), res->point_a);
	res->local_b = px_pose_inverse_transform_point(px_model_pose(b), res->point_b);
	res->valid = 1;
	return PX_OK;
}
