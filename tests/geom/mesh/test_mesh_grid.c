/*
 * The mesh hint grid (opt-in, px_mesh_opts.grid_cells > 0): cold queries
 * (no hint) start from the triangle the grid names for the query's cell.
 *
 * References: a linear scan over every triangle. Checked: cold answers
 * equal the scan for points inside the grid, outside it and far outside
 * it, on random soups with needles, collapsed and duplicate triangles,
 * on a closed torus, a flat sheet and a mesh collapsed to one point, for
 * many grid budgets; every cell names the triangle closest to its
 * centre; the hint's distance is never below the exact answer and never
 * more than the cell's reach above it; a grid whose cells name the wrong
 * triangles still gives exact answers (the hint only sets the starting
 * bound); budgets are obeyed; queries allocate nothing.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_gen.h"
#include "mesh_internal.h"
#include "px_alloc_count.h"
#include "px_mesh.h"
#include "px_test.h"
#include "px_test_geom.h"

static px_vec3 rand_v(double s)
{
	return px_v3(px_rand_range(-s, s), px_rand_range(-s, s),
		     px_rand_range(-s, s));
}

static const struct mesh *impl_of(const struct px_model *m)
{
	return px_model_impl(m);
}

/* Exact distance by a scan over every triangle (model frame). */
static double brute(const struct px_model *m, px_vec3 p)
{
	return px_test_mesh_brute(m, p);
}

static double leaf_dist(const struct mesh *M, uint32_t li, px_vec3 p)
{
	const struct mtri t_ = px__mtri_get(M, li), *t = &t_;
	return sqrt(px_tri_closest(p, t->a, t->b, t->c, NULL, NULL, NULL, NULL, NULL));
}

/* Centre of the cell a point falls in (clamped to the grid), computed
 * here independently of the library's lookup. */
static px_vec3 cell_centre(const struct mesh *M, px_vec3 p, size_t *cell)
{
	double x[3] = {p.x, p.y, p.z}, o[3] = {M->gorg.x, M->gorg.y, M->gorg.z}, c[3];
	long i[3];
	int k;
	for (k = 0; k < 3; k++) {
		double f = floor((x[k] - o[k]) / M->gcell);
		f = f < 0 ? 0 : (f > M->gdim[k] - 1 ? M->gdim[k] - 1 : f);
		i[k] = (long)f;
		c[k] = o[k] + ((double)i[k] + 0.5) * M->gcell;
	}
	*cell = ((size_t)i[2] * (size_t)M->gdim[1] + (size_t)i[1]) * (size_t)M->gdim[0] +
		(size_t)i[0];
	return px_v3(c[0], c[1], c[2]);
}

/* Query points around the mesh box: inside the grid, just outside and
 * far outside it. */
static px_vec3 rand_point(const struct px_model *m, int kind)
{
	px_aabb b = px_model_local_aabb(m);
	px_vec3 c = px_aabb_center(&b), h = px_aabb_half_extents(&b);
	double s = fmax(1e-3, fmax(h.x, fmax(h.y, h.z)));
	double f = kind == 0 ? 1.1 : (kind == 1 ? 2.0 : 1e3);
	return px_v3(c.x + f * (h.x + 0.1 * s) * px_rand_range(-1, 1),
		     c.y + f * (h.y + 0.1 * s) * px_rand_range(-1, 1),
		     c.z + f * (h.z + 0.1 * s) * px_rand_range(-1, 1));
}

/* Cold answers against the scan, and the hint's bound for each point. */
static void check_mesh(const struct px_model *m, int nq)
{
	const struct mesh *M = impl_of(m);
	int i;
	for (i = 0; i < nq; i++) {
		px_vec3 p = rand_point(m, i % 3), c;
		struct px_model_result r;
		double ref = brute(m, p), L = 1.0 + px_v3_norm(p), dh;
		size_t cell;
		uint32_t li;

		PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, -1, 0, &r), 1);
		PX_CHECK_MSG(fabs(fabs(r.distance) - ref) <= 1e-12 * (1 + ref) + 1e-14 * L,
			     "point %d (%g %g %g): %.17g vs linear scan %.17g", i, p.x, p.y,
			     p.z, fabs(r.distance), ref);
		if (!M->grid)
			continue;
		li = px__mesh_grid_hint(M, p);
		PX_CHECK(li < M->nt);
		c = cell_centre(M, p, &cell);
		PX_CHECK_INT_EQ(li, M->grid[cell]);
		dh = leaf_dist(M, li, p);
		/* an upper bound: never below the answer */
		PX_CHECK_MSG(dh >= ref * (1 - 1e-12) - 1e-14 * L, "hint %.17g below exact %.17g",
			     dh, ref);
		/* and a tight one: within twice the distance to the centre
		 * (the hint is exact there; distances are 1-Lipschitz) */
		PX_CHECK_MSG(dh <= ref + 2 * px_v3_dist(p, c) + 1e-12 * L,
			     "hint %.17g, exact %.17g, %g from the cell centre", dh, ref,
			     px_v3_dist(p, c));
	}
}

/* Every cell (or a sample of them) names the triangle closest to its
 * centre. */
static void check_cells(const struct px_model *m, int max_cells)
{
	const struct mesh *M = impl_of(m);
	size_t n, i, step;
	if (!M->grid)
		return;
	n = (size_t)M->gdim[0] * (size_t)M->gdim[1] * (size_t)M->gdim[2];
	step = n > (size_t)max_cells ? n / (size_t)max_cells : 1;
	for (i = (size_t)px_rand_int(0, (int)step - 1); i < n; i += step) {
		size_t x = i % (size_t)M->gdim[0], y = (i / (size_t)M->gdim[0]) % (size_t)M->gdim[1],
		       z = i / ((size_t)M->gdim[0] * (size_t)M->gdim[1]);
		px_vec3 c = px_v3(M->gorg.x + ((double)x + 0.5) * M->gcell,
				  M->gorg.y + ((double)y + 0.5) * M->gcell,
				  M->gorg.z + ((double)z + 0.5) * M->gcell);
		double ref = brute(m, c), dh = leaf_dist(M, M->grid[i], c);
		PX_CHECK_MSG(fabs(dh - ref) <= 1e-12 * (1 + ref) + 1e-14 * (1 + px_v3_norm(c)),
			     "cell %zu: hint triangle at %.17g, closest at %.17g", i, dh, ref);
	}
	/* the grid covers the mesh box */
	PX_CHECK(M->gorg.x <= M->box.min.x && M->gorg.y <= M->box.min.y &&
		 M->gorg.z <= M->box.min.z);
	PX_CHECK(M->gorg.x + M->gdim[0] * M->gcell >= M->box.max.x &&
		 M->gorg.y + M->gdim[1] * M->gcell >= M->box.max.y &&
		 M->gorg.z + M->gdim[2] * M->gcell >= M->box.max.z);
}

static const long budgets[] = {0, -1, 1, 7, 64, 1000, 40000};

static void test_soups(void)
{
	int rep;
	for (rep = 0; rep < 10; rep++) {
		size_t nt = (size_t)px_rand_int(1, 500), nv = 3 * nt, i;
		double *xyz = malloc(3 * nv * sizeof(double));
		uint32_t *tri = malloc(3 * nt * sizeof(uint32_t));
		struct px_mesh_opts o;
		struct px_model *m;
		size_t cells;
		memset(&o, 0, sizeof(o));
		o.grid_cells = budgets[rep % 7];
		for (i = 0; i < nt; i++) {
			px_vec3 c = rand_v(2), a = px_v3_add(c, rand_v(0.3)),
				b = px_v3_add(c, rand_v(0.3)), d = px_v3_add(c, rand_v(0.3));
			if (i % 11 == 3)
				d = b; /* collapsed */
			if (i % 13 == 5)
				d = px_v3_lerp(a, b, 0.7); /* collinear */
			if (i % 7 == 2) /* needle: height 1e-12 of its length */
				d = px_v3_add(px_v3_lerp(a, b, 0.4), px_v3(1e-12, -1e-12, 0));
			if (i % 9 == 4 && i > 0) { /* duplicate of the previous one */
				memcpy(&a, xyz + 9 * (i - 1), sizeof(a));
				memcpy(&b, xyz + 9 * (i - 1) + 3, sizeof(b));
				memcpy(&d, xyz + 9 * (i - 1) + 6, sizeof(d));
			}
			memcpy(xyz + 9 * i, &a, sizeof(a));
			memcpy(xyz + 9 * i + 3, &b, sizeof(b));
			memcpy(xyz + 9 * i + 6, &d, sizeof(d));
			tri[3 * i] = (uint32_t)(3 * i);
			tri[3 * i + 1] = (uint32_t)(3 * i + 1);
			tri[3 * i + 2] = (uint32_t)(3 * i + 2);
		}
		PX_CHECK_INT_EQ(px_mesh_model(xyz, nv, tri, nt, &o, NULL, &m), PX_OK);
		if (o.grid_cells <= 0) {
			PX_CHECK(impl_of(m)->grid == NULL);
		} else {
			const struct mesh *M = impl_of(m);
			long cap = o.grid_cells;
			PX_CHECK(M->grid != NULL);
			cells = (size_t)M->gdim[0] * (size_t)M->gdim[1] * (size_t)M->gdim[2];
			PX_CHECK_MSG(cells >= 1 && cells <= (size_t)cap &&
					     (cells == 1 || cells <= nt / 8),
				     "%zu cells for a budget of %ld, %zu triangles", cells, cap, nt);
		}
		check_cells(m, 300);
		check_mesh(m, 150);
		px_model_free(m);
		free(xyz);
		free(tri);
	}
}

static void test_shapes(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct px_mesh_opts o;
	double xyz[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
	uint32_t sheet[6] = {0, 1, 2, 0, 2, 3};
	double pt[9] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
	uint32_t one[3] = {0, 1, 2};
	int b;

	memset(&o, 0, sizeof(o));
	PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 60, 30, &g), 0);
	for (b = 0; b < 3; b++) {
		o.grid_cells = b == 0 ? 0 : (b == 1 ? 5 : 3000);
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, NULL, &m), PX_OK);
		check_cells(m, 200);
		check_mesh(m, 200);
		px_model_free(m);
	}
	gen_free(&g);
	o.grid_cells = 1000;
	/* a flat sheet (the box has no thickness) */
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 4, sheet, 2, &o, NULL, &m), PX_OK);
	PX_CHECK(impl_of(m)->grid != NULL);
	check_cells(m, 100);
	check_mesh(m, 100);
	px_model_free(m);
	/* everything collapsed to one point */
	PX_CHECK_INT_EQ(px_mesh_model(pt, 3, one, 1, &o, NULL, &m), PX_OK);
	PX_CHECK(impl_of(m)->grid != NULL);
	check_cells(m, 10);
	check_mesh(m, 30);
	px_model_free(m);
}

/* A grid naming the wrong triangles (the farthest one, everywhere) only
 * costs time: the answers stay exact. */
static void test_wrong_hints_stay_exact(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct mesh *M;
	size_t n, i;
	int q;
	struct px_mesh_opts o;

	memset(&o, 0, sizeof(o));
	o.grid_cells = 64L * 64 * 64;
	PX_CHECK_INT_EQ(gen_sphere(1.0, 16, 32, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, NULL, &m), PX_OK);
	M = (struct mesh *)impl_of(m);
	PX_CHECK(M->grid != NULL);
	n = (size_t)M->gdim[0] * (size_t)M->gdim[1] * (size_t)M->gdim[2];
	for (i = 0; i < n; i++)
		M->grid[i] = (uint32_t)px_rand_int(0, (int)M->nt - 1);
	for (q = 0; q < 200; q++) {
		px_vec3 p = rand_point(m, q % 3);
		struct px_model_result r;
		double ref = brute(m, p);
		PX_CHECK_INT_EQ(px_model_query_ex(m, p, INFINITY, -1, 0, &r), 1);
		PX_CHECK_MSG(fabs(fabs(r.distance) - ref) <= 1e-12 * (1 + ref) + 1e-14 * px_v3_norm(p),
			     "%.17g vs %.17g", fabs(r.distance), ref);
		/* a bound also holds with a distance limit */
		PX_CHECK_INT_EQ(px_model_query_ex(m, p, 0.5 * ref, -1, 0, &r), 0);
	}
	px_model_free(m);
	gen_free(&g);
}

static void test_options(void)
{
	struct gen_mesh g;
	struct px_model *m = NULL;
	struct px_mesh_opts o;
	struct px_mesh_report rp;
	memset(&o, 0, sizeof(o));
	PX_CHECK_INT_EQ(gen_sphere(1.0, 8, 16, &g), 0);
	o.grid_cells = PX_MESH_MAX_GRID_CELLS + 1;
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, &rp, &m), PX_E_INVAL);
	PX_CHECK(m == NULL && rp.message[0]);
	o.grid_cells = -5;
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, &rp, &m), PX_OK);
	PX_CHECK(impl_of(m)->grid == NULL);
	px_model_free(m);
	gen_free(&g);
}

static void test_grid_no_alloc(void)
{
	struct gen_mesh g;
	struct px_model *m;
	struct px_model_result r;
	uint64_t a;
	int i;
	struct px_mesh_opts o;
	memset(&o, 0, sizeof(o));
	o.grid_cells = 64L * 64 * 64;
	PX_CHECK_INT_EQ(gen_torus(1.0, 0.3, 80, 40, &g), 0);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, &o, NULL, &m), PX_OK);
	PX_CHECK(impl_of(m)->grid != NULL);
	a = px_alloc_region_begin();
	for (i = 0; i < 2000; i++) {
		px_vec3 p = px_v3(2 * cos(0.01 * i), 1.7 * sin(0.013 * i), 3 * sin(0.1 * i));
		px_model_query(m, p, &r);
		px_model_query_ex(m, p, 0.05, -1, 0, &r);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_model_free(m);
	gen_free(&g);
}

static const struct px_test tests[] = {
	PX_T(test_soups), PX_T(test_shapes), PX_T(test_wrong_hints_stay_exact),
	PX_T(test_options), PX_T(test_grid_no_alloc)};
PX_TEST_MAIN(tests)
