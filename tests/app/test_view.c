/* The browser view's server (view/px_view.h) with a WebSocket client
 * written here on a plain socket: the messages of a connection, the
 * frames against the records fed, malformed requests, and a loop that
 * runs the same with clients that never read or vanish.
 * PX_TEST_NEEDS: libwebsockets */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_cloud_feed.h"
#include "px_control.h"
#include "px_app.h"
#include "px_config.h"
#include "px_prim.h"
#include "px_scene.h"
#include "px_test.h"
#include "px_test_app.h"
#include "px_view.h"

#define HAPTIC_SIM "config/examples/haptic_sim.yaml"
#define AVOID_URDF "config/examples/can_avoid_urdf.yaml"

static char root[64];

/* A folder with a page, once. */
static const char *web_root(void)
{
	FILE *f;
	char path[96];
	if (root[0])
		return root;
	snprintf(root, sizeof(root), "/tmp/px-view-test-%d", (int)getpid());
	mkdir(root, 0700);
	snprintf(path, sizeof(path), "%s/index.html", root);
	f = fopen(path, "w");
	PX_CHECK(f != NULL);
	fputs("<html><body>view</body></html>\n", f);
	fclose(f);
	return root;
}

/* A port free now (bound to 0 and let go). */
static int free_port(void)
{
	struct sockaddr_in a;
	socklen_t n = sizeof(a);
	int fd = socket(AF_INET, SOCK_STREAM, 0), port;
	memset(&a, 0, sizeof(a));
	a.sin_family = AF_INET;
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	PX_CHECK(bind(fd, (struct sockaddr *)&a, sizeof(a)) == 0);
	PX_CHECK(getsockname(fd, (struct sockaddr *)&a, &n) == 0);
	port = ntohs(a.sin_port);
	close(fd);
	return port;
}

static int connect_to(int port)
{
	struct sockaddr_in a;
	int fd = socket(AF_INET, SOCK_STREAM, 0);
	memset(&a, 0, sizeof(a));
	a.sin_family = AF_INET;
	a.sin_port = htons((uint16_t)port);
	a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
	PX_CHECK(connect(fd, (struct sockaddr *)&a, sizeof(a)) == 0);
	return fd;
}

/* Read exactly n bytes within timeout_ms; 0 ok, -1 not. */
static int read_n(int fd, unsigned char *buf, size_t n, int timeout_ms)
{
	size_t got = 0;
	while (got < n) {
		struct pollfd p = {fd, POLLIN, 0};
		ssize_t k;
		if (poll(&p, 1, timeout_ms) <= 0)
			return -1;
		k = read(fd, buf + got, n - got);
		if (k <= 0)
			return -1;
		got += (size_t)k;
	}
	return 0;
}

/* An HTTP request; the status line's code, or -1 when the server closed
 * without one. */
static int http_status(int port, const char *request)
{
	char buf[512];
	size_t got = 0;
	int fd = connect_to(port), code = -1;
	PX_CHECK(write(fd, request, strlen(request)) == (ssize_t)strlen(request));
	while (got < sizeof(buf) - 1) {
		struct pollfd p = {fd, POLLIN, 0};
		ssize_t k;
		if (poll(&p, 1, 2000) <= 0)
			break;
		k = read(fd, buf + got, sizeof(buf) - 1 - got);
		if (k <= 0)
			break;
		got += (size_t)k;
		buf[got] = '\0';
		if (strstr(buf, "\r\n"))
			break;
	}
	buf[got] = '\0';
	if (!strncmp(buf, "HTTP/1.", 7))
		code = atoi(buf + 9);
	close(fd);
	return code;
}

/* The WebSocket handshake on /ws; the socket, the response checked. */
static int ws_open(int port, const char *path)
{
	char req[512], resp[1024] = "";
	size_t got = 0;
	int fd = connect_to(port);
	snprintf(req, sizeof(req),
		 "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\n"
		 "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
		 "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: %s\r\n\r\n",
		 path, port, PX_VIEW_PROTOCOL);
	PX_CHECK(write(fd, req, strlen(req)) == (ssize_t)strlen(req));
	while (got < sizeof(resp) - 1 && !strstr(resp, "\r\n\r\n")) {
		if (read_n(fd, (unsigned char *)resp + got, 1, 2000))
			break;
		resp[++got] = '\0';
	}
	resp[got] = '\0';
	if (strncmp(resp, "HTTP/1.1 101", 12) != 0) {
		if (getenv("PX_VIEW_TEST_DEBUG"))
			fprintf(stderr, "handshake: %s\n", resp);
		close(fd);
		return -1;
	}
	PX_CHECK(strstr(resp, "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=") != NULL);
	return fd;
}

/* One whole text message (fragments joined), malloc'd; NULL on close or
 * timeout. */
static char *ws_read(int fd, int timeout_ms)
{
	char *msg = NULL;
	size_t n = 0;
	for (;;) {
		unsigned char h[2], ext[8];
		uint64_t len;
		int fin, op, i;
		char *p;
		if (read_n(fd, h, 2, timeout_ms))
			break;
		fin = h[0] & 0x80;
		op = h[0] & 0x0f;
		len = h[1] & 0x7f;
		PX_CHECK(!(h[1] & 0x80)); /* a server never masks */
		if (len == 126) {
			if (read_n(fd, ext, 2, timeout_ms))
				break;
			len = (uint64_t)ext[0] << 8 | ext[1];
		} else if (len == 127) {
			if (read_n(fd, ext, 8, timeout_ms))
				break;
			for (len = 0, i = 0; i < 8; i++)
				len = len << 8 | ext[i];
		}
		PX_CHECK(len < 64u << 20);
		p = realloc(msg, n + len + 1);
		PX_CHECK(p != NULL);
		msg = p;
		if (len && read_n(fd, (unsigned char *)msg + n, len, timeout_ms))
			break;
		if (op == 8)
			break; /* close */
		n += len;
		msg[n] = '\0';
		if (fin)
			return msg;
	}
	free(msg);
	return NULL;
}

static double num_after(const char *s, const char *key)
{
	const char *p = strstr(s, key);
	PX_CHECK_MSG(p != NULL, "no %s in %.200s", key, s);
	return strtod(p + strlen(key), NULL);
}

/* A started view of scene sc (may be NULL) whose frames take src (may
 * be NULL: none). */
static struct px_view *make_view_src(int port, const struct px_scene *sc,
				     const struct px_view_sources *src)
{
	struct px_view_options o;
	struct px_view *v = NULL;
	char msg[256], *scene;
	size_t len;
	px_view_options_default(&o);
	o.port = port;
	o.web_root = web_root();
	o.name = "test";
	o.stall_ms = 300;
	PX_CHECK_MSG(px_view_create(&o, &v, msg, sizeof(msg)) == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_view_scene_json(sc, NULL, &scene, &len), PX_OK);
	PX_CHECK_INT_EQ(px_view_set_scene(v, scene, len), PX_OK);
	free(scene);
	if (src)
		PX_CHECK_INT_EQ(px_view_set_sources(v, src), PX_OK);
	PX_CHECK_INT_EQ(px_view_start(v), PX_OK);
	if (src)
		PX_CHECK_INT_EQ(px_view_set_sources(v, src), PX_E_STATE);
	return v;
}

static struct px_view *make_view(int port, const struct px_scene *sc)
{
	return make_view_src(port, sc, NULL);
}

static void sleep_ms(int ms)
{
	struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000};
	nanosleep(&ts, NULL);
}

/* hello, scene (the sphere), the frames fed (positions as fed), end. */
static void test_messages_of_a_connection(void)
{
	struct px_scene *sc;
	struct px_model *m;
	struct px_prim p = {PX_PRIM_SPHERE, 0.05, 0, 0};
	struct px_view *v;
	int port = free_port(), fd, i;
	char *s;
	PX_NEEDS(VIEW);
	PX_CHECK_INT_EQ(px_scene_create(4, &sc), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_OK);
	PX_CHECK(px_scene_add(sc, m, "ball") >= 0);
	v = make_view(port, sc);
	PX_CHECK_INT_EQ(http_status(port, "GET / HTTP/1.1\r\nHost: x\r\n\r\n"), 200);
	fd = ws_open(port, "/ws");
	PX_CHECK(fd >= 0);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"type\":\"hello\"") && strstr(s, "\"mode\":\"live\""));
	free(s);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"type\":\"scene\"") && strstr(s, "\"name\":\"ball\"") &&
		 strstr(s, "\"kind\":\"prim\""));
	PX_CHECK_NEAR(num_after(s, "\"bounds\":["), -0.05, 1e-3);
	free(s);
	for (i = 0; i < 5; i++) {
		struct px_app_record r;
		memset(&r, 0, sizeof(r));
		r.t_s = 0.1 * i;
		r.cycle = (uint64_t)(100 * i);
		r.dev_m[0] = 0.01 * i;
		r.dev_m[1] = -0.02;
		r.dev_m[2] = 0.5;
		r.distance_m = i == 2 ? NAN : 0.1;
		PX_CHECK_INT_EQ(px_view_feed_record(v, &r), 1);
		/* within 1/rate: decimated away */
		r.t_s += 0.001;
		PX_CHECK_INT_EQ(px_view_feed_record(v, &r), 0);
		s = ws_read(fd, 2000);
		PX_CHECK(s && strstr(s, "\"type\":\"frame\""));
		PX_CHECK_NEAR(num_after(s, "\"tool\":["), 0.01 * i, 1e-12);
		PX_CHECK_INT_EQ((long long)num_after(s, "\"cycle\":"), 100 * i);
		if (i == 2)
			PX_CHECK(strstr(s, "\"distance_m\":null") != NULL);
		free(s);
	}
	px_view_end(v);
	s = ws_read(fd, 2000);
	PX_CHECK(s && !strcmp(s, "{\"type\":\"end\"}"));
	free(s);
	close(fd);
	px_view_free(v);
	px_scene_free(sc);
}

/* Malformed and refused requests get an error; the server goes on. */
static void test_bad_requests_answered(void)
{
	struct px_view *v;
	int port = free_port(), fd;
	char *s;
	PX_NEEDS(VIEW);
	v = make_view(port, NULL);
	PX_CHECK_INT_EQ(http_status(port, "GET /nothing.js HTTP/1.1\r\nHost: x\r\n\r\n"), 404);
	PX_CHECK_INT_EQ(http_status(port, "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\n\r\n"), 405);
	PX_CHECK(http_status(port, "GARBAGE\r\n\r\n") != 200);
	PX_CHECK(http_status(port, "GET /../../etc/passwd HTTP/1.1\r\nHost: x\r\n\r\n") != 200);
	PX_CHECK(ws_open(port, "/other") < 0); /* the WebSocket is on /ws only */
	PX_CHECK_INT_EQ(http_status(port, "GET / HTTP/1.1\r\nHost: x\r\n\r\n"), 200);
	fd = ws_open(port, "/ws");
	PX_CHECK(fd >= 0);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"type\":\"hello\""));
	free(s);
	close(fd);
	px_view_free(v);
}

/* A client that never reads falls behind: frames dropped, then closed;
 * the feed never waits. */
static void test_slow_client_dropped_and_closed(void)
{
	static char big[PX_VIEW_FRAME_MAX];
	struct px_view *v;
	struct px_view_stats st;
	struct timespec t0;
	int port = free_port(), fd, i, sz = 4096;
	PX_NEEDS(VIEW);
	v = make_view(port, NULL);
	fd = ws_open(port, "/ws");
	PX_CHECK(fd >= 0);
	/* a small receive buffer so that it fills soon */
	setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &sz, sizeof(sz));
	memset(big, ' ', sizeof(big));
	big[0] = '{';
	big[sizeof(big) - 1] = '}';
	clock_gettime(CLOCK_MONOTONIC, &t0);
	/* frames until the server gives up on the client (at most 30 s) */
	for (i = 0;; i++) {
		struct timespec a, b;
		int64_t took;
		clock_gettime(CLOCK_MONOTONIC, &a);
		PX_CHECK_INT_EQ(px_view_feed_json(v, big, sizeof(big)), PX_OK);
		clock_gettime(CLOCK_MONOTONIC, &b);
		took = (b.tv_sec - a.tv_sec) * 1000000000LL + (b.tv_nsec - a.tv_nsec);
		PX_CHECK_MSG(took < 50000000, "a feed took %lld ns", (long long)took);
		if (i % 10 == 0)
			sleep_ms(1);
		px_view_stats(v, &st);
		if (st.clients_closed || b.tv_sec - t0.tv_sec > 30)
			break;
	}
	px_view_stats(v, &st);
	if (getenv("PX_VIEW_TEST_DEBUG"))
		fprintf(stderr, "i %d fed %llu sent %llu dropped %llu closed %llu\n", i,
			(unsigned long long)st.frames_fed, (unsigned long long)st.frames_sent,
			(unsigned long long)st.frames_dropped, (unsigned long long)st.clients_closed);
	PX_CHECK(st.frames_dropped > 0);
	PX_CHECK_INT_EQ((long long)st.clients_closed, 1);
	close(fd);
	px_view_free(v);
}

/* The record hook of a run with a view: feeds it. */
static void feed(void *user, const struct px_app_record *r)
{
	px_view_feed_record(user, r);
}

struct run {
	uint64_t cycles, allocs, overruns;
	double max_force_n, min_distance_m;
};

static struct run run_app(int virtual_time, double dur_s, struct px_view *v)
{
	struct px_config *cfg = NULL;
	static struct px_config_diag diag;
	struct px_app_options o;
	struct px_app *app = NULL;
	struct px_app_summary s;
	struct run out;
	char msg[256];
	PX_CHECK_INT_EQ(px_config_load_file(HAPTIC_SIM, &cfg, &diag), PX_OK);
	px_app_options_default(&o);
	o.config = HAPTIC_SIM;
	o.virtual_time = virtual_time;
	o.duration_s = dur_s;
	o.note = px_test_app_note;
	o.heap_count = px_alloc_count_thread;
	o.telemetry = "build/tests/view-telemetry.csv";
	if (v) {
		o.record = feed;
		o.user = v;
	}
	PX_CHECK_MSG(px_app_create(cfg, &o, &app, msg, sizeof(msg)) == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	px_app_drain(app, v ? feed : NULL, v);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	out.cycles = s.cycles;
	out.allocs = s.allocations_after_setup;
	out.overruns = s.overruns;
	out.max_force_n = s.max_force_n;
	out.min_distance_m = s.min_distance_m;
	px_app_free(app);
	px_config_free(cfg);
	return out;
}

/* The same run with and without a view and clients (one reading, one
 * never reading, one gone): the same cycles and figures, no heap call
 * after setup, on the virtual clock and on the real one. */
static void test_loop_unaffected_by_clients(void)
{
	struct px_view *v;
	struct px_view_stats st;
	struct run a, b;
	int port = free_port(), reader, idle, gone, k;
	PX_NEEDS(VIEW);
	if (!strcmp(px_alloc_count_mode(), "none"))
		PX_SKIP("no allocation counter in this build");
	a = run_app(1, 2.0, NULL);
	v = make_view(port, NULL);
	reader = ws_open(port, "/ws");
	idle = ws_open(port, "/ws");
	gone = ws_open(port, "/ws");
	PX_CHECK(reader >= 0 && idle >= 0 && gone >= 0);
	close(gone);
	PX_CHECK(http_status(port, "BAD\r\n\r\n") != 200);
	b = run_app(1, 2.0, v);
	PX_CHECK_INT_EQ((long long)b.cycles, (long long)a.cycles);
	PX_CHECK_INT_EQ((long long)a.allocs, 0);
	PX_CHECK_INT_EQ((long long)b.allocs, 0);
	PX_CHECK_NEAR(b.max_force_n, a.max_force_n, 0);
	PX_CHECK_NEAR(b.min_distance_m, a.min_distance_m, 0);
	/* the reading client got frames */
	for (k = 0; k < 5; k++) {
		char *s = ws_read(reader, 2000);
		PX_CHECK(s != NULL);
		free(s);
	}
	px_view_stats(v, &st);
	PX_CHECK(st.frames_fed >= 59 && st.frames_fed <= 61);
	/* the real clock: 0.3 s each way, no heap call after setup */
	a = run_app(0, 0.3, NULL);
	b = run_app(0, 0.3, v);
	PX_CHECK_INT_EQ((long long)a.allocs, 0);
	PX_CHECK_INT_EQ((long long)b.allocs, 0);
	/* (how many cycles the real clock allowed depends on the machine's
	 * load, not on the view) */
	PX_CHECK(b.cycles > 0 && a.cycles > 0);
	close(reader);
	close(idle);
	px_view_free(v);
}

/* A port taken: create fails saying so. */
static void test_port_taken(void)
{
	struct px_view_options o;
	struct px_view *v = NULL, *w = NULL;
	char msg[256];
	int port = free_port();
	PX_NEEDS(VIEW);
	v = make_view(port, NULL);
	px_view_options_default(&o);
	o.port = port;
	o.web_root = web_root();
	PX_CHECK_INT_EQ(px_view_create(&o, &w, msg, sizeof(msg)), PX_E_IO);
	PX_CHECK(w == NULL && strstr(msg, "cannot listen"));
	o.web_root = "/nonexistent-folder";
	PX_CHECK_INT_EQ(px_view_create(&o, &w, msg, sizeof(msg)), PX_E_NOTFOUND);
	px_view_free(v);
}

/* A chain of two revolute joints with a capsule on each link, as an
 * arm the view draws (no URDF: the capsules are the links). */
static void two_link_chain(struct px_control_chain *c)
{
	px_control_chain_init(c, px_pose_identity());
	PX_CHECK_INT_EQ(px_control_chain_add_dh(c, PX_CONTROL_REVOLUTE, 0.4, 0, 0.1, 0), PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_dh(c, PX_CONTROL_REVOLUTE, 0.3, 0, 0, 0), PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_capsule(c, 1, px_v3(-0.4, 0, 0), px_v3(0, 0, 0), 0.03),
			PX_OK);
	PX_CHECK_INT_EQ(px_control_chain_add_capsule(c, 2, px_v3(-0.3, 0, 0), px_v3(0, 0, 0), 0.02),
			PX_OK);
}

/* scene.robot: a link per capsule, tessellated, with the distances;
 * frame.links: the capsules' poses by forward kinematics of the
 * record's joint positions; frame.clearances: the record's closest
 * pair inside the influence distance only. */
static void test_arm_links_and_clearances(void)
{
	struct px_control_chain c;
	struct px_app_arm in;
	struct px_view_arm *arm;
	struct px_view_scene_info info;
	struct px_view_sources src;
	struct px_view_frame_extra x;
	struct px_app_record r;
	px_pose frames[3];
	double q[2] = {0.7, -0.4}, poses[PX_VIEW_MAX_LINKS][7], before[7];
	char *json, buf[PX_VIEW_FRAME_MAX];
	size_t len;
	int n, k;
	two_link_chain(&c);
	memset(&in, 0, sizeof(in));
	in.chain = &c;
	in.record_joints = 2;
	in.protective_distance_m = 0.05;
	in.influence_distance_m = 0.2;
	PX_CHECK_INT_EQ(px_view_arm_create(&in, &arm), PX_OK);
	PX_CHECK_INT_EQ(px_view_arm_link_count(arm), 2);
	memset(&info, 0, sizeof(info));
	info.arm = arm;
	PX_CHECK_INT_EQ(px_view_scene_json(NULL, &info, &json, &len), PX_OK);
	PX_CHECK(strstr(json, "\"robot\":{\"links\":[{\"name\":\"capsule 0 (link 1)\",\"positions\":[") &&
		 strstr(json, "\"name\":\"capsule 1 (link 2)\""));
	PX_CHECK_NEAR(num_after(json, "\"protective_distance_m\":"), 0.05, 1e-12);
	PX_CHECK_NEAR(num_after(json, "\"influence_distance_m\":"), 0.2, 1e-12);
	PX_CHECK(strstr(json, "\"indices\":[]") == NULL);
	free(json);
	/* the links at q: each capsule's middle where the chain puts it */
	memset(&r, 0, sizeof(r));
	r.q[0] = (float)q[0];
	r.q[1] = (float)q[1];
	r.valid = 1;
	q[0] = r.q[0];
	q[1] = r.q[1];
	PX_CHECK_INT_EQ(px_control_chain_fk(&c, q, frames, 3), PX_OK);
	n = px_view_arm_links(arm, &r, poses, PX_VIEW_MAX_LINKS);
	PX_CHECK_INT_EQ(n, 2);
	for (k = 0; k < 2; k++) {
		px_vec3 mid = px_pose_transform_point(frames[k + 1],
						      px_v3(k ? -0.15 : -0.2, 0, 0));
		PX_CHECK_NEAR(poses[k][0], mid.x, 1e-7);
		PX_CHECK_NEAR(poses[k][1], mid.y, 1e-7);
		PX_CHECK_NEAR(poses[k][2], mid.z, 1e-7);
	}
	memcpy(before, poses[1], sizeof(before));
	r.q[1] = 0.3f;
	PX_CHECK_INT_EQ(px_view_arm_links(arm, &r, poses, PX_VIEW_MAX_LINKS), 2);
	PX_CHECK(fabs(poses[1][0] - before[0]) + fabs(poses[1][1] - before[1]) > 1e-3);
	PX_CHECK_INT_EQ(px_view_arm_links(arm, &r, poses, 1), PX_E_NOSPC);
	/* the frame: links, and the pair within the influence distance */
	memset(&src, 0, sizeof(src));
	src.arm = arm;
	r.dev_m[0] = 0.5, r.proxy_m[0] = 0.6;
	r.distance_m = 0.1;
	px_view_frame_fill(&src, &r, &x);
	PX_CHECK_INT_EQ(x.n_links, 2);
	PX_CHECK_INT_EQ(x.n_clearances, 1);
	PX_CHECK(!x.has_closest);
	n = px_view_frame_json_extra(&r, &x, 1, buf, sizeof(buf));
	PX_CHECK(n > 0 && strstr(buf, "\"links\":[[") && strstr(buf, "\"closest\":null"));
	PX_CHECK_NEAR(num_after(buf, "\"clearances\":[["), 0.5, 1e-12);
	PX_CHECK_NEAR(num_after(buf, "0.6,0,0,"), 0.1, 1e-12);
	r.distance_m = 0.2; /* nothing within the influence distance */
	px_view_frame_fill(&src, &r, &x);
	PX_CHECK_INT_EQ(x.n_clearances, 0);
	PX_CHECK(px_view_frame_json_extra(&r, &x, 1, buf, sizeof(buf)) > 0 &&
		 !strstr(buf, "clearances"));
	/* a chain with more joints than the record carries: no links */
	in.record_joints = 1;
	px_view_arm_free(arm);
	PX_CHECK_INT_EQ(px_view_arm_create(&in, &arm), PX_OK);
	PX_CHECK_INT_EQ(px_view_arm_links(arm, &r, poses, PX_VIEW_MAX_LINKS), 0);
	px_view_arm_free(arm);
}

/* A haptic run's frame: the scene's point nearest the tool. */
static void test_closest_point(void)
{
	struct px_scene *sc;
	struct px_model *m;
	struct px_prim p = {PX_PRIM_SPHERE, 0.1, 0, 0};
	struct px_view_sources src;
	struct px_view_frame_extra x;
	struct px_app_record r;
	char buf[PX_VIEW_FRAME_MAX];
	PX_CHECK_INT_EQ(px_scene_create(4, &sc), PX_OK);
	PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_OK);
	PX_CHECK(px_scene_add(sc, m, "ball") >= 0);
	memset(&src, 0, sizeof(src));
	memset(&r, 0, sizeof(r));
	src.scene = sc;
	r.dev_m[0] = 0.3;
	px_view_frame_fill(&src, &r, &x);
	PX_CHECK(x.has_closest);
	PX_CHECK(px_view_frame_json_extra(&r, &x, 0, buf, sizeof(buf)) > 0);
	PX_CHECK_NEAR(num_after(buf, "\"closest\":["), 0.1, 1e-9);
	PX_CHECK(!strstr(buf, "\"links\"") && !strstr(buf, "\"type\""));
	px_scene_free(sc);
	/* no scene: null */
	src.scene = NULL;
	px_view_frame_fill(&src, &r, &x);
	PX_CHECK(px_view_frame_json_extra(&r, &x, 1, buf, sizeof(buf)) > 0 &&
		 strstr(buf, "\"closest\":null"));
}

/* A model posed anew after the sources were set: its pose in every
 * frame (frame.models), the others not; the closest point follows it. */
static void test_moved_models(void)
{
	struct px_scene *sc;
	struct px_model *m;
	struct px_prim p = {PX_PRIM_SPHERE, 0.05, 0, 0};
	struct px_view_sources src;
	struct px_app_record r;
	struct px_view *v;
	px_pose P = px_pose_identity();
	int port = free_port(), fd, i;
	char *s;
	PX_NEEDS(VIEW);
	PX_CHECK_INT_EQ(px_scene_create(4, &sc), PX_OK);
	for (i = 0; i < 2; i++) {
		PX_CHECK_INT_EQ(px_prim_model(&p, &m), PX_OK);
		PX_CHECK(px_scene_add(sc, m, i ? "still" : "moving") >= 0);
	}
	memset(&src, 0, sizeof(src));
	src.scene = sc;
	v = make_view_src(port, sc, &src);
	fd = ws_open(port, "/ws");
	PX_CHECK(fd >= 0);
	for (i = 0; i < 2; i++)
		free(ws_read(fd, 2000)); /* hello, scene */
	memset(&r, 0, sizeof(r));
	r.dev_m[0] = 0.5;
	PX_CHECK_INT_EQ(px_view_feed_record(v, &r), 1);
	s = ws_read(fd, 2000);
	PX_CHECK(s && !strstr(s, "\"models\"") && strstr(s, "\"closest\":["));
	PX_CHECK_NEAR(num_after(s, "\"closest\":["), 0.05, 1e-9);
	free(s);
	P.t = px_v3(0.2, 0, 0);
	PX_CHECK_INT_EQ(px_scene_set_pose(sc, 0, P), PX_OK);
	r.t_s = 1;
	PX_CHECK_INT_EQ(px_view_feed_record(v, &r), 1);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"models\":[[0,0.2,0,0,1,0,0,0]]"));
	PX_CHECK_NEAR(num_after(s, "\"closest\":["), 0.25, 1e-9);
	free(s);
	close(fd);
	px_view_free(v);
	px_scene_free(sc);
}

/* A cloud message keeps at most PX_VIEW_CLOUD_MAX points. */
static void test_cloud_message(void)
{
	size_t n = 50000, i, len, commas = 0;
	float *xyz = malloc(3 * n * sizeof(float));
	char *json, *p;
	PX_CHECK(xyz != NULL);
	for (i = 0; i < 3 * n; i++)
		xyz[i] = (float)(i % 7) * 0.25f;
	PX_CHECK_INT_EQ(px_view_cloud_json(3, 1.5, xyz, n, &json, &len), PX_OK);
	PX_CHECK(strstr(json, "{\"type\":\"cloud\",\"id\":3,\"t_s\":1.5,\"positions\":[") == json);
	for (p = strstr(json, "\"positions\":["); *p; p++)
		commas += *p == ',';
	PX_CHECK((commas + 1) % 3 == 0);
	PX_CHECK((commas + 1) / 3 <= PX_VIEW_CLOUD_MAX && (commas + 1) / 3 >= PX_VIEW_CLOUD_MAX / 2);
	free(json);
	PX_CHECK_INT_EQ(px_view_cloud_json(3, 0, xyz, 0, &json, &len), PX_OK);
	PX_CHECK(strstr(json, "\"positions\":[]}") != NULL);
	free(json);
	free(xyz);
}

struct arm_run {
	uint64_t cycles, allocs;
	double min_clearance_m;
};

/* The view the arm run feeds once it exists (the app is made first:
 * the view's sources are the app's). */
static struct px_view *arm_view;

static void feed_arm(void *user, const struct px_app_record *r)
{
	(void)user;
	if (arm_view)
		px_view_feed_record(arm_view, r);
}

/* A view of app's arm and cloud as proxima-run makes it; *fd a page
 * connected before the run. */
static struct px_view *arm_view_make(struct px_app *app, int port,
				     struct px_view_arm **va, int *fd)
{
	struct px_app_arm arm;
	struct px_view_options vo;
	struct px_view_scene_info info;
	struct px_view_sources src;
	struct px_view *v = NULL;
	char msg[256], *scene;
	size_t len;
	PX_CHECK_INT_EQ(px_app_arm(app, &arm), 1);
	PX_CHECK(arm.robot != NULL && arm.cloud_feed != NULL && arm.record_joints == 6);
	PX_CHECK_INT_EQ(px_view_arm_create(&arm, va), PX_OK);
	px_view_options_default(&vo);
	vo.port = port;
	vo.web_root = web_root();
	vo.queue_frames = 400; /* the virtual clock feeds fast: keep them all */
	PX_CHECK_MSG(px_view_create(&vo, &v, msg, sizeof(msg)) == PX_OK, "%s", msg);
	memset(&info, 0, sizeof(info));
	memset(&src, 0, sizeof(src));
	info.arm = *va;
	info.cloud_name = "depth sensor";
	src.scene = px_app_scene(app);
	src.arm = *va;
	src.cloud_feed = arm.cloud_feed;
	src.cloud_id = (int)px_scene_count(px_app_scene(app));
	PX_CHECK_INT_EQ(px_view_scene_json(px_app_scene(app), &info, &scene, &len), PX_OK);
	PX_CHECK_INT_EQ(px_view_set_scene(v, scene, len), PX_OK);
	free(scene);
	PX_CHECK_INT_EQ(px_view_set_sources(v, &src), PX_OK);
	PX_CHECK_INT_EQ(px_view_start(v), PX_OK);
	*fd = ws_open(port, "/ws");
	PX_CHECK(*fd >= 0);
	sleep_ms(100); /* connected before the first frame */
	return v;
}

/* The URDF arm with its depth sensor, 6 s on the virtual clock (the box
 * is in reach from 3 s); with a
 * view (port > 0) fed as proxima-run feeds it, *fd its page. */
static struct arm_run run_arm(int port, int *fd)
{
	struct px_config *cfg = NULL;
	static struct px_config_diag diag;
	struct px_app_options o;
	struct px_app *app = NULL;
	struct px_app_summary s;
	struct px_view_arm *va = NULL;
	struct arm_run out;
	char msg[256];
	PX_CHECK_INT_EQ(px_config_load_file(AVOID_URDF, &cfg, &diag), PX_OK);
	px_app_options_default(&o);
	o.config = AVOID_URDF;
	o.virtual_time = 1;
	o.duration_s = 6.0;
	o.note = px_test_app_note;
	o.heap_count = px_alloc_count_thread;
	o.telemetry = "build/tests/view-arm-telemetry.csv";
	o.record = feed_arm;
	PX_CHECK_MSG(px_app_create(cfg, &o, &app, msg, sizeof(msg)) == PX_OK, "%s", msg);
	arm_view = port > 0 ? arm_view_make(app, port, &va, fd) : NULL;
	PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
	PX_CHECK_INT_EQ(px_app_shutdown(app, "end of run"), PX_OK);
	px_app_drain(app, feed_arm, NULL);
	PX_CHECK_INT_EQ(px_app_summary(app, &s), PX_OK);
	out.cycles = s.cycles;
	out.allocs = s.allocations_after_setup;
	out.min_clearance_m = s.min_clearance_m;
	if (arm_view)
		px_view_end(arm_view); /* the page reads to the end */
	px_app_free(app);
	px_config_free(cfg);
	px_view_arm_free(va);
	return out;
}

/* The top-level arrays of key's array in s ("links":[[...],...]). */
static int rows_of(const char *s, const char *key)
{
	const char *p = strstr(s, key);
	int depth = 0, n = 0;
	if (!p)
		return 0;
	for (p += strlen(key); *p; p++) {
		if (*p == '[' && ++depth == 2)
			n++;
		if (*p == ']' && depth-- == 1)
			break;
	}
	return n;
}

/* An arm run with a page attached: scene.robot's links, frames with the
 * links moving and the closest pair, the depth sensor's swapped clouds;
 * the loop the same as without the view (cycles, clearance, no heap
 * call after setup). */
static void test_arm_run_with_view(void)
{
	struct arm_run a, b;
	char *s, first[512] = "";
	int port = free_port(), fd = -1, frames = 0, moved = 0, clouds = 0,
	    points = 0, pairs = 0;
	PX_NEEDS(VIEW);
	PX_NEEDS(XML);
	if (!strcmp(px_alloc_count_mode(), "none"))
		PX_SKIP("no allocation counter in this build");
	a = run_arm(0, NULL);
	b = run_arm(port, &fd);
	PX_CHECK_INT_EQ((long long)b.cycles, (long long)a.cycles);
	PX_CHECK_INT_EQ((long long)a.allocs, 0);
	PX_CHECK_INT_EQ((long long)b.allocs, 0);
	PX_CHECK_NEAR(b.min_clearance_m, a.min_clearance_m, 0);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"type\":\"hello\""));
	free(s);
	s = ws_read(fd, 2000);
	PX_CHECK(s && strstr(s, "\"type\":\"scene\""));
	PX_CHECK(strstr(s, "{\"id\":1,\"name\":\"depth sensor\",\"kind\":\"cloud\"") != NULL);
	PX_CHECK_INT_EQ(rows_of(s, "\"bounds\":"), 0);
	PX_CHECK(strstr(s, "\"robot\":{\"links\":[{\"name\":\"base_link\"") &&
		 strstr(s, "\"name\":\"forearm_link\"") && strstr(s, "\"name\":\"wrist3_link\""));
	PX_CHECK_NEAR(num_after(s, "\"protective_distance_m\":"), 0.05, 1e-12);
	free(s);
	while ((s = ws_read(fd, 3000)) != NULL) {
		if (strstr(s, "\"type\":\"end\"")) {
			free(s);
			break;
		}
		if (strstr(s, "\"type\":\"cloud\"")) {
			clouds++;
			PX_CHECK_INT_EQ((long long)num_after(s, "\"id\":"), 1);
			if (!strstr(s, "\"positions\":[]"))
				points++;
		} else if (strstr(s, "\"type\":\"frame\"")) {
			const char *l = strstr(s, "\"links\":[[");
			frames++;
			PX_CHECK_INT_EQ(rows_of(s, "\"links\":"), 7);
			PX_CHECK(strstr(s, "\"closest\":null") != NULL);
			pairs += strstr(s, "\"clearances\":[[") != NULL;
			if (l && !first[0])
				snprintf(first, sizeof(first), "%s", l);
			else if (l && strncmp(first, l, strlen(first)))
				moved++;
		}
		free(s);
	}
	/* (records every 10 ms, frames at most 30 a second: every 40 ms) */
	PX_CHECK_MSG(frames >= 145 && frames <= 181, "%d frames", frames);
	PX_CHECK_MSG(moved > 0 && pairs > 0, "links moved in %d frames, %d pairs", moved, pairs);
	/* (the virtual clock drains once a loop second: a cloud each) */
	PX_CHECK_MSG(clouds >= 4 && points >= 3, "%d clouds, %d with points", clouds, points);
	close(fd);
	px_view_free(arm_view);
	arm_view = NULL;
}

static const struct px_test tests[] = {
	PX_T(test_messages_of_a_connection),
	PX_T(test_bad_requests_answered),
	PX_T(test_slow_client_dropped_and_closed),
	PX_T(test_loop_unaffected_by_clients),
	PX_T(test_port_taken),
	PX_T(test_arm_links_and_clearances),
	PX_T(test_closest_point),
	PX_T(test_moved_models),
	PX_T(test_cloud_message),
	PX_T(test_arm_run_with_view),
};

PX_TEST_MAIN(tests)
