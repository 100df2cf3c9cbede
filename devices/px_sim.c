/* Simulated haptic / pose device: mass-spring-damper arm, scripted hand,
 * HID reports through the real codec, fault injection. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_file.h"
#include "px_sim.h"
#include "dev_internal.h"

#define REP_MAX 64
#define QCAP 32          /* reports in flight (delay) */
#define MAX_IDS 8
#define STEP_NS 100000   /* integration step bound */
#define MAX_STEPS 20000  /* per poll: bounds a poll after a long pause */
#define MAX_REPORTS 64   /* per poll */

struct px_sim_csv {
	size_t n;
	double *t, *p; /* p: 3 per sample */
};

struct qrep {
	int64_t t_deliver;
	int nan;
	size_t len;
	uint8_t b[REP_MAX];
};

struct sim {
	struct px_sim_haptic_config cfg;
	struct px_sim_sine sines[PX_SIM_MAX_SINES];
	struct px_sim_fault faults[PX_SIM_MAX_FAULTS];
	const struct px_codec_map *map;
	int ids[MAX_IDS];
	int n_ids;
	uint64_t rng;
	int started;
	int64_t t0, t, next_report;
	double x[3], v[3], f[3], hand[3];
	double tq[3];
	int enable;             /* of the newest command received */
	/* fault state */
	int unplugged;
	unsigned corrupt_turn;
	int stuck_have[MAX_IDS];
	size_t stuck_len[MAX_IDS];
	uint8_t stuck_b[MAX_IDS][REP_MAX];
	/* in flight */
	struct qrep q[QCAP];
	unsigned qn;
	uint64_t sent, faulted, outs;
	uint8_t last_out[REP_MAX];
	size_t last_out_len;
};

static const char *const fault_names[PX_SIM_FAULT__COUNT] = {
	"none", "drop", "delay", "duplicate", "corrupt", "stuck", "nan",
	"unplug", "bus_off", "estop",
};

const char *px_sim_fault_name(int kind)
{
	if (kind < 0 || kind >= PX_SIM_FAULT__COUNT)
		return NULL;
	return fault_names[kind];
}

int px_sim_fault_from_name(const char *name)
{
	int i;
	if (!name)
		return PX_E_INVAL;
	for (i = 1; i < PX_SIM_FAULT__COUNT; i++)
		if (!strcmp(name, fault_names[i]))
			return i;
	return PX_E_NOTFOUND;
}

/* ---- CSV trajectories ------------------------------------------------- */

void px_sim_csv_free(struct px_sim_csv *c)
{
	if (!c)
		return;
	free(c->t);
	free(c->p);
	free(c);
}

size_t px_sim_csv_count(const struct px_sim_csv *c)
{
	return c ? c->n : 0;
}

double px_sim_csv_duration_s(const struct px_sim_csv *c)
{
	return c && c->n ? c->t[c->n - 1] - c->t[0] : 0.0;
}

/* One row "t,x,y,z". Returns 0, or the 1-based field at fault with
 * *why: "is empty", "is not a number", "is not finite", or text after
 * the fourth field (field 5). */
static int parse_row(const char *s, double v[4], const char **why)
{
	int k;
	char *end;
	for (k = 0; k < 4; k++) {
		while (*s == ' ' || *s == '\t')
			s++;
		if (*s == ',' || *s == 0) {
			*why = "is empty";
			return k + 1;
		}
		errno = 0;
		v[k] = strtod(s, &end);
		if (end == s || errno == ERANGE) {
			*why = "is not a number";
			return k + 1;
		}
		if (!isfinite(v[k])) {
			*why = "is not finite";
			return k + 1;
		}
		s = end;
		while (*s == ' ' || *s == '\t')
			s++;
		if (k < 3) {
			if (*s != ',') {
				*why = *s ? "is not a number" : "is missing";
				return *s ? k + 1 : k + 2;
			}
			s++;
		}
	}
	while (*s == ' ' || *s == '\t')
		s++;
	if (*s) {
		*why = "is extra text after z_m";
		return 5;
	}
	return 0;
}

int px_sim_csv_load(const char *path, struct px_sim_csv **out, char *msg,
		    size_t cap)
{
	char *data = NULL, *cur, *line;
	struct px_sim_csv *c;
	size_t capn = 0, len = 0;
	int lineno = 0, rc = PX_OK, header_ok = 1;
	if (msg && cap)
		msg[0] = 0;
	if (!path || !out)
		return PX_E_INVAL;
	*out = NULL;
	/* whole, within the text limit: a NUL byte (/dev/zero) is an error
	 * at its place, not a blank line read forever */
	rc = px_file_read(path, PX_FILE_TEXT_MAX_BYTES, PX_FILE_TEXT, "trajectory",
			  &data, &len, msg, cap);
	if (rc != PX_OK)
		return rc;
	c = calloc(1, sizeof *c);
	if (!c) {
		free(data);
		return PX_E_NOMEM;
	}
	cur = data;
	while ((line = px_file_next_line(&cur)) != NULL) {
		double v[4];
		const char *s = line, *why = "";
		int field;
		lineno++;
		while (isspace((unsigned char)*s))
			s++;
		if (*s == 0 || *s == '#')
			continue;
		field = parse_row(s, v, &why);
		if (field) {
			if (header_ok && c->n == 0 && px_file_is_header(s)) {
				header_ok = 0;
				continue;
			}
			if (msg)
				snprintf(msg, cap,
					 "%s:%d: expected 4 finite numbers "
					 "t_s,x_m,y_m,z_m (field %d %s)", path,
					 lineno, field, why);
			rc = PX_E_PARSE;
			break;
		}
		header_ok = 0;
		if (c->n && !(v[0] > c->t[c->n - 1])) {
			if (msg)
				snprintf(msg, cap,
					 "%s:%d: time %g not after %g", path,
					 lineno, v[0], c->t[c->n - 1]);
			rc = PX_E_PARSE;
			break;
		}
		if (c->n == capn) {
			size_t nc = capn ? 2 * capn : 64;
			double *nt = realloc(c->t, nc * sizeof *nt);
			double *np;
			if (!nt) {
				rc = PX_E_NOMEM;
				break;
			}
			c->t = nt;
			np = realloc(c->p, nc * 3 * sizeof *np);
			if (!np) {
				rc = PX_E_NOMEM;
				break;
			}
			c->p = np;
			capn = nc;
		}
		c->t[c->n] = v[0];
		c->p[3 * c->n] = v[1];
		c->p[3 * c->n + 1] = v[2];
		c->p[3 * c->n + 2] = v[3];
		c->n++;
	}
	free(data);
	if (rc == PX_OK && c->n == 0) {
		if (msg)
			snprintf(msg, cap, "%s: no samples", path);
		rc = PX_E_PARSE;
	}
	if (rc != PX_OK) {
		px_sim_csv_free(c);
		return rc;
	}
	*out = c;
	return PX_OK;
}

static void csv_eval(const struct px_sim_csv *c, int repeat, double t,
		     double p[3], double v[3])
{
	size_t lo, hi, k;
	double t0 = c->t[0], tn = c->t[c->n - 1], a, dt;
	for (k = 0; k < 3; k++)
		v[k] = 0.0;
	if (c->n == 1 || t <= t0) {
		for (k = 0; k < 3; k++)
			p[k] = c->p[k];
		return;
	}
	if (t >= tn) {
		if (!repeat) {
			for (k = 0; k < 3; k++)
				p[k] = c->p[3 * (c->n - 1) + k];
			return;
		}
		t = t0 + fmod(t - t0, tn - t0);
	}
	lo = 0;
	hi = c->n - 1; /* t[lo] <= t < t[hi] */
	while (hi - lo > 1) {
		size_t mid = lo + (hi - lo) / 2;
		if (c->t[mid] <= t)
			lo = mid;
		else
			hi = mid;
	}
	dt = c->t[hi] - c->t[lo];
	a = (t - c->t[lo]) / dt;
	for (k = 0; k < 3; k++) {
		double p0 = c->p[3 * lo + k], p1 = c->p[3 * hi + k];
		p[k] = p0 + a * (p1 - p0);
		v[k] = (p1 - p0) / dt;
	}
}

void px_sim_traj_eval(const struct px_sim_traj *tr, double t, double p[3],
		      double v[3])
{
	size_t i;
	int k;
	for (k = 0; k < 3; k++) {
		p[k] = tr ? tr->center_m[k] : 0.0;
		v[k] = 0.0;
	}
	if (!tr)
		return;
	if (tr->kind == PX_SIM_TRAJ_SINES) {
		for (i = 0; i < tr->n_sines; i++) {
			const struct px_sim_sine *s = &tr->sines[i];
			double w = 2.0 * M_PI * s->frequency_hz;
			if (s->axis < 0 || s->axis > 2)
				continue;
			p[s->axis] += s->amplitude_m * sin(w * t + s->phase_rad);
			v[s->axis] += s->amplitude_m * w *
				      cos(w * t + s->phase_rad);
		}
	} else if (tr->kind == PX_SIM_TRAJ_CSV && tr->csv) {
		double cp[3], cv[3];
		csv_eval(tr->csv, tr->repeat, t, cp, cv);
		for (k = 0; k < 3; k++) {
			p[k] += cp[k];
			v[k] = cv[k];
		}
	}
}

/* ---- the device -------------------------------------------------------- */

static uint64_t rng_next(struct sim *s)
{
	/* xorshift64*: deterministic per seed, no state beyond 64 bits. */
	uint64_t x = s->rng;
	x ^= x >> 12;
	x ^= x << 25;
	x ^= x >> 27;
	s->rng = x;
	return x * 2685821657736338717ull;
}

static double rng_unit(struct sim *s)
{
	return (double)(rng_next(s) >> 11) * (1.0 / 9007199254740992.0);
}

static double rng_normal(struct sim *s)
{
	double u1 = rng_unit(s), u2 = rng_unit(s);
	if (u1 < 1e-300)
		u1 = 1e-300;
	return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

void px_sim_haptic_config_default(struct px_sim_haptic_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof *c);
	c->mass_kg = 0.15;
	c->damping_n_s_per_m = 2.0;
	c->hand_stiffness_n_per_m = 400.0;
	c->hand_damping_n_s_per_m = 4.0;
	c->report_period_ns = 1000000;
	c->seed = 1;
	c->traj.kind = PX_SIM_TRAJ_HOLD;
}

/* Which fault of kind applies at t (window and probability), or NULL. */
static const struct px_sim_fault *fault_at(struct sim *s, int kind,
					   int64_t t, int roll)
{
	size_t i;
	for (i = 0; i < s->cfg.n_faults; i++) {
		const struct px_sim_fault *f = &s->faults[i];
		double p;
		if (f->kind != kind || t < f->start_ns ||
		    t >= f->start_ns + f->duration_ns)
			continue;
		p = f->probability > 0.0 ? f->probability : 1.0;
		if (!roll || p >= 1.0 || rng_unit(s) < p)
			return f;
	}
	return NULL;
}

static void enqueue(struct sim *s, int64_t t, const uint8_t *b, size_t len,
		    int nan)
{
	struct qrep *r;
	if (s->qn >= QCAP)
		return; /* a full device queue drops, as a real one would */
	r = &s->q[s->qn++];
	r->t_deliver = t;
	r->nan = nan;
	r->len = len;
	memcpy(r->b, b, len);
}

static void integrate(struct sim *s, int64_t to)
{
	int64_t span = to - s->t;
	int64_t steps, i;
	double h;
	int k;
	if (span <= 0)
		return;
	steps = (span + STEP_NS - 1) / STEP_NS;
	if (steps > MAX_STEPS)
		steps = MAX_STEPS;
	h = (double)span * 1e-9 / (double)steps;
	for (i = 1; i <= steps; i++) {
		double t_s = (double)(s->t - s->t0) * 1e-9 + (double)i * h;
		double hp[3], hv[3];
		px_sim_traj_eval(&s->cfg.traj, t_s, hp, hv);
		for (k = 0; k < 3; k++) {
			double a;
			s->hand[k] = hp[k];
			if (s->cfg.follow_hand) {
				s->x[k] = hp[k];
				s->v[k] = hv[k];
				continue;
			}
			a = (s->f[k] +
			     s->cfg.hand_stiffness_n_per_m * (hp[k] - s->x[k]) +
			     s->cfg.hand_damping_n_s_per_m * (hv[k] - s->v[k]) -
			     s->cfg.damping_n_s_per_m * s->v[k]) /
			    s->cfg.mass_kg;
			s->v[k] += h * a;
			s->x[k] += h * s->v[k];
		}
	}
	s->t = to;
}

static void emit(struct px_dev *d, struct sim *s, int64_t t)
{
	double axis[PX_AXIS__COUNT] = {0};
	int i, k;
	if (fault_at(s, PX_SIM_FAULT_UNPLUG, t, 0)) {
		if (!s->unplugged) {
			s->unplugged = 1;
			s->qn = 0;
			px_dev_set_state(d, PX_DEV_STATE_UNPLUGGED, t);
		}
		return;
	}
	if (s->unplugged) {
		s->unplugged = 0;
		px_dev_set_state(d, PX_DEV_STATE_RUNNING, t);
	}
	for (k = 0; k < 3; k++)
		axis[k] = s->x[k] + (s->cfg.position_noise_m > 0.0
					     ? s->cfg.position_noise_m *
						       rng_normal(s)
					     : 0.0);
	for (i = 0; i < s->n_ids; i++) {
		uint8_t b[REP_MAX];
		int n = px_codec_encode_input(s->map, s->ids[i], axis, 0, b,
					      sizeof b);
		const struct px_sim_fault *f;
		int64_t when = t;
		int nan = 0, dup = 0;
		if (n <= 0)
			continue;
		s->sent++;
		if (fault_at(s, PX_SIM_FAULT_DROP, t, 1)) {
			s->faulted++;
			continue;
		}
		if (fault_at(s, PX_SIM_FAULT_STUCK, t, 0)) {
			if (s->stuck_have[i]) {
				memcpy(b, s->stuck_b[i], s->stuck_len[i]);
				n = (int)s->stuck_len[i];
			}
			s->faulted++;
		}
		if (!fault_at(s, PX_SIM_FAULT_STUCK, t, 0) || !s->stuck_have[i]) {
			memcpy(s->stuck_b[i], b, (size_t)n);
			s->stuck_len[i] = (size_t)n;
			s->stuck_have[i] = 1;
		}
		if (fault_at(s, PX_SIM_FAULT_CORRUPT, t, 1)) {
			int numbered = px_codec_numbered(s->map);
			s->faulted++;
			switch (s->corrupt_turn++ % 3u) {
			case 0: /* truncated transfer */
				n = n > 1 ? n / 2 : 0;
				break;
			case 1: /* id byte hit */
				if (numbered)
					b[0] ^= 0xA5;
				else
					n = n > 1 ? n - 1 : 0;
				break;
			default: { /* a high bit of the first value flipped */
				size_t fk, at = (size_t)numbered;
				for (fk = 0; fk < s->map->n_inputs; fk++) {
					const struct px_codec_field *fl =
						&s->map->inputs[fk];
					if (fl->report_id != s->ids[i])
						continue;
					at += fl->byte_order == PX_BIG_ENDIAN
						      ? fl->byte_offset
						      : px_codec_field_end(fl) - 1;
					break;
				}
				if (at < (size_t)n)
					b[at] ^= 0x40;
				break;
			}
			}
		}
		if (fault_at(s, PX_SIM_FAULT_NAN, t, 1)) {
			nan = 1;
			s->faulted++;
		}
		if ((f = fault_at(s, PX_SIM_FAULT_DELAY, t, 1))) {
			when = t + f->delay_ns;
			s->faulted++;
		}
		if (fault_at(s, PX_SIM_FAULT_DUPLICATE, t, 1)) {
			dup = 1;
			s->faulted++;
		}
		enqueue(s, when, b, (size_t)n, nan);
		if (dup)
			enqueue(s, when, b, (size_t)n, nan);
	}
}

static void deliver(struct px_dev *d, struct sim *s, int64_t now)
{
	unsigned i, j = 0;
	for (i = 0; i < s->qn; i++) {
		struct qrep *r = &s->q[i];
		if (r->t_deliver > now) {
			if (j != i)
				s->q[j] = *r;
			j++;
			continue;
		}
		if (r->nan) {
			/* What a device with float fields sends when its
			 * sensor fails: the sample path must refuse it. */
			double a[PX_AXIS__COUNT] = {NAN, NAN, NAN, 0, 0, 0};
			px_dev_feed_axes(d, a, 7u, 0, 0, r->t_deliver);
			continue;
		}
		px_dev_feed_report(d, r->b, r->len, r->t_deliver);
	}
	s->qn = j;
}

static int sim_poll(struct px_dev *d, int64_t now)
{
	struct sim *s = px_dev_impl(d);
	int n = 0;
	if (!s->started) {
		s->started = 1;
		s->t0 = s->t = now;
		s->next_report = now;
		integrate(s, now);
	}
	while (s->next_report <= now && n < MAX_REPORTS) {
		integrate(s, s->next_report);
		emit(d, s, s->next_report);
		s->next_report += s->cfg.report_period_ns;
		n++;
	}
	if (s->next_report <= now) /* far behind: skip, keep the phase */
		s->next_report += ((now - s->next_report) /
					   s->cfg.report_period_ns +
				   1) * s->cfg.report_period_ns;
	integrate(s, now);
	deliver(d, s, now);
	return s->unplugged ? PX_E_NODEV : PX_OK;
}

static int sim_force(struct px_dev *d, const struct px_force_cmd *c,
		     int64_t now)
{
	struct sim *s = px_dev_impl(d);
	double w[PX_WRENCH__COUNT];
	struct px_codec_diag diag;
	uint8_t b[REP_MAX];
	int n, k;
	if (s->cfg.follow_hand)
		return PX_E_UNSUPPORTED;
	n = px__dev_encode_force(d, s->map, c, now, b, sizeof b);
	if (n < 0)
		return n;
	if (s->unplugged)
		return PX_E_NODEV;
	/* The device end: decode what was sent (channels the map does not
	 * carry read 0). */
	memset(w, 0, sizeof w);
	memcpy(s->last_out, b, (size_t)n);
	s->last_out_len = (size_t)n;
	n = px_codec_decode_output(s->map, b, (size_t)n, w, &diag);
	if (n < 0) {
		px_dev_record(d, PX_DEV_ERR_ENCODE, n, 0, diag.report_id,
			      &diag, "simulated device rejected output",
			      now);
		return n;
	}
	s->outs++;
	for (k = 0; k < 3; k++) {
		s->f[k] = w[k];
		s->tq[k] = w[3 + k];
	}
	s->enable = c->enable != 0;
	return PX_OK;
}

static const struct px_dev_ops sim_haptic_ops = {
	.backend = "sim-haptic",
	.caps = PX_DEV_CAP_POSE | PX_DEV_CAP_FORCE,
	.poll = sim_poll,
	.force = sim_force,
};

static const struct px_dev_ops sim_pose_ops = {
	.backend = "sim-pose",
	.caps = PX_DEV_CAP_POSE,
	.poll = sim_poll,
};

#define BAD(...)                                            \
	do {                                                \
		if (msg)                                    \
			snprintf(msg, cap, __VA_ARGS__);    \
		return PX_E_INVAL;                          \
	} while (0)

int px_sim_haptic_create(const struct px_dev_config *dcfg,
			 const struct px_sim_haptic_config *cfg,
			 struct px_dev **out, char *msg, size_t cap)
{
	struct px_dev_config dc;
	const struct px_codec_map *map;
	struct px_codec_diag diag;
	struct sim *s;
	uint32_t have_in = 0, have_out = 0;
	size_t i;
	int rc;
	const char *nm;

	if (msg && cap)
		msg[0] = 0;
	if (out)
		*out = NULL;
	if (!dcfg || !cfg || !out)
		BAD("NULL argument");
	nm = dcfg->name ? dcfg->name : "sim";
	map = dcfg->codec ? dcfg->codec : px_codec_builtin("haptic");
	if (!(cfg->mass_kg > 0.0) || !isfinite(cfg->mass_kg))
		BAD("%s: mass_kg must be > 0", nm);
	if (!(cfg->damping_n_s_per_m >= 0.0) ||
	    !(cfg->hand_stiffness_n_per_m >= 0.0) ||
	    !(cfg->hand_damping_n_s_per_m >= 0.0) ||
	    !isfinite(cfg->damping_n_s_per_m) ||
	    !isfinite(cfg->hand_stiffness_n_per_m) ||
	    !isfinite(cfg->hand_damping_n_s_per_m))
		BAD("%s: damping and hand coefficients must be finite, >= 0",
		    nm);
	if (cfg->report_period_ns <= 0)
		BAD("%s: report_period_ns must be > 0", nm);
	if (!(cfg->position_noise_m >= 0.0) || !isfinite(cfg->position_noise_m))
		BAD("%s: position_noise_m must be finite, >= 0", nm);
	if (cfg->traj.n_sines > PX_SIM_MAX_SINES ||
	    (cfg->traj.n_sines && !cfg->traj.sines))
		BAD("%s: at most %d sines", nm, PX_SIM_MAX_SINES);
	for (i = 0; i < cfg->traj.n_sines; i++)
		if (cfg->traj.sines[i].axis < 0 || cfg->traj.sines[i].axis > 2 ||
		    !isfinite(cfg->traj.sines[i].amplitude_m) ||
		    !isfinite(cfg->traj.sines[i].frequency_hz) ||
		    !isfinite(cfg->traj.sines[i].phase_rad))
			BAD("%s: trajectory sines[%zu]: axis x, y or z and "
			    "finite numbers", nm, i);
	if (cfg->traj.kind == PX_SIM_TRAJ_CSV && !cfg->traj.csv)
		BAD("%s: csv trajectory without a loaded file", nm);
	if (cfg->traj.kind < PX_SIM_TRAJ_HOLD || cfg->traj.kind > PX_SIM_TRAJ_CSV)
		BAD("%s: unknown trajectory kind %d", nm, cfg->traj.kind);
	if (cfg->n_faults > PX_SIM_MAX_FAULTS ||
	    (cfg->n_faults && !cfg->faults))
		BAD("%s: at most %d faults", nm, PX_SIM_MAX_FAULTS);
	for (i = 0; i < cfg->n_faults; i++) {
		const struct px_sim_fault *f = &cfg->faults[i];
		if (f->kind <= PX_SIM_FAULT_NONE ||
		    f->kind > PX_SIM_FAULT_UNPLUG || f->duration_ns <= 0 ||
		    !(f->probability >= 0.0 && f->probability <= 1.0) ||
		    (f->kind == PX_SIM_FAULT_DELAY && f->delay_ns <= 0))
			BAD("%s: faults[%zu]: kind %s needs duration_ns > 0, "
			    "probability in [0, 1]%s", nm, i,
			    px_sim_fault_name(f->kind)
				    ? px_sim_fault_name(f->kind)
				    : "?",
			    f->kind == PX_SIM_FAULT_DELAY
				    ? " and delay_ns > 0"
				    : " (bus_off and estop are for CAN/GPIO)");
	}
	if (px_codec_check(map, &diag) != PX_OK) {
		char tmp[160];
		px_codec_diag_format(&diag, nm, tmp, sizeof tmp);
		BAD("%s", tmp);
	}
	for (i = 0; i < map->n_inputs; i++)
		have_in |= 1u << map->inputs[i].axis;
	for (i = 0; i < map->n_outputs; i++)
		have_out |= 1u << map->outputs[i].axis;
	if ((have_in & 7u) != 7u)
		BAD("%s: codec map needs x, y and z inputs", nm);
	if (!cfg->follow_hand && (have_out & 7u) != 7u)
		BAD("%s: codec map needs fx, fy and fz outputs", nm);

	dc = *dcfg;
	dc.codec = map;
	if (dc.min_report_interval_ns == 0)
		dc.min_report_interval_ns = cfg->report_period_ns / 2;
	rc = px_dev_create(cfg->follow_hand ? &sim_pose_ops : &sim_haptic_ops,
			   &dc, sizeof *s, out);
	if (rc != PX_OK)
		BAD("%s: device creation failed: %s", nm, px_strerror(rc));
	s = px_dev_impl(*out);
	s->cfg = *cfg;
	if (cfg->traj.n_sines)
		memcpy(s->sines, cfg->traj.sines,
		       cfg->traj.n_sines * sizeof s->sines[0]);
	s->cfg.traj.sines = s->sines;
	if (cfg->n_faults)
		memcpy(s->faults, cfg->faults,
		       cfg->n_faults * sizeof s->faults[0]);
	s->cfg.faults = s->faults;
	s->map = map;
	s->rng = cfg->seed ? cfg->seed : 0x9E3779B97F4A7C15ull;
	for (i = 0; i < map->n_inputs; i++) {
		int id = map->inputs[i].report_id, k, seen = 0;
		for (k = 0; k < s->n_ids; k++)
			if (s->ids[k] == id)
				seen = 1;
		if (!seen && s->n_ids < MAX_IDS)
			s->ids[s->n_ids++] = id;
	}
	return PX_OK;
}

int px_sim_haptic_state(struct px_dev *d, struct px_sim_haptic_state *st)
{
	struct sim *s;
	int k;
	if (!d || !st)
		return PX_E_INVAL;
	if (px_dev_ops(d) != &sim_haptic_ops && px_dev_ops(d) != &sim_pose_ops)
		return PX_E_INVAL;
	s = px_dev_impl(d);
	memset(st, 0, sizeof *st);
	st->t_ns = s->t;
	for (k = 0; k < 3; k++) {
		st->pos_m[k] = s->x[k];
		st->vel_m_s[k] = s->v[k];
		st->hand_m[k] = s->hand[k];
		st->force_n[k] = s->f[k];
		st->torque_n_m[k] = s->tq[k];
	}
	st->enable = s->enable;
	st->reports_sent = s->sent;
	st->reports_faulted = s->faulted;
	st->outputs_decoded = s->outs;
	return PX_OK;
}

int px_sim_haptic_last_output(struct px_dev *d, uint8_t *buf, size_t cap)
{
	struct sim *s;
	if (!d || !buf || px_dev_ops(d) != &sim_haptic_ops)
		return PX_E_INVAL;
	s = px_dev_impl(d);
	if (cap < s->last_out_len)
		return PX_E_NOSPC;
	memcpy(buf, s->last_out, s->last_out_len);
	return (int)s->last_out_len;
}
