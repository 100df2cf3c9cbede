/*
 * pair_gjk.c - exact convex pairs through the models' support
 * functions: the distance by GJK and, for an overlapping pair, the
 * penetration depth by EPA (pair_internal.h).
 */
#include <math.h>

#include "mesh_internal.h"
#include "pair_internal.h"
#include "px_mesh.h"

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

#define GJK_REL 1e-10

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

static int shp_support(const struct shp *s, px_vec3 d, px_vec3 *out)
{
	if (s->v && s->nv > 3) {
		double hb = px_v3_dot(s->v[0], d);
		int k, kb = 0;
		for (k = 1; k < s->nv; k++) {
			double h = px_v3_dot(s->v[k], d);
			if (h > hb) {
				hb = h;
				kb = k;
			}
		}
		*out = s->v[kb];
		return PX_OK;
	}
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
	if (s->v && s->nv > 3) {
		px_vec3 c = s->v[0];
		int k;
		for (k = 1; k < s->nv; k++)
			c = px_v3_add(c, s->v[k]);
		return px_v3_scale(c, 1.0 / s->nv);
	}
	if (s->v)
		return px_v3_scale(px_v3_add(s->v[0], px_v3_add(s->v[1], s->v[2])), 1.0 / 3.0);
	return px_model_pose(s->m).t;
}

int px__gjk(const struct shp *a, const struct shp *b, double *dist, px_vec3 *pa,
	    px_vec3 *pb, int *iters, struct gjk_vert S[4], int *n_out, px_vec3 *vout,
	    double *lower)
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

/* One EPA run: the polytope's vertices and faces, and the horizon of the
 * step under way (edges of the removed faces not shared by two). */
struct epa {
	const struct px_model *a, *b;
	struct gjk_vert V[EPA_MAX_V];
	struct epa_face F[EPA_MAX_F];
	int E[EPA_MAX_E][2];
	int nv, nf, ne;
	double scale;
};

/* The starting tetrahedron from GJK's simplex S[0..ns-1], its faces
 * wound outwards. Returns 0 when A - B is flat there (no polytope). */
static int epa_start(struct epa *P, const struct gjk_vert *S, int ns)
{
	/* outward winding: each face away from the opposite vertex */
	static const int T[4][4] = {{1, 2, 3, 0}, {0, 3, 2, 1}, {0, 1, 3, 2}, {0, 2, 1, 3}};
	int k;

	P->nv = ns;
	P->nf = 0;
	P->scale = 0.0;
	for (k = 0; k < ns; k++) {
		P->V[k] = S[k];
		P->scale = fmax(P->scale, px_v3_norm(S[k].w));
	}
	P->scale = fmax(P->scale, 1e-300);
	if (!epa_blowup(P->a, P->b, P->V, &P->nv, P->scale))
		return 0;
	for (k = 0; k < 4; k++) {
		const struct gjk_vert *V = P->V;
		int x = T[k][0], y = T[k][1], z = T[k][2], o = T[k][3];
		px_vec3 n = px_v3_cross(px_v3_sub(V[y].w, V[x].w), px_v3_sub(V[z].w, V[x].w));
		if (px_v3_dot(n, px_v3_sub(V[o].w, V[x].w)) > 0.0) {
			int t = y;
			y = z;
			z = t;
		}
		epa_face_make(V, &P->F[P->nf++], x, y, z);
	}
	return 1;
}

/* The live face nearest the origin, -1 when none. */
static int epa_nearest(const struct epa *P)
{
	int k, best = -1;
	for (k = 0; k < P->nf; k++)
		if (P->F[k].alive && (best < 0 || P->F[k].d < P->F[best].d))
			best = k;
	return best;
}

/* Whether face f is seen from w (best, the face w was found along, is). */
static int epa_sees(const struct epa *P, int f, int best, px_vec3 w)
{
	const struct epa_face *F = &P->F[f];
	const px_vec3 v0 = P->V[F->v[0]].w;
	if (f == best)
		return 1;
	if (isfinite(F->d))
		return px_v3_dot(F->n, px_v3_sub(w, v0)) > 1e-12 * P->scale;
	/* a sliver: by its unnormalised normal */
	return px_v3_dot(px_v3_cross(px_v3_sub(P->V[F->v[1]].w, v0), px_v3_sub(P->V[F->v[2]].w, v0)),
			 px_v3_sub(w, v0)) > 0.0;
}

/* Remove the faces seen from w; their boundary, the horizon, is left in
 * E[0..ne-1]. Returns 0, or -1 when the horizon outgrows the buffer. */
static int epa_horizon(struct epa *P, int best, px_vec3 w)
{
	int k, i;
	P->ne = 0;
	for (k = 0; k < P->nf; k++) {
		if (!P->F[k].alive || !epa_sees(P, k, best, w))
			continue;
		P->F[k].alive = 0;
		for (i = 0; i < 3; i++) {
			int x = P->F[k].v[i], y = P->F[k].v[(i + 1) % 3], j, found = -1;
			for (j = 0; j < P->ne; j++)
				if (P->E[j][0] == y && P->E[j][1] == x)
					found = j;
			if (found >= 0) {
				P->E[found][0] = P->E[P->ne - 1][0];
				P->E[found][1] = P->E[P->ne - 1][1];
				P->ne--;
			} else if (P->ne < EPA_MAX_E) {
				P->E[P->ne][0] = x;
				P->E[P->ne][1] = y;
				P->ne++;
			} else {
				return -1;
			}
		}
	}
	return 0;
}

/* Add w as a vertex and a fan of faces from the horizon to it, in the
 * slots of removed faces first. Returns 0, or -1 when the faces outgrow
 * the buffer. */
static int epa_fan(struct epa *P, const struct gjk_vert *w)
{
	int i, slot = 0;
	P->V[P->nv] = *w;
	for (i = 0; i < P->ne; i++) {
		while (slot < P->nf && P->F[slot].alive)
			slot++;
		if (slot == P->nf) {
			if (P->nf == EPA_MAX_F)
				return -1;
			P->nf++;
		}
		epa_face_make(P->V, &P->F[slot], P->E[i][0], P->E[i][1], P->nv);
	}
	P->nv++;
	return 0;
}

/* Witness points of a converged run from its nearest face best. */
static void epa_witness(const struct epa *P, int best, px_vec3 *pa, px_vec3 *pb)
{
	/* A flat part of A - B is cut into coplanar faces that tie on
	 * distance; the witnesses come from the one that holds the foot of
	 * the origin (else they fall off the surfaces: the foot's weights
	 * are then those of another face's edge). */
	const struct epa_face *F = P->F, *fb = &P->F[best];
	const struct gjk_vert *V = P->V;
	px_vec3 foot = px_v3_scale(fb->n, fb->d), q, miss;
	double gap = INFINITY, u = 0, v = 0;
	int pick = best, k, f, sub;
	/* the nearest face itself passes the test, so pick and its weights
	 * u, v are always set here */
	for (k = 0; k < P->nf; k++) {
		double g, uk, vk;
		if (!F[k].alive || !isfinite(F[k].d) ||
		    F[k].d - fb->d > EPA_REL * fmax(fb->d, 1e-6 * P->scale) ||
		    px_v3_dot(F[k].n, fb->n) < 1.0 - 1e-9)
			continue;
		g = px_tri_closest(foot, V[F[k].v[0]].w, V[F[k].v[1]].w, V[F[k].v[2]].w, &q, &f,
				   &sub, &uk, &vk);
		if (g < gap) {
			gap = g;
			pick = k;
			u = uk;
			v = vk;
		}
	}
	/* the same weights on both sides: each support point lies on its
	 * model's supporting plane (to the tolerance), so both witnesses
	 * lie on the surfaces */
	*pa = px_v3_add(px_v3_scale(V[F[pick].v[0]].a, 1.0 - u - v),
			px_v3_add(px_v3_scale(V[F[pick].v[1]].a, u),
				  px_v3_scale(V[F[pick].v[2]].a, v)));
	*pb = px_v3_add(px_v3_scale(V[F[pick].v[0]].b, 1.0 - u - v),
			px_v3_add(px_v3_scale(V[F[pick].v[1]].b, u),
				  px_v3_scale(V[F[pick].v[2]].b, v)));
	/* the weights' point misses the foot by the rounding of a curved
	 * hull (up to ~1e-7 of the size): half the miss to each side, so
	 * that pa - pb = depth * normal holds exactly */
	miss = px_v3_scale(px_v3_sub(foot, px_v3_sub(*pa, *pb)), 0.5);
	*pa = px_v3_add(*pa, miss);
	*pb = px_v3_sub(*pb, miss);
}

int px__epa(const struct px_model *a, const struct px_model *b,
	    const struct gjk_vert *S, int ns, double *depth, px_vec3 *normal,
	    px_vec3 *pa, px_vec3 *pb, int *iters)
{
	struct epa P;
	double upper = INFINITY;
	px_vec3 up_n = px_v3(0, 0, 1);
	int it, best = -1, conv = 0;

	P.a = a;
	P.b = b;
	if (!epa_start(&P, S, ns))
		return -1;
	for (it = 0; it < 4 * EPA_MAX_V; it++) {
		struct gjk_vert w;
		double h;
		best = epa_nearest(&P);
		if (best < 0 || !isfinite(P.F[best].d))
			return -1;
		px_model_support(a, P.F[best].n, &w.a);
		px_model_support(b, px_v3_neg(P.F[best].n), &w.b);
		w.w = px_v3_sub(w.a, w.b);
		h = px_v3_dot(P.F[best].n, w.w);
		if (h < upper) {
			upper = h;
			up_n = P.F[best].n;
		}
		if (h - P.F[best].d <= EPA_REL * fmax(P.F[best].d, 1e-6 * P.scale)) {
			conv = 1;
			break;
		}
		/* out of room for a vertex, the horizon or the fan: the
		 * upper bound stands */
		if (P.nv >= EPA_MAX_V || epa_horizon(&P, best, w.w) < 0 || epa_fan(&P, &w) < 0)
			break;
	}
	*iters += it;
	if (conv) {
		*depth = P.F[best].d;
		*normal = P.F[best].n;
		epa_witness(&P, best, pa, pb);
		return 1;
	}
	/* the best upper bound's direction */
	px_model_support(a, up_n, pa);
	*depth = upper;
	*normal = up_n;
	*pb = px_v3_madd(*pa, up_n, -upper);
	return 0;
}
