/* Scene: nearest surface against brute force over every model, the
 * broad phase, the control adapter's no-overestimate contract, scale,
 * config loading and its errors, no allocation in queries. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_mesh.h"
#include "px_config.h"
#include "px_control.h"
#include "px_model.h"
#include "px_prim.h"
#include "px_scene.h"
#include "px_test.h"
#include "px_test_config.h"

static px_pose random_pose(double spread)
{
	px_pose p;
	px_vec3 axis = px_v3(px_rand_normal(), px_rand_normal(), px_rand_normal());
	if (px_v3_norm(axis) < 1e-6)
		axis = px_v3(0, 0, 1);
	px_quat_from_axis_angle(axis, px_rand_range(-3.14, 3.14), &p.q);
	p.t = px_v3(px_rand_range(-spread, spread), px_rand_range(-spread, spread),
		    px_rand_range(-spread, spread));
	return p;
}

static struct px_scene *random_scene(int n)
{
	struct px_scene *s;
	int i;
	PX_CHECK_INT_EQ(px_scene_create((size_t)n, &s), PX_OK);
	for (i = 0; i < n; i++) {
		struct px_prim pr;
		struct px_model *m;
		memset(&pr, 0, sizeof(pr));
		switch (px_rand_int(0, 3)) {
		case 0:
			pr.type = PX_PRIM_SPHERE;
			pr.a = px_rand_range(0.05, 0.5);
			break;
		case 1:
			pr.type = PX_PRIM_BOX;
			pr.a = px_rand_range(0.05, 0.5);
			pr.b = px_rand_range(0.05, 0.5);
			pr.c = px_rand_range(0.05, 0.5);
			break;
		case 2:
			pr.type = PX_PRIM_CAPSULE;
			pr.a = px_rand_range(0.05, 0.3);
			pr.b = px_rand_range(0.05, 0.5);
			break;
		default:
			pr.type = PX_PRIM_TORUS;
			pr.a = px_rand_range(0.2, 0.5);
			pr.b = px_rand_range(0.02, 0.15);
			break;
		}
		PX_CHECK_INT_EQ(px_prim_model(&pr, &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_set_pose(m, random_pose(3.0)), PX_OK);
		PX_CHECK_INT_EQ(px_scene_add(s, m, NULL), i);
	}
	return s;
}

/* min over models of the signed distance, no broad phase */
static double brute(const struct px_scene *s, px_vec3 p, int *which)
{
	double best = INFINITY;
	size_t i;
	*which = -1;
	for (i = 0; i < px_scene_count(s); i++) {
		struct px_model_result r;
		PX_CHECK_INT_EQ(px_model_query(px_scene_model(s, i), p, &r), 1);
		if (r.distance < best) {
			best = r.distance;
			*which = (int)i;
		}
	}
	return best;
}

static void test_nearest_matches_brute_force(void)
{
	int round;
	long queried = 0, points = 0;
	for (round = 0; round < 10; round++) {
		int n = px_rand_int(1, 40), k;
		struct px_scene *s = random_scene(n);
		for (k = 0; k < 200; k++) {
			px_vec3 p = px_v3(px_rand_range(-4, 4), px_rand_range(-4, 4),
					  px_rand_range(-4, 4));
			struct px_scene_hit h;
			int which;
			double d = brute(s, p, &which);
			PX_CHECK_INT_EQ(px_scene_nearest(s, p, INFINITY, &h), 1);
			PX_CHECK_NEAR(h.distance_m, d, 1e-12);
			PX_CHECK(h.model >= 0 && h.model < n);
			PX_CHECK_NEAR(h.r.distance, d, 1e-12);
			/* the answer's point lies on the model it names */
			{
				struct px_model_result r;
				px_model_query(px_scene_model(s, (size_t)h.model),
					       h.r.point, &r);
				PX_CHECK_NEAR(r.distance, 0, 1e-9);
			}
			queried += h.models_queried;
			points++;
			/* range: nothing reported beyond it */
			{
				double range = fabs(d) * px_rand_range(0.2, 1.8);
				int rc = px_scene_nearest(s, p, range, &h);
				if (fabs(d) < range * (1 - 1e-9)) {
					PX_CHECK_INT_EQ(rc, 1);
					PX_CHECK_NEAR(h.distance_m, d, 1e-12);
				} else if (fabs(d) > range * (1 + 1e-9)) {
					PX_CHECK_INT_EQ(rc, 0);
					PX_CHECK_INT_EQ(h.model, -1);
				}
			}
		}
		px_scene_free(s);
	}
	printf("  broad phase: %.2f narrow-phase queries per point\n",
	       (double)queried / (double)points);
}

/* Coherent queries along random walks (a moving probe, with jumps) give
 * the plain query's answer whatever the hints, and allocate nothing, also
 * through the control adapter. (The work figures are printed: with a
 * best-first hierarchy the hint saves little.) */
static void test_coherent_matches_plain(void)
{
	struct gen_mesh g;
	struct px_scene *s;
	struct px_model *m;
	static struct px_scene_hints hints;
	struct px_control_query q;
	long it_plain = 0, it_coh = 0;
	int round, k, i;
	PX_CHECK_INT_EQ(px_scene_create(8, &s), PX_OK);
	for (i = 0; i < 2; i++) {
		px_pose pose = px_pose_identity();
		PX_CHECK_INT_EQ(gen_sphere(0.5 + 0.2 * i, 24 + 8 * i, 48, &g), 0);
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL,
					      &m), PX_OK);
		gen_free(&g);
		pose.t = px_v3(i ? 1.0 : -1.0, 0, 0);
		PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
		PX_CHECK_INT_EQ(px_scene_add(s, m, "ball"), i);
	}
	for (i = 0; i < 3; i++) {
		struct px_prim pr;
		memset(&pr, 0, sizeof(pr));
		pr.type = PX_PRIM_BOX;
		pr.a = pr.b = pr.c = 0.2;
		PX_CHECK_INT_EQ(px_prim_model(&pr, &m), PX_OK);
		PX_CHECK_INT_EQ(px_model_set_pose(m, random_pose(2.0)), PX_OK);
		PX_CHECK_INT_EQ(px_scene_add(s, m, NULL), i + 2);
	}
	for (round = 0; round < 20; round++) {
		px_vec3 p = px_v3(px_rand_range(-2, 2), px_rand_range(-1, 1),
				  px_rand_range(-1, 1));
		uint64_t a;
		px_scene_hints_reset(&hints);
		a = px_alloc_region_begin();
		for (k = 0; k < 300; k++) {
			struct px_scene_hit h0, h1;
			int r0, r1;
			/* steps of a few mm, now and then a jump */
			double step = px_rand_unit() < 0.02 ? 0.5 : 0.004;
			p = px_v3_add(p, px_v3(step * px_rand_normal(),
					       step * px_rand_normal(),
					       step * px_rand_normal()));
			r0 = px_scene_nearest(s, p, INFINITY, &h0);
			r1 = px_scene_nearest_coherent(s, p, INFINITY, &hints, &h1);
			PX_CHECK_INT_EQ(r1, r0);
			PX_CHECK_NEAR(h1.distance_m, h0.distance_m, 1e-12);
			if (h0.model >= 0 && h0.model < 2) {
				it_plain += h0.r.iterations;
				it_coh += h1.r.iterations;
			}
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	}
	printf("  mesh work per query: plain %.1f, coherent %.1f\n",
	       (double)it_plain / 6000.0, (double)it_coh / 6000.0);
	/* the control adapter answers as the plain one */
	PX_CHECK_INT_EQ(px_scene_control_query_coherent(s, &hints, &q), PX_OK);
	for (k = 0; k < 500; k++) {
		px_vec3 p = px_v3(px_rand_range(-2, 2), px_rand_range(-1, 1),
				  px_rand_range(-1, 1));
		struct px_control_hit c;
		struct px_scene_hit h;
		uint64_t a = px_alloc_region_begin();
		PX_CHECK_INT_EQ(q.point(q.ctx, p, INFINITY, &c), PX_OK);
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		PX_CHECK_INT_EQ(px_scene_nearest(s, p, INFINITY, &h), 1);
		PX_CHECK(c.valid);
		PX_CHECK_NEAR(c.distance_m, h.distance_m, 1e-12);
	}
	PX_CHECK_INT_EQ(px_scene_control_query_coherent(s, NULL, &q), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_scene_nearest_coherent(s, px_v3(0, 0, 0), INFINITY,
						  NULL, &(struct px_scene_hit){0}),
			PX_E_INVAL);
	px_scene_free(s);
}

static void test_broad_phase_skips_far_models(void)
{
	/* 50 unit spheres on a line, 10 m apart: a point near one of them
	 * needs that one and at most its box neighbours. */
	struct px_scene *s;
	struct px_scene_hit h;
	int i;
	PX_CHECK_INT_EQ(px_scene_create(50, &s), PX_OK);
	for (i = 0; i < 50; i++) {
		struct px_prim pr = {PX_PRIM_SPHERE, 1.0, 0, 0};
		struct px_model *m;
		px_pose pose = px_pose_identity();
		pose.t = px_v3(10.0 * i, 0, 0);
		PX_CHECK_INT_EQ(px_prim_model(&pr, &m), PX_OK);
		px_model_set_pose(m, pose);
		PX_CHECK(px_scene_add(s, m, "ball") >= 0);
	}
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(201.5, 0.2, 0), INFINITY, &h), 1);
	PX_CHECK_INT_EQ(h.model, 20);
	PX_CHECK(h.models_queried <= 2);
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(200, 0, 0), INFINITY, &h), 1);
	PX_CHECK_NEAR(h.distance_m, -1.0, 1e-12);
	PX_CHECK(h.r.inside);
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(NAN, 0, 0), 1, &h), PX_E_NAN);
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(0, 0, 0), -1, &h), PX_E_INVAL);
	/* capacity */
	{
		struct px_prim pr = {PX_PRIM_SPHERE, 1.0, 0, 0};
		struct px_model *m;
		PX_CHECK_INT_EQ(px_prim_model(&pr, &m), PX_OK);
		PX_CHECK_INT_EQ(px_scene_add(s, m, "extra"), PX_E_NOSPC);
	}
	PX_CHECK(strcmp(px_scene_name(s, 3), "ball") == 0);
	PX_CHECK(strcmp(px_scene_name(s, 99), "") == 0);
	px_scene_free(s);
	px_scene_free(NULL);
}

/* A model that answers like a unit sphere but claims a gap. */
static int loose_closest(const void *impl, const struct px_model_query *q,
			 struct px_model_result *r)
{
	struct px_prim pr = {PX_PRIM_SPHERE, 1.0, 0, 0};
	(void)impl;
	px_prim_closest(&pr, q->p, 1, r);
	r->is_signed = 0;
	r->inside = 0;
	r->certified = 0;
	r->gap = 0.25;
	return 1;
}

static px_aabb loose_aabb(const void *impl)
{
	px_aabb b = {{-1, -1, -1}, {1, 1, 1}};
	(void)impl;
	return b;
}

static const struct px_model_ops loose_ops = {
	.name = "loose",
	.kind = PX_MODEL_CUSTOM,
	.closest = loose_closest,
	.aabb = loose_aabb,
};

static void test_control_adapter_never_overestimates(void)
{
	struct px_scene *s = random_scene(12);
	struct px_control_query q;
	struct px_model *m;
	struct px_control_hit hit;
	int k;
	uint64_t a;
	PX_CHECK_INT_EQ(px_scene_control_query(s, &q), PX_OK);
	a = px_alloc_region_begin();
	for (k = 0; k < 500; k++) {
		px_vec3 p = px_v3(px_rand_range(-4, 4), px_rand_range(-4, 4),
				  px_rand_range(-4, 4));
		int which;
		double d = brute(s, p, &which);
		PX_CHECK_INT_EQ(q.point(q.ctx, p, 10.0, &hit), PX_OK);
		PX_CHECK(hit.valid == (fabs(d) <= 10.0));
		if (!hit.valid)
			continue;
		PX_CHECK(fabs(hit.distance_m) <= fabs(d) + 1e-12);
		PX_CHECK(!hit.two_sided);
		PX_CHECK_NEAR(px_v3_norm(hit.normal), 1, 1e-9);
		/* query = point + distance * normal for exact answers */
		PX_CHECK_NEAR(px_v3_dist(px_v3_madd(hit.point_m, hit.normal,
						    hit.distance_m),
					 p),
			      0, 1e-9);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_scene_free(s);

	/* an uncertified answer reports distance - gap, two-sided */
	PX_CHECK_INT_EQ(px_scene_create(1, &s), PX_OK);
	PX_CHECK_INT_EQ(px_model_create(&loose_ops, NULL, 0, &m), PX_OK);
	PX_CHECK_INT_EQ(px_scene_add(s, m, "loose"), 0);
	px_scene_control_query(s, &q);
	PX_CHECK_INT_EQ(q.point(q.ctx, px_v3(3, 0, 0), 10.0, &hit), PX_OK);
	PX_CHECK(hit.valid && hit.two_sided);
	PX_CHECK_NEAR(hit.distance_m, 2.0 - 0.25, 1e-12);
	PX_CHECK_INT_EQ(q.point(q.ctx, px_v3(1.1, 0, 0), 10.0, &hit), PX_OK);
	PX_CHECK_NEAR(hit.distance_m, 0.0, 0);
	px_scene_free(s);
}

static const char *write_tmp(const char *name, const char *text)
{
	static char path[4][256];
	static int k;
	FILE *f;
	char *p = path[k++ % 4];
	snprintf(p, 256, "build/tmp_scene_%d_%s", (int)px_test_seed() % 1000, name);
	f = fopen(p, "w");
	PX_CHECK(f != NULL);
	if (f) {
		fputs(text, f);
		fclose(f);
	}
	return p;
}

static int load(const char *text, struct px_scene **s,
		struct px_config_diag *diag)
{
	struct px_config *cfg = NULL;
	int rc = px_config_load_mem("scene.yaml", text, strlen(text), &cfg, diag);
	if (rc != PX_OK)
		return rc;
	rc = px_scene_config_load(cfg, s, diag);
	px_config_free(cfg);
	return rc;
}

static void test_config_example_scene(void)
{
	static struct px_config_diag diag;
	struct px_config *cfg;
	struct px_scene *s;
	struct px_scene_hit h;
	struct px_control_query q;
	struct px_control_hit hit;
	uint64_t a;
	int k;
	if (px_config_load_file("config/examples/haptic_sim.yaml", &cfg, &diag) !=
	    PX_OK)
		PX_SKIP("config/examples/haptic_sim.yaml not found");
	PX_CHECK_INT_EQ(px_scene_config_load(cfg, &s, &diag), PX_OK);
	px_config_diag_print(&diag, stdout);
	px_config_free(cfg);
	PX_CHECK_INT_EQ(px_scene_count(s), 3);
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 0)), PX_MODEL_NURBS);
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 1)), PX_MODEL_MESH);
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 2)), PX_MODEL_PRIMITIVE);
	PX_CHECK(strcmp(px_scene_name(s, 1), "knob") == 0);
	/* above the terrain's middle, far from the rest: NURBS, unsigned */
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(-0.08, -0.08, 0.0), 1.0, &h), 1);
	PX_CHECK_INT_EQ(h.model, 0);
	PX_CHECK(!h.r.is_signed && h.distance_m > 0);
	/* centre of the knob (scaled 1.2: radius 0.024, inscribed >= 0.023) */
	PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(-0.035, 0, 0), 1.0, &h), 1);
	PX_CHECK_INT_EQ(h.model, 1);
	PX_CHECK(h.distance_m < -0.022 && h.distance_m > -0.0241);
	px_scene_control_query(s, &q);
	a = px_alloc_region_begin();
	for (k = 0; k < 300; k++) {
		px_vec3 p = px_v3(px_rand_range(-0.1, 0.1), px_rand_range(-0.1, 0.1),
				  px_rand_range(-0.02, 0.1));
		size_t i;
		double best = INFINITY;
		PX_CHECK_INT_EQ(q.point(q.ctx, p, 1.0, &hit), PX_OK);
		PX_CHECK(hit.valid);
		for (i = 0; i < px_scene_count(s); i++) {
			struct px_model_result r;
			px_model_query(px_scene_model(s, i), p, &r);
			if (r.distance < best)
				best = r.distance;
		}
		PX_CHECK(fabs(hit.distance_m) <= fabs(best) + 1e-12);
		PX_CHECK_NEAR(hit.distance_m, best, 1e-9);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	px_scene_free(s);
}

static void test_config_scale(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	struct px_scene *s;
	char text[2048];
	const char *stl = "solid t\n facet normal 0 0 1\n  outer loop\n"
			  "   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
			  "  endloop\n endfacet\nendsolid t\n";
	const char *path = write_tmp("tri.stl", stl);
	int k;
	/* relative file names are relative to the config: use absolute */
	{
		char abs_path[512], cwd[400];
		PX_CHECK(getcwd(cwd, sizeof(cwd)) != NULL);
		snprintf(abs_path, sizeof(abs_path), "%s/%s", cwd, path);
		snprintf(text, sizeof(text),
			 "scene:\n  models:\n"
			 "    - {file: %s, kind: mesh}\n"
			 "    - {file: %s, kind: mesh, scale: 2.5, pose: {xyz_m: "
			 "[0, 0, 10]}}\n",
			 abs_path, abs_path);
	}
	PX_CHECK_INT_EQ(load(text, &s, &diag), PX_OK);
	px_config_diag_print(&diag, stdout);
	PX_CHECK_INT_EQ(px_scene_count(s), 2);
	for (k = 0; k < 100; k++) {
		px_vec3 p = px_v3(px_rand_range(-1, 1), px_rand_range(-1, 1),
				  px_rand_range(-1, 1));
		struct px_model_result r1, r2;
		PX_CHECK_INT_EQ(px_model_query(px_scene_model(s, 0), p, &r1), 1);
		PX_CHECK_INT_EQ(px_model_query(px_scene_model(s, 1),
					       px_v3_add(px_v3_scale(p, 2.5),
							 px_v3(0, 0, 10)),
					       &r2),
				1);
		PX_CHECK_NEAR(r2.distance, 2.5 * r1.distance, 1e-6);
		PX_CHECK_NEAR(px_v3_dist(r2.point,
					 px_v3_add(px_v3_scale(r1.point, 2.5),
						   px_v3(0, 0, 10))),
			      0, 1e-6);
	}
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 1)), PX_MODEL_MESH);
	px_scene_free(s);
	remove(path);
}

/* kind cad: the shipped STEP block (60 x 40 x 20 mm, read in metres) as
 * one signed B-rep; scale multiplies metres; a build without
 * OpenCASCADE refuses it at the file with the reason. */
static void test_config_cad(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	struct px_scene *s = NULL;
	struct px_model_result r;
	char text[2048], cwd[400];
	int i, found = 0;

	PX_CHECK(getcwd(cwd, sizeof(cwd)) != NULL);
	snprintf(text, sizeof(text),
		 "scene:\n  models:\n"
		 "    - {file: %s/config/examples/parts/filleted_block.step, kind: cad}\n"
		 "    - {file: %s/config/examples/parts/filleted_block.step, kind: cad,"
		 " scale: 2, pose: {xyz_m: [0, 0, 1]}}\n",
		 cwd, cwd);
	if (!PX_HAVE_OCCT) {
		PX_CHECK_INT_EQ(load(text, &s, &diag), PX_E_PARSE);
		for (i = 0; i < diag.count; i++)
			found += strstr(diag.errors[i].msg, "built without OpenCASCADE") != NULL;
		PX_CHECK(found == 2);
	}
	PX_NEEDS(OCCT);
	if (load(text, &s, &diag) != PX_OK) {
		px_config_diag_print(&diag, stdout);
		PX_CHECK(0);
		return;
	}
	PX_CHECK_INT_EQ(px_scene_count(s), 2);
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 0)), PX_MODEL_BREP);
	PX_CHECK_INT_EQ(px_model_kind(px_scene_model(s, 1)), PX_MODEL_BREP);
	/* 10 mm inside the bottom face; twice that in the scaled copy */
	PX_CHECK_INT_EQ(px_model_query(px_scene_model(s, 0), px_v3(0.01, 0.02, 0.01), &r), 1);
	PX_CHECK(r.is_signed);
	PX_CHECK_NEAR(r.distance, -0.01, 1e-12);
	PX_CHECK_INT_EQ(px_model_query(px_scene_model(s, 1), px_v3(0.02, 0.04, 1.02), &r), 1);
	PX_CHECK(r.is_signed);
	PX_CHECK_NEAR(r.distance, -0.02, 1e-12);
	px_scene_free(s);
}

static int has(const struct px_config_diag *d, const char *msg)
{
	int i;
	for (i = 0; i < d->count; i++)
		if (strcmp(d->errors[i].msg, msg) == 0)
			return 1;
	for (i = 0; i < d->count; i++)
		printf("  got: %s\n", d->errors[i].msg);
	return 0;
}

static void test_config_errors(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	struct px_scene *s = (struct px_scene *)&diag;
	PX_CHECK_INT_EQ(load("scene:\n  models:\n    - {file: nope.stl, kind: mesh}\n",
			     &s, &diag),
			PX_E_PARSE);
	PX_CHECK(s == NULL);
	PX_CHECK_INT_EQ(diag.count, 1);
	PX_CHECK(strncmp(diag.errors[0].msg,
			 "scene.yaml:3:14: scene.models[0].file: nope.stl: ", 49) == 0);
	PX_CHECK_INT_EQ(load("scene:\n  primitives:\n    - type: sphere\n"
			     "      half_height_m: 1\n",
			     &s, &diag),
			PX_E_PARSE);
	PX_CHECK(has(&diag, "scene.yaml:3:7: scene.primitives[0].radius_m: "
			    "missing required key for type 'sphere'"));
	PX_CHECK(has(&diag, "scene.yaml:4:22: scene.primitives[0].half_height_m: "
			    "not used by type 'sphere'"));
	PX_CHECK_INT_EQ(load("scene:\n  models:\n    - {file: a.obj, kind: nurb}\n",
			     &s, &diag),
			PX_E_PARSE);
	PX_CHECK(has(&diag, "scene.yaml:3:27: scene.models[0].kind: unknown value "
			    "'nurb' (expected one of: mesh, nurbs, cloud, cad)"));
	PX_CHECK_INT_EQ(load("scene:\n  models:\n    - {file: a.ply, kind: mesh, "
			     "cloud_radius_m: 0.1}\n",
			     &s, &diag),
			PX_E_PARSE);
	PX_CHECK(has(&diag, "scene.yaml:3:49: scene.models[0].cloud_radius_m: "
			    "only for kind 'cloud' (kind is 'mesh')"));
	PX_CHECK_INT_EQ(load("scene:\n  primitives:\n    - {type: torus, radius_m: "
			     "0.1, tube_radius_m: 0.2}\n",
			     &s, &diag),
			PX_E_PARSE);
	PX_CHECK(has(&diag, "scene.yaml:3:7: scene.primitives[0]: invalid torus "
			    "dimensions: value out of range"));
	PX_CHECK_INT_EQ(load("scene:\n  modles: []\n", &s, &diag), PX_E_PARSE);
	PX_CHECK(diag.count == 1 && strstr(diag.errors[0].msg, "scene.modles: unknown key"));
	/* an absent section is an empty scene */
	PX_CHECK_INT_EQ(load("loop: {period_ns: 1000000}\n", &s, &diag), PX_OK);
	PX_CHECK_INT_EQ(px_scene_count(s), 0);
	{
		struct px_scene_hit h;
		PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(0, 0, 0), INFINITY, &h), 0);
	}
	px_scene_free(s);
}

/* Haptic proxy on a scene: pressed into the -x face of a box, then the
 * device slides along y past the end of that face, into free space. The
 * proxy must follow it out (no phantom wall left by the face's plane),
 * never be inside the box, and the force must fall back to zero. */
static void test_proxy_leaves_the_end_of_a_face(void)
{
	struct px_scene *s;
	struct px_model *m;
	struct px_prim box = {PX_PRIM_BOX, 0.02, 0.02, 0.02};
	struct px_control_query q;
	struct px_control_haptic_params hp;
	struct px_control_haptic h;
	struct px_control_haptic_out out;
	int k, inside = 0;
	double max_pen = 0;
	px_vec3 dev = px_v3(-0.05, 0, 0);
	PX_CHECK_INT_EQ(px_scene_create(1, &s), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&box, &m), PX_OK);
	PX_CHECK_INT_EQ(px_scene_add(s, m, "box"), 0);
	px_scene_control_query(s, &q);
	px_control_haptic_params_default(&hp);
	PX_CHECK_INT_EQ(px_control_haptic_init(&h, &hp, 1000000), PX_OK);
	for (k = 0; k < 400; k++) {
		struct px_scene_hit sh;
		if (k < 40)
			dev.x += 0.001; /* into the face, 10 mm deep */
		else if (k < 120)
			dev.y += 0.001; /* along it, past its end at y = 0.02 */
		PX_CHECK_INT_EQ(px_control_haptic_step(&h, &q, dev, NULL, &out),
				PX_OK);
		if (k == 60)
			PX_CHECK(out.contact && out.penetration_m > 0.009);
		if (out.penetration_m > max_pen)
			max_pen = out.penetration_m;
		PX_CHECK_INT_EQ(px_scene_nearest(s, out.proxy_m, INFINITY, &sh), 1);
		if (sh.distance_m < 0)
			inside++;
	}
	PX_CHECK_INT_EQ(inside, 0);
	PX_CHECK(max_pen > 0.009 && max_pen < 0.012);
	PX_CHECK_MSG(!out.contact && out.penetration_m == 0,
		     "proxy held %.4f m behind a face it has left (proxy %.4f "
		     "%.4f %.4f, device %.4f %.4f %.4f)",
		     out.penetration_m, out.proxy_m.x, out.proxy_m.y,
		     out.proxy_m.z, dev.x, dev.y, dev.z);
	PX_CHECK_NEAR(px_v3_dist(out.proxy_m, dev), 0, 1e-9);
	PX_CHECK(px_v3_norm(out.force_n) < 0.05);
	px_scene_free(s);
}

/* Tracked queries (px_scene_nearest_tracked) along smooth paths through a
 * scene of NURBS models (a scaled terrain, a closed rational sphere -
 * signed -, a curve-only circle: px_strack and px_track streams) and a
 * mesh: every answer equals the plain global one, the streams do the
 * work (tracked answers, hot path), a model moved between queries is
 * followed, jumps of the closest point are reported, and nothing is
 * allocated once the streams are made. */
static void test_tracked_matches_plain(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	struct px_scene *s, *other;
	struct px_scene_tracking *t;
	struct px_model_stream_opts so;
	struct px_model_stream_stats st;
	struct px_control_query q;
	char text[4096], cwd[400];
	px_vec3 prev_p = px_v3(0, 0, 0), prev_pt = px_v3(0, 0, 0);
	int prev_model = -1, k, pass, real_jumps = 0, missed = 0, reported = 0;
	long stream_answers = 0;
	uint64_t a;

	PX_CHECK(getcwd(cwd, sizeof(cwd)) != NULL);
	snprintf(text, sizeof(text),
		 "scene:\n  models:\n"
		 "    - {name: terrain, file: %s/config/examples/scenes/terrain.obj,"
		 " kind: nurbs, scale: 1.25, pose: {xyz_m: [0.0, 0.0, 0.005]}}\n"
		 "    - {name: ball, file: %s/tests/data/sphere.obj, kind: nurbs,"
		 " scale: 0.015, pose: {xyz_m: [-0.04, 0.03, 0.0]}}\n"
		 "    - {name: ring, file: %s/tests/data/circle.obj, kind: nurbs,"
		 " scale: 0.01, pose: {xyz_m: [0.03, -0.04, 0.01],"
		 " rpy_rad: [0.4, 0.0, 0.0]}}\n"
		 "    - {name: knob, file: %s/config/examples/scenes/knob.stl,"
		 " kind: mesh, pose: {xyz_m: [-0.03, -0.05, 0.0]}}\n",
		 cwd, cwd, cwd, cwd);
	if (load(text, &s, &diag) != PX_OK) {
		px_config_diag_print(&diag, stdout);
		PX_CHECK(0);
		return;
	}
	px_model_stream_opts_default(&so);
	so.verify_every = 7;
	PX_CHECK_INT_EQ(px_scene_tracking_create(s, &so, &t), PX_OK);
	/* three NURBS models follow with streams, the mesh with hints */
	PX_CHECK_INT_EQ(px_scene_tracking_stats(t, &st), 3);
	/* the closed sphere is signed, also behind the scale */
	{
		struct px_scene_hit h;
		PX_CHECK_INT_EQ(px_scene_nearest(s, px_v3(-0.04, 0.03, 0.0), 1.0,
						 &h),
				1);
		PX_CHECK_INT_EQ(h.model, 1);
		PX_CHECK(h.r.is_signed && h.distance_m < -0.02);
	}
	a = px_alloc_region_begin();
	for (pass = 0; pass < 2; pass++) {
		for (k = 0; k < 6000; k++) {
			double tt = (double)k / 1000.0 + 0.37 * pass;
			struct px_scene_hit h0, h1;
			int r0, r1;
			px_vec3 p = px_v3(0.09 * sin(0.9 * tt + 0.3 * pass),
					  0.08 * sin(1.3 * tt + 1.0),
					  0.012 + 0.025 * sin(2.1 * tt));
			if (pass == 1 && k >= 2000 && k < 4000) {
				/* the ball moves under the point */
				px_pose pose = px_pose_identity();
				pose.t = px_v3(-0.04 + 0.02 * sin(3.0 * tt), 0.03,
					       0.0);
				PX_CHECK_INT_EQ(px_scene_set_pose(s, 1, pose), PX_OK);
			}
			r0 = px_scene_nearest(s, p, 1.0, &h0);
			r1 = px_scene_nearest_tracked(s, p, 1.0, t, &h1);
			PX_CHECK_INT_EQ(r1, r0);
			PX_CHECK_NEAR(h1.distance_m, h0.distance_m, 1e-9);
			if (fabs(h1.distance_m - h0.distance_m) > 1e-9)
				printf("  step %d pass %d: model %d %.12g vs %d %.12g\n",
				       k, pass, h1.model, h1.distance_m, h0.model,
				       h0.distance_m);
			if (h1.model != h0.model)
				/* only a tie may name another model */
				PX_CHECK_NEAR(h1.distance_m, h0.distance_m, 1e-12);
			else
				PX_CHECK(px_v3_dist(h1.r.point, h0.r.point) < 1e-6);
			PX_CHECK_INT_EQ(h1.r.is_signed, h0.r.is_signed);
			if (h1.model >= 0 && h1.model < 3)
				stream_answers++;
			/* a closest point moving far more than the query
			 * point, within one model, or another model, is a
			 * jump the answer must report */
			if (k > 0 && h1.model >= 0 && prev_model >= 0) {
				double dq = px_v3_dist(p, prev_p);
				double dx = px_v3_dist(h1.r.point, prev_pt);
				int real = h1.model != prev_model ||
					   dx > 50.0 * dq + 1e-6;
				real_jumps += real;
				missed += real && !h1.jumped;
				reported += h1.jumped;
			}
			prev_p = p;
			prev_pt = h1.r.point;
			prev_model = h1.model;
		}
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	PX_CHECK_INT_EQ(px_scene_tracking_stats(t, &st), 3);
	printf("  tracked scene: %ld stream answers of 12000; streams: %llu "
	       "queries, %llu tracked (%llu hot), %llu global, %llu cold, "
	       "%llu verified, %llu disagreements; jumps %d real, %d missed, "
	       "%d reported\n",
	       stream_answers, (unsigned long long)st.queries,
	       (unsigned long long)st.tracked, (unsigned long long)st.hot,
	       (unsigned long long)st.global, (unsigned long long)st.cold,
	       (unsigned long long)st.verifications,
	       (unsigned long long)st.disagreements, real_jumps, missed,
	       reported);
	PX_CHECK(stream_answers > 3000);
	/* the streams, not a global query behind them, answered */
	PX_CHECK(st.tracked > st.queries / 2);
	PX_CHECK(st.hot > st.tracked / 4);
	PX_CHECK(st.verifications > 100);
	PX_CHECK_INT_EQ((long)st.disagreements, 0);
	PX_CHECK(real_jumps > 0);
	PX_CHECK_INT_EQ(missed, 0);

	/* the control adapter answers as the plain one */
	PX_CHECK_INT_EQ(px_scene_control_query_tracked(s, t, &q), PX_OK);
	for (k = 0; k < 300; k++) {
		px_vec3 p = px_v3(0.05 * cos(k * 0.01), 0.05 * sin(k * 0.01), 0.01);
		struct px_control_hit c;
		struct px_scene_hit h;
		PX_CHECK_INT_EQ(q.point(q.ctx, p, 1.0, &c), PX_OK);
		PX_CHECK_INT_EQ(px_scene_nearest(s, p, 1.0, &h), 1);
		PX_CHECK(c.valid);
		PX_CHECK_NEAR(c.distance_m, h.distance_m, 1e-9);
	}
	/* bad input: a NaN point leaves the streams as they were; a
	 * tracking state of another world is refused */
	{
		struct px_scene_hit h;
		PX_CHECK_INT_EQ(px_scene_nearest_tracked(s, px_v3(NAN, 0, 0), 1.0,
							 t, &h),
				PX_E_NAN);
		PX_CHECK_INT_EQ(px_scene_create(1, &other), PX_OK);
		PX_CHECK_INT_EQ(px_scene_nearest_tracked(other, px_v3(0, 0, 0),
							 1.0, t, &h),
				PX_E_INVAL);
		PX_CHECK_INT_EQ(px_scene_nearest_tracked(s, px_v3(0, 0, 0), 1.0,
							 NULL, &h),
				PX_E_INVAL);
		PX_CHECK_INT_EQ(px_scene_control_query_tracked(other, t, &q),
				PX_E_INVAL);
		px_scene_free(other);
	}
	px_scene_tracking_free(t);
	px_scene_free(s);
}

static void test_schema_documented(void)
{
	char why[200];
	char *docs;
	PX_CHECK_INT_EQ(px_config_schema_validate(px_scene_config_schema(), why,
						  sizeof(why)),
			PX_OK);
	docs = px_test_read_text("docs/config.md");
	if (!docs)
		PX_SKIP("docs/config.md not found (run from the source tree)");
	PX_CHECK(strstr(docs, "## scene") != NULL);
	px_test_check_documented(docs, px_scene_config_schema(), 8);
	free(docs);
}

static const struct px_test tests[] = {
	PX_T(test_nearest_matches_brute_force),
	PX_T(test_broad_phase_skips_far_models),
	PX_T(test_coherent_matches_plain),
	PX_T(test_control_adapter_never_overestimates),
	PX_T(test_config_example_scene),
	PX_T(test_config_scale),
	PX_T(test_config_cad),
	PX_T(test_config_errors),
	PX_T(test_proxy_leaves_the_end_of_a_face),
	PX_T(test_tracked_matches_plain),
	PX_T(test_schema_documented),
};
PX_TEST_MAIN(tests)
