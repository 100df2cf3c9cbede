/*
 * mesh_gen.h - closed test meshes (UV sphere, subdivided box, torus) for
 * tests and benchmarks. Arrays are malloc'ed; the caller frees them.
 * Triangles face outwards (counter-clockwise seen from outside).
 */
#ifndef PX_MESH_GEN_H
#define PX_MESH_GEN_H

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

struct gen_mesh {
	double *xyz;
	uint32_t *tri;
	size_t nv, nt;
};

static inline void gen_free(struct gen_mesh *g)
{
	free(g->xyz);
	free(g->tri);
	g->xyz = NULL;
	g->tri = NULL;
}

static inline void gen_quad(struct gen_mesh *g, uint32_t a, uint32_t b,
			    uint32_t c, uint32_t d)
{
	uint32_t *t = g->tri + 3 * g->nt;
	t[0] = a, t[1] = b, t[2] = c, t[3] = a, t[4] = c, t[5] = d;
	g->nt += 2;
}

/* Sphere of radius r: nlat >= 2 rings of latitude, nlon >= 3. */
static inline int gen_sphere(double r, int nlat, int nlon, struct gen_mesh *g)
{
	int i, j;
	uint32_t S;
	g->nv = (size_t)(nlat - 1) * nlon + 2;
	g->nt = 0;
	g->xyz = (double *)malloc(3 * g->nv * sizeof(double));
	g->tri = (uint32_t *)malloc(6 * (size_t)nlat * nlon * sizeof(uint32_t));
	if (!g->xyz || !g->tri)
		return -1;
	g->xyz[0] = 0, g->xyz[1] = 0, g->xyz[2] = r;
	for (i = 1; i < nlat; i++)
		for (j = 0; j < nlon; j++) {
			double th = M_PI * i / nlat, ph = 2 * M_PI * j / nlon;
			double *v = g->xyz + 3 * (1 + (size_t)(i - 1) * nlon + j);
			v[0] = r * sin(th) * cos(ph);
			v[1] = r * sin(th) * sin(ph);
			v[2] = r * cos(th);
		}
	S = (uint32_t)(g->nv - 1);
	g->xyz[3 * S] = 0, g->xyz[3 * S + 1] = 0, g->xyz[3 * S + 2] = -r;
#define GEN_V(i, j) ((uint32_t)(1 + (size_t)((i) - 1) * nlon + ((j) % nlon)))
	for (j = 0; j < nlon; j++) {
		uint32_t *t = g->tri + 3 * g->nt;
		t[0] = 0, t[1] = GEN_V(1, j), t[2] = GEN_V(1, j + 1);
		g->nt++;
	}
	for (i = 1; i < nlat - 1; i++)
		for (j = 0; j < nlon; j++)
			gen_quad(g, GEN_V(i, j), GEN_V(i + 1, j), GEN_V(i + 1, j + 1),
				 GEN_V(i, j + 1));
	for (j = 0; j < nlon; j++) {
		uint32_t *t = g->tri + 3 * g->nt;
		t[0] = GEN_V(nlat - 1, j), t[1] = S, t[2] = GEN_V(nlat - 1, j + 1);
		g->nt++;
	}
#undef GEN_V
	return 0;
}

/* Torus: major radius R about z, tube radius r, nu x nv quads. */
static inline int gen_torus(double R, double r, int nu, int nv,
			    struct gen_mesh *g)
{
	int i, j;
	g->nv = (size_t)nu * nv;
	g->nt = 0;
	g->xyz = (double *)malloc(3 * g->nv * sizeof(double));
	g->tri = (uint32_t *)malloc(6 * g->nv * sizeof(uint32_t));
	if (!g->xyz || !g->tri)
		return -1;
	for (i = 0; i < nu; i++)
		for (j = 0; j < nv; j++) {
			double u = 2 * M_PI * i / nu, v = 2 * M_PI * j / nv;
			double *p = g->xyz + 3 * ((size_t)i * nv + j);
			p[0] = (R + r * cos(v)) * cos(u);
			p[1] = (R + r * cos(v)) * sin(u);
			p[2] = r * sin(v);
		}
#define GEN_T(i, j) ((uint32_t)(((size_t)((i) % nu)) * nv + ((j) % nv)))
	for (i = 0; i < nu; i++)
		for (j = 0; j < nv; j++)
			gen_quad(g, GEN_T(i, j), GEN_T(i + 1, j), GEN_T(i + 1, j + 1),
				 GEN_T(i, j + 1));
#undef GEN_T
	return 0;
}

/* Box of half extents h[3], each face an n x n grid of quads. Vertices
 * along shared edges are emitted once per face at identical positions
 * (the mesh module welds them). */
static inline int gen_box(const double h[3], int n, struct gen_mesh *g)
{
	int k, s, i, j;
	size_t per = (size_t)(n + 1) * (n + 1);
	g->nv = 6 * per;
	g->nt = 0;
	g->xyz = (double *)malloc(3 * g->nv * sizeof(double));
	g->tri = (uint32_t *)malloc(6 * 2 * (size_t)n * n * 3 * sizeof(uint32_t));
	if (!g->xyz || !g->tri)
		return -1;
	for (k = 0; k < 3; k++)
		for (s = 0; s < 2; s++) {
			int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
			uint32_t base = (uint32_t)((2 * k + s) * per);
			for (i = 0; i <= n; i++)
				for (j = 0; j <= n; j++) {
					double *p = g->xyz + 3 * (base + (size_t)i * (n + 1) + j);
					p[k] = s ? h[k] : -h[k];
					/* (i / n) first: exact at both ends */
					p[k1] = -h[k1] + 2 * h[k1] * ((double)i / n);
					p[k2] = -h[k2] + 2 * h[k2] * ((double)j / n);
				}
			for (i = 0; i < n; i++)
				for (j = 0; j < n; j++) {
					uint32_t a = base + (uint32_t)(i * (n + 1) + j);
					uint32_t b = a + (uint32_t)(n + 1), c = b + 1, d = a + 1;
					/* e_k1 x e_k2 = e_k: (a, b, c, d) faces +k */
					if (s)
						gen_quad(g, a, b, c, d);
					else
						gen_quad(g, a, d, c, b);
				}
		}
	return 0;
}

/* L-shaped prism, |z| <= hz: the polygon (0,0) (2,0) (2,1) (1,1) (1,2)
 * (0,2) scaled by s, with a reflex edge along (s, s, z). */
static inline int gen_lprism(double s, double hz, struct gen_mesh *g)
{
	static const double P[6][2] = {{1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}, {2, 1}};
	int i;
	g->nv = 12;
	g->nt = 0;
	g->xyz = (double *)malloc(3 * 12 * sizeof(double));
	g->tri = (uint32_t *)malloc(3 * 20 * sizeof(uint32_t));
	if (!g->xyz || !g->tri)
		return -1;
	for (i = 0; i < 6; i++) {
		double *b = g->xyz + 3 * i, *t = g->xyz + 3 * (6 + i);
		b[0] = t[0] = s * P[i][0];
		b[1] = t[1] = s * P[i][1];
		b[2] = -hz;
		t[2] = hz;
	}
	for (i = 1; i < 5; i++) {
		uint32_t *t = g->tri + 3 * g->nt;
		/* top fan from the reflex vertex (counter-clockwise from +z) */
		t[0] = 6, t[1] = (uint32_t)(6 + i), t[2] = (uint32_t)(6 + i + 1);
		/* bottom, reversed */
		t[3] = 0, t[4] = (uint32_t)(i + 1), t[5] = (uint32_t)i;
		g->nt += 2;
	}
	for (i = 0; i < 6; i++) {
		uint32_t a = (uint32_t)i, b = (uint32_t)((i + 1) % 6);
		gen_quad(g, a, b, b + 6, a + 6);
	}
	return 0;
}

#endif
