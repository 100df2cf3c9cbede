/* Models as triangles for display (geom/model/px_tess.h): every vertex
 * and every triangle's middle on the surface, trimmed holes open,
 * meshes and clouds as they are. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "brep_gen.h"
#include "px_brep.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_prim.h"
#include "px_tess.h"
#include "px_test.h"

static px_vec3 vtx(const struct px_tess *t, uint32_t i)
{
	return px_v3(t->xyz[3 * i], t->xyz[3 * i + 1], t->xyz[3 * i + 2]);
}

static px_vec3 middle(const struct px_tess *t, size_t k)
{
	px_vec3 a = vtx(t, t->tri[3 * k]), b = vtx(t, t->tri[3 * k + 1]),
		c = vtx(t, t->tri[3 * k + 2]);
	return px_v3((a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3,
		     (a.z + b.z + c.z) / 3);
}

static double area(const struct px_tess *t, size_t k)
{
	px_vec3 a = vtx(t, t->tri[3 * k]), b = vtx(t, t->tri[3 * k + 1]),
		c = vtx(t, t->tri[3 * k + 2]);
	return 0.5 * px_v3_norm(px_v3_cross(px_v3_sub(b, a), px_v3_sub(c, a)));
}

/* Every triangle's vertices and middle within tol of m's surface. */
static void check_on_surface(const struct px_model *m, const struct px_tess *t,
			     double tol)
{
	size_t k;
	PX_CHECK(t->n_triangles > 0);
	for (k = 0; k < t->n_triangles; k++) {
		struct px_model_result r;
		int j;
		for (j = 0; j < 3; j++) {
			PX_CHECK(t->tri[3 * k + j] < t->n_vertices);
			PX_CHECK(px_model_query(m, vtx(t, t->tri[3 * k + j]), &r) >= 0);
			PX_CHECK_MSG(fabs(r.distance) < 1e-9, "vertex off by %g", r.distance);
		}
		PX_CHECK(px_model_query(m, middle(t, k), &r) >= 0);
		PX_CHECK_MSG(fabs(r.distance) < tol, "triangle %zu off by %g", k,
			     r.distance);
	}
}

static void test_sheet_hole_stays_open(void)
{
	struct brep_gen *g = brep_gen_sheet_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_tess t;
	double sum = 0;
	size_t k;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_tessellate(m, NULL, &t), PX_OK);
	check_on_surface(m, &t, 1e-12);
	for (k = 0; k < t.n_triangles; k++) {
		px_vec3 c = middle(&t, k);
		/* nothing over the hole (a chord cuts in by its sagitta) */
		PX_CHECK_MSG(hypot(c.x - 0.5, c.y - 0.5) > 0.25 - 1e-3,
			     "triangle %zu over the hole", k);
		sum += area(&t, k);
	}
	/* the domain's area less at most a cell along the edges */
	PX_CHECK(sum <= 1 - M_PI * 0.0625 + 1e-9);
	PX_CHECK(sum > 1 - M_PI * 0.0625 - 0.08);
	px_tess_free(&t);
	px_model_free(m);
	free(g);
}

static void test_drilled_cube_on_surface(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_tess t;
	size_t k, top = 0;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_tessellate(m, NULL, &t), PX_OK);
	/* the cylinder's chords: 48 pieces about a radius of 0.2 */
	check_on_surface(m, &t, 0.2 * (1 - cos(M_PI / 48)) + 1e-9);
	for (k = 0; k < t.n_triangles; k++) {
		px_vec3 c = middle(&t, k);
		if (fabs(c.z - 1) < 1e-12) {
			top++;
			PX_CHECK(hypot(c.x - 0.5, c.y - 0.5) > 0.2 - 1e-3);
		}
	}
	PX_CHECK(top > 0);
	px_tess_free(&t);
	px_model_free(m);
	free(g);
}

static void test_primitives_on_surface(void)
{
	const struct px_prim ps[] = {
		{PX_PRIM_SPHERE, 0.3, 0, 0},   {PX_PRIM_BOX, 0.1, 0.2, 0.3},
		{PX_PRIM_CAPSULE, 0.1, 0.2, 0}, {PX_PRIM_CYLINDER, 0.1, 0.2, 0},
		{PX_PRIM_CONE, 0.1, 0.2, 0.05}, {PX_PRIM_TORUS, 0.3, 0.1, 0},
	};
	size_t i;
	for (i = 0; i < sizeof(ps) / sizeof(ps[0]); i++) {
		struct px_model *m;
		struct px_tess t;
		size_t k;
		PX_CHECK_INT_EQ(px_prim_model(&ps[i], &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_tessellate(m, NULL, &t), PX_OK);
		PX_CHECK(t.n_triangles > 0 && !t.points_only);
		for (k = 0; k < t.n_vertices; k++) {
			struct px_model_result r;
			PX_CHECK(px_model_query(m, vtx(&t, (uint32_t)k), &r) >= 0);
			PX_CHECK_MSG(fabs(r.distance) < 1e-9, "prim %zu vertex off by %g",
				     i, r.distance);
		}
		px_tess_free(&t);
		px_model_free(m);
	}
}

static void test_mesh_and_cloud_as_they_are(void)
{
	const double xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
	const uint32_t tri[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
	struct px_model *m;
	struct px_tess t;
	PX_CHECK_INT_EQ(px_mesh_model(xyz, 4, tri, 4, NULL, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_tessellate(m, NULL, &t), PX_OK);
	PX_CHECK_INT_EQ((long long)t.n_triangles, 4);
	check_on_surface(m, &t, 1e-12);
	px_tess_free(&t);
	px_model_free(m);
	PX_CHECK_INT_EQ(px_cloud_model(xyz, 4, 0.0, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_tessellate(m, NULL, &t), PX_OK);
	PX_CHECK(t.points_only && t.n_vertices == 4 && t.n_triangles == 0);
	PX_CHECK_NEAR(t.xyz[11], 1.0, 0);
	px_tess_free(&t);
	px_model_free(m);
}

static const struct px_test tests[] = {
	PX_T(test_sheet_hole_stays_open),
	PX_T(test_drilled_cube_on_surface),
	PX_T(test_primitives_on_surface),
	PX_T(test_mesh_and_cloud_as_they_are),
};

PX_TEST_MAIN(tests)
