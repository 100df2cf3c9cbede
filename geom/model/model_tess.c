/* Models as triangles for display (px_tess.h). Setup only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "px_brep.h"
#include "px_cloud.h"
#include "px_dist.h"
#include "px_mesh.h"
#include "px_nurbs.h"
#include "px_prim.h"
#include "px_tess.h"
#include "px_trim.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void px_tess_opts_default(struct px_tess_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->grid_per_span = 6;
	o->max_per_dir = 64;
	o->trimmed_min = 48;
	o->segments = 32;
	o->halfspace_m = 1.0;
	o->max_vertices = 2000000;
}

void px_tess_free(struct px_tess *t)
{
	if (!t)
		return;
	free(t->xyz);
	free(t->tri);
	memset(t, 0, sizeof(*t));
}

/* The arrays growing; the first failure sticks in rc. */
struct tb {
	struct px_tess *t;
	size_t cap_v, cap_t, max_v;
	int rc;
};

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
	size_t c = *cap ? *cap : 256;
	void *q;
	if (need <= *cap)
		return 0;
	while (c < need)
		c *= 2;
	q = realloc(*p, c * elem);
	if (!q)
		return -1;
	*p = q;
	*cap = c;
	return 0;
}

static uint32_t vert(struct tb *b, double x, double y, double z)
{
	struct px_tess *t = b->t;
	if (b->rc)
		return 0;
	if (t->n_vertices >= b->max_v) {
		b->rc = PX_E_NOSPC;
		return 0;
	}
	if (grow((void **)&t->xyz, &b->cap_v, t->n_vertices + 1,
		 3 * sizeof(double))) {
		b->rc = PX_E_NOMEM;
		return 0;
	}
	t->xyz[3 * t->n_vertices] = x;
	t->xyz[3 * t->n_vertices + 1] = y;
	t->xyz[3 * t->n_vertices + 2] = z;
	return (uint32_t)t->n_vertices++;
}

static void tri(struct tb *b, uint32_t i, uint32_t j, uint32_t k)
{
	struct px_tess *t = b->t;
	if (b->rc)
		return;
	if (grow((void **)&t->tri, &b->cap_t, t->n_triangles + 1,
		 3 * sizeof(uint32_t))) {
		b->rc = PX_E_NOMEM;
		return;
	}
	t->tri[3 * t->n_triangles] = i;
	t->tri[3 * t->n_triangles + 1] = j;
	t->tri[3 * t->n_triangles + 2] = k;
	t->n_triangles++;
}

/* Two triangles over the quad a b c d (counter-clockwise). */
static void quad(struct tb *b, uint32_t a, uint32_t bb, uint32_t c, uint32_t d)
{
	tri(b, a, bb, c);
	tri(b, a, c, d);
}

/* ---- primitives: a profile (rho, z) turned about z ---------------------- */

static void revolve(struct tb *b, const double *rz, int k, int closed, int seg)
{
	uint32_t base = (uint32_t)b->t->n_vertices;
	int i, j;
	for (i = 0; i < k; i++)
		for (j = 0; j < seg; j++) {
			double a = 2.0 * M_PI * j / seg;
			vert(b, rz[2 * i] * cos(a), rz[2 * i] * sin(a), rz[2 * i + 1]);
		}
	for (i = 0; i < (closed ? k : k - 1); i++) {
		int i1 = (i + 1) % k;
		for (j = 0; j < seg; j++) {
			int j1 = (j + 1) % seg;
			quad(b, base + (uint32_t)(i * seg + j),
			     base + (uint32_t)(i * seg + j1),
			     base + (uint32_t)(i1 * seg + j1),
			     base + (uint32_t)(i1 * seg + j));
		}
	}
}

/* An arc of the profile: centre (0, zc), radius r, angles a0..a1 from
 * the -z axis towards +rho, n pieces (n + 1 points from *k on). */
static void arc(double *rz, int *k, double zc, double r, double a0, double a1,
		int n)
{
	int i;
	for (i = 0; i <= n; i++) {
		double a = a0 + (a1 - a0) * i / n;
		rz[2 * *k] = r * sin(a);
		rz[2 * *k + 1] = zc - r * cos(a);
		++*k;
	}
}

static void box(struct tb *b, double hx, double hy, double hz)
{
	static const int f[6][4][3] = {
		{{-1, -1, -1}, {-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}},
		{{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},
		{{-1, -1, -1}, {1, -1, -1}, {1, -1, 1}, {-1, -1, 1}},
		{{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}},
		{{-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}, {1, -1, -1}},
		{{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}};
	int i, j;
	for (i = 0; i < 6; i++) {
		uint32_t v[4];
		for (j = 0; j < 4; j++)
			v[j] = vert(b, f[i][j][0] * hx, f[i][j][1] * hy,
				    f[i][j][2] * hz);
		quad(b, v[0], v[1], v[2], v[3]);
	}
}

static int prim(struct tb *b, const struct px_model *m,
		const struct px_tess_opts *o)
{
	struct px_prim p;
	int seg = o->segments < 3 ? 3 : o->segments, k = 0, n = seg / 2;
	double *rz;
	if (px_prim_get(m, &p) != PX_OK)
		return PX_E_INVAL;
	if (p.type == PX_PRIM_BOX) {
		box(b, p.a, p.b, p.c);
		return b->rc;
	}
	if (p.type == PX_PRIM_HALFSPACE) {
		double h = o->halfspace_m / 2;
		uint32_t v0 = vert(b, -h, -h, 0), v1 = vert(b, h, -h, 0);
		uint32_t v2 = vert(b, h, h, 0), v3 = vert(b, -h, h, 0);
		quad(b, v0, v1, v2, v3);
		return b->rc;
	}
	rz = malloc((size_t)(2 * n + 8) * 2 * sizeof(double));
	if (!rz)
		return PX_E_NOMEM;
	switch (p.type) {
	case PX_PRIM_SPHERE:
		arc(rz, &k, 0, p.a, 0, M_PI, n);
		break;
	case PX_PRIM_CAPSULE:
		arc(rz, &k, -p.b, p.a, 0, M_PI / 2, n / 2);
		arc(rz, &k, p.b, p.a, M_PI / 2, M_PI, n / 2);
		break;
	case PX_PRIM_CYLINDER:
	case PX_PRIM_CONE: {
		double top = p.type == PX_PRIM_CONE ? p.c : p.a;
		const double pr[8] = {0, -p.b, p.a, -p.b, top, p.b, 0, p.b};
		memcpy(rz, pr, sizeof(pr));
		k = 4;
		break;
	}
	case PX_PRIM_TORUS: {
		int i;
		for (i = 0; i < n; i++) {
			double a = 2.0 * M_PI * i / n;
			rz[2 * k] = p.a + p.b * cos(a);
			rz[2 * k + 1] = p.b * sin(a);
			k++;
		}
		revolve(b, rz, k, 1, seg);
		free(rz);
		return b->rc;
	}
	default:
		free(rz);
		return PX_E_UNSUPPORTED;
	}
	revolve(b, rz, k, 0, seg);
	free(rz);
	return b->rc;
}

/* ---- surfaces on a grid ------------------------------------------------- */

/* The grid values of direction dir: every distinct knot in the domain,
 * each span cut into per pieces, at most max + 1 values (*n). */
static double *grid_values(const struct px_nurbs_surf *s, int dir, int per,
			   int max, int min, int *n)
{
	const double *kn = s->knots[dir];
	int p = s->degree[dir], nk = s->n_knots[dir], spans = 0, i, j;
	double lo = kn[p], hi = kn[nk - p - 1], *g;
	for (i = p; i < nk - p - 1; i++)
		if (kn[i + 1] > kn[i])
			spans++;
	if (spans < 1)
		spans = 1;
	if (spans * per < min)
		per = (min + spans - 1) / spans;
	if (max < min)
		max = min;
	if (spans * per > max)
		per = max / spans > 0 ? max / spans : 1;
	g = malloc((size_t)(spans * per + 1) * sizeof(double));
	if (!g)
		return NULL;
	*n = 0;
	if (spans * per > max) {
		/* more spans than the grid allows: uniform in the domain */
		for (i = 0; i <= max; i++)
			g[(*n)++] = lo + (hi - lo) * i / max;
		return g;
	}
	for (i = p; i < nk - p - 1; i++) {
		if (!(kn[i + 1] > kn[i]))
			continue;
		for (j = 0; j < per; j++)
			g[(*n)++] = kn[i] + (kn[i + 1] - kn[i]) * j / per;
	}
	g[(*n)++] = hi;
	return g;
}

static int surface(struct tb *b, const struct px_nurbs_surf *s,
		   const struct px_trim *trim, int reversed,
		   const struct px_tess_opts *o)
{
	int nu, nv, i, j, rc = PX_OK, min = trim ? o->trimmed_min : 1;
	double *gu = grid_values(s, 0, o->grid_per_span, o->max_per_dir, min, &nu);
	double *gv = grid_values(s, 1, o->grid_per_span, o->max_per_dir, min, &nv);
	unsigned char *in = NULL;
	uint32_t base = (uint32_t)b->t->n_vertices;
	if (gu && gv)
		in = malloc((size_t)nu * (size_t)nv);
	if (!in) {
		rc = PX_E_NOMEM;
		goto out;
	}
	for (j = 0; j < nv; j++)
		for (i = 0; i < nu; i++) {
			px_vec3 q = px_nurbs_surf_point(s, gu[i], gv[j]);
			vert(b, q.x, q.y, q.z);
			in[j * nu + i] = !trim || px_trim_contains(trim, gu[i], gv[j],
								  NULL) != PX_TRIM_OUTSIDE;
		}
	for (j = 0; j + 1 < nv; j++)
		for (i = 0; i + 1 < nu; i++) {
			int c[4] = {j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1,
				    (j + 1) * nu + i};
			uint32_t v[4];
			int k;
			for (k = 0; k < 4; k++)
				v[k] = base + (uint32_t)c[k];
			/* a corner outside the trimmed domain drops the
			 * triangle: holes stay open */
			if (in[c[0]] && in[c[1]] && in[c[2]])
				reversed ? tri(b, v[0], v[2], v[1]) : tri(b, v[0], v[1], v[2]);
			if (in[c[0]] && in[c[2]] && in[c[3]])
				reversed ? tri(b, v[0], v[3], v[2]) : tri(b, v[0], v[2], v[3]);
		}
	rc = b->rc;
out:
	free(gu);
	free(gv);
	free(in);
	return rc;
}

static int nurbs(struct tb *b, const struct px_model *m,
		 const struct px_tess_opts *o)
{
	const struct px_nurbs_surf *s;
	int n = px_nurbs_model_surfaces(m, &s), i, rc = PX_OK;
	if (n < 0)
		return PX_E_UNSUPPORTED; /* another NURBS-kind model */
	for (i = 0; i < n && rc == PX_OK; i++)
		rc = surface(b, &s[i], NULL, 0, o);
	return rc;
}

static int brep(struct tb *b, const struct px_model *m,
		const struct px_tess_opts *o)
{
	const struct px_brep *br = px_model_brep(m);
	struct px_brep_info info;
	int i, rc = PX_OK;
	if (!br || px_brep_get_info(br, &info) != PX_OK)
		return PX_E_UNSUPPORTED;
	for (i = 0; i < info.n_faces && rc == PX_OK; i++) {
		const struct px_nurbs_surf *s;
		const struct px_trim *t;
		int rev;
		rc = px_brep_face(br, i, &s, &t, &rev);
		if (rc == PX_OK)
			rc = surface(b, s, t, rev, o);
	}
	return rc;
}

int px_model_tessellate(const struct px_model *m, const struct px_tess_opts *o,
			struct px_tess *out)
{
	struct px_tess_opts def;
	struct tb b;
	size_t i, n;
	int rc = PX_OK;
	if (!out)
		return PX_E_INVAL;
	memset(out, 0, sizeof(*out));
	if (!m)
		return PX_E_INVAL;
	if (!o) {
		px_tess_opts_default(&def);
		o = &def;
	}
	memset(&b, 0, sizeof(b));
	b.t = out;
	b.max_v = o->max_vertices;
	switch (px_model_kind(m)) {
	case PX_MODEL_MESH:
		n = px_mesh_triangle_count(m);
		for (i = 0; i < n && !b.rc; i++) {
			px_vec3 v[3];
			uint32_t a, c, d;
			if (px_mesh_triangle(m, i, v) != PX_OK)
				continue;
			a = vert(&b, v[0].x, v[0].y, v[0].z);
			c = vert(&b, v[1].x, v[1].y, v[1].z);
			d = vert(&b, v[2].x, v[2].y, v[2].z);
			tri(&b, a, c, d);
		}
		rc = b.rc;
		break;
	case PX_MODEL_CLOUD:
		out->points_only = 1;
		n = px_cloud_point_count(m);
		for (i = 0; i < n && !b.rc; i++) {
			px_vec3 p;
			if (px_cloud_point(m, i, &p) == PX_OK)
				vert(&b, p.x, p.y, p.z);
		}
		rc = b.rc;
		break;
	case PX_MODEL_PRIMITIVE:
		rc = prim(&b, m, o);
		break;
	case PX_MODEL_NURBS:
		rc = nurbs(&b, m, o);
		break;
	case PX_MODEL_BREP:
		rc = brep(&b, m, o);
		break;
	default:
		rc = PX_E_UNSUPPORTED;
	}
	return rc;
}
