/*
 * Scenes: the hierarchy must give exactly what a loop over every model
 * gives (nearest model, models within a distance, tool against the
 * scene), for random scenes of mixed representations whose poses change
 * every cycle.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_gen.h"
#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_mesh.h"
#include "px_prim.h"
#include "px_scene.h"
#include "px_test.h"
#include "px_test_geom.h"

#define NM 40

static struct px_model *rand_model(int i)
{
	struct px_model *m = NULL;
	int kind = i % 9;
	if (kind < 6) {
		static const enum px_prim_type T[6] = {PX_PRIM_SPHERE, PX_PRIM_BOX, PX_PRIM_CAPSULE,
						       PX_PRIM_CYLINDER, PX_PRIM_CONE, PX_PRIM_TORUS};
		struct px_prim p = {T[kind], px_rand_range(0.2, 0.5), px_rand_range(0.1, 0.15),
				    px_rand_range(0.0, 0.3)};
		PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_OK);
	} else if (kind < 8) {
		struct gen_mesh g;
		if (kind == 6)
			gen_sphere(0.3, 6, 8, &g);
		else
			gen_torus(0.3, 0.1, 12, 6, &g);
		PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &m), PX_OK);
		gen_free(&g);
	} else {
		double x[300];
		int k;
		for (k = 0; k < 300; k++)
			x[k] = px_rand_range(-0.3, 0.3);
		PX_CHECK_INT_EQ(px_cloud_model(x, 100, 0.0, NULL, &m), PX_OK);
	}
	return m;
}

struct world {
	struct px_scene *s;
	struct px_model *m[NM + 1];
	int n;
};

static void make_world(struct world *w, int with_floor)
{
	int i;
	PX_CHECK_INT_EQ(px_scene_create(NM + 1, &w->s), PX_OK);
	w->n = 0;
	for (i = 0; i < NM; i++) {
		w->m[w->n] = rand_model(i);
		PX_CHECK_INT_EQ(px_scene_add_kept(w->s, w->m[w->n], NULL), PX_OK);
		w->n++;
	}
	if (with_floor) {
		struct px_prim hs = {PX_PRIM_HALFSPACE, 0, 0, 0};
		px_pose P = px_pose_identity();
		P.t.z = -4.0;
		PX_CHECK_INT_EQ(px_prim_model(&hs, &w->m[w->n]), PX_OK);
		px_model_set_pose(w->m[w->n], P);
		PX_CHECK_INT_EQ(px_scene_add_kept(w->s, w->m[w->n], NULL), PX_OK);
		w->n++;
	}
}

static void move_world(struct world *w)
{
	int i;
	for (i = 0; i < NM; i++)
		px_model_set_pose(w->m[i], px_test_rand_pose(3.0));
	PX_CHECK_INT_EQ(px_scene_update(w->s), PX_OK);
}

static void free_world(struct world *w)
{
	int i;
	px_scene_free(w->s);
	for (i = 0; i < w->n; i++)
		px_model_free(w->m[i]);
}

static void test_nearest_and_within(void)
{
	struct world w;
	int cycle, i;
	make_world(&w, 1);
	PX_CHECK_INT_EQ(px_scene_count(w.s), NM + 1);
	{
		struct px_scene_hit h;
		PX_CHECK_INT_EQ(px_scene_nearest(w.s, px_v3(0, 0, 0), INFINITY, &h), PX_E_STATE);
	}
	for (cycle = 0; cycle < 10; cycle++) {
		move_world(&w);
		for (i = 0; i < 60; i++) {
			px_vec3 p = px_v3(px_rand_range(-4, 4), px_rand_range(-4, 4), px_rand_range(-4, 4));
			double best = INFINITY, lim = px_rand_range(0, 1.0);
			int bid = -1, k, cnt = 0, rc;
			struct px_scene_hit h, hits[NM + 1];
			size_t nf;
			char seen[NM + 1];
			for (k = 0; k < w.n; k++) {
				struct px_model_result r;
				px_model_query(w.m[k], p, &r);
				if (r.distance < best) {
					best = r.distance;
					bid = k;
				}
				if (r.distance <= lim)
					cnt++;
			}
			PX_CHECK_INT_EQ(px_scene_nearest(w.s, p, INFINITY, &h), 1);
			PX_CHECK_MSG(h.distance_m == best, "nearest %d (%.15g) vs loop %d (%.15g)",
				     h.model, h.distance_m, bid, best);
			/* a bound below the nearest distance finds nothing */
			rc = px_scene_nearest(w.s, p, best > 0 ? 0.5 * best : INFINITY, &h);
			PX_CHECK_INT_EQ(rc, best > 0 ? 0 : 1);
			rc = px_scene_within(w.s, p, lim, hits, NM + 1, &nf);
			PX_CHECK_INT_EQ(rc, cnt);
			PX_CHECK_INT_EQ(nf, cnt);
			memset(seen, 0, sizeof(seen));
			for (k = 0; k < rc; k++) {
				struct px_model_result r;
				PX_CHECK(!seen[hits[k].model]);
				seen[hits[k].model] = 1;
				px_model_query(w.m[hits[k].model], p, &r);
				PX_CHECK(r.distance <= lim && r.distance == hits[k].distance_m);
			}
			if (cnt > 1) {
				rc = px_scene_within(w.s, p, lim, hits, 1, &nf);
				PX_CHECK_INT_EQ(rc, PX_E_NOSPC);
				PX_CHECK_INT_EQ(nf, cnt);
			}
		}
	}
	free_world(&w);
}

static void test_tool(void)
{
	struct world w;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.2, 0, 0}, cap = {PX_PRIM_CAPSULE, 0.1, 0.3, 0};
	struct px_model *tools[3];
	struct gen_mesh g;
	int cycle, t;
	make_world(&w, 0);
	PX_CHECK_INT_EQ(px_prim_model(&sp, &tools[0]), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&cap, &tools[1]), PX_OK);
	gen_torus(0.25, 0.08, 12, 6, &g);
	PX_CHECK_INT_EQ(px_mesh_model(g.xyz, g.nv, g.tri, g.nt, NULL, NULL, &tools[2]), PX_OK);
	gen_free(&g);
	for (cycle = 0; cycle < 20; cycle++) {
		move_world(&w);
		for (t = 0; t < 3; t++) {
			struct px_scene_hit hits[NM];
			double lim = px_rand_range(0, 1.5);
			int k, cnt = 0, rc;
			size_t nf;
			px_model_set_pose(tools[t], px_test_rand_pose(2.5));
			for (k = 0; k < w.n; k++) {
				struct px_pair_result r;
				memset(&r, 0, sizeof(r));
				px_pair_distance(tools[t], w.m[k], NULL, &r);
				if (r.distance <= lim)
					cnt++;
			}
			rc = px_scene_tool(w.s, tools[t], lim, NULL, hits, NM, &nf);
			PX_CHECK_MSG(rc == cnt, "tool %d: %d hits vs loop %d", t, rc, cnt);
			for (k = 0; k < rc; k++) {
				struct px_pair_result r;
				memset(&r, 0, sizeof(r));
				px_pair_distance(tools[t], w.m[hits[k].model], NULL, &r);
				PX_CHECK(hits[k].distance_m == r.distance);
				PX_CHECK_NEAR(px_v3_dist(hits[k].point, hits[k].tool_point),
					      hits[k].distance_m, 1e-9 + (hits[k].intersecting ? INFINITY : 0));
			}
		}
	}
	for (t = 0; t < 3; t++)
		px_model_free(tools[t]);
	free_world(&w);
}

static void test_no_alloc_and_errors(void)
{
	struct world w;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.2, 0, 0};
	struct px_model *tool;
	struct px_scene *s2;
	struct px_scene_hit hits[8], h;
	uint64_t a;
	int i;
	make_world(&w, 1);
	PX_CHECK_INT_EQ(px_prim_model(&sp, &tool), PX_OK);
	move_world(&w);
	a = px_alloc_region_begin();
	for (i = 0; i < 200; i++) {
		px_pose P = px_pose_identity();
		P.t = px_v3(2 * cos(0.03 * i), 2 * sin(0.03 * i), 0);
		px_model_set_pose(w.m[i % NM], P);
		px_scene_update(w.s);
		px_model_set_pose(tool, P);
		px_scene_nearest(w.s, P.t, INFINITY, &h);
		px_scene_within(w.s, P.t, 0.5, hits, 8, NULL);
		px_scene_tool(w.s, tool, 0.5, NULL, hits, 8, NULL);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	PX_CHECK_INT_EQ(px_scene_nearest(w.s, px_v3(NAN, 0, 0), INFINITY, &h), PX_E_NAN);
	PX_CHECK_INT_EQ(px_scene_within(w.s, px_v3(0, 0, 0), -1, hits, 8, NULL), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_scene_create(0, &s2), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_scene_create(1, &s2), PX_OK);
	px_model_set_pose(tool, px_pose_identity());
	PX_CHECK_INT_EQ(px_scene_add_kept(s2, tool, NULL), PX_OK);
	PX_CHECK_INT_EQ(px_scene_add_kept(s2, tool, NULL), PX_E_NOSPC);
	PX_CHECK_INT_EQ(px_scene_update(s2), PX_OK);
	PX_CHECK_INT_EQ(px_scene_nearest(s2, px_v3(1, 0, 0), INFINITY, &h), 1);
	PX_CHECK_NEAR(h.distance_m, 0.8, 1e-12);
	px_scene_free(s2);
	px_scene_free(NULL);
	px_model_free(tool);
	free_world(&w);
}

/* Poses set through the scene are seen by the very next query, in the
 * hierarchy of a large scene (refit of a leaf and its ancestors) as in
 * a small one; models the scene owns need no update, kept ones moved on
 * their own do; nothing is allocated. */
static void test_set_pose_seen_at_once(void)
{
	static const int sizes[2] = {6, 40};
	int si;
	for (si = 0; si < 2; si++) {
		struct px_scene *s;
		struct px_scene_hit h, hits[NM];
		int n = sizes[si], i, k;
		uint64_t a;
		PX_CHECK_INT_EQ(px_scene_create((size_t)n, &s), PX_OK);
		for (i = 0; i < n; i++)
			PX_CHECK_INT_EQ(px_scene_add(s, rand_model(i), NULL), i);
		a = px_alloc_region_begin();
		for (k = 0; k < 400; k++) {
			px_vec3 p = px_v3(px_rand_range(-3, 3), px_rand_range(-3, 3),
					  px_rand_range(-3, 3));
			double best = INFINITY, lim = px_rand_range(0, 1.0);
			int j, cnt = 0;
			size_t nf;
			PX_CHECK_INT_EQ(px_scene_set_pose(s, (size_t)(k % n),
							  px_test_rand_pose(3.0)),
					PX_OK);
			for (j = 0; j < n; j++) {
				struct px_model_result r;
				px_model_query(px_scene_model(s, (size_t)j), p, &r);
				best = fmin(best, r.distance);
				cnt += r.distance <= lim;
			}
			PX_CHECK_INT_EQ(px_scene_nearest(s, p, INFINITY, &h), 1);
			PX_CHECK_MSG(h.distance_m == best, "n %d: nearest %.15g vs loop %.15g",
				     n, h.distance_m, best);
			PX_CHECK_INT_EQ(px_scene_within(s, p, lim, hits, NM, &nf), cnt);
		}
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		PX_CHECK_INT_EQ(px_scene_set_pose(s, (size_t)n, px_pose_identity()),
				PX_E_INVAL);
		px_scene_free(s);
	}
	/* kept models: moved on their own, seen after the update */
	{
		struct world w;
		struct px_scene_hit h;
		int c;
		make_world(&w, 0);
		PX_CHECK_INT_EQ(px_scene_update(w.s), PX_OK);
		for (c = 0; c < 20; c++) {
			px_vec3 p = px_v3(px_rand_range(-3, 3), px_rand_range(-3, 3),
					  px_rand_range(-3, 3));
			double best = INFINITY;
			int j;
			move_world(&w);
			for (j = 0; j < w.n; j++) {
				struct px_model_result r;
				px_model_query(w.m[j], p, &r);
				best = fmin(best, r.distance);
			}
			PX_CHECK_INT_EQ(px_scene_nearest(w.s, p, INFINITY, &h), 1);
			PX_CHECK(h.distance_m == best);
		}
		free_world(&w);
	}
}

static const struct px_test tests[] = {PX_T(test_nearest_and_within), PX_T(test_tool),
				       PX_T(test_no_alloc_and_errors),
				       PX_T(test_set_pose_seen_at_once)};
PX_TEST_MAIN(tests)
