/* Device handle: hand-off of the newest sample, staleness, status and
 * error records. */
#include <errno.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_arena.h"
#include "px_dev.h"
#include "px_loop.h"
#include "px_param.h"
#include "dev_internal.h"

enum {
	C_REPORTS, C_SAMPLES, C_DECODE, C_NONFINITE, C_DUP, C_STUCK,
	C_UNPLUG, C_REPLUG, C_WRITES, C_WERR, C_IOERR, C_BUSERR, C_ERRORS,
	C_SAFE, C_SAFE_ERR, C__COUNT
};

/* The last-error record, copied through a seqlock as 64-bit words. */
struct errrec {
	int32_t kind, err, sys_errno, pad;
	int64_t frame_id, t_ns;
	const char *what;
	struct px_codec_diag diag;
};
#define EWORDS ((sizeof(struct errrec) + 7) / 8)

struct px_dev {
	const struct px_dev_ops *ops;
	struct px_dev_config cfg;
	char name[32];
	struct px_arena arena;
	struct px_param *hand; /* struct px_pose_sample */
	void *impl;
	_Atomic int state;
	int started;
	/* an output was written since the last confirmed safe output (any
	 * thread reads it: px_dev_status) */
	_Atomic int dirty;
	/* loop clock of the newest cycle call, for the safe output that
	 * stop/free send (a simulated device lives on the virtual clock;
	 * the loop itself may be gone by then) */
	_Atomic int64_t last_now_ns;

	/* feeding thread */
	double axis[PX_AXIS__COUNT];
	uint64_t buttons;
	uint64_t seq;
	int have_prev;
	int64_t prev_t;
	px_vec3 prev_pos, vel;
	uint32_t same;
	int stuck;
	double last_axis[PX_AXIS__COUNT];
	uint64_t last_buttons;
	int64_t rep_t[256];
	uint64_t rep_hash[256];

	/* loop thread */
	uint64_t read_seq;
	struct px_loop *loop;
	int loop_idx;

	_Atomic uint64_t cnt[C__COUNT];
	_Atomic unsigned eseq;
	atomic_flag ebusy;
	_Atomic uint64_t ewords[EWORDS];
};

int64_t px_dev_mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static void seen(struct px_dev *d, int64_t now_ns)
{
	atomic_store_explicit(&d->last_now_ns, now_ns, memory_order_relaxed);
}

/* When a safe output is sent from stop/free: just after the newest
 * cycle call on its clock, else CLOCK_MONOTONIC. */
static int64_t dev_now(struct px_dev *d)
{
	int64_t t = atomic_load_explicit(&d->last_now_ns, memory_order_relaxed);
	return t == INT64_MIN ? px_dev_mono_ns() : t;
}

static void inc(struct px_dev *d, int c)
{
	atomic_fetch_add_explicit(&d->cnt[c], 1, memory_order_relaxed);
}

static uint64_t get(const struct px_dev *d, int c)
{
	return atomic_load_explicit(&((struct px_dev *)d)->cnt[c],
				    memory_order_relaxed);
}

void px_dev_config_default(struct px_dev_config *cfg)
{
	if (!cfg)
		return;
	memset(cfg, 0, sizeof *cfg);
	cfg->stale_timeout_ns = 20000000;
}

int px_dev_create(const struct px_dev_ops *ops,
		  const struct px_dev_config *cfg, size_t impl_size,
		  struct px_dev **out)
{
	struct px_dev *d;
	struct px_pose_sample init;
	size_t impl_off, arena_off, arena_sz, total;
	uint8_t *mem;
	int i, rc;

	if (out)
		*out = NULL;
	if (!ops || !cfg || !out || cfg->stale_timeout_ns <= 0 ||
	    cfg->min_report_interval_ns < 0)
		return PX_E_INVAL;
	if (cfg->codec && px_codec_check(cfg->codec, NULL) != PX_OK)
		return PX_E_INVAL;
	impl_off = (sizeof *d + 63) & ~(size_t)63;
	arena_off = impl_off + ((impl_size + 63) & ~(size_t)63);
	arena_sz = px_param_size(sizeof(struct px_pose_sample)) + 256;
	total = arena_off + arena_sz;
	mem = calloc(1, total);
	if (!mem)
		return PX_E_NOMEM;
	d = (struct px_dev *)mem;
	d->ops = ops;
	d->cfg = *cfg;
	if (cfg->name)
		snprintf(d->name, sizeof d->name, "%s", cfg->name);
	d->cfg.name = d->name;
	d->impl = impl_size ? mem + impl_off : NULL;
	px_arena_init(&d->arena, mem + arena_off, arena_sz);
	memset(&init, 0, sizeof init);
	init.q = px_quat_identity();
	rc = px_param_create(&d->arena, sizeof init, &init, &d->hand);
	if (rc != PX_OK) {
		free(mem);
		return rc;
	}
	atomic_init(&d->state, PX_DEV_STATE_CLOSED);
	atomic_init(&d->dirty, 0);
	atomic_init(&d->last_now_ns, INT64_MIN);
	atomic_init(&d->eseq, 0);
	atomic_flag_clear(&d->ebusy);
	for (i = 0; i < C__COUNT; i++)
		atomic_init(&d->cnt[i], 0);
	for (i = 0; i < (int)EWORDS; i++)
		atomic_init(&d->ewords[i], 0);
	for (i = 0; i < 256; i++)
		d->rep_t[i] = INT64_MIN;
	d->loop_idx = -1;
	*out = d;
	return PX_OK;
}

void px_dev_free(struct px_dev *d)
{
	if (!d)
		return;
	/* Belt and braces: whoever frees a device that was driven without
	 * making it safe first still leaves no command in effect. */
	if (atomic_load(&d->dirty))
		(void)px_dev_safe(d, dev_now(d));
	px_dev_stop(d);
	if (d->ops->destroy)
		d->ops->destroy(d);
	free(d);
}

int px_dev_start(struct px_dev *d)
{
	int rc = PX_OK;
	if (!d)
		return PX_E_INVAL;
	if (d->started)
		return PX_E_STATE;
	if (d->ops->start)
		rc = d->ops->start(d);
	if (rc < 0) {
		if (px_dev_state(d) == PX_DEV_STATE_CLOSED)
			px_dev_set_state(d, PX_DEV_STATE_FAILED, 0);
		return rc;
	}
	d->started = 1;
	if (px_dev_state(d) == PX_DEV_STATE_CLOSED)
		px_dev_set_state(d, PX_DEV_STATE_RUNNING, 0);
	return PX_OK;
}

void px_dev_stop(struct px_dev *d)
{
	if (!d || !d->started)
		return;
	/* before the threads that would send it stop */
	if (atomic_load(&d->dirty))
		(void)px_dev_safe(d, dev_now(d));
	if (d->ops->stop)
		d->ops->stop(d);
	d->started = 0;
	atomic_store(&d->state, PX_DEV_STATE_CLOSED);
}

int px_dev_attach(struct px_dev *d, struct px_loop *l)
{
	int idx;
	if (!d || !l)
		return PX_E_INVAL;
	if (!(d->ops->caps & PX_DEV_CAP_POSE)) {
		if (!(d->ops->caps & PX_DEV_CAP_DIO))
			return PX_E_INVAL;
		d->loop = l; /* a pressed e-stop trips it */
		return 0;
	}
	idx = px_loop_input_add(l, d->name, d->cfg.stale_timeout_ns);
	if (idx < 0)
		return idx;
	d->loop = l;
	d->loop_idx = idx;
	return idx;
}

int px_dev_force_attach(struct px_dev *d, struct px_loop *l,
			struct px_force_cmd *cmd)
{
	int rc;
	if (!d || !l || !cmd || !(d->ops->caps & PX_DEV_CAP_FORCE))
		return PX_E_INVAL;
	/* force_n and torque_n_m are adjacent doubles: one block of 6. */
	_Static_assert(offsetof(struct px_force_cmd, torque_n_m) ==
			       offsetof(struct px_force_cmd, force_n) +
				       3 * sizeof(double),
		       "force and torque must be contiguous");
	rc = px_loop_output_add(l, d->name, cmd->force_n, 6);
	if (rc < 0)
		return rc;
	rc = px_loop_enable_add(l, d->name, &cmd->enable);
	return rc < 0 ? rc : PX_OK;
}

/* ---- feeding side ---------------------------------------------------- */

static uint64_t hash_bytes(const uint8_t *p, size_t n)
{
	uint64_t h = 1469598103934665603ull ^ n;
	size_t i;
	for (i = 0; i < n; i++) {
		h ^= p[i];
		h *= 1099511628211ull;
	}
	return h;
}

int px_dev_feed_report(struct px_dev *d, const uint8_t *buf, size_t len,
		       int64_t t_ns)
{
	struct px_codec_values v;
	struct px_codec_diag diag;
	int rc, id;
	if (!d || !d->cfg.codec)
		return PX_E_INVAL;
	inc(d, C_REPORTS);
	memset(&v, 0, sizeof v);
	rc = px_codec_decode(d->cfg.codec, buf, len, &v, &diag);
	if (rc < 0) {
		px_dev_record(d, PX_DEV_ERR_DECODE, rc, 0, diag.report_id,
			      &diag, NULL, t_ns);
		return rc;
	}
	id = v.report_id & 0xff;
	if (d->cfg.min_report_interval_ns > 0) {
		uint64_t h = hash_bytes(buf, len);
		if (d->rep_t[id] != INT64_MIN && h == d->rep_hash[id] &&
		    t_ns - d->rep_t[id] < d->cfg.min_report_interval_ns) {
			px_dev_record(d, PX_DEV_ERR_DUPLICATE, PX_E_CORRUPT, 0,
				      id, NULL, NULL, t_ns);
			return 0;
		}
		d->rep_hash[id] = h;
		d->rep_t[id] = t_ns;
	}
	return px_dev_feed_axes(d, v.axis, v.axis_mask, v.buttons,
				v.button_mask, t_ns);
}

int px_dev_feed_axes(struct px_dev *d, const double axis[PX_AXIS__COUNT],
		     uint32_t axis_mask, uint64_t buttons,
		     uint64_t button_mask, int64_t t_ns)
{
	struct px_pose_sample s;
	px_vec3 r;
	double ang;
	int i, same = 1;
	if (!d || !axis)
		return PX_E_INVAL;
	for (i = 0; i < PX_AXIS__COUNT; i++)
		if ((axis_mask >> i) & 1u && !isfinite(axis[i])) {
			px_dev_record(d, PX_DEV_ERR_NONFINITE, PX_E_NAN, 0, -1,
				      NULL, NULL, t_ns);
			return PX_E_NAN;
		}
	for (i = 0; i < PX_AXIS__COUNT; i++)
		if ((axis_mask >> i) & 1u)
			d->axis[i] = axis[i];
	d->buttons = (d->buttons & ~button_mask) | (buttons & button_mask);

	if (d->cfg.stuck_limit > 0) {
		for (i = 0; i < PX_AXIS__COUNT; i++)
			if (d->axis[i] != d->last_axis[i])
				same = 0;
		if (d->buttons != d->last_buttons)
			same = 0;
		memcpy(d->last_axis, d->axis, sizeof d->axis);
		d->last_buttons = d->buttons;
		if (!same || d->seq == 0) {
			d->same = 0;
			d->stuck = 0;
		} else if (++d->same >= d->cfg.stuck_limit) {
			if (!d->stuck) {
				d->stuck = 1;
				px_dev_record(d, PX_DEV_ERR_STUCK, PX_E_CORRUPT,
					      0, -1, NULL, NULL, t_ns);
			}
			return 0;
		}
	}

	memset(&s, 0, sizeof s);
	s.pos_m.x = d->axis[PX_AXIS_X];
	s.pos_m.y = d->axis[PX_AXIS_Y];
	s.pos_m.z = d->axis[PX_AXIS_Z];
	r.x = d->axis[PX_AXIS_RX];
	r.y = d->axis[PX_AXIS_RY];
	r.z = d->axis[PX_AXIS_RZ];
	ang = sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
	if (!(ang > 0.0) || px_quat_from_axis_angle(r, ang, &s.q) != PX_OK)
		s.q = px_quat_identity();
	if (axis_mask & 7u) {
		if (d->have_prev && t_ns > d->prev_t) {
			double dt = (double)(t_ns - d->prev_t) * 1e-9;
			d->vel.x = (s.pos_m.x - d->prev_pos.x) / dt;
			d->vel.y = (s.pos_m.y - d->prev_pos.y) / dt;
			d->vel.z = (s.pos_m.z - d->prev_pos.z) / dt;
		}
		d->prev_pos = s.pos_m;
		d->prev_t = t_ns;
		d->have_prev = 1;
	}
	s.vel_m_s = d->vel;
	s.buttons = d->buttons;
	s.t_ns = t_ns;
	s.seq = ++d->seq;
	s.valid = 1;
	px_param_write(d->hand, &s);
	inc(d, C_SAMPLES);
	return 1;
}

/* ---- cycle side -------------------------------------------------------- */

int px_dev_pose_read(struct px_dev *d, int64_t now_ns,
		     struct px_pose_sample *out)
{
	const struct px_pose_sample *s;
	int st, gone;
	if (!d || !out)
		return PX_E_INVAL;
	seen(d, now_ns);
	if (d->ops->poll)
		d->ops->poll(d, now_ns);
	s = px_param_read(d->hand, NULL);
	*out = *s;
	st = px_dev_state(d);
	gone = st == PX_DEV_STATE_UNPLUGGED || st == PX_DEV_STATE_FAILED;
	out->age_ns = out->seq ? now_ns - out->t_ns : 0;
	out->fresh = out->seq != d->read_seq;
	d->read_seq = out->seq;
	if (gone)
		out->valid = 0;
	out->stale = !out->valid || out->age_ns > d->cfg.stale_timeout_ns;
	if (out->fresh && out->valid && d->loop)
		px_loop_input_stamp(d->loop, d->loop_idx, out->t_ns);
	if (gone)
		return PX_E_NODEV;
	return out->fresh;
}

int px_dev_force_write(struct px_dev *d, const struct px_force_cmd *c,
		       int64_t now_ns)
{
	int i, rc;
	int st;
	if (!d || !c)
		return PX_E_INVAL;
	if (!(d->ops->caps & PX_DEV_CAP_FORCE) || !d->ops->force)
		return PX_E_UNSUPPORTED;
	for (i = 0; i < 3; i++)
		if (!isfinite(c->force_n[i]) || !isfinite(c->torque_n_m[i])) {
			px_dev_record(d, PX_DEV_ERR_ENCODE, PX_E_NAN, 0, -1,
				      NULL, "force command not finite", now_ns);
			inc(d, C_WERR);
			return PX_E_NAN;
		}
	st = px_dev_state(d);
	if (st == PX_DEV_STATE_UNPLUGGED || st == PX_DEV_STATE_FAILED)
		return PX_E_NODEV;
	atomic_store_explicit(&d->dirty, 1, memory_order_relaxed);
	seen(d, now_ns);
	rc = d->ops->force(d, c, now_ns);
	px_dev_count_write(d, rc >= 0);
	return rc;
}

int px_dev_estop_read(struct px_dev *d, int64_t now_ns, int *pressed)
{
	if (!d || !pressed)
		return PX_E_INVAL;
	if (!(d->ops->caps & PX_DEV_CAP_DIO) || !d->ops->estop)
		return PX_E_UNSUPPORTED;
	return d->ops->estop(d, now_ns, pressed);
}

int px_dev_dio_write(struct px_dev *d, int which, int value, int64_t now_ns)
{
	if (!d || (which != PX_DIO_ENABLE && which != PX_DIO_TIMING))
		return PX_E_INVAL;
	if (!(d->ops->caps & PX_DEV_CAP_DIO) || !d->ops->dio_write)
		return PX_E_UNSUPPORTED;
	atomic_store_explicit(&d->dirty, 1, memory_order_relaxed);
	seen(d, now_ns);
	return d->ops->dio_write(d, which, value != 0, now_ns);
}

/* The generic safe output: one zero command through the back end's own
 * force op (enable 0 encodes as zero in every back end), and the
 * digital outputs off. An absent output line (PX_E_UNSUPPORTED) is not
 * an error. */
static int generic_safe(struct px_dev *d, int64_t now_ns)
{
	int rc = PX_OK, r;
	if ((d->ops->caps & PX_DEV_CAP_FORCE) && d->ops->force) {
		struct px_force_cmd zero;
		memset(&zero, 0, sizeof zero);
		rc = d->ops->force(d, &zero, now_ns);
		if (rc == PX_E_UNSUPPORTED)
			rc = PX_OK; /* a map with no outputs sends nothing */
	}
	if ((d->ops->caps & PX_DEV_CAP_DIO) && d->ops->dio_write) {
		r = d->ops->dio_write(d, PX_DIO_ENABLE, 0, now_ns);
		if (r < 0 && r != PX_E_UNSUPPORTED && rc == PX_OK)
			rc = r;
		r = d->ops->dio_write(d, PX_DIO_TIMING, 0, now_ns);
		if (r < 0 && r != PX_E_UNSUPPORTED && rc == PX_OK)
			rc = r;
	}
	return rc;
}

int px_dev_safe(struct px_dev *d, int64_t now_ns)
{
	int rc;
	if (!d)
		return PX_E_INVAL;
	if (!(d->ops->caps & (PX_DEV_CAP_FORCE | PX_DEV_CAP_DIO)))
		return PX_OK;
	rc = d->ops->safe ? d->ops->safe(d, now_ns) : generic_safe(d, now_ns);
	if (rc > 0)
		rc = PX_OK;
	if (d->ops->caps & PX_DEV_CAP_FORCE)
		px_dev_count_write(d, rc == PX_OK);
	if (rc == PX_OK) {
		inc(d, C_SAFE);
		atomic_store(&d->dirty, 0);
	} else {
		inc(d, C_SAFE_ERR);
		atomic_store(&d->dirty, 1);
		px_dev_record(d, PX_DEV_ERR_IO, rc, 0, -1, NULL,
			      "safe output not confirmed", now_ns);
	}
	return rc;
}

/* ---- status ------------------------------------------------------------ */

void px_dev_count_write(struct px_dev *d, int ok)
{
	if (!d)
		return;
	inc(d, ok ? C_WRITES : C_WERR);
}

void px_dev_record(struct px_dev *d, int kind, int err, int sys_errno,
		   int64_t frame_id, const struct px_codec_diag *diag,
		   const char *what, int64_t t_ns)
{
	struct errrec e;
	uint64_t w[EWORDS];
	unsigned q;
	size_t i;
	if (!d)
		return;
	inc(d, C_ERRORS);
	switch (kind) {
	case PX_DEV_ERR_DECODE: inc(d, C_DECODE); break;
	case PX_DEV_ERR_NONFINITE: inc(d, C_NONFINITE); break;
	case PX_DEV_ERR_DUPLICATE: inc(d, C_DUP); break;
	case PX_DEV_ERR_STUCK: inc(d, C_STUCK); break;
	case PX_DEV_ERR_IO: inc(d, C_IOERR); break;
	case PX_DEV_ERR_BUS: inc(d, C_BUSERR); break;
	default: break;
	}
	if (atomic_flag_test_and_set_explicit(&d->ebusy, memory_order_acquire))
		return;
	memset(&e, 0, sizeof e);
	e.kind = kind;
	e.err = err;
	e.sys_errno = sys_errno;
	e.frame_id = frame_id;
	e.t_ns = t_ns;
	e.what = what;
	if (diag)
		e.diag = *diag;
	else
		e.diag.what = PX_CODEC_OK;
	memset(w, 0, sizeof w);
	memcpy(w, &e, sizeof e);
	q = atomic_load_explicit(&d->eseq, memory_order_relaxed);
	atomic_store_explicit(&d->eseq, q + 1, memory_order_relaxed);
	atomic_thread_fence(memory_order_release);
	for (i = 0; i < EWORDS; i++)
		atomic_store_explicit(&d->ewords[i], w[i],
				      memory_order_relaxed);
	atomic_store_explicit(&d->eseq, q + 2, memory_order_release);
	atomic_flag_clear_explicit(&d->ebusy, memory_order_release);
}

static int read_err(const struct px_dev *cd, struct errrec *e)
{
	struct px_dev *d = (struct px_dev *)cd;
	uint64_t w[EWORDS];
	int tries;
	size_t i;
	for (tries = 0; tries < 1000; tries++) {
		unsigned q1 = atomic_load_explicit(&d->eseq,
						   memory_order_acquire);
		unsigned q2;
		if (q1 & 1u)
			continue;
		for (i = 0; i < EWORDS; i++)
			w[i] = atomic_load_explicit(&d->ewords[i],
						    memory_order_relaxed);
		atomic_thread_fence(memory_order_acquire);
		q2 = atomic_load_explicit(&d->eseq, memory_order_relaxed);
		if (q1 == q2) {
			memcpy(e, w, sizeof *e);
			return q1 != 0;
		}
	}
	return -1;
}

void px_dev_set_state(struct px_dev *d, int state, int64_t t_ns)
{
	int old;
	if (!d)
		return;
	old = atomic_exchange(&d->state, state);
	if (old == state)
		return;
	if (state == PX_DEV_STATE_UNPLUGGED) {
		inc(d, C_UNPLUG);
		px_dev_record(d, PX_DEV_ERR_UNPLUG, PX_E_NODEV, 0, -1, NULL,
			      NULL, t_ns);
	} else if (old == PX_DEV_STATE_UNPLUGGED &&
		   state == PX_DEV_STATE_RUNNING) {
		inc(d, C_REPLUG);
	}
}

int px_dev_state(const struct px_dev *d)
{
	return d ? atomic_load(&((struct px_dev *)d)->state)
		 : PX_DEV_STATE_CLOSED;
}

const char *px_dev_errkind_name(int kind)
{
	static const char *const names[PX_DEV_ERR__COUNT] = {
		"none", "decode", "non-finite", "duplicate", "stuck",
		"unplugged", "open", "io", "encode", "bus", "e-stop",
	};
	if (kind < 0 || kind >= PX_DEV_ERR__COUNT)
		return "unknown";
	return names[kind];
}

static void format_err(const struct px_dev *d, const struct errrec *e,
		       char *buf, size_t cap)
{
	char detail[128] = "";
	char frame[32] = "";
	char sys[96] = "";
	if (e->frame_id >= 0 &&
	    !(e->kind == PX_DEV_ERR_DECODE && e->diag.what != PX_CODEC_OK))
		snprintf(frame, sizeof frame, " [frame 0x%llx]",
			 (unsigned long long)e->frame_id);
	if (e->sys_errno) {
		const char *nm = strerrorname_np(e->sys_errno);
		snprintf(sys, sizeof sys, ": errno %s (%d): %s",
			 nm ? nm : "?", e->sys_errno, strerror(e->sys_errno));
	}
	switch (e->kind) {
	case PX_DEV_ERR_DECODE:
		if (e->diag.what != PX_CODEC_OK)
			px_codec_diag_format(&e->diag, NULL, detail,
					     sizeof detail);
		else
			snprintf(detail, sizeof detail, "frame rejected: %s",
				 e->err == PX_E_RANGE
					 ? "value outside its plausible range"
					 : e->err == PX_E_PARSE
						   ? "frame too short"
						   : px_strerror_name(e->err));
		break;
	case PX_DEV_ERR_DUPLICATE:
		snprintf(detail, sizeof detail,
			 "duplicate report 0x%02llx dropped",
			 (unsigned long long)e->frame_id);
		frame[0] = 0;
		break;
	case PX_DEV_ERR_STUCK:
		snprintf(detail, sizeof detail,
			 "value unchanged for %u samples: stuck",
			 d->cfg.stuck_limit);
		break;
	case PX_DEV_ERR_NONFINITE:
		snprintf(detail, sizeof detail, "non-finite value rejected");
		break;
	case PX_DEV_ERR_UNPLUG:
		snprintf(detail, sizeof detail, "device unplugged");
		break;
	case PX_DEV_ERR_BUS:
		snprintf(detail, sizeof detail, "bus error frame");
		break;
	default:
		snprintf(detail, sizeof detail, "%s error %s",
			 px_dev_errkind_name(e->kind),
			 px_strerror_name(e->err));
		break;
	}
	/* Truncation is acceptable: the message is for people. */
	if (snprintf(buf, cap, "%s (%s): %s%s%s%s%s", d->name,
		     d->ops->backend, detail, frame, e->what ? ": " : "",
		     e->what ? e->what : "", sys) < 0)
		buf[0] = 0;
}

int px_dev_status(const struct px_dev *d, struct px_dev_status *st)
{
	struct errrec e;
	int have;
	if (!d || !st)
		return PX_E_INVAL;
	memset(st, 0, sizeof *st);
	snprintf(st->name, sizeof st->name, "%s", d->name);
	st->backend = d->ops->backend;
	st->state = px_dev_state(d);
	st->reports = get(d, C_REPORTS);
	st->samples = get(d, C_SAMPLES);
	st->decode_errors = get(d, C_DECODE);
	st->nonfinite = get(d, C_NONFINITE);
	st->duplicates = get(d, C_DUP);
	st->stuck = get(d, C_STUCK);
	st->unplugs = get(d, C_UNPLUG);
	st->replugs = get(d, C_REPLUG);
	st->writes = get(d, C_WRITES);
	st->write_errors = get(d, C_WERR);
	st->io_errors = get(d, C_IOERR);
	st->bus_errors = get(d, C_BUSERR);
	st->errors = get(d, C_ERRORS);
	st->safe_writes = get(d, C_SAFE);
	st->safe_errors = get(d, C_SAFE_ERR);
	st->outputs_safe = st->safe_writes > 0 && !atomic_load(&d->dirty);
	st->last_frame_id = -1;
	have = read_err(d, &e);
	if (have > 0) {
		st->last_kind = e.kind;
		st->last_err = e.err;
		st->last_errno = e.sys_errno;
		st->last_frame_id = e.frame_id;
		st->last_t_ns = e.t_ns;
		format_err(d, &e, st->last_msg, sizeof st->last_msg);
	} else {
		snprintf(st->last_msg, sizeof st->last_msg, "%s (%s): %s",
			 d->name, d->ops->backend,
			 have < 0 ? "error record busy" : "no error");
	}
	return PX_OK;
}

const char *px_dev_name(const struct px_dev *d)
{
	return d ? d->name : "";
}

unsigned px_dev_caps(const struct px_dev *d)
{
	return d ? d->ops->caps : 0;
}

int64_t px_dev_stale_timeout_ns(const struct px_dev *d)
{
	return d ? d->cfg.stale_timeout_ns : 0;
}

void *px_dev_impl(struct px_dev *d)
{
	return d ? d->impl : NULL;
}

const struct px_dev_config *px_dev_config(const struct px_dev *d)
{
	return d ? &d->cfg : NULL;
}

const struct px_dev_ops *px_dev_ops(const struct px_dev *d)
{
	return d ? d->ops : NULL;
}

struct px_loop *px__dev_loop(const struct px_dev *d)
{
	return d ? d->loop : NULL;
}



void px__dev_force_wrench(const struct px_force_cmd *c,
			  double w[PX_WRENCH__COUNT])
{
	int k;
	for (k = 0; k < PX_WRENCH__COUNT; k++)
		w[k] = 0.0;
	if (c->enable)
		for (k = 0; k < 3; k++) {
			w[k] = c->force_n[k];
			w[3 + k] = c->torque_n_m[k];
		}
}

int px__dev_encode_force(struct px_dev *d, const struct px_codec_map *m,
			 const struct px_force_cmd *c, int64_t now,
			 uint8_t *buf, size_t cap)
{
	double w[PX_WRENCH__COUNT];
	struct px_codec_diag diag;
	int n;
	px__dev_force_wrench(c, w);
	n = px_codec_encode(m, w, buf, cap, NULL, &diag);
	if (n < 0)
		px_dev_record(d, PX_DEV_ERR_ENCODE, n, 0, diag.report_id,
			      &diag, NULL, now);
	return n;
}
