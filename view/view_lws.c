/* The view's server on libwebsockets (px_view.h): static files from the
 * web root, the WebSocket of PX_VIEW_PROTOCOL on /ws, one service thread.
 *
 * Frames go through a ring of queue_frames + 1 fixed slots: the feeding
 * thread writes slot head % n under the lock and wakes the service thread
 * (lws_cancel_service); each connection keeps the sequence number of the
 * next frame it sends and copies one slot out under the lock when its
 * socket can take more. A connection more than queue_frames behind jumps
 * to the newest frame (the skipped ones are counted as dropped).
 *
 * A swapped point cloud is one message that stays: the newest "cloud"
 * is kept (shared, counted references under the lock) and every
 * connection sends it before its next frame when it has not sent that
 * one, so a page that connects later gets the cloud as it is. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <libwebsockets.h>

#include "px_cloud.h"
#include "px_view.h"
#include "view_internal.h"

/* Big messages (scene, track) go out in fragments of this size. */
#define CHUNK 32768

struct slot {
	uint64_t seq;
	size_t len;
	char text[PX_VIEW_FRAME_MAX];
};

struct msg {
	char *p;
	size_t n;
};

/* A message several connections send at once (lock: mu). */
struct shared {
	int refs;
	uint64_t seq;
	struct msg m;
};

enum stage { ST_HELLO, ST_SCENE, ST_TRACK, ST_FRAMES, ST_DONE };

struct sess {
	struct px_view *v;
	struct lws *wsi;
	enum stage stage;
	size_t off;             /* sent of the current big message */
	uint64_t next;          /* next frame's sequence number */
	int64_t waiting_ns;     /* asked to write since then (0: not asked) */
	int killed;
	unsigned char *buf;     /* LWS_PRE + CHUNK (>= a frame) */
	struct shared *cloud;   /* being sent (off), or NULL */
	uint64_t cloud_seq;     /* the last cloud sent */
};

struct px_view {
	struct px_view_options o;
	char addr[64], root[PATH_MAX], name[128], mode[8];
	struct lws_context *ctx;
	struct lws_protocols protos[3];
	struct lws_http_mount mount;
	pthread_t th;
	int started;
	atomic_int stop, ended;
	struct msg hello, scene, track;
	/* the ring (lock: mu) */
	pthread_mutex_t mu;
	struct slot *ring;
	int ring_n;
	uint64_t head;          /* sequence number of the next frame fed */
	struct shared *cloud;   /* the newest cloud message, or NULL */
	/* the feeding thread's */
	double last_t_s;
	char fbuf[PX_VIEW_FRAME_MAX];
	struct px_view_sources src;
	struct px_view_frame_extra extra;
	px_pose *ref_pose;      /* the scene's poses when set, ref_n of them */
	size_t ref_n;
	float *cloud_xyz;       /* PX_VIEW_CLOUD_MAX points */
	uint64_t cloud_frame, cloud_seq;
	/* the service thread's */
	struct sess **sess;
	int n_sess;
	atomic_int clients, ends_pending;
	atomic_ullong connections, fed, sent, dropped, closed, refused;
};

static int64_t now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* libwebsockets' own log: its last error line, kept for create's msg. */
static char lws_last[200];

static void lws_emit(int level, const char *line)
{
	size_t n;
	if (!(level & LLL_ERR))
		return;
	snprintf(lws_last, sizeof(lws_last), "%s", line);
	n = strlen(lws_last);
	while (n && (lws_last[n - 1] == '\n' || lws_last[n - 1] == '\r'))
		lws_last[--n] = '\0';
}

static void sess_remove(struct px_view *v, struct sess *s)
{
	int i;
	for (i = 0; i < v->n_sess; i++)
		if (v->sess[i] == s) {
			v->sess[i] = v->sess[--v->n_sess];
			break;
		}
}

/* The big message of stage st (NULL: none for this stage). */
static const struct msg *stage_msg(struct px_view *v, enum stage st)
{
	if (st == ST_HELLO)
		return &v->hello;
	if (st == ST_SCENE)
		return &v->scene;
	if (st == ST_TRACK)
		return v->track.p ? &v->track : NULL;
	return NULL;
}

/* Send the next fragment of a big message; 1 when more remain. */
static int send_big(struct sess *s, const struct msg *m)
{
	size_t n = m->n - s->off;
	int start = s->off == 0, end;
	if (n > CHUNK)
		n = CHUNK;
	end = s->off + n == m->n;
	memcpy(s->buf + LWS_PRE, m->p + s->off, n);
	if (lws_write(s->wsi, s->buf + LWS_PRE, n,
		      (enum lws_write_protocol)lws_write_ws_flags(LWS_WRITE_TEXT, start,
								  end)) < (int)n)
		return -1;
	s->off += n;
	return !end;
}

static int send_text(struct sess *s, const char *t, size_t n)
{
	memcpy(s->buf + LWS_PRE, t, n);
	return lws_write(s->wsi, s->buf + LWS_PRE, n, LWS_WRITE_TEXT) < (int)n ? -1
									       : 0;
}

static void shared_release(struct shared *sh)
{
	if (sh && --sh->refs == 0) {
		free(sh->m.p);
		free(sh);
	}
}

/* The newest cloud when this connection has not sent it: 1 while its
 * fragments go out (nothing else may go between them), 0 none, -1
 * close. */
static int send_cloud(struct px_view *v, struct sess *s)
{
	int rc;
	if (!s->cloud) {
		pthread_mutex_lock(&v->mu);
		if (v->cloud && v->cloud->seq != s->cloud_seq) {
			s->cloud = v->cloud;
			s->cloud->refs++;
			s->off = 0;
		}
		pthread_mutex_unlock(&v->mu);
		if (!s->cloud)
			return 0;
	}
	rc = send_big(s, &s->cloud->m);
	if (rc == 0) {
		s->cloud_seq = s->cloud->seq;
		pthread_mutex_lock(&v->mu);
		shared_release(s->cloud);
		pthread_mutex_unlock(&v->mu);
		s->cloud = NULL;
		s->off = 0;
	}
	if (rc >= 0)
		lws_callback_on_writable(s->wsi);
	return rc < 0 ? -1 : 1;
}

/* The connection can take more: the next message. 0 ok, -1 close. */
static int writable(struct px_view *v, struct sess *s)
{
	const struct msg *m;
	uint64_t head;
	size_t len = 0;
	int rc;
	s->waiting_ns = 0;
	while (s->stage < ST_FRAMES && !(m = stage_msg(v, s->stage))) {
		s->stage++;
		s->off = 0;
	}
	if (s->stage < ST_FRAMES) {
		rc = send_big(s, m);
		if (rc < 0)
			return -1;
		if (rc == 0) {
			s->stage++;
			s->off = 0;
		}
		lws_callback_on_writable(s->wsi);
		return 0;
	}
	if (s->stage == ST_DONE)
		return 0;
	rc = send_cloud(v, s);
	if (rc)
		return rc < 0 ? -1 : 0;
	pthread_mutex_lock(&v->mu);
	head = v->head;
	if (s->next < head) {
		const struct slot *sl;
		if (head - s->next > (uint64_t)v->o.queue_frames) {
			/* behind: the newest frame wins */
			atomic_fetch_add(&v->dropped, head - 1 - s->next);
			s->next = head - 1;
		}
		sl = &v->ring[s->next % (uint64_t)v->ring_n];
		len = sl->len;
		memcpy(s->buf + LWS_PRE, sl->text, len);
		s->next++;
	}
	pthread_mutex_unlock(&v->mu);
	if (len) {
		if (lws_write(s->wsi, s->buf + LWS_PRE, len, LWS_WRITE_TEXT) < (int)len)
			return -1;
		atomic_fetch_add(&v->sent, 1);
		if (s->next < head)
			lws_callback_on_writable(s->wsi);
		else if (atomic_load(&v->ended))
			lws_callback_on_writable(s->wsi); /* the end next */
		return 0;
	}
	if (atomic_load(&v->ended)) {
		static const char end[] = "{\"type\":\"end\"}";
		if (send_text(s, end, sizeof(end) - 1))
			return -1;
		s->stage = ST_DONE;
		atomic_fetch_sub(&v->ends_pending, 1);
	}
	return 0;
}

/* Woken by a feed, an end or a stop: every connection is asked for a
 * writable callback; one asked stall_ms ago whose socket has not taken
 * anything since is closed (measured from the ask, not from its last
 * write, so that a server thread kept off the CPU closes nobody). */
static void wake(struct px_view *v)
{
	int64_t t = now_ns();
	uint64_t head;
	int i;
	pthread_mutex_lock(&v->mu);
	head = v->head;
	pthread_mutex_unlock(&v->mu);
	for (i = 0; i < v->n_sess; i++) {
		struct sess *s = v->sess[i];
		if (s->killed)
			continue;
		if (s->waiting_ns &&
		    t - s->waiting_ns > (int64_t)v->o.stall_ms * 1000000) {
			s->killed = 1;
			atomic_fetch_add(&v->closed, 1);
			lws_set_timeout(s->wsi, PENDING_TIMEOUT_USER_OK,
					LWS_TO_KILL_ASYNC);
			continue;
		}
		if (!s->waiting_ns && (s->next < head || s->stage < ST_FRAMES ||
				       s->cloud))
			s->waiting_ns = t;
		lws_callback_on_writable(s->wsi);
	}
}

static int cb_view(struct lws *wsi, enum lws_callback_reasons reason,
		   void *user, void *in, size_t len)
{
	struct px_view *v = lws_context_user(lws_get_context(wsi));
	struct sess *s = user;
	char uri[64];
	(void)in;
	switch (reason) {
	case LWS_CALLBACK_FILTER_PROTOCOL_CONNECTION:
		if (lws_hdr_copy(wsi, uri, sizeof(uri), WSI_TOKEN_GET_URI) <= 0 ||
		    strcmp(uri, "/ws") != 0 || v->n_sess >= v->o.max_clients ||
		    atomic_load(&v->stop)) {
			atomic_fetch_add(&v->refused, 1);
			return 1;
		}
		return 0;
	case LWS_CALLBACK_ESTABLISHED:
		memset(s, 0, sizeof(*s));
		s->v = v;
		s->wsi = wsi;
		s->buf = malloc(LWS_PRE + CHUNK);
		if (!s->buf)
			return -1;
		pthread_mutex_lock(&v->mu);
		s->next = v->head; /* frames from now on */
		pthread_mutex_unlock(&v->mu);
		v->sess[v->n_sess++] = s;
		atomic_fetch_add(&v->clients, 1);
		atomic_fetch_add(&v->ends_pending, 1);
		atomic_fetch_add(&v->connections, 1);
		lws_callback_on_writable(wsi);
		return 0;
	case LWS_CALLBACK_SERVER_WRITEABLE:
		if (!s->buf || s->killed)
			return -1;
		return writable(v, s);
	case LWS_CALLBACK_RECEIVE:
		return 0; /* read-only: nothing a page sends is acted on */
	case LWS_CALLBACK_CLOSED:
		if (s->cloud) {
			pthread_mutex_lock(&v->mu);
			shared_release(s->cloud);
			pthread_mutex_unlock(&v->mu);
			s->cloud = NULL;
		}
		if (s->buf) {
			sess_remove(v, s);
			if (s->stage != ST_DONE)
				atomic_fetch_sub(&v->ends_pending, 1);
			atomic_fetch_sub(&v->clients, 1);
			free(s->buf);
			s->buf = NULL;
		}
		return 0;
	case LWS_CALLBACK_EVENT_WAIT_CANCELLED:
		wake(v);
		return 0;
	default:
		return 0;
	}
	(void)len;
}

/* HTTP: GET only (lws answers 404 for what the web root lacks and 4xx
 * for what it cannot parse); the rest as libwebsockets' own. */
static int cb_http(struct lws *wsi, enum lws_callback_reasons reason,
		   void *user, void *in, size_t len)
{
	if (reason == LWS_CALLBACK_FILTER_HTTP_CONNECTION &&
	    lws_hdr_total_length(wsi, WSI_TOKEN_GET_URI) <= 0) {
		lws_return_http_status(wsi, HTTP_STATUS_METHOD_NOT_ALLOWED, NULL);
		return -1;
	}
	return lws_callback_http_dummy(wsi, reason, user, in, len);
}

static void *service(void *arg)
{
	struct px_view *v = arg;
	while (!atomic_load(&v->stop))
		if (lws_service(v->ctx, 0) < 0)
			break;
	return NULL;
}

static int make_hello(struct px_view *v)
{
	struct view_buf b;
	memset(&b, 0, sizeof(b));
	b.growable = 1;
	view_buf_printf(&b, "{\"type\":\"hello\",\"version\":1,\"mode\":");
	view_buf_str(&b, v->mode);
	view_buf_puts(&b, ",\"name\":");
	view_buf_str(&b, v->name);
	view_buf_printf(&b, ",\"period_ns\":%lld,\"rate_hz\":",
			(long long)v->o.period_ns);
	view_buf_num(&b, v->o.rate_hz, 6);
	view_buf_puts(&b, "}");
	if (b.err) {
		free(b.p);
		return b.err;
	}
	v->hello.p = b.p;
	v->hello.n = b.n;
	return PX_OK;
}

/* px_view_create() with its message always in why (WHY_MAX bytes). */
#define WHY_MAX 320
#define FAIL(rc, ...) (snprintf(why, WHY_MAX, __VA_ARGS__), (rc))
static int create(const struct px_view_options *o, struct px_view **out,
		  char *why)
{
	struct lws_context_creation_info info;
	struct px_view *v;
	char index[PATH_MAX + 16];
	int rc;
	if (!o || !out)
		return FAIL(PX_E_INVAL, "view: no options");
	*out = NULL;
	if (o->port < 1 || o->port > 65535)
		return FAIL(PX_E_INVAL, "view: port %d is not 1..65535",
			    o->port);
	if (!o->web_root || !*o->web_root)
		return FAIL(PX_E_INVAL, "view: no web root folder");
	if (!(o->rate_hz > 0 && o->rate_hz <= 1000) || o->max_clients < 1 ||
	    o->queue_frames < 1 || o->stall_ms < 1 ||
	    (o->mode && strcmp(o->mode, "live") && strcmp(o->mode, "replay")))
		return FAIL(PX_E_INVAL, "view: invalid options");
	v = calloc(1, sizeof(*v));
	if (!v)
		return FAIL(PX_E_NOMEM, "view: out of memory");
	v->o = *o;
	snprintf(v->addr, sizeof(v->addr), "%s", o->addr ? o->addr : "127.0.0.1");
	snprintf(v->name, sizeof(v->name), "%s", o->name ? o->name : "");
	snprintf(v->mode, sizeof(v->mode), "%s", o->mode ? o->mode : "live");
	if (!realpath(o->web_root, v->root)) {
		free(v);
		return FAIL(PX_E_NOTFOUND, "view: web root %s: %s",
			    o->web_root, strerror(errno));
	}
	snprintf(index, sizeof(index), "%s/index.html", v->root);
	if (access(index, R_OK) != 0) {
		free(v);
		return FAIL(PX_E_NOTFOUND,
			    "view: no index.html in %s (make view-web builds the page)",
			    o->web_root);
	}
	pthread_mutex_init(&v->mu, NULL);
	v->ring_n = o->queue_frames + 1;
	v->ring = calloc((size_t)v->ring_n, sizeof(*v->ring));
	v->sess = calloc((size_t)o->max_clients, sizeof(*v->sess));
	v->last_t_s = -1e300;
	if (!v->ring || !v->sess || make_hello(v) != PX_OK) {
		px_view_free(v);
		return FAIL(PX_E_NOMEM, "view: out of memory");
	}
	v->protos[0].name = "http";
	v->protos[0].callback = cb_http;
	v->protos[1].name = PX_VIEW_PROTOCOL;
	v->protos[1].callback = cb_view;
	v->protos[1].per_session_data_size = sizeof(struct sess);
	v->protos[1].rx_buffer_size = 1024;
	v->mount.mountpoint = "/";
	v->mount.mountpoint_len = 1;
	v->mount.origin = v->root;
	v->mount.def = "index.html";
	v->mount.origin_protocol = LWSMPRO_FILE;
	memset(&info, 0, sizeof(info));
	info.port = o->port;
	info.iface = v->addr;
	info.protocols = v->protos;
	info.mounts = &v->mount;
	info.user = v;
	info.options = LWS_SERVER_OPTION_VALIDATE_UTF8;
	if (!strchr(v->addr, ':'))
		info.options |= LWS_SERVER_OPTION_DISABLE_IPV6;
	lws_last[0] = '\0';
	lws_set_log_level(LLL_ERR, lws_emit);
	v->ctx = lws_create_context(&info);
	if (!v->ctx) {
		rc = FAIL(PX_E_IO, "view: cannot listen on %.63s:%d (the port taken, or "
			  "the address not this machine's)%s%.160s",
			  v->addr, o->port, lws_last[0] ? ": " : "", lws_last);
		px_view_free(v);
		return rc;
	}
	*out = v;
	return PX_OK;
}

#undef FAIL

int px_view_create(const struct px_view_options *o, struct px_view **out,
		   char *msg, size_t cap)
{
	char why[WHY_MAX] = "";
	int rc = create(o, out, why);
	if (msg && cap)
		snprintf(msg, cap, "%s", why);
	return rc;
}

int px_view_port(const struct px_view *v)
{
	return v ? v->o.port : PX_E_INVAL;
}

static int set_msg(struct px_view *v, struct msg *m, const char *json,
		   size_t len)
{
	char *p;
	if (!v || !json || v->started)
		return PX_E_INVAL;
	p = malloc(len + 1);
	if (!p)
		return PX_E_NOMEM;
	memcpy(p, json, len);
	p[len] = '\0';
	free(m->p);
	m->p = p;
	m->n = len;
	return PX_OK;
}

int px_view_set_scene(struct px_view *v, const char *json, size_t len)
{
	return v ? set_msg(v, &v->scene, json, len) : PX_E_INVAL;
}

int px_view_set_track(struct px_view *v, const char *json, size_t len)
{
	return v ? set_msg(v, &v->track, json, len) : PX_E_INVAL;
}

int px_view_set_sources(struct px_view *v, const struct px_view_sources *src)
{
	size_t i, n;
	if (!v || !src)
		return PX_E_INVAL;
	if (v->started)
		return PX_E_STATE;
	free(v->ref_pose);
	free(v->cloud_xyz);
	v->ref_pose = NULL;
	v->cloud_xyz = NULL;
	v->ref_n = 0;
	v->src = *src;
	/* the scene's poses now: a model away from its pose is "moved" */
	n = src->scene ? px_scene_count(src->scene) : 0;
	if (n > 1024)
		n = 1024; /* the first ones are watched */
	if (n) {
		v->ref_pose = malloc(n * sizeof(*v->ref_pose));
		if (!v->ref_pose)
			return PX_E_NOMEM;
		for (i = 0; i < n; i++)
			v->ref_pose[i] = px_model_pose(px_scene_model(src->scene, i));
		v->ref_n = n;
	}
	if (src->cloud_feed) {
		v->cloud_xyz = malloc(3 * sizeof(float) * PX_VIEW_CLOUD_MAX);
		if (!v->cloud_xyz)
			return PX_E_NOMEM;
	}
	return PX_OK;
}

int px_view_start(struct px_view *v)
{
	if (!v)
		return PX_E_INVAL;
	if (v->started)
		return PX_E_STATE;
	if (!v->scene.p) {
		static const char none[] =
			"{\"type\":\"scene\",\"models\":[],\"tool\":{\"radius_m\":0},"
			"\"robot\":null,\"bounds\":[-0.1,-0.1,-0.1,0.1,0.1,0.1]}";
		int rc = set_msg(v, &v->scene, none, sizeof(none) - 1);
		if (rc)
			return rc;
	}
	if (pthread_create(&v->th, NULL, service, v) != 0)
		return PX_E_NOMEM;
	v->started = 1;
	return PX_OK;
}

int px_view_feed_json(struct px_view *v, const char *json, size_t len)
{
	struct slot *sl;
	if (!v || !json || len == 0 || len > PX_VIEW_FRAME_MAX)
		return PX_E_INVAL;
	pthread_mutex_lock(&v->mu);
	sl = &v->ring[v->head % (uint64_t)v->ring_n];
	memcpy(sl->text, json, len);
	sl->len = len;
	sl->seq = v->head++;
	pthread_mutex_unlock(&v->mu);
	atomic_fetch_add(&v->fed, 1);
	if (v->started)
		lws_cancel_service(v->ctx);
	return PX_OK;
}

/* The models away from their pose when the sources were set. */
static void moved_models(struct px_view *v, struct px_view_frame_extra *x)
{
	size_t i;
	for (i = 0; i < v->ref_n && x->n_models < PX_VIEW_MAX_MOVED; i++) {
		px_pose P = px_model_pose(px_scene_model(v->src.scene, i));
		double *m = x->models[x->n_models];
		if (!memcmp(&P, &v->ref_pose[i], sizeof(P)))
			continue;
		m[0] = (double)i;
		m[1] = P.t.x, m[2] = P.t.y, m[3] = P.t.z;
		m[4] = P.q.w, m[5] = P.q.x, m[6] = P.q.y, m[7] = P.q.z;
		x->n_models++;
	}
}

/* A newer cloud than the last sent: pinned while copied (the producer
 * cannot rebuild it meanwhile), then the message every connection
 * sends next. The far point of an empty frame is no point. */
static void feed_cloud(struct px_view *v, double t_s)
{
	struct px_cloud_feed_stats st;
	struct shared *sh, *old;
	struct px_model *m;
	uint64_t frame;
	size_t n, step, i, k = 0;
	char *json;
	size_t len;
	px_cloud_feed_stats(v->src.cloud_feed, &st);
	if (!st.taken)
		return;
	m = px_cloud_feed_pin(v->src.cloud_feed, &frame);
	if (!m || frame == v->cloud_frame) {
		px_cloud_feed_unpin(v->src.cloud_feed);
		return;
	}
	n = px_cloud_point_count(m);
	step = n > PX_VIEW_CLOUD_MAX ? (n + PX_VIEW_CLOUD_MAX - 1) / PX_VIEW_CLOUD_MAX : 1;
	for (i = 0; i < n && k < PX_VIEW_CLOUD_MAX; i += step) {
		px_vec3 p;
		if (px_cloud_point(m, i, &p) != PX_OK ||
		    fabs(p.z) >= 0.5 * PX_CLOUD_FEED_FAR_M)
			continue;
		v->cloud_xyz[3 * k] = (float)p.x;
		v->cloud_xyz[3 * k + 1] = (float)p.y;
		v->cloud_xyz[3 * k + 2] = (float)p.z;
		k++;
	}
	px_cloud_feed_unpin(v->src.cloud_feed);
	v->cloud_frame = frame;
	if (px_view_cloud_json(v->src.cloud_id, t_s, v->cloud_xyz, k, &json, &len))
		return;
	sh = malloc(sizeof(*sh));
	if (!sh) {
		free(json);
		return;
	}
	sh->refs = 1;
	sh->seq = ++v->cloud_seq;
	sh->m.p = json;
	sh->m.n = len;
	pthread_mutex_lock(&v->mu);
	old = v->cloud;
	v->cloud = sh;
	shared_release(old);
	pthread_mutex_unlock(&v->mu);
}

int px_view_feed_record(struct px_view *v, const struct px_app_record *r)
{
	int n;
	if (!v || !r)
		return 0;
	/* decimated by loop time; a clock that went back (a new run)
	 * starts again */
	if (r->t_s >= v->last_t_s && r->t_s - v->last_t_s < 0.999 / v->o.rate_hz)
		return 0;
	v->last_t_s = r->t_s;
	px_view_frame_fill(&v->src, r, &v->extra);
	moved_models(v, &v->extra);
	if (v->src.cloud_feed)
		feed_cloud(v, r->t_s); /* before the frame: the page has both */
	n = px_view_frame_json_extra(r, &v->extra, 1, v->fbuf, sizeof(v->fbuf));
	if (n <= 0)
		return 0;
	return px_view_feed_json(v, v->fbuf, (size_t)n) == PX_OK;
}

void px_view_end(struct px_view *v)
{
	if (!v)
		return;
	atomic_store(&v->ended, 1);
	if (v->started)
		lws_cancel_service(v->ctx);
}

void px_view_stats(struct px_view *v, struct px_view_stats *s)
{
	if (!s)
		return;
	memset(s, 0, sizeof(*s));
	if (!v)
		return;
	s->clients = atomic_load(&v->clients);
	s->connections = atomic_load(&v->connections);
	s->frames_fed = atomic_load(&v->fed);
	s->frames_sent = atomic_load(&v->sent);
	s->frames_dropped = atomic_load(&v->dropped);
	s->clients_closed = atomic_load(&v->closed);
	s->refused = atomic_load(&v->refused);
}

void px_view_stop(struct px_view *v, int wait_ms)
{
	int64_t until;
	if (!v || !v->started)
		return;
	px_view_end(v);
	until = now_ns() + (int64_t)wait_ms * 1000000;
	while (atomic_load(&v->ends_pending) > 0 && now_ns() < until) {
		struct timespec ts = {0, 5000000};
		nanosleep(&ts, NULL);
	}
	atomic_store(&v->stop, 1);
	lws_cancel_service(v->ctx);
	pthread_join(v->th, NULL);
	v->started = 0;
}

void px_view_free(struct px_view *v)
{
	if (!v)
		return;
	px_view_stop(v, 0);
	if (v->ctx)
		lws_context_destroy(v->ctx); /* closes what is still open */
	pthread_mutex_destroy(&v->mu);
	free(v->ring);
	free(v->sess);
	free(v->hello.p);
	free(v->scene.p);
	free(v->track.p);
	shared_release(v->cloud);
	free(v->ref_pose);
	free(v->cloud_xyz);
	free(v);
}
