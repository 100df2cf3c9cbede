/* The app's cycle (read, compute, write: real-time rules, no allocation,
 * no I/O but device calls), the safe shutdown, the drain and the run. */
#include "app_internal.h"

int64_t app_mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}


/* ---- loop phases (real-time rules: no allocation, no I/O) --------- */

int app_phase_read(struct px_loop *l, const struct px_loop_cycle *c,
		      void *user)
{
	struct px_app *a = user;
	int i;
	if (!a->counting) {
		/* Everything this thread does from here on counts. */
		a->counting = 1;
		a->heap_base = app_heap_count(a);
		a->t0_ns = c->read_ns;
	}
	if (a->co) {
		int64_t newest = 0;
		int have = a->n_drives > 0;
		/* on the in-process bus, the robot's side first, as another
		 * process would have answered the last SYNC by now */
		if (a->arm)
			px_canopen_sim_step(a->arm, c->read_ns);
		px_canopen_rx(a->co, c->read_ns);
		for (i = 0; i < a->n_drives; i++) {
			struct px_canopen_drive_status ds;
			px_canopen_drive_status(a->co, (size_t)i, &ds);
			if (ds.feedback_ns == 0) {
				have = 0;
				continue;
			}
			a->q[a->drive_joint[i]] = ds.position;
			if (ds.feedback_ns > newest)
				newest = ds.feedback_ns;
		}
		a->have_q = have;
		if (have && newest > a->last_feedback_ns) {
			a->last_feedback_ns = newest;
			px_loop_input_stamp(l, a->arm_input, newest);
		}
		a->enabled = px_canopen_all_enabled(a->co);
		if (a->enabled)
			a->enabled_cycles++;
		/* a drive lost (heartbeat timeout) or in fault: safe state,
		 * held while the problem lasts */
		if (px_canopen_first_problem(a->co) >= 0) {
			a->drive_problem_cycles++;
			px_loop_trip(l);
		}
	}
	app_sensor_read(a, l, c->read_ns);
	for (i = 0; i < a->n_dev; i++) {
		int rc;
		if (!(px_dev_caps(a->dev[i]) & PX_DEV_CAP_POSE))
			continue;
		rc = px_dev_pose_read(a->dev[i], c->read_ns, &a->sample[i]);
		(void)rc; /* staleness reaches the watchdog through the stamp */
	}
	if (a->tele.n_dds)
		app_teleop_read_phase(a, l, c->read_ns);
	{
		/* e-stop lines: a pressed (or unreadable) one trips the loop
		 * inside px_dev_estop_read (px_dev_attach), every cycle it is
		 * held, so safe state cannot be left while it is */
		int any = 0;
		for (i = 0; i < a->n_dio; i++) {
			int p = 0;
			int rc = px_dev_estop_read(a->dio[i], c->read_ns, &p);
			if (rc != PX_E_UNSUPPORTED && p)
				any = 1;
		}
		if (any && !a->estop_pressed) {
			a->estop_presses++;
			if (a->estop_first_ns < 0) {
				a->estop_first_ns = c->read_ns;
				a->estop_first_cycle = c->index;
				a->safe_at_estop = c->safe;
			}
		}
		if (any)
			a->estop_cycles++;
		a->estop_pressed = any;
	}
	if (a->ctl_dev >= 0) {
		const struct px_pose_sample *s = &a->sample[a->ctl_dev];
		double v = px_v3_norm(s->vel_m_s);
		double lim = a->cfg->safety.velocity_limit_m_per_s;
		if (s->valid && v > lim) {
			if (!a->over_velocity) {
				a->velocity_trips++;
				px_loop_trip(l);
			}
			a->over_velocity = 1;
		} else {
			a->over_velocity = 0;
		}
	}
	return PX_OK;
}

/* Avoidance: nominal joint velocity from the demo task, scaled and
 * deflected by the clearances (px_control_avoid_step), into drive
 * targets (CSP: integrated positions; CSV: velocities). */
static void avoid_compute(struct px_app *a, const struct px_loop_cycle *c)
{
	double qnom[PX_CONTROL_MAX_JOINTS] = {0};
	double t = (double)(c->deadline_ns - a->t0_ns) * 1e-9;
	double dt = (double)c->period_ns * 1e-9;
	size_t k;
	int i, rc;
	if (!a->have_q || !a->enabled) {
		for (i = 0; i < PX_CONTROL_MAX_JOINTS; i++)
			a->targets[i] = a->csp ? a->q[i] : 0.0;
		return;
	}
	if (!a->started) {
		memcpy(a->qcmd, a->q, sizeof(a->qcmd));
		a->started = 1;
	}
	/* the task: a remote pose to follow, else the demo's sinusoids */
	for (k = app_teleop_follow(a, qnom) ? a->sim.n_nominal : 0;
	     k < a->sim.n_nominal; k++) {
		const struct raw_nominal *nm = &a->sim.nominal[k];
		if (nm->joint < a->ctl.chain.n_joints)
			qnom[nm->joint] += nm->amplitude_rad_per_s *
					   cos(2 * M_PI * nm->frequency_hz * t +
					       nm->phase_rad);
	}
	if (a->robot)
		rc = app_robot_step(a, qnom, c->period_ns);
	else
		rc = px_control_avoid_step(&a->ctl.chain, &a->ctl.avoid, &a->query,
					   a->q, qnom, c->period_ns, &a->aout);
	if (rc < 0) {
		a->query_errors++;
		a->last_query_err = rc;
	}
	for (i = 0; i < a->ctl.chain.n_joints; i++) {
		double v = rc < 0 ? 0.0 : a->aout.qdot[i];
		a->qcmd[i] += v * dt;
		a->targets[i] = a->csp ? a->qcmd[i] : v;
	}
}

int app_phase_compute(struct px_loop *l, const struct px_loop_cycle *c,
			 void *user)
{
	struct px_app *a = user;
	int64_t t = app_mono_ns();
	int i;
	a->have_out = 0;
	if (a->avoiding)
		avoid_compute(a, c);
	if (a->ctl_dev >= 0 && a->sample[a->ctl_dev].valid) {
		const struct px_pose_sample *s = &a->sample[a->ctl_dev];
		if (a->rendering) {
			int rc = px_control_haptic_step(&a->haptic, &a->query,
							s->pos_m, &s->vel_m_s,
							&a->out);
			if (rc < 0) {
				a->query_errors++;
				a->last_query_err = rc;
			}
			a->cmd.force_n[0] = a->out.force_n.x;
			a->cmd.force_n[1] = a->out.force_n.y;
			a->cmd.force_n[2] = a->out.force_n.z;
			a->cmd.enable = 1;
		} else {
			struct px_control_hit h;
			memset(&a->out, 0, sizeof(a->out));
			a->out.proxy_m = s->pos_m;
			if (a->query.point(a->query.ctx, s->pos_m, 1e3, &h) == PX_OK &&
			    h.valid)
				a->out.distance_m = h.distance_m;
			else
				a->out.distance_m = INFINITY;
		}
		a->have_out = 1;
	}
	if (a->tele.n_dds)
		app_teleop_compute(a);
	for (i = 0; i < a->n_ov; i++)
		if (c->deadline_ns >= a->ov_start[i] && c->deadline_ns < a->ov_end[i]) {
			/* injected overrun: this compute takes ov_ns */
			if (px_loop_vclock_advance(l, a->ov_ns[i]) == PX_E_STATE) {
				int64_t until = app_mono_ns() + a->ov_ns[i];
				while (app_mono_ns() < until)
					;
			}
		}
	if (a->o.alloc_probe && c->index == 10) {
		/* self-check of the heap counter (PX_RUN_ALLOC_PROBE=1): one
		 * deliberate allocation and release inside a cycle */
		void *volatile p = malloc(64);
		free(p);
	}
	a->compute_t0 = app_mono_ns() - t;
	px_stats_record(a->compute, a->compute_t0);
	return PX_OK;
}

/* The closest pair of an avoidance cycle in the record's point
 * columns: the link point as the device's, the obstacle's as the
 * proxy's. */
static void record_pair(struct px_app_record *r, px_vec3 pa, px_vec3 pb)
{
	r->dev_m[0] = pa.x;
	r->dev_m[1] = pa.y;
	r->dev_m[2] = pa.z;
	r->proxy_m[0] = pb.x;
	r->proxy_m[1] = pb.y;
	r->proxy_m[2] = pb.z;
}

/* The telemetry record of this cycle (every decimation-th), pushed to
 * the ring (dropped and counted when it is full). f: the force sent. */
static void push_record(struct px_app *a, const struct px_loop_cycle *c,
			double f)
{
	struct px_app_record r;
	const struct px_pose_sample *s =
		a->ctl_dev >= 0 ? &a->sample[a->ctl_dev] : NULL;
	memset(&r, 0, sizeof(r));
	r.t_s = (double)(c->deadline_ns - a->t0_ns) * 1e-9;
	r.cycle = c->index;
	if (s) {
		r.dev_m[0] = s->pos_m.x;
		r.dev_m[1] = s->pos_m.y;
		r.dev_m[2] = s->pos_m.z;
		r.valid = s->valid;
		r.dev_quat_xyzw[0] = (float)s->q.x;
		r.dev_quat_xyzw[1] = (float)s->q.y;
		r.dev_quat_xyzw[2] = (float)s->q.z;
		r.dev_quat_xyzw[3] = (float)s->q.w;
	} else {
		r.dev_quat_xyzw[3] = 1;
	}
	r.proxy_m[0] = a->out.proxy_m.x;
	r.proxy_m[1] = a->out.proxy_m.y;
	r.proxy_m[2] = a->out.proxy_m.z;
	memcpy(r.force_n, a->cmd.force_n, sizeof(r.force_n));
	r.force_mag_n = f;
	/* a sample that broke the velocity limit has no meaningful
	 * distance: left empty (NaN) rather than spoiling the plots */
	r.distance_m = a->have_out && !a->over_velocity ? a->out.distance_m
							: NAN;
	r.penetration_m = a->have_out && !a->over_velocity
				  ? a->out.penetration_m
				  : NAN;
	r.latency_ns = c->wake_ns - c->deadline_ns;
	r.compute_ns = a->compute_t0;
	r.scale = 1.0;
	if (a->avoiding && a->started) {
		int k = a->aout.closest_capsule, j;
		r.scale = c->safe ? 0.0 : a->aout.scale;
		for (j = 0; j < TELE_JOINTS && j < a->ctl.chain.n_joints; j++)
			r.qdot[j] = c->safe ? 0.0 : a->aout.qdot[j];
		for (j = 0; j < TELE_JOINTS && j < a->ctl.chain.n_joints; j++)
			r.q[j] = (float)a->q[j];
		r.distance_m = a->aout.min_clearance_m;
		r.penetration_m = 0;
		r.queries = a->aout.point_queries;
		r.valid = 1;
		if (a->robot_models && a->uout.closest.body >= 0) {
			record_pair(&r, a->uout.closest.point_robot,
				    a->uout.closest.point_obstacle);
			r.queries = a->uout.pairs;
		} else if (k >= 0) {
			record_pair(&r, a->aout.caps[k].point_m,
				    a->aout.caps[k].obstacle_m);
		}
	}
	r.contact = a->out.contact;
	r.safe = c->safe;
	if (!a->avoiding)
		r.queries = a->out.point_queries;
	px_ring_push(a->ring, &r);
}

int app_phase_write(struct px_loop *l, const struct px_loop_cycle *c,
		       void *user)
{
	struct px_app *a = user;
	double f;
	(void)l;
	if (a->tele.n_dds)
		app_teleop_write(a, c);
	if (a->rendering && a->ctl_dev >= 0) {
		/* In safe state the loop has zeroed cmd and cleared enable. */
		if (px_dev_force_write(a->dev[a->ctl_dev], &a->cmd, c->write_ns) !=
		    PX_OK)
			a->write_errors++;
	}
	if (a->n_dio) {
		int i;
		if (c->safe && a->estop_first_ns >= 0 &&
		    a->safe_first_after_estop_ns < 0) {
			a->safe_first_after_estop_ns = c->write_ns;
			a->safe_first_cycle_after_estop = c->index;
		}
		if (c->safe && a->estop_first_ns < 0)
			a->safe_cycles_before_estop++;
		/* enable relay: on while the loop runs outside safe state;
		 * timing line: toggles every cycle (scope probe) */
		a->timing_level = !a->timing_level;
		for (i = 0; i < a->n_dio; i++) {
			int rc = px_dev_dio_write(a->dio[i], PX_DIO_ENABLE, !c->safe,
						  c->write_ns);
			if (rc != PX_OK && rc != PX_E_UNSUPPORTED)
				a->enable_errors++;
			(void)px_dev_dio_write(a->dio[i], PX_DIO_TIMING,
					       a->timing_level, c->write_ns);
		}
	}
	if (a->co) {
		int i;
		/* safe state: hold where the arm is, drives to quick stop;
		 * without avoidance (an arm beside a haptic device) the
		 * drives are enabled and hold still */
		if (c->safe || !a->avoiding)
			for (i = 0; i < PX_CONTROL_MAX_JOINTS; i++)
				a->targets[i] = a->csp ? a->q[i] : 0.0;
		if (px_canopen_tx(a->co, c->write_ns, a->targets,
				  PX_CONTROL_MAX_JOINTS,
				  !c->safe && a->have_q) != PX_OK)
			a->write_errors++;
		if (a->avoiding && a->started && !c->safe) {
			if (a->aout.min_clearance_m < a->min_clearance_m)
				a->min_clearance_m = a->aout.min_clearance_m;
			if (a->aout.min_clearance_m < a->min_distance_m)
				a->min_distance_m = a->aout.min_clearance_m;
			if (a->aout.scale < a->min_scale)
				a->min_scale = a->aout.scale;
			if (a->aout.scale == 0)
				a->stop_cycles++;
		}
	}
	{
		/* what went out this cycle: finite? in safe state? phase? */
		int i, bad = 0;
		for (i = 0; i < 3; i++)
			bad |= !isfinite(a->cmd.force_n[i]) ||
			       !isfinite(a->cmd.torque_n_m[i]);
		for (i = 0; a->co && i < PX_CONTROL_MAX_JOINTS; i++)
			bad |= !isfinite(a->targets[i]);
		if (bad)
			a->nonfinite_outputs++;
		if (c->safe && c->index < a->safe_bits_n)
			a->safe_bits[c->index >> 3] |= (uint8_t)(1u << (c->index & 7));
		if (!a->have_deadline) {
			/* periods skipped before the first cycle count too */
			a->first_deadline_ns =
				c->deadline_ns - (int64_t)c->missed * c->period_ns;
			a->have_deadline = 1;
			if (a->max_cycles && !a->o.virtual_time)
				a->stop_deadline_ns =
					a->first_deadline_ns +
					(int64_t)(a->max_cycles - 1) * c->period_ns;
		}
		a->last_deadline_ns = c->deadline_ns;
	}
	f = sqrt(a->cmd.force_n[0] * a->cmd.force_n[0] +
		 a->cmd.force_n[1] * a->cmd.force_n[1] +
		 a->cmd.force_n[2] * a->cmd.force_n[2]);
	if (f > a->max_force_n)
		a->max_force_n = f;
	/* Figures of the rendering only while it drives the device: not in
	 * safe state (force zeroed) nor on a sample that broke the velocity
	 * limit (a corrupted report the loop is tripping on). */
	if (a->have_out && !c->safe && !a->over_velocity) {
		if (a->out.distance_m < a->min_distance_m)
			a->min_distance_m = a->out.distance_m;
		if (a->out.penetration_m > a->max_penetration_m)
			a->max_penetration_m = a->out.penetration_m;
		if (a->out.contact)
			a->contact_cycles++;
	}
	if (c->index % (uint64_t)a->decimation == 0)
		push_record(a, c, f);
	atomic_store_explicit(&a->allocs, app_heap_count(a) - a->heap_base,
			      memory_order_relaxed);
	if (a->stop_deadline_ns && c->deadline_ns >= a->stop_deadline_ns) {
		a->ended_by_time = 1; /* --duration-s of real time gone */
		return PX_LOOP_STOP;
	}
	return PX_OK;
}


/* ---- shutdown: the safe state before anything closes ---------------- */



int64_t app_shutdown_now(struct px_app *a)
{
	return a->loop && a->o.virtual_time ? px_loop_now_ns(a->loop) : app_mono_ns();
}

int64_t app_shutdown_period_ns(struct px_app *a)
{
	return a->cfg && a->cfg->loop.period_ns > 0 ? a->cfg->loop.period_ns
						  : 1000000;
}

/* Let period_ns pass between two shutdown rounds: the virtual clock
 * jumps, the real one sleeps; an arm on the in-process bus answers as it
 * does in the read phase. */
static int64_t shutdown_wait(void *user, int64_t now, int64_t period_ns)
{
	struct px_app *a = user;
	if (a->o.virtual_time) {
		now += period_ns;
	} else {
		struct timespec ts = {(time_t)(period_ns / 1000000000),
				      (long)(period_ns % 1000000000)};
		nanosleep(&ts, NULL);
		now = app_mono_ns();
	}
	if (a->arm)
		px_canopen_sim_step(a->arm, now);
	return now;
}

/* The drives of one master after its safe stop: counted, and the first
 * that did not confirm named. */
void app_shutdown_drives(struct px_app *a, const char *dev, struct px_canopen *co, int rc,
			    const struct px_canopen_stop_result *r)
{
	a->sd.drives += (int)r->drives;
	a->sd.drives_disabled += (int)r->disabled;
	a->sd.drives_faulted += (int)r->faulted;
	if (rc != PX_OK && !a->sd.why[0]) {
		struct px_canopen_drive_status ds;
		memset(&ds, 0, sizeof(ds));
		ds.state = PX_CIA402_UNKNOWN;
		if (r->first_unconfirmed >= 0)
			px_canopen_drive_status(co, (size_t)r->first_unconfirmed,
						&ds);
		snprintf(a->sd.why, sizeof(a->sd.why),
			 "device '%s': drive %d (node %u) not confirmed disabled "
			 "within %.0f ms (%u rounds): %s, last state %s%s",
			 dev, r->first_unconfirmed, ds.node_id,
			 (double)SHUTDOWN_TIMEOUT_NS * 1e-6, r->rounds,
			 px_strerror(rc), px_cia402_state_name(ds.state),
			 ds.lost ? ", heartbeat lost" : "");
	}
}

/*
 * Every exit path comes here before any device closes: zero force and
 * torque with enable off on each force sink, enable relays and timing
 * lines off, then each CANopen master's drives to quick stop and
 * disabled (px_devcfg_safe_stop), each confirmed where the device can;
 * a device that could not take it (unplugged) is tried again each
 * period within SHUTDOWN_TIMEOUT_NS. The loop has stopped: this runs on
 * the main thread. Once per process.
 */
void app_safe_shutdown(struct px_app *a, const char *reason)
{
	int64_t t0, now, period = app_shutdown_period_ns(a);
	int confirmed[MAX_DEVS];
	int i, pending;
	if (a->sd.done)
		return;
	a->sd.done = 1;
	snprintf(a->sd.reason, sizeof(a->sd.reason), "%s", reason);
	now = t0 = app_shutdown_now(a);
	memset(confirmed, 0, sizeof(confirmed));
	/* first the force at the hand: one try each, at once */
	for (i = 0; i < a->n_dev; i++) {
		unsigned caps = px_dev_caps(a->dev[i]);
		a->sd.force_devs += (caps & PX_DEV_CAP_FORCE) != 0;
		a->sd.dio_devs += (caps & PX_DEV_CAP_DIO) != 0;
		if (a->dev_owned[i] && (caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
			confirmed[i] = px_dev_safe(a->dev[i], now) == PX_OK;
	}
	/* the handles' devices and their masters' drives */
	for (i = 0; i < a->n_dcfg; i++) {
		struct px_devcfg_safe_config sc;
		struct px_devcfg_safe_result r;
		struct px_canopen *co = px_devcfg_canopen(a->dcfg[i]);
		px_devcfg_safe_config_default(&sc);
		sc.canopen.timeout_ns = SHUTDOWN_TIMEOUT_NS;
		sc.canopen.max_rounds =
			(uint32_t)(SHUTDOWN_TIMEOUT_NS / period + 1);
		sc.canopen.period_ns = period;
		sc.canopen.wait = shutdown_wait;
		sc.canopen.user = a;
		(void)px_devcfg_safe_stop(a->dcfg[i], now, &sc, &r);
		if (co) {
			app_shutdown_drives(a, a->co_name ? a->co_name : "canopen", co,
					r.canopen_rc, &r.canopen);
			now += r.canopen.elapsed_ns;
		}
	}
	for (i = 0; i < a->n_dev; i++) {
		struct px_dev_status st;
		if (!a->dev_owned[i] && px_dev_status(a->dev[i], &st) == PX_OK)
			confirmed[i] = st.outputs_safe;
	}
	/* again, for a device that could not take it yet */
	for (;;) {
		pending = 0;
		for (i = 0; i < a->n_dev; i++) {
			struct px_dev *d = a->dev[i];
			unsigned caps = px_dev_caps(d);
			if (confirmed[i] || !(caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
				continue;
			if (caps & PX_DEV_CAP_POSE) {
				/* a simulated device lives in its poll: it
				 * comes back there */
				struct px_pose_sample ps;
				(void)px_dev_pose_read(d, now, &ps);
			}
			if (px_dev_safe(d, now) == PX_OK)
				confirmed[i] = 1;
			else
				pending++;
		}
		if (!pending || now - t0 >= SHUTDOWN_TIMEOUT_NS)
			break;
		now = shutdown_wait(a, now, period);
	}
	for (i = 0; i < a->n_dev; i++) {
		unsigned caps = px_dev_caps(a->dev[i]);
		if (!(caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
			continue;
		if (confirmed[i]) {
			a->sd.force_zeroed += (caps & PX_DEV_CAP_FORCE) != 0;
			a->sd.relays_off += (caps & PX_DEV_CAP_DIO) != 0;
		} else if (!a->sd.why[0]) {
			struct px_dev_status st;
			px_dev_status(a->dev[i], &st);
			snprintf(a->sd.why, sizeof(a->sd.why),
				 "device '%s': %s not confirmed within %.0f ms: %s",
				 st.name,
				 caps & PX_DEV_CAP_FORCE ? "zero force" : "relay off",
				 (double)SHUTDOWN_TIMEOUT_NS * 1e-6, st.last_msg);
		}
	}
	a->sd.elapsed_ns = now - t0;
	a->sd.safe = !a->sd.why[0];
}

/* "safe (force zeroed on 1/1 device, relay off on 1/1, 6/6 drives
 * disabled) after SIGINT in 2.0 ms", or NOT SAFE and why. */

/* ---- outside the cycle: telemetry, faults, status ------------------ */

/* Joints whose commanded velocity is recorded (CSV columns, plot). */
int app_avoid_joints(const struct px_app *a)
{
	int n = a->ctl.chain.n_joints;
	return n < TELE_JOINTS ? n : TELE_JOINTS;
}

void app_drain(struct px_app *a,
	       void (*record)(void *user, const struct px_app_record *r),
	       void *user)
{
	struct px_app_record r;
	struct px_fault f;
	while (px_ring_pop(a->ring, &r) == PX_OK) {
		a->n_rows++;
		a->last = r;
		a->have_last = 1;
		if (record)
			record(user, &r);
		/* The proxy must stay on the free side of closed models:
		 * check each recorded proxy against the scene (not in the
		 * cycle; the scene is only read). */
		if (a->rendering && r.valid && !r.safe) {
			struct px_scene_hit h;
			px_vec3 p = px_v3(r.proxy_m[0], r.proxy_m[1], r.proxy_m[2]);
			if (px_scene_nearest(a->scene, p, INFINITY, &h) == 1 &&
			    h.distance_m < a->min_proxy_distance_m)
				a->min_proxy_distance_m = h.distance_m;
		}
	}
	while (px_loop_fault_pop(a->loop, &f) == PX_OK) {
		if (f.cause >= 0 && f.cause < PX_FAULT__COUNT)
			a->faults_by_cause[f.cause]++;
		a->faults_popped++;
		if (a->sim.n_faults && a->n_lfaults < 100000) {
			if (a->n_lfaults == a->cap_lfaults) {
				size_t cap = a->cap_lfaults ? 2 * a->cap_lfaults : 256;
				struct px_fault *p =
					realloc(a->lfaults, cap * sizeof(*p));
				if (!p)
					continue;
				a->lfaults = p;
				a->cap_lfaults = cap;
			}
			a->lfaults[a->n_lfaults++] = f;
		}
	}
}

static void *loop_thread(void *arg)
{
	struct px_app *a = arg;
	a->loop_rc = px_loop_run(a->loop, a->max_cycles);
	atomic_store(&a->loop_done, 1);
	return NULL;
}

static void tick(struct px_app *a)
{
	if (a->o.tick)
		a->o.tick(a->o.user);
}

/* The run: on the virtual clock this thread steps the loop in batches
 * and drains between them; on the real clock the loop has its own thread
 * and this one drains every 20 ms. */
int app_run(struct px_app *a)
{
	uint64_t stop_at = a->o.at_cycle ? a->o.stop_at_cycle : 0;
	if (atomic_load(&a->stop_requested))
		return PX_OK; /* a signal during setup: straight to shutdown */
	if (a->o.virtual_time) {
		/* Drain well before the ring can fill. */
		uint64_t batch = (uint64_t)a->decimation *
				 (px_ring_capacity(a->ring) / 2);
		uint64_t done = 0, allocs = 0;
		int rc = PX_OK;
		if (batch > 1000)
			batch = 1000;
		while (!atomic_load(&a->stop_requested) && rc == PX_OK &&
		       (a->max_cycles == 0 || done < a->max_cycles)) {
			uint64_t k, before = app_heap_count(a);
			for (k = 0; k < batch && rc == PX_OK &&
				    !atomic_load(&a->stop_requested) &&
				    (a->max_cycles == 0 || done < a->max_cycles);
			     k++, done++) {
				rc = px_loop_step(a->loop);
				if (stop_at && done + 1 == stop_at)
					a->o.at_cycle(a->o.user);
			}
			/* only the cycles' own heap calls, not the drain's */
			allocs += app_heap_count(a) - before;
			app_drain(a, a->o.record, a->o.user);
			tick(a);
		}
		atomic_store(&a->allocs, allocs);
		return rc < 0 ? rc : PX_OK;
	} else {
		pthread_t th;
		int fired = 0;
		if (pthread_create(&th, NULL, loop_thread, a) != 0) {
			app_note(a, "%s: cannot start the loop thread\n", app_name(a));
			return PX_E_NOMEM;
		}
		while (!atomic_load(&a->loop_done)) {
			struct timespec ts = {0, 20000000};
			nanosleep(&ts, NULL);
			app_drain(a, a->o.record, a->o.user);
			tick(a);
			if (stop_at && !fired && !atomic_load(&a->stop_requested)) {
				struct px_loop_status ls;
				px_loop_status(a->loop, &ls);
				if (ls.cycles >= stop_at) {
					fired = 1;
					a->o.at_cycle(a->o.user);
				}
			}
		}
		pthread_join(th, NULL);
		app_drain(a, a->o.record, a->o.user);
		return a->loop_rc;
	}
}
