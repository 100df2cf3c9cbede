/*
 * Hostile input for every file reader: size limits (sparse files just
 * over the limit, FIFOs and /dev/zero, which has no size to look at),
 * NUL bytes with their line and column, extents that would overflow
 * squared distances (clouds, curves, surfaces, scaled scene models),
 * missing PLY properties, empty CSV fields, NaN lines that looked like
 * headers, YAML tags that contradict their values, binary STL counts
 * that disagree with the size, and PLY double coordinates kept exact.
 * Every refusal is checked for its code and for a message that names
 * the file and the place.
 * Here under core/: the size limits, NUL checks and file-kind refusals
 * every reader shares are core/px_file's.
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "px_arena.h"
#include "px_can.h"
#include "px_cloud.h"
#include "px_dist.h"
#include "px_config.h"
#include "px_file.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "px_obj.h"
#include "px_sim.h"
#include "px_test.h"
#include "px_scene.h"

static char tmpdir[64];

static void cleanup(void)
{
	char cmd[128];
	if (!tmpdir[0])
		return;
	snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
	if (system(cmd) != 0)
		fprintf(stderr, "could not remove %s\n", tmpdir);
	tmpdir[0] = '\0';
}


static const char *tpath(const char *name)
{
	static char buf[8][256];
	static int k;
	char *b = buf[k++ & 7];
	if (!tmpdir[0]) {
		snprintf(tmpdir, sizeof tmpdir, "/tmp/px_readers_XXXXXX");
		PX_CHECK(mkdtemp(tmpdir) != NULL);
		atexit(cleanup);
	}
	snprintf(b, 256, "%s/%s", tmpdir, name);
	return b;
}

static const char *put_bytes(const char *name, const void *data, size_t len)
{
	const char *p = tpath(name);
	FILE *f = fopen(p, "wb");
	PX_CHECK(f != NULL);
	PX_CHECK_INT_EQ(fwrite(data, 1, len, f), len);
	fclose(f);
	return p;
}

static const char *put(const char *name, const char *text)
{
	return put_bytes(name, text, strlen(text));
}

/* A sparse file of size bytes (no disk used): only its size is real. */
static const char *sparse(const char *name, size_t size)
{
	const char *p = tpath(name);
	int fd = open(p, O_WRONLY | O_CREAT | O_TRUNC, 0600);
	PX_CHECK(fd >= 0);
	PX_CHECK_INT_EQ(ftruncate(fd, (off_t)size), 0);
	close(fd);
	return p;
}

static void has(const char *msg, const char *a, const char *b)
{
	PX_CHECK_MSG(strstr(msg, a) != NULL && (!b || strstr(msg, b) != NULL),
		     "message '%s' lacks '%s'%s%s", msg, a, b ? " or " : "",
		     b ? b : "");
}

/* A FIFO fed with n bytes of c by a child process; returns its pid. */
static pid_t fifo_feed(const char *p, size_t n, char c)
{
	pid_t pid;
	unlink(p);
	PX_CHECK_INT_EQ(mkfifo(p, 0600), 0);
	pid = fork();
	PX_CHECK(pid >= 0);
	if (pid == 0) {
		char buf[4096];
		int fd = open(p, O_WRONLY);
		memset(buf, c, sizeof buf);
		signal(SIGPIPE, SIG_DFL);
		while (fd >= 0 && n > 0) {
			size_t k = n < sizeof buf ? n : sizeof buf;
			ssize_t w = write(fd, buf, k);
			if (w <= 0)
				break;
			n -= (size_t)w;
		}
		_exit(0);
	}
	return pid;
}

static void reap(pid_t pid)
{
	int st;
	waitpid(pid, &st, 0);
}

/* ---- px_file_read ------------------------------------------------------ */

static void test_file_read_limits(void)
{
	char *d = NULL, msg[512];
	size_t len = 7;
	const char *p;
	pid_t pid;

	/* a regular file: judged by its size, at and just over the limit */
	p = sparse("at.bin", 4096);
	PX_CHECK_INT_EQ(px_file_read(p, 4096, 0, "test", &d, &len, msg, sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(len, 4096);
	PX_CHECK(d != NULL && d[4096] == '\0');
	free(d);
	p = sparse("over.bin", 4097);
	PX_CHECK_INT_EQ(px_file_read(p, 4096, 0, "test", &d, &len, msg, sizeof msg),
			PX_E_RANGE);
	PX_CHECK(d == NULL && len == 0);
	has(msg, p, "larger than the 4096-byte limit for test files");

	/* a FIFO has no size: the running count decides */
	p = tpath("fifo");
	pid = fifo_feed(p, 4096, 'a');
	PX_CHECK_INT_EQ(px_file_read(p, 4096, PX_FILE_TEXT, "test", &d, &len, msg,
				     sizeof msg), PX_OK);
	reap(pid);
	PX_CHECK_INT_EQ(len, 4096);
	PX_CHECK(d[0] == 'a' && d[4095] == 'a' && d[4096] == '\0');
	free(d);
	pid = fifo_feed(p, 1 << 20, 'a');
	PX_CHECK_INT_EQ(px_file_read(p, 4096, PX_FILE_TEXT, "test", &d, &len, msg,
				     sizeof msg), PX_E_RANGE);
	reap(pid);
	has(msg, p, "limit");

	/* /dev/zero: the limit ends a binary read, the first NUL a text one */
	PX_CHECK_INT_EQ(px_file_read("/dev/zero", (size_t)1 << 20, 0, "model", &d,
				     &len, msg, sizeof msg), PX_E_RANGE);
	has(msg, "/dev/zero: larger than the 1 MiB limit for model files", NULL);
	PX_CHECK_INT_EQ(px_file_read("/dev/zero", PX_FILE_MODEL_MAX_BYTES,
				     PX_FILE_TEXT, "points", &d, &len, msg, sizeof msg),
			PX_E_PARSE);
	has(msg, "/dev/zero:1:1: NUL byte", NULL);

	/* the NUL's place: line and column */
	p = put_bytes("nul.txt", "ab\ncd\r\nef\0g\n", 12);
	PX_CHECK_INT_EQ(px_file_read(p, 4096, PX_FILE_TEXT, "test", &d, &len, msg,
				     sizeof msg), PX_E_PARSE);
	has(msg, p, ":3:3: NUL byte");
	PX_CHECK_INT_EQ(px_file_read(p, 4096, 0, "test", &d, &len, msg, sizeof msg),
			PX_OK);
	PX_CHECK_INT_EQ(len, 12);
	free(d);

	PX_CHECK_INT_EQ(px_file_read(tpath("none"), 4096, 0, "test", &d, &len, msg,
				     sizeof msg), PX_E_NOTFOUND);
	has(msg, "none: cannot open", NULL);
	PX_CHECK_INT_EQ(px_file_read(tmpdir, 4096, 0, "test", &d, &len, msg,
				     sizeof msg), PX_E_IO);
	has(msg, "is a directory", NULL);

	/* empty files read as empty, NUL-terminated */
	p = put("empty.txt", "");
	PX_CHECK_INT_EQ(px_file_read(p, 4096, PX_FILE_TEXT, "test", &d, &len, msg,
				     sizeof msg), PX_OK);
	PX_CHECK(len == 0 && d && d[0] == '\0');
	free(d);
}

static void test_next_line(void)
{
	char text[] = "a\r\n\nb c\rd\nlast";
	char *cur = text, *l;
	const char *want[] = {"a", "", "b c\rd", "last"};
	int n = 0;
	while ((l = px_file_next_line(&cur)) != NULL) {
		PX_CHECK(n < 4);
		PX_CHECK_MSG(strcmp(l, want[n]) == 0, "line %d: '%s'", n, l);
		n++;
	}
	PX_CHECK_INT_EQ(n, 4);
}

/* ---- every reader: its limit, /dev/zero, a FIFO, NUL with place --------- */

static void test_readers_size_limits(void)
{
	PX_NEEDS(ASSIMP);
	struct px_cloud_report crep;
	struct px_mesh_report mrep;
	struct px_model *m = (struct px_model *)1;
	struct px_obj_model *o = (struct px_obj_model *)1;
	struct px_obj_error oe;
	struct px_sim_csv *csv = (struct px_sim_csv *)1;
	struct px_can_bus *bus = (struct px_can_bus *)1;
	static struct px_config_diag diag;
	struct px_config *cfg = (struct px_config *)1;
	char msg[600];
	const char *p;

	p = sparse("big.xyz", PX_FILE_MODEL_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_E_RANGE);
	PX_CHECK(m == NULL);
	has(crep.message, p, "1 GiB limit");
	p = sparse("big.ply", PX_FILE_MODEL_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_E_RANGE);
	has(crep.message, p, "1 GiB limit");
	p = sparse("big.stl", PX_FILE_MODEL_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &mrep, &m), PX_E_RANGE);
	has(mrep.message, p, "1 GiB limit");
	PX_CHECK_INT_EQ(px_model_load(p, 0.0, &m, msg, sizeof msg), PX_E_RANGE);
	has(msg, p, "1 GiB limit");
	p = sparse("big.obj", PX_FILE_MODEL_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_obj_load_file(p, &o, &oe), PX_E_RANGE);
	PX_CHECK(o == NULL);
	has(oe.msg, "1 GiB limit", NULL);
	PX_CHECK(strcmp(oe.file, p) == 0);
	p = sparse("big.csv", PX_FILE_TEXT_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_RANGE);
	PX_CHECK(csv == NULL);
	has(msg, p, "64 MiB limit");
	p = sparse("big.log", PX_FILE_LOG_MAX_BYTES + 1);
	PX_CHECK_INT_EQ(px_can_replay_open(p, NULL, &bus, msg, sizeof msg),
			PX_E_RANGE);
	PX_CHECK(bus == NULL);
	has(msg, p, "256 MiB limit");
	p = sparse("big.yaml", ((size_t)64 << 20) + 1);
	PX_CHECK(px_config_load_file(p, &cfg, &diag) != PX_OK);
	PX_CHECK(cfg == NULL && diag.count > 0);
	has(diag.errors[0].msg, p, "64 MiB");
	unlink(tpath("big.xyz"));
	unlink(tpath("big.ply"));
	unlink(tpath("big.stl"));
	unlink(tpath("big.obj"));
	unlink(tpath("big.csv"));
	unlink(tpath("big.log"));
	unlink(tpath("big.yaml"));
}

/* /dev/zero is endless NUL bytes: every text reader stops at the first
 * with its place, instead of skipping "blank" lines forever. */
static void test_readers_dev_zero(void)
{
	PX_NEEDS(ASSIMP);
	struct px_cloud_report crep;
	struct px_model *m = (struct px_model *)1;
	struct px_obj_model *o = (struct px_obj_model *)1;
	struct px_obj_error oe;
	struct px_sim_csv *csv = (struct px_sim_csv *)1;
	struct px_can_bus *bus = (struct px_can_bus *)1;
	char msg[600];
	const char *z = tpath("zero.xyz");

	PX_CHECK_INT_EQ(px_cloud_load("/dev/zero", 0.0, &crep, &m), PX_E_PARSE);
	PX_CHECK(m == NULL);
	has(crep.message, "/dev/zero:1:1: NUL byte", NULL);
	/* a name that looks like a cloud */
	unlink(z);
	PX_CHECK_INT_EQ(symlink("/dev/zero", z), 0);
	PX_CHECK_INT_EQ(px_model_load(z, 0.0, &m, msg, sizeof msg), PX_E_PARSE);
	has(msg, "zero.xyz:1:1: NUL byte", NULL);
	unlink(z);
	/* OBJ faces as a mesh (the importer): text, so the same */
	z = tpath("zero.obj");
	unlink(z);
	PX_CHECK_INT_EQ(symlink("/dev/zero", z), 0);
	PX_CHECK_INT_EQ(px_model_load(z, 0.0, &m, msg, sizeof msg), PX_E_PARSE);
	has(msg, "zero.obj:1:1: NUL byte", NULL);
	unlink(z);
	PX_CHECK_INT_EQ(px_obj_load_file("/dev/zero", &o, &oe), PX_E_PARSE);
	PX_CHECK(o == NULL && oe.line == 1 && oe.column == 1);
	has(oe.msg, "NUL byte", NULL);
	PX_CHECK_INT_EQ(px_sim_csv_load("/dev/zero", &csv, msg, sizeof msg),
			PX_E_PARSE);
	PX_CHECK(csv == NULL);
	has(msg, "/dev/zero:1:1: NUL byte", NULL);
	PX_CHECK_INT_EQ(px_can_replay_open("/dev/zero", NULL, &bus, msg, sizeof msg),
			PX_E_PARSE);
	PX_CHECK(bus == NULL);
	has(msg, "/dev/zero:1:1: NUL byte", NULL);
}

/* A FIFO as a model: no size to check, so the running count ends it. */
static void test_model_fifo(void)
{
	struct px_cloud_report crep;
	struct px_model *m = NULL;
	const char *p = tpath("pipe.xyz");
	pid_t pid = fifo_feed(p, 3 * 1000, '1');
	/* "111...": one long number, not a point; read whole, then parsed */
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_E_PARSE);
	reap(pid);
	has(crep.message, p, ":1:");
	unlink(p);
	/* a good cloud through a FIFO loads */
	{
		static const char pts[] = "0 0 0\n1 0 0\n0 1 0\n";
		PX_CHECK_INT_EQ(mkfifo(p, 0600), 0);
		pid = fork();
		PX_CHECK(pid >= 0);
		if (pid == 0) {
			int fd = open(p, O_WRONLY);
			if (fd >= 0 && write(fd, pts, sizeof pts - 1) < 0)
				_exit(1);
			_exit(0);
		}
		PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_OK);
		reap(pid);
		PX_CHECK_INT_EQ(px_cloud_point_count(m), 3);
		px_model_free(m);
		unlink(p);
	}
}

static void test_readers_nul_place(void)
{
	PX_NEEDS(ASSIMP);
	struct px_cloud_report crep;
	struct px_model *m = NULL;
	struct px_obj_model *o = NULL;
	struct px_obj_error oe;
	struct px_sim_csv *csv = NULL;
	struct px_can_bus *bus = NULL;
	char msg[600];
	const char *p;

	/* a NUL inside a line used to cut it silently ("4 5" and a lost 6) */
	p = put_bytes("nul.xyz", "1 2 3\n4 5\0 6\n", 13);
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_E_PARSE);
	has(crep.message, p, ":2:4: NUL byte");
	p = put_bytes("nul.obj", "v 0 0 0\nv 1 0\0 0\nv 0 1 0\nf 1 2 3\n", 33);
	PX_CHECK_INT_EQ(px_obj_load_file(p, &o, &oe), PX_E_PARSE);
	PX_CHECK_INT_EQ(oe.line, 2);
	PX_CHECK_INT_EQ(oe.column, 6);
	p = put_bytes("nul.csv", "0,0,0,0\n1,0\0,0,0\n", 18);
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_PARSE);
	has(msg, p, ":2:4: NUL byte");
	p = put_bytes("nul.log", "(1.000000) can0 123#00\n(1.0\0", 28);
	PX_CHECK_INT_EQ(px_can_replay_open(p, NULL, &bus, msg, sizeof msg),
			PX_E_PARSE);
	has(msg, p, ":2:5: NUL byte");
	/* an ASCII PLY header with a NUL: its line */
	p = put_bytes("nul.ply", "ply\nformat ascii 1.0\nelem\0ent vertex 1\n", 38);
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &crep, &m), PX_E_PARSE);
	has(crep.message, p, ":3:");
}

/* ---- extents that overflow -------------------------------------------- */

static void test_cloud_extent(void)
{
	struct px_cloud_report rep;
	struct px_model *m = NULL;
	struct px_model_result r;
	const char *p;
	size_t i;

	/* the crash: points near +-1e308 (extent infinite, the grid's cell
	 * counts with it) */
	p = put("e308.xyz", "0 0 0\n1e308 0 0\n-1e308 1 1\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_RANGE);
	PX_CHECK(m == NULL);
	has(rep.message, p, ":2: field 1: coordinate 1e+308 beyond");
	PX_CHECK_INT_EQ(rep.line, 2);
	PX_CHECK_INT_EQ(px_model_load(p, 0.0, &m, NULL, 0), PX_E_RANGE);
	{
		double xyz[] = {0, 0, 0, 1, 2, 3, 4, 5, -1e200};
		PX_CHECK_INT_EQ(px_cloud_model(xyz, 3, 0.0, &rep, &m), PX_E_RANGE);
		has(rep.message, "point 2: coordinate z = -1e+200", NULL);
		xyz[8] = 3;
		PX_CHECK_INT_EQ(px_cloud_model(xyz, 3, 1e200, &rep, &m), PX_E_RANGE);
		has(rep.message, "radius", NULL);
	}
	/* inside the limit but wide enough to overflow the grid's volume
	 * (extent 2e140 cubed): built, and the answers are the brute-force
	 * nearest */
	{
		double xyz[3 * 64];
		for (i = 0; i < 64; i++) {
			xyz[3 * i] = ((double)(i % 4) - 1.5) * 1e140;
			xyz[3 * i + 1] = ((double)(i / 4 % 4) - 1.5) * 1e140;
			xyz[3 * i + 2] = ((double)(i / 16) - 1.5) * 1e140;
		}
		PX_CHECK_INT_EQ(px_cloud_model(xyz, 64, 0.0, &rep, &m), PX_OK);
		for (i = 0; i < 50; i++) {
			px_vec3 q = px_v3(((double)(i % 7) - 3.1) * 0.7e140,
					  ((double)(i % 5) - 2.2) * 0.9e140,
					  ((double)(i % 3) - 1.3) * 1.1e140);
			double best = INFINITY;
			size_t j;
			for (j = 0; j < 64; j++)
				best = fmin(best, px_v3_norm(px_v3_sub(
							  q, px_v3(xyz[3 * j], xyz[3 * j + 1],
								   xyz[3 * j + 2]))));
			PX_CHECK_INT_EQ(px_model_query(m, q, &r), 1);
			PX_CHECK_CLOSE(r.distance, best, 0, 1e-15);
		}
		px_model_free(m);
	}
}

/* The 3x3 biquadratic dome of half-width S (the control points at +-S,
 * the middle one raised), its distance model in *dm. */
static void dome(double S, unsigned char *mem, size_t cap, struct px_nurbs_surf *s,
		 struct px_dist_model **dm)
{
	static const double k[] = {0, 0, 0, 1, 1, 1};
	struct px_arena a;
	double sx[27];
	int i;
	for (i = 0; i < 9; i++) {
		sx[3 * i] = (i % 3 - 1) * S;
		sx[3 * i + 1] = (i / 3 - 1) * S;
		sx[3 * i + 2] = i == 4 ? S : -S;
	}
	px_arena_init(&a, mem, cap);
	PX_CHECK_INT_EQ(px_nurbs_surf_init(s, &a, 2, 2, 3, 3, k, 6, k, 6, sx, NULL, NULL),
			PX_OK);
	PX_CHECK_INT_EQ(px_dist_model_create(NULL, 0, s, 1, NULL, dm), PX_OK);
}

static void test_nurbs_extent(void)
{
	static unsigned char mem[8192], m1[1 << 15], m2[1 << 15];
	static const double k[] = {0, 0, 0, 1, 1, 1};
	struct px_arena a;
	struct px_nurbs_curve c;
	struct px_nurbs_error e;
	double x[] = {0, 0, 0, 1, 1e200, 0, 2, 0, 0};
	double w[] = {1, 1, 1};
	double sx[27], sw[9];
	int i;

	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, NULL, &e), PX_E_RANGE);
	PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_COORD_RANGE);
	PX_CHECK_INT_EQ(e.index, 1);
	has(e.msg, "control point 1", "beyond");
	px_arena_init(&a, mem, sizeof mem);
	PX_CHECK_INT_EQ(px_nurbs_curve_init(&c, &a, 2, 3, k, 6, x, NULL, &e), PX_E_RANGE);
	x[4] = 1.0;
	x[6] = PX_NURBS_MAX_COORD; /* at the limit */
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, NULL, &e), PX_OK);
	x[6] = 2 * PX_NURBS_MAX_COORD;
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, NULL, &e), PX_E_RANGE);
	PX_CHECK_INT_EQ(e.index, 2);
	x[6] = 2.0;
	/* weights: bounded, and within a ratio of each other */
	w[2] = 1e120;
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, w, &e), PX_E_RANGE);
	PX_CHECK_INT_EQ(e.index, 2);
	has(e.msg, "weight", NULL);
	w[0] = 1e-3;
	w[2] = 1e3;
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, w, &e), PX_OK);
	w[2] = 2e3;
	PX_CHECK_INT_EQ(px_nurbs_curve_validate(2, 3, k, 6, x, w, &e), PX_E_RANGE);
	PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_WEIGHT);
	PX_CHECK_INT_EQ(e.index, 2);
	has(e.msg, "control point 2 has weight 2000", "of control point 0");

	for (i = 0; i < 9; i++) {
		sx[3 * i] = i % 3;
		sx[3 * i + 1] = i / 3;
		sx[3 * i + 2] = 0.0;
		sw[i] = 1.0;
	}
	sx[3 * 5 + 2] = -3 * PX_NURBS_MAX_COORD;
	PX_CHECK_INT_EQ(px_nurbs_surf_validate(2, 2, 3, 3, k, 6, k, 6, sx, sw, &e),
			PX_E_RANGE);
	PX_CHECK_INT_EQ(e.fault, PX_NURBS_FAULT_COORD_RANGE);
	PX_CHECK_INT_EQ(e.index_i, 2);
	PX_CHECK_INT_EQ(e.index_j, 1);

	/* at the limit a surface answers as its unit-size copy, scaled: the
	 * fourth powers of its extent in the search stay finite (at 5e77
	 * about a quarter of these answers were wrong) */
	{
		struct px_nurbs_surf s1, s2;
		struct px_dist_model *d1 = NULL, *d2 = NULL;
		struct px_dist_result r1, r2;
		const double S = PX_NURBS_MAX_COORD;
		int j;
		dome(1.0, m1, sizeof m1, &s1, &d1);
		dome(S, m2, sizeof m2, &s2, &d2);
		for (j = 0; j < 100; j++) {
			px_vec3 p = px_v3(((j * 37) % 21 - 10) * 0.15, ((j * 11) % 17 - 8) * 0.2,
					  ((j * 7) % 13 - 6) * 0.3);
			PX_CHECK_INT_EQ(px_dist_query(d1, p, &r1), PX_OK);
			PX_CHECK_INT_EQ(px_dist_query(d2, px_v3_scale(p, S), &r2), PX_OK);
			PX_CHECK_MSG(fabs(r2.dist / S - r1.dist) <= 1e-9 * (1 + r1.dist),
				     "point %d: %.17g at scale 1e75, %.17g at scale 1", j,
				     r2.dist / S, r1.dist);
		}
		px_dist_model_free(d1);
		px_dist_model_free(d2);
	}

	/* through an OBJ file: the control point's place */
	{
		struct px_obj_model *o = NULL;
		struct px_obj_error oe;
		const char *p = put("far.obj", "v 0 0 0\nv 1 1e200 0\nv 2 0 0\ncstype bspline\n"
					       "deg 2\ncurv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend\n");
		int rc = px_obj_load_file(p, &o, &oe);
		PX_CHECK_MSG(rc == PX_E_RANGE || rc == PX_E_PARSE, "rc %d: %s", rc, oe.msg);
		PX_CHECK(o == NULL);
		PX_CHECK_MSG(oe.line == 6, "line %d: %s", oe.line, oe.msg);
		has(oe.msg, "beyond", NULL);
	}
}

/* A scene model scaled beyond the reach: refused at setup with its
 * place, and px_scene_add() refuses the box itself. */
static void test_scene_extent(void)
{
	PX_NEEDS(YAML);
	static struct px_config_diag diag;
	struct px_config *cfg = NULL;
	struct px_scene *w = NULL;
	struct px_model *m = NULL;
	char yaml[512];
	const char *p = put("far.xyz", "0 0 0\n1e147 0 0\n");
	double xyz[] = {0, 0, 0, 1e149, 0, 0};
	px_pose pose = px_pose_identity();

	snprintf(yaml, sizeof yaml, "scene:\n  models:\n    - file: %s\n"
		 "      kind: cloud\n      scale: 1e6\n", p);
	PX_CHECK_INT_EQ(px_config_load_mem("s.yaml", yaml, strlen(yaml), &cfg, &diag),
			PX_OK);
	PX_CHECK(px_scene_config_load(cfg, &w, &diag) != PX_OK);
	PX_CHECK(w == NULL);
	PX_CHECK(diag.count > 0);
	has(diag.errors[0].msg, "s.yaml:3:", "beyond");
	px_config_free(cfg);
	/* a scale so small that near queries would leave the reach in the
	 * file's units: a key error */
	snprintf(yaml, sizeof yaml, "scene:\n  models:\n    - file: %s\n"
		 "      kind: cloud\n      scale: 1e-300\n", p);
	PX_CHECK(px_config_load_mem("s.yaml", yaml, strlen(yaml), &cfg, &diag) != PX_OK ||
		 px_scene_config_load(cfg, &w, &diag) != PX_OK);
	PX_CHECK(w == NULL && diag.count > 0);
	has(diag.errors[0].msg, "s.yaml:5:14:", "scale");
	px_config_free(cfg);
	cfg = NULL;

	PX_CHECK_INT_EQ(px_scene_create(2, &w), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_model(xyz, 2, 0.0, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_scene_add(w, m, "ok"), 0);
	xyz[3] = 1e150;
	PX_CHECK_INT_EQ(px_cloud_model(xyz, 2, 1e149, NULL, &m), PX_OK);
	PX_CHECK_INT_EQ(px_scene_add(w, m, "far"), PX_E_RANGE);
	pose.t = px_v3(0, 2e150, 0);
	PX_CHECK_INT_EQ(px_scene_set_pose(w, 0, pose), PX_E_RANGE);
	pose.t = px_v3(0, 1e6, 0);
	PX_CHECK_INT_EQ(px_scene_set_pose(w, 0, pose), PX_OK);
	px_scene_free(w);
}

/* ---- silent garbage ----------------------------------------------------- */

static void test_ply_missing_property(void)
{
	PX_NEEDS(ASSIMP);
	struct px_cloud_report rep;
	struct px_model *m = NULL;
	char msg[600];
	const char *p = put("noz.ply", "ply\nformat ascii 1.0\nelement vertex 2\n"
				       "property float x\nproperty float y\nend_header\n"
				       "1 2\n3 4\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_PARSE);
	PX_CHECK(m == NULL);
	has(rep.message, p, ":3: PLY element 'vertex' has no scalar property 'z'");
	PX_CHECK_INT_EQ(px_model_load(p, 0.0, &m, msg, sizeof msg), PX_E_PARSE);
	has(msg, "property 'z'", NULL);
	/* x as a list is no coordinate either */
	p = put("listx.ply", "ply\nformat ascii 1.0\nelement vertex 1\n"
			     "property list uchar float x\nproperty float y\n"
			     "property float z\nend_header\n1 5 2 3\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_PARSE);
	has(rep.message, "property 'x'", NULL);
}

static void test_empty_fields(void)
{
	static const struct {
		const char *text, *where;
	} cases[] = {
		{"1,,2\n", ":1:3: field 2 is empty"},
		{"1,2,\n", ":1:5: field 3 is empty"},
		{",1,2,3\n", ":1:1: field 1 is empty"},
		{"0 0 0\n1 ; ;2 3\n", ":2:5: field 2 is empty"},
	};
	struct px_cloud_report rep;
	struct px_model *m = NULL;
	struct px_sim_csv *csv = NULL;
	char msg[600];
	size_t i;
	const char *p;
	for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		p = put("empty.csv", cases[i].text);
		PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_PARSE);
		PX_CHECK(m == NULL);
		has(rep.message, p, cases[i].where);
	}
	/* extra columns after three numbers stay ignored, blanks between
	 * fields stay one separator */
	p = put("extra.csv", "1, 2 ,3,,7\n4  5\t6\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 2);
	px_model_free(m);

	p = put("empty_t.csv", "0,0,0,0\n1,,0,0\n");
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_PARSE);
	has(msg, p, ":2: expected 4 finite numbers t_s,x_m,y_m,z_m (field 2 is empty)");
	p = put("empty_t2.csv", "0,0,0,\n");
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_PARSE);
	has(msg, ":1:", "field 4 is empty");
}

static void test_nan_first_line(void)
{
	struct px_cloud_report rep;
	struct px_model *m = NULL;
	struct px_sim_csv *csv = NULL;
	char msg[600];
	const char *p;

	/* NaN and inf read as numbers: data, and then an error, never a
	 * header to skip */
	p = put("nan1.csv", "NaN,0,0\n1,2,3\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_NAN);
	has(rep.message, p, ":1: field 1: non-finite");
	PX_CHECK_INT_EQ(rep.line, 1);
	p = put("inf1.xyz", "0 inf 0\n1 2 3\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_E_NAN);
	has(rep.message, p, ":1: field 2: non-finite");
	/* a real header is still a header */
	p = put("hdr.csv", "x,y,z\n1,2,3\n");
	PX_CHECK_INT_EQ(px_cloud_load(p, 0.0, &rep, &m), PX_OK);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 1);
	px_model_free(m);

	p = put("nan_t.csv", "NaN,0,0,0\n1,0,0,0\n");
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_PARSE);
	PX_CHECK(csv == NULL);
	has(msg, p, ":1: expected 4 finite numbers t_s,x_m,y_m,z_m (field 1 is not finite)");
	p = put("inf_t.csv", "t_s,x_m,y_m,z_m\n0,0,-inf,0\n");
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_E_PARSE);
	has(msg, ":2:", "field 3 is not finite");
	p = put("hdr_t.csv", "time,x,y,z\n0,0,0,0\n1,1,0,0\n");
	PX_CHECK_INT_EQ(px_sim_csv_load(p, &csv, msg, sizeof msg), PX_OK);
	PX_CHECK_INT_EQ(px_sim_csv_count(csv), 2);
	px_sim_csv_free(csv);
}

static int tag_errors(const char *yaml, const char **first)
{
	static struct px_config_diag diag;
	struct px_config *cfg = NULL;
	int i, n = 0;
	px_config_load_mem("t.yaml", yaml, strlen(yaml), &cfg, &diag);
	px_config_free(cfg);
	*first = "";
	for (i = 0; i < diag.count; i++)
		if (strstr(diag.errors[i].msg, "YAML tag") ||
		    strstr(diag.errors[i].msg, "quoted string")) {
			if (!n)
				*first = diag.errors[i].msg;
			n++;
		}
	return n;
}

static void test_yaml_tags(void)
{
	PX_NEEDS(YAML);
	static const struct {
		const char *yaml, *msg;
	} bad[] = {
		{"loop:\n  period_ns: !!null 2000000\n",
		 "t.yaml:2:14: YAML tag '!!null' contradicts its value '2000000'"},
		{"loop:\n  period_ns: !!int abc\n",
		 "t.yaml:2:14: YAML tag '!!int' contradicts its value 'abc'"},
		{"loop:\n  period_ns: !!int 1.5\n",
		 "t.yaml:2:14: YAML tag '!!int' contradicts its value '1.5'"},
		{"loop:\n  period_ns: !!float fast\n",
		 "t.yaml:2:14: YAML tag '!!float' contradicts its value 'fast'"},
		{"telemetry:\n  enabled: !!bool 3\n",
		 "t.yaml:2:12: YAML tag '!!bool' contradicts its value '3'"},
		{"loop:\n  period_ns: !!seq 5\n",
		 "t.yaml:2:14: YAML tag '!!seq' belongs on a sequence"},
		{"loop: !!seq {period_ns: 1000000}\n",
		 "t.yaml:1:7: YAML tag '!!seq' belongs on a sequence"},
		{"loop: !!int {period_ns: 1000000}\n",
		 "t.yaml:1:7: YAML tag '!!int' belongs on a scalar"},
		{"loop:\n  period_ns: !!str 1000000\n", "quoted string '1000000'"},
	};
	static const char *const good[] = {
		"loop:\n  period_ns: !!int 1000000\n",
		"loop:\n  period_ns: !!float 1000000\n",
		"loop: !!map {period_ns: !!int 0x10000}\n",
		"telemetry:\n  enabled: !!bool false\n",
	};
	const char *first;
	size_t i;
	for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		PX_CHECK_MSG(tag_errors(bad[i].yaml, &first) >= 1, "no tag error for:\n%s",
			     bad[i].yaml);
		has(first, bad[i].msg, NULL);
	}
	for (i = 0; i < sizeof good / sizeof good[0]; i++)
		PX_CHECK_MSG(tag_errors(good[i], &first) == 0, "'%s' for:\n%s", first,
			     good[i]);
}

/* ---- STL ---------------------------------------------------------------- */

static void stl_binary(unsigned char *b, uint32_t count_in_header, size_t n_tri,
		       const char *head)
{
	size_t i;
	memset(b, 0, 84 + 50 * n_tri);
	if (head)
		memcpy(b, head, strlen(head));
	memcpy(b + 80, &count_in_header, 4);
	for (i = 0; i < n_tri; i++) {
		float v[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
		v[5] = (float)i;
		v[8] = (float)i;
		v[11] = (float)i;
		memcpy(b + 84 + 50 * i, v, sizeof v);
	}
}

static void test_stl_binary_count(void)
{
	PX_NEEDS(ASSIMP);
	unsigned char b[84 + 50 * 3];
	struct px_mesh_report rep;
	struct px_model *m = NULL;
	const char *p;

	stl_binary(b, 3, 2, NULL);
	p = put_bytes("short.stl", b, 84 + 50 * 2);
	PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_E_PARSE);
	PX_CHECK(m == NULL);
	has(rep.message, p, "binary STL: header says 3 triangles (needs 234 bytes), "
			    "file has 184 bytes");
	/* a binary header that starts with "solid", as some exporters write */
	stl_binary(b, 1, 2, "solid exported");
	p = put_bytes("solid.stl", b, 84 + 50 * 2);
	PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_E_PARSE);
	has(rep.message, "header says 1 triangles (needs 134 bytes), file has 184",
	    "NUL byte at 1:");
	/* consistent: loads */
	stl_binary(b, 2, 2, "solid exported");
	p = put_bytes("good.stl", b, 84 + 50 * 2);
	PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_OK);
	PX_CHECK_INT_EQ(rep.n_triangles, 2);
	px_model_free(m);
	/* too short for either */
	p = put_bytes("tiny.stl", b + 80, 10);
	PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_E_PARSE);
	has(rep.message, p, "shorter than a binary STL's 84-byte header");
}

/* ---- PLY doubles kept exact -------------------------------------------- */

static void put_be(unsigned char *b, const void *v, size_t n)
{
	size_t i;
	for (i = 0; i < n; i++)
		b[i] = ((const unsigned char *)v)[n - 1 - i];
}

static void check_far_cloud(const char *p)
{
	struct px_cloud_report rep;
	struct px_model *m = NULL;
	struct px_model_result r;
	px_vec3 q;
	PX_CHECK_MSG(px_cloud_load(p, 0.0, &rep, &m) == PX_OK, "%s", rep.message);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 3);
	PX_CHECK_INT_EQ(px_cloud_point(m, 0, &q), PX_OK);
	PX_CHECK_MSG(q.x == 5000000.123 && q.y == -2.5 && q.z == 0.001, "%.17g %.17g %.17g",
		     q.x, q.y, q.z);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(5000000.123, -2.5, 0.001), &r), 1);
	PX_CHECK_MSG(fabs(r.distance) <= 1e-9, "distance %.17g", r.distance);
	PX_CHECK_INT_EQ(r.index, 0);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(5000000.123, -2.5, 1.001), &r), 1);
	PX_CHECK_MSG(fabs(r.distance - 1.0) <= 1e-9, "distance %.17g", r.distance);
	px_model_free(m);
	/* the same through the model dispatch (a mesh first, then a cloud) */
	PX_CHECK_INT_EQ(px_model_load(p, 0.0, &m, NULL, 0), PX_OK);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(5000000.123, -2.5, 0.001), &r), 1);
	PX_CHECK_MSG(fabs(r.distance) <= 1e-9, "distance %.17g", r.distance);
	px_model_free(m);
}

static void test_ply_double_exact(void)
{
	PX_NEEDS(ASSIMP);
	static const char head[] = "element vertex 3\nproperty double x\n"
				   "property double y\nproperty double z\nend_header\n";
	const double v[9] = {5000000.123, -2.5, 0.001, 1, 2, 3, -4, 5, 6};
	unsigned char buf[512];
	size_t n, i;
	const char *p;

	p = put("far_a.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\n"
			     "property double y\nproperty double z\nend_header\n"
			     "5000000.123 -2.5 0.001\n1 2 3\n-4 5 6\n");
	check_far_cloud(p);
	n = (size_t)snprintf((char *)buf, sizeof buf,
			     "ply\nformat binary_little_endian 1.0\n%s", head);
	memcpy(buf + n, v, sizeof v);
	p = put_bytes("far_le.ply", buf, n + sizeof v);
	check_far_cloud(p);
	n = (size_t)snprintf((char *)buf, sizeof buf,
			     "ply\nformat binary_big_endian 1.0\n%s", head);
	for (i = 0; i < 9; i++)
		put_be(buf + n + 8 * i, &v[i], 8);
	p = put_bytes("far_be.ply", buf, n + sizeof v);
	check_far_cloud(p);

	/* integer types, signed and unsigned, both byte orders */
	{
		struct px_cloud_report rep;
		struct px_model *m = NULL;
		px_vec3 q;
		int32_t xi = -123456789;
		int16_t yi = -2;
		uint8_t zi = 250;
		n = (size_t)snprintf((char *)buf, sizeof buf,
				     "ply\nformat binary_big_endian 1.0\nelement vertex 1\n"
				     "property int x\nproperty short y\nproperty uchar z\n"
				     "end_header\n");
		put_be(buf + n, &xi, 4);
		put_be(buf + n + 4, &yi, 2);
		buf[n + 6] = zi;
		p = put_bytes("ints.ply", buf, n + 7);
		PX_CHECK_MSG(px_cloud_load(p, 0.0, &rep, &m) == PX_OK, "%s", rep.message);
		PX_CHECK_INT_EQ(px_cloud_point(m, 0, &q), PX_OK);
		PX_CHECK(q.x == -123456789.0 && q.y == -2.0 && q.z == 250.0);
		px_model_free(m);
	}

	/* a mesh passes through the importer's floats: far coordinates that
	 * would move are refused, near ones load */
	{
		struct px_mesh_report rep;
		struct px_model *m = NULL;
		p = put("far_mesh.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
					"property double x\nproperty double y\nproperty double z\n"
					"element face 1\nproperty list uchar int vertex_indices\n"
					"end_header\n5000000.123 0 0\n5000001.123 0 0\n"
					"5000000.123 1 0\n3 0 1 2\n");
		PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_E_RANGE);
		PX_CHECK(m == NULL);
		has(rep.message, p, "vertex 0: x = 5000000.1");
		p = put("near_mesh.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"
					 "property double x\nproperty double y\nproperty double z\n"
					 "element face 1\nproperty list uchar int vertex_indices\n"
					 "end_header\n0.1 0 0\n1.1 0 0\n0.1 1 0\n3 0 1 2\n");
		PX_CHECK_MSG(px_mesh_load(p, NULL, &rep, &m) == PX_OK, "%s", rep.message);
		px_model_free(m);
		/* decimal coordinates of an ASCII STL and of OBJ faces too */
		p = put("far.stl", "solid far\nfacet normal 0 0 1\nouter loop\n"
				   "vertex 5000000.123 0 0\nvertex 5000001.123 0 0\n"
				   "vertex 5000000.123 1 0\nendloop\nendfacet\nendsolid far\n");
		PX_CHECK_INT_EQ(px_mesh_load(p, NULL, &rep, &m), PX_E_RANGE);
		has(rep.message, p, "vertex 0: x = 5000000.1");
		p = put("far_faces.obj", "v 5000000.123 0 0\nv 5000001.123 0 0\n"
					 "v 5000000.123 1 0\nf 1 2 3\n");
		PX_CHECK_INT_EQ(px_model_load(p, 0.0, &m, NULL, 0), PX_E_RANGE);
		p = put("near.stl", "solid near\nfacet normal 0 0 1\nouter loop\n"
				    "vertex 0.123 0 0\nvertex 1.123 0 0\nvertex 0.123 1 0\n"
				    "endloop\nendfacet\nendsolid near\n");
		PX_CHECK_MSG(px_mesh_load(p, NULL, &rep, &m) == PX_OK, "%s", rep.message);
		px_model_free(m);
	}
}

static const struct px_test tests[] = {
	PX_T(test_file_read_limits),
	PX_T(test_next_line),
	PX_T(test_readers_size_limits),
	PX_T(test_readers_dev_zero),
	PX_T(test_model_fifo),
	PX_T(test_readers_nul_place),
	PX_T(test_cloud_extent),
	PX_T(test_nurbs_extent),
	PX_T(test_scene_extent),
	PX_T(test_ply_missing_property),
	PX_T(test_empty_fields),
	PX_T(test_nan_first_line),
	PX_T(test_yaml_tags),
	PX_T(test_stl_binary_count),
	PX_T(test_ply_double_exact),
};

PX_TEST_MAIN(tests)
