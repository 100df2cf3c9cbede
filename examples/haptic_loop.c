/*
 * haptic_loop.c - a 1 kHz haptic loop of one's own: px_loop runs the
 * cycle, a simulated haptic device (px_sim.h) gives the pose and takes
 * the force, a scene (px_scene.h) holds a sphere to touch.
 *
 * The simulated hand moves up and down through the top of a 5 cm
 * sphere; a spring pushes the device's probe back out along the
 * surface normal. On the virtual clock the run takes a moment and is
 * deterministic. Exits 0 when the probe touched the sphere, the wall
 * held it to well under the hand's own depth and the loop never went to
 * safe state.
 */
#include <math.h>
#include <stdio.h>

#include <proxima/px_loop.h>
#include <proxima/px_prim.h>
#include <proxima/px_sim.h>
#include <proxima/px_scene.h>

#define RADIUS_M 0.05
#define HAND_DEPTH_M 0.005 /* how far the hand reaches into the sphere */
/* Against the hand's 400 N/m the probe rests at 2/7 of the hand's depth,
 * 1.4 N: within the simulated device's 3 N. */
#define STIFFNESS_N_PER_M 1000.0

struct app {
	struct px_dev *dev;
	struct px_scene *scene;
	struct px_pose_sample pose;
	struct px_force_cmd cmd; /* zeroed by the loop in safe state */
	double max_depth_m;
};

static int on_read(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	(void)l;
	return px_dev_pose_read(a->dev, c->read_ns, &a->pose) < 0 ? -1 : PX_OK;
}

static int on_compute(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	struct px_scene_hit hit;
	(void)l;
	int rc = px_scene_nearest(a->scene, a->pose.pos_m, INFINITY, &hit);
	if (rc < 0)
		return rc;
	double depth = rc == 1 && hit.distance_m < 0 ? -hit.distance_m : 0.0;
	a->cmd.force_n[0] = STIFFNESS_N_PER_M * depth * hit.r.direction.x;
	a->cmd.force_n[1] = STIFFNESS_N_PER_M * depth * hit.r.direction.y;
	a->cmd.force_n[2] = STIFFNESS_N_PER_M * depth * hit.r.direction.z;
	a->cmd.enable = 1;
	/* The probe starts at the origin, inside the ball: count from when
	 * the wall has pushed it out (half a second). */
	if (c->index >= 500)
		a->max_depth_m = fmax(a->max_depth_m, depth);
	return PX_OK;
}

static int on_write(struct px_loop *l, const struct px_loop_cycle *c, void *u)
{
	struct app *a = u;
	(void)l;
	return px_dev_force_write(a->dev, &a->cmd, c->write_ns);
}

int main(void)
{
	static struct app a;
	struct px_prim ball = {PX_PRIM_SPHERE, RADIUS_M, 0, 0};
	struct px_sim_sine up_down = {PX_AXIS_Z, 0.02, 0.5, 0.0};
	struct px_sim_haptic_config sim;
	struct px_dev_config dcfg;
	struct px_loop_config lcfg;
	struct px_loop_status st;
	struct px_model *m;
	struct px_loop *loop;

	px_sim_haptic_config_default(&sim);
	sim.traj.kind = PX_SIM_TRAJ_SINES;
	sim.traj.center_m[2] = RADIUS_M + 0.02 - HAND_DEPTH_M;
	sim.traj.sines = &up_down;
	sim.traj.n_sines = 1;
	px_dev_config_default(&dcfg);
	dcfg.name = "sim";
	px_loop_config_default(&lcfg);
	lcfg.clock = PX_LOOP_CLOCK_VIRTUAL;
	lcfg.read = on_read, lcfg.compute = on_compute, lcfg.write = on_write;
	lcfg.user = &a;
	if (px_scene_create(1, &a.scene) || px_prim_model(&ball, &m) ||
	    px_scene_add(a.scene, m, "ball") < 0 ||
	    px_sim_haptic_create(&dcfg, &sim, &a.dev, NULL, 0) ||
	    px_dev_start(a.dev) || px_loop_create(&lcfg, &loop) ||
	    px_dev_attach(a.dev, loop) < 0 ||
	    px_dev_force_attach(a.dev, loop, &a.cmd)) {
		fprintf(stderr, "haptic_loop: setup failed\n");
		return 1;
	}
	int rc = px_loop_run(loop, 3000); /* 3 s of virtual time */
	px_loop_status(loop, &st);
	printf("%llu cycles, deepest %.2f mm (hand %.2f mm), %s\n",
	       (unsigned long long)st.cycles, a.max_depth_m * 1e3,
	       HAND_DEPTH_M * 1e3, st.safe_entries ? "went safe" : "never safe");
	px_loop_free(loop);
	px_dev_stop(a.dev);
	px_dev_free(a.dev);
	px_scene_free(a.scene);
	return rc >= 0 && st.cycles == 3000 && !st.safe_entries &&
			       a.max_depth_m > 0.0 &&
			       a.max_depth_m < 0.5 * HAND_DEPTH_M ? 0 : 1;
}
