/* PX_TEST_NEEDS: libxml2 assimp (tests/run.sh skips it in builds without them) */
/*
 * Avoidance on a URDF robot's own link models (robot/px_urdf.h): the
 * shipped example arm (config/examples/robots/arm6, written by
 * proxima-armgen) with STL links; clearances against brute-force
 * references (every link triangle against every cloud point; a ball's
 * centre against the link surface) on random configurations, touching
 * and penetrating ones included; coherent answers equal to cold ones
 * along random joint paths; self pairs and the allowed-collision list;
 * the command from the contacts against px_control_avoid_command's
 * formula; scripted approaches of an obstacle that moves into the arm's
 * path and leaves again; no allocation over thousands of cycles.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_features.h"
#include "px_mesh.h"
#include "px_prim.h"
#include "px_test.h"
#include "px_urdf.h"

#define ARM "config/examples/robots/arm6/arm6.urdf"
#define BODIES 7

static struct px_urdf_robot *arm(void)
{
	const char *pk[1] = {"config/examples/robots"};
	struct px_urdf_opts o;
	struct px_urdf_error e;
	struct px_urdf *u = NULL;
	struct px_urdf_robot *r = NULL;
	memset(&o, 0, sizeof(o));
	o.package_paths = pk;
	o.n_package_paths = 1;
	PX_CHECK_MSG(px_urdf_load(ARM, &o, &u, &e) == PX_OK, "%s", e.msg);
	PX_CHECK_MSG(px_urdf_robot_create(u, "base_link", "tool0", px_pose_identity(), &r, &e) ==
			     PX_OK,
		     "%s", e.msg);
	px_urdf_free(u);
	return r;
}

static void random_q(double *q)
{
	int j;
	q[0] = px_rand_range(-3.1, 3.1);
	q[1] = px_rand_range(-1.5, 1.5);
	for (j = 2; j < 6; j++)
		q[j] = px_rand_range(-2.5, 2.5);
}

/* Brute force: the smallest distance from any cloud point to any
 * triangle of body b (world frame). */
static double brute_cloud(const struct px_urdf_robot *r, int b, const double *pts, int n)
{
	const struct px_urdf_body *bd = px_urdf_robot_body(r, b);
	px_pose pose = px_model_pose(bd->model);
	size_t t, nt = px_mesh_triangle_count(bd->model);
	double best = INFINITY;
	int i;
	for (t = 0; t < nt; t++) {
		px_vec3 v[3], w[3];
		int k;
		PX_CHECK_INT_EQ(px_mesh_triangle(bd->model, t, v), PX_OK);
		for (k = 0; k < 3; k++)
			w[k] = px_pose_transform_point(pose, v[k]);
		for (i = 0; i < n; i++) {
			px_vec3 p = px_v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
			double d2 = px_tri_closest(p, w[0], w[1], w[2], NULL, NULL, NULL, NULL, NULL);
			if (d2 < best)
				best = d2;
		}
	}
	return sqrt(best);
}

/* The smallest signed distance of the cloud points to a closed link
 * mesh (negative: a point inside). */
static double signed_min(const struct px_model *m, const double *pts, int n)
{
	double best = INFINITY;
	int i;
	for (i = 0; i < n; i++) {
		struct px_model_result res;
		PX_CHECK_INT_EQ(px_model_query(m, px_v3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]),
					       &res),
				1);
		if (res.distance < best)
			best = res.distance;
	}
	return best;
}

/* The shipped arm: 6 joints, one STL body per link, closed outward
 * (points inside are at negative distance), straight along x at q = 0. */
static void test_arm_loads(void)
{
	struct px_urdf_robot *r;
	int b;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_urdf_robot_dof(r), 6);
	PX_CHECK_INT_EQ(px_urdf_robot_body_count(r), BODIES);
	for (b = 0; b < BODIES; b++) {
		const struct px_urdf_body *bd = px_urdf_robot_body(r, b);
		struct px_model_result res;
		px_aabb box = px_model_world_aabb(bd->model);
		PX_CHECK_INT_EQ(bd->frame, b);
		PX_CHECK_INT_EQ(px_model_query(bd->model, px_aabb_center(&box), &res), 1);
		PX_CHECK_MSG(res.distance < 0, "body %d (%s): centre at %g, not inside", b,
			     px_urdf_robot_body_link(r, b), res.distance);
	}
	px_urdf_robot_free(r);
}

/* Self pairs: bodies on frames two or more apart (15 of the 21 pairs of
 * 7 bodies on 7 frames); the allowed list takes pairs out; an unknown
 * link is named. */
static void test_self_pairs(void)
{
	struct px_urdf_robot *r;
	struct px_urdf_error e;
	const char *al[4] = {"base_link", "upper_arm_link", "wrist3_link", "wrist1_link"};
	const char *bad[2] = {"base_link", "elbow_link"};
	struct px_urdf_clearance cl[32], mn;
	double q[6] = {0, 0, 0, 0, 0, 0};
	int n, i;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, &e), 15);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, al, 2, &e), 13);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, bad, 1, &e), PX_E_NOTFOUND);
	PX_CHECK(strstr(e.msg, "elbow_link") != NULL);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, &e), 15);
	PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
	n = px_urdf_robot_self_clearances(r, NULL, 0, cl, 32, &mn);
	PX_CHECK_INT_EQ(n, 15);
	for (i = 0; i < n; i++) {
		PX_CHECK(abs(px_urdf_robot_body(r, cl[i].body)->frame -
			     px_urdf_robot_body(r, cl[i].other_body)->frame) >= 2);
		PX_CHECK_INT_EQ(cl[i].obstacle, -1);
		PX_CHECK(cl[i].distance_m > 0.05); /* stretched out: apart */
	}
	/* folded back at the elbow: the forearm meets the upper arm's
	 * neighbours (wrist links against the shoulder or base) */
	q[2] = 2.8;
	q[3] = 2.5;
	PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
	n = px_urdf_robot_self_clearances(r, NULL, 0, cl, 32, &mn);
	PX_CHECK_INT_EQ(n, 15);
	PX_CHECK(mn.distance_m < 0.1);
	PX_CHECK_INT_EQ(px_urdf_robot_self_clearances(r, NULL, 0, cl, 3, NULL), PX_E_NOSPC);
	px_urdf_robot_free(r);
}

/* Every body against a cloud (brute force: every triangle against every
 * point) and a ball (its centre's signed distance to the link surface
 * minus the radius: negative when they overlap), on random
 * configurations with the obstacles placed near, on and inside links. */
static void test_clearances_reference(void)
{
	struct px_urdf_robot *r;
	struct px_model *obs[2], *cloud = NULL, *ball;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.04, 0, 0};
	struct px_urdf_clearance cl[2 * BODIES];
	double pts[3 * 60], q[6];
	int it, k, n, touching = 0, penetrating = 0, inside = 0;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_prim_model(&sp, &ball), PX_OK);
	for (it = 0; it < 60; it++) {
		px_pose bp = px_pose_identity();
		const struct px_urdf_body *tb;
		px_aabb box;
		px_vec3 c;
		int i;
		random_q(q);
		PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
		/* a cloud around a random body's box, some points inside */
		tb = px_urdf_robot_body(r, px_rand_int(0, BODIES - 1));
		box = px_model_world_aabb(tb->model);
		c = px_aabb_center(&box);
		for (i = 0; i < 60; i++) {
			double s = it % 3 == 0 ? 0.02 : 0.15;
			pts[3 * i] = c.x + px_rand_range(-s, s) + (it % 3 == 2 ? 0.12 : 0);
			pts[3 * i + 1] = c.y + px_rand_range(-s, s);
			pts[3 * i + 2] = c.z + px_rand_range(-s, s);
		}
		px_model_free(cloud);
		cloud = NULL;
		PX_CHECK_INT_EQ(px_cloud_model(pts, 60, 0.0, NULL, &cloud), PX_OK);
		/* the ball at a body's surface point pushed in or out */
		bp.t = px_v3_add(c, px_v3(px_rand_range(-0.08, 0.08), px_rand_range(-0.08, 0.08),
					  px_rand_range(-0.08, 0.08)));
		PX_CHECK_INT_EQ(px_model_set_pose(ball, bp), PX_OK);
		obs[0] = cloud;
		obs[1] = ball;
		PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 2), PX_OK);
		n = px_urdf_robot_clearances(r, NULL, 0, cl, 2 * BODIES, NULL);
		PX_CHECK_INT_EQ(n, 2 * BODIES);
		for (k = 0; k < n; k++) {
			const struct px_urdf_body *bd = px_urdf_robot_body(r, cl[k].body);
			if (cl[k].obstacle == 0) {
				/* all points outside the link: the exact distance,
				 * certified; a point inside: either an overlap with
				 * a depth no more than the deepest point's, or (the
				 * mesh/cloud path measuring surfaces only) the
				 * distance to the surface */
				double ref = brute_cloud(r, cl[k].body, pts, 60);
				double deep = signed_min(bd->model, pts, 60);
				if (deep > 1e-9) {
					PX_CHECK(!cl[k].local_only);
					PX_CHECK_MSG(fabs(cl[k].distance_m - ref) <= 1e-9,
						     "body %d cloud: %.12g vs brute force %.12g",
						     cl[k].body, cl[k].distance_m, ref);
				} else if (cl[k].intersecting) {
					PX_CHECK(cl[k].distance_m <= 0);
					PX_CHECK_MSG(-cl[k].distance_m <= -deep + 1e-9,
						     "body %d cloud: depth %.12g, deepest point %.12g",
						     cl[k].body, -cl[k].distance_m, -deep);
					/* the deepest point's depth itself, certified */
					PX_CHECK_MSG(fabs(cl[k].distance_m - deep) <= 1e-9,
						     "body %d cloud: %.12g, deepest point %.12g",
						     cl[k].body, cl[k].distance_m, deep);
					PX_CHECK(!cl[k].local_only);
					inside++;
				} else {
					PX_CHECK_MSG(fabs(cl[k].distance_m - ref) <= 1e-9,
						     "body %d cloud (a point inside): %.12g vs %.12g",
						     cl[k].body, cl[k].distance_m, ref);
					/* only a point on the surface: touching */
					PX_CHECK_MSG(deep > -1e-9, "body %d cloud: a point %.12g deep missed",
						     cl[k].body, deep);
					inside++;
				}
				touching += ref < 0.01;
			} else {
				struct px_model_result res;
				double ref;
				PX_CHECK_INT_EQ(px_model_query(bd->model, bp.t, &res), 1);
				ref = res.distance - sp.a;
				PX_CHECK_MSG(fabs(cl[k].distance_m - ref) <= 1e-7,
					     "body %d ball: %.12g vs %.12g", cl[k].body,
					     cl[k].distance_m, ref);
				if (ref < 0) {
					penetrating++;
					PX_CHECK(cl[k].intersecting);
				}
			}
		}
	}
	PX_CHECK_MSG(touching >= 10, "only %d touching cloud pairs", touching);
	PX_CHECK_MSG(penetrating >= 10, "only %d penetrating ball pairs", penetrating);
	PX_CHECK_MSG(inside >= 5, "only %d clouds reaching inside a link", inside);
	px_model_free(cloud);
	px_model_free(ball);
	px_urdf_robot_free(r);
}

/* Coherent calls (each pair from its last answer) equal cold calls
 * along random smooth joint paths, obstacle and self pairs alike. */
static void test_coherent_equals_cold(void)
{
	struct px_urdf_robot *r;
	struct px_model *obs[1], *cloud;
	struct px_urdf_clearance a[BODIES + 16], b[BODIES + 16];
	double pts[3 * 200], q[6], v[6];
	int path, step, k, n, j, compared = 0, skipped = 0, cloud_inside = 0;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	for (k = 0; k < 200; k++) {
		pts[3 * k] = px_rand_range(0.2, 0.9);
		pts[3 * k + 1] = px_rand_range(-0.6, 0.6);
		pts[3 * k + 2] = px_rand_range(0.0, 0.8);
	}
	PX_CHECK_INT_EQ(px_cloud_model(pts, 200, 0.0, NULL, &cloud), PX_OK);
	obs[0] = cloud;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 1), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, NULL), 15);
	for (path = 0; path < 4; path++) {
		random_q(q);
		for (j = 0; j < 6; j++)
			v[j] = px_rand_range(-0.02, 0.02);
		for (step = 0; step < 60; step++) {
			int nb, ns;
			for (j = 0; j < 6; j++)
				q[j] += v[j];
			PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
			nb = px_urdf_robot_clearances(r, NULL, 1, a, BODIES, NULL);
			ns = px_urdf_robot_self_clearances(r, NULL, 1, a + nb, 16, NULL);
			PX_CHECK_INT_EQ(nb, BODIES);
			PX_CHECK_INT_EQ(ns, 15);
			n = px_urdf_robot_clearances(r, NULL, 0, b, BODIES, NULL);
			n += px_urdf_robot_self_clearances(r, NULL, 0, b + n, 16, NULL);
			for (k = 0; k < n; k++) {
				if (k < nb) {
					/* link against cloud: exact and signed, also
					 * with a point inside (px_pair.h) */
					PX_CHECK(!a[k].local_only && !b[k].local_only);
					PX_CHECK_MSG(a[k].distance_m == b[k].distance_m,
						     "path %d step %d cloud pair %d: coherent %.17g cold "
						     "%.17g", path, step, k, a[k].distance_m,
						     b[k].distance_m);
					cloud_inside += a[k].distance_m < 0.0;
				}
				/* self pairs overlapping: the depth search is
				 * local (px_pair.h); apart pairs must agree */
				if (a[k].local_only || b[k].local_only || a[k].intersecting ||
				    b[k].intersecting) {
					skipped++;
					continue;
				}
				compared++;
				PX_CHECK_MSG(fabs(a[k].distance_m - b[k].distance_m) <= 1e-9,
					     "path %d step %d pair %d: coherent %.12g cold %.12g", path,
					     step, k, a[k].distance_m, b[k].distance_m);
			}
		}
	}
	PX_CHECK_MSG(compared > 20 * skipped, "%d pairs compared, %d skipped", compared, skipped);
	printf("    %d cloud pairs with a point inside a link, coherent = cold\n", cloud_inside);
	px_model_free(cloud);
	px_urdf_robot_free(r);
}

/* The step's command is px_control_avoid_command on the clearances
 * within the influence distance (each pair's witness and separating
 * direction), and zero work allocates. */
static void test_step_is_the_command(void)
{
	struct px_urdf_robot *r;
	struct px_model *obs[1], *ball;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.05, 0, 0};
	struct px_control_avoid_params p;
	struct px_urdf_avoid_out out;
	struct px_control_avoid_out ref;
	struct px_urdf_clearance cl[BODIES + 15];
	struct px_control_contact ks[BODIES + 15];
	px_pose bp = px_pose_identity();
	double q[6] = {0.2, 0.3, -0.4, 0.1, 0.2, 0}, qn[6] = {0.5, -0.2, 0.1, 0, 0.3, 0};
	int n, k, nk = 0, closest, j;
	uint64_t a;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_prim_model(&sp, &ball), PX_OK);
	bp.t = px_v3(0.55, 0.25, 0.2);
	PX_CHECK_INT_EQ(px_model_set_pose(ball, bp), PX_OK);
	obs[0] = ball;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 1), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, NULL), 15);
	px_control_avoid_params_default(&p);
	p.influence_distance_m = 0.4;
	a = px_alloc_region_begin();
	PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 0, q, qn, 1000000, &out), PX_OK);
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	PX_CHECK(out.pairs > 0 && out.pairs < BODIES + 15); /* far pairs skipped */
	n = px_urdf_robot_clearances(r, NULL, 0, cl, BODIES, NULL);
	n += px_urdf_robot_self_clearances(r, NULL, 0, cl + n, 15, NULL);
	for (k = 0; k < n; k++) {
		const struct px_urdf_body *bd = px_urdf_robot_body(r, cl[k].body);
		int self = cl[k].other_body >= 0;
		if (cl[k].distance_m >= (self ? p.self_influence_distance_m : p.influence_distance_m))
			continue;
		ks[nk].influence_distance_m = self ? p.self_influence_distance_m : 0;
		ks[nk].protective_distance_m = self ? p.self_protective_distance_m : 0;
		ks[nk].link = bd->frame;
		ks[nk].other_link =
			cl[k].other_body >= 0 ? px_urdf_robot_body(r, cl[k].other_body)->frame : -1;
		ks[nk].clearance_m = cl[k].distance_m;
		ks[nk].point_m = cl[k].point_robot;
		ks[nk].other_m = cl[k].point_obstacle;
		ks[nk].normal = cl[k].normal;
		nk++;
	}
	PX_CHECK(nk >= 1);
	PX_CHECK_INT_EQ(px_control_avoid_command(px_urdf_robot_chain(r), &p, q, qn, 1000000, ks, nk,
						 &ref, &closest),
			PX_OK);
	for (j = 0; j < 6; j++)
		PX_CHECK_NEAR(out.cmd.qdot[j], ref.qdot[j], 1e-9);
	PX_CHECK_NEAR(out.cmd.scale, ref.scale, 1e-12);
	PX_CHECK_NEAR(out.cmd.min_clearance_m, ref.min_clearance_m, 1e-12);
	PX_CHECK(out.closest.body >= 0);
	PX_CHECK_NEAR(out.closest.distance_m, out.cmd.min_clearance_m, 1e-12);
	PX_CHECK(out.cmd.scale < 1);
	/* bad input: zero command, the error */
	PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 0, NULL, qn, 1000000, &out), PX_E_INVAL);
	for (j = 0; j < 6; j++)
		PX_CHECK(out.cmd.qdot[j] == 0);
	px_model_free(ball);
	px_urdf_robot_free(r);
}

/* approach_only: a nominal motion away from the obstacle keeps full
 * speed, the same motion toward it is slowed. */
static void test_approach_only(void)
{
	struct px_urdf_robot *r;
	struct px_model *obs[1], *ball;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.05, 0, 0};
	struct px_control_avoid_params p;
	struct px_urdf_avoid_out out;
	px_pose bp = px_pose_identity();
	double q[6] = {0, 0, 0, 0, 0, 0}, toward[6] = {0.3, 0, 0, 0, 0, 0},
	       away[6] = {-0.3, 0, 0, 0, 0, 0};
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_prim_model(&sp, &ball), PX_OK);
	/* beside the forearm, on the side shoulder_pan > 0 turns it to */
	bp.t = px_v3(0.6, 0.2, 0.38);
	PX_CHECK_INT_EQ(px_model_set_pose(ball, bp), PX_OK);
	obs[0] = ball;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 1), PX_OK);
	px_control_avoid_params_default(&p);
	p.approach_only = true;
	p.repulsive_speed_m_per_s = 0;
	PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 0, q, toward, 1000000, &out), PX_OK);
	PX_CHECK_MSG(out.cmd.scale < 0.9, "toward: scale %g", out.cmd.scale);
	PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 0, q, away, 1000000, &out), PX_OK);
	PX_CHECK_NEAR(out.cmd.scale, 1.0, 1e-12);
	PX_CHECK_NEAR(out.cmd.qdot[0], -0.3, 1e-12);
	p.approach_only = false;
	PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 0, q, away, 1000000, &out), PX_OK);
	PX_CHECK(out.cmd.scale < 0.9);
	px_model_free(ball);
	px_urdf_robot_free(r);
}

/*
 * Scripted approaches: the task swings the arm (shoulder_pan at a
 * constant speed, back and forth) while a box obstacle moves into its
 * path, stays, and leaves. The command is integrated each 1 ms cycle.
 * The arm never comes closer than the protective distance minus 5 mm
 * (the first-order guard closes at most half the margin per cycle; the
 * rest is the obstacle's own motion, at most 0.3 m/s x 1 ms, plus
 * curvature), and once the obstacle is gone it moves at full speed.
 * No allocation over all cycles.
 */
static void test_scripted_approaches(void)
{
	struct px_urdf_robot *r;
	struct px_model *obs[1], *box;
	struct px_prim bx = {PX_PRIM_BOX, 0.08, 0.08, 0.3};
	struct px_control_avoid_params p;
	struct px_urdf_avoid_out out;
	double worst = INFINITY;
	int run, approached = 0;
	uint64_t a, allocs = 0;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	r = arm();
	PX_CHECK_INT_EQ(px_prim_model(&bx, &box), PX_OK);
	obs[0] = box;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 1), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_set_self(r, NULL, 0, NULL), 15);
	px_control_avoid_params_default(&p);
	p.influence_distance_m = 0.25;
	p.protective_distance_m = 0.05;
	p.approach_only = true;
	for (run = 0; run < 6; run++) {
		double q[6] = {0, px_rand_range(-0.3, 0.3), px_rand_range(-0.6, 0.6), 0, 0, 0};
		double ang = px_rand_range(0.4, 1.2), rad = px_rand_range(0.45, 0.9);
		double full_after = 0;
		int cyc, slowed = 0;
		for (cyc = 0; cyc < 4000; cyc++) {
			double t = cyc * 1e-3, qn[6] = {0};
			px_pose bp = px_pose_identity();
			/* obstacle: comes in from outside during 0.5 s, stays
			 * until 2 s, then goes up and away within 0.5 s */
			double in = t < 0.5 ? t / 0.5 : 1.0, out_ = t < 2.0 ? 0 : fmin(1, (t - 2) / 0.5);
			bp.t = px_v3(rad * cos(ang) * (2 - in), rad * sin(ang) * (2 - in),
				     0.3 + 1.5 * out_);
			PX_CHECK_INT_EQ(px_model_set_pose(box, bp), PX_OK);
			qn[0] = 0.6; /* toward the obstacle's angle */
			if (q[0] > 2.5)
				qn[0] = 0;
			a = px_alloc_region_begin();
			PX_CHECK_INT_EQ(px_urdf_avoid_step(r, &p, NULL, 1, q, qn, 1000000, &out), PX_OK);
			allocs += px_alloc_region_end(a);
			if (t > 0.5 && out.cmd.min_clearance_m < worst)
				worst = out.cmd.min_clearance_m;
			if (out.cmd.scale < 0.5)
				slowed = 1;
			if (t > 2.6 && qn[0] > 0 && out.cmd.scale == 1.0 && full_after == 0)
				full_after = t;
			for (int j = 0; j < 6; j++)
				q[j] += out.cmd.qdot[j] * 1e-3;
		}
		approached += slowed;
		if (slowed && q[0] < 2.5)
			PX_CHECK_MSG(full_after > 0, "run %d: not back to full speed (scale %g)", run,
				     out.cmd.scale);
	}
	PX_CHECK_MSG(approached >= 3, "only %d runs approached the obstacle", approached);
	PX_CHECK_MSG(worst >= p.protective_distance_m - 0.005,
		     "came within %g m (protective %g)", worst, p.protective_distance_m);
	PX_CHECK_INT_EQ(allocs, 0);
	px_model_free(box);
	px_urdf_robot_free(r);
}

static const struct px_test tests[] = {
	PX_T(test_arm_loads),
	PX_T(test_self_pairs),
	PX_T(test_clearances_reference),
	PX_T(test_coherent_equals_cold),
	PX_T(test_step_is_the_command),
	PX_T(test_approach_only),
	PX_T(test_scripted_approaches),
};
PX_TEST_MAIN(tests)
