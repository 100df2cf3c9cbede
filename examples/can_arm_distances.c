/*
 * can_arm_distances.c - distances from a robot arm's links to the scene,
 * with the joint positions read over CAN: two CiA 402 drives on the
 * simulated bus (px_canopen_sim answers as the drives would), the
 * CANopen master in a 1 kHz px_loop on the virtual clock, and the link
 * capsules' clearances to a ball from px_control_chain_clearances().
 *
 * The base joint turns at 0.5 rad/s for two seconds, swinging the arm
 * towards the ball. Exits 0 when the drives came up, the arm moved, and
 * the last clearances agree with the ones worked out by hand from the
 * positions the drives reported.
 */
#include <math.h>
#include <stdio.h>

#include <proxima/px_canopen.h>
#include <proxima/px_control.h>
#include <proxima/px_loop.h>
#include <proxima/px_prim.h>
#include <proxima/px_scene.h>

static const struct px_canopen_drive_cfg drives[2] = {
	{1, PX_CIA402_CSV, 0, 100000.0, 0}, /* counts per rad */
	{2, PX_CIA402_CSV, 1, 100000.0, 0},
};
static const double len_m[2] = {0.4, 0.3}, rad_m[2] = {0.05, 0.04};
static const px_vec3 ball = {0.1, 0.75, 0.0};
#define BALL_M 0.1

struct arm {
	struct px_canopen *co;
	struct px_canopen_sim *sim;
	struct px_control_chain chain;
	struct px_control_avoid_params params;
	struct px_control_query query;
	double q[2], qdot[2];
	struct px_control_clearance cl[2];
	int enable; /* cleared by the loop in safe state */
};

static int on_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct arm *a = u;
	struct px_canopen_drive_status ds;
	(void)l;
	px_canopen_sim_step(a->sim, c->read_ns); /* the drives' side */
	if (px_canopen_rx(a->co, c->read_ns) < 0)
		return PX_E_IO;
	for (int i = 0; i < 2; i++) {
		px_canopen_drive_status(a->co, (size_t)i, &ds);
		a->q[i] = ds.position;
	}
	return PX_OK;
}

static int on_compute(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct arm *a = u;
	(void)l;
	a->qdot[0] = c->read_ns < 2000000000 ? 0.5 : 0.0;
	a->qdot[1] = 0.0;
	a->enable = 1;
	return px_control_chain_clearances(&a->chain, &a->params, &a->query,
					   a->q, 1.0, a->cl, NULL);
}

static int on_write(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct arm *a = u;
	(void)l;
	return px_canopen_tx(a->co, c->write_ns, a->qdot, 2, a->enable);
}

/* Ball to segment p..q, minus both radii. */
static double by_hand(px_vec3 p, px_vec3 q, double r)
{
	px_vec3 d = px_v3_sub(q, p), w = px_v3_sub(ball, p);
	double t = fmin(1.0, fmax(0.0, px_v3_dot(w, d) / px_v3_dot(d, d)));
	return px_v3_norm(px_v3_sub(w, px_v3_scale(d, t))) - r - BALL_M;
}

int main(void)
{
	static struct arm a;
	struct px_can_sim_config bc;
	struct px_can_sim *bus;
	struct px_can_bus *ep_master, *ep_arm;
	struct px_canopen_config cc;
	struct px_canopen_sim_config sc = {0};
	struct px_loop_config lc;
	struct px_loop *loop;
	struct px_scene *scene;
	struct px_model *m;
	struct px_prim sphere = {PX_PRIM_SPHERE, BALL_M, 0, 0};
	char msg[200] = "";

	px_control_chain_init(&a.chain, px_pose_identity());
	for (int i = 0; i < 2; i++) { /* planar: DH a = length, joints about z */
		px_control_chain_add_dh(&a.chain, PX_CONTROL_REVOLUTE, len_m[i], 0, 0, 0);
		px_control_chain_add_capsule(&a.chain, i + 1, px_v3(-len_m[i], 0, 0),
					     px_v3(0, 0, 0), rad_m[i]);
	}
	px_control_avoid_params_default(&a.params);
	px_can_sim_config_default(&bc);
	px_canopen_config_default(&cc);
	cc.drives = sc.drives = drives;
	cc.n_drives = sc.n_drives = 2;
	px_loop_config_default(&lc);
	lc.clock = PX_LOOP_CLOCK_VIRTUAL;
	lc.read = on_read, lc.compute = on_compute, lc.write = on_write;
	lc.user = &a;
	if (px_scene_create(1, &scene) || px_prim_model(&sphere, &m) ||
	    px_model_set_pose(m, (px_pose){px_quat_identity(), ball}) ||
	    px_scene_add(scene, m, "ball") < 0 ||
	    px_scene_control_query(scene, &a.query) ||
	    px_can_sim_create(&bc, &bus) || px_can_sim_endpoint(bus, &ep_master) ||
	    px_can_sim_endpoint(bus, &ep_arm) ||
	    px_canopen_create(&cc, ep_master, &a.co, msg, sizeof msg) ||
	    px_canopen_sim_create(&sc, ep_arm, &a.sim) ||
	    px_loop_create(&lc, &loop) || px_loop_enable_add(loop, "drives", &a.enable) < 0) {
		fprintf(stderr, "can_arm_distances: setup failed %s\n", msg);
		return 1;
	}
	int rc = px_loop_run(loop, 2500), ok = rc >= 0 && px_canopen_all_enabled(a.co);
	px_pose f[3];
	px_control_chain_fk(&a.chain, a.q, f, 3);
	for (int i = 0; i < 2; i++) {
		double want = by_hand(f[i].t, f[i + 1].t, rad_m[i]);
		printf("link %d: clearance %.4f m (by hand %.4f m)\n", i + 1,
		       a.cl[i].clearance_m, want);
		ok = ok && a.cl[i].valid && fabs(a.cl[i].clearance_m - want) < 1e-3;
	}
	printf("joints %.3f %.3f rad after %.1f s\n", a.q[0], a.q[1],
	       (double)px_loop_now_ns(loop) * 1e-9);
	ok = ok && fabs(a.q[0] - 1.0) < 0.01 && fabs(a.q[1]) < 1e-6;
	px_loop_free(loop);
	px_canopen_free(a.co);
	px_canopen_sim_free(a.sim);
	px_can_sim_free(bus);
	px_scene_free(scene);
	return ok ? 0 : 1;
}
