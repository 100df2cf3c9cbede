/*
 * proxima-view - replay a run in the browser, or write it as one page.
 *
 *   proxima-view [--port [ADDR:]PORT] [--config CFG] [--web-root DIR]
 *                [--summary FILE] [--rate HZ] TELEMETRY.csv
 *   proxima-view --html OUT.html [--config CFG] [--template FILE]
 *                [--summary FILE] [--rate HZ] TELEMETRY.csv
 *
 * Serves the view's page (view/px_view.h) in replay mode: "hello", the
 * scene of CFG's scene section tessellated (px_view_scene_json()), and
 * the whole run as one "track" message from the telemetry CSV with the
 * run's summary JSON (--summary, else run-summary.json beside the CSV
 * when there is one); the page plays it. The track holds a frame at most
 * every 1/HZ s of loop time (60; 0: every row) and at every change of
 * contact or safe state, with the closest point on the scene; for an arm (CFG in
 * avoidance mode, its robot made as for a config check) the links where
 * the CSV has the joint positions (telemetry.joint_positions). Until Ctrl-C. With --html it
 * writes one self-contained page instead: the report template (the
 * built page's report-template.html) with {"scene":...,"track":...} put
 * where it says PX_VIEW_DATA, written through tools/tool_out.h.
 *
 * Inputs have limits (CSV line and row counts, JSON size and nesting:
 * tools/view_internal.h); errors name the file and line. Exit status:
 * 0 ok, 1 an input or output failed, 2 usage error.
 */
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "px_app.h"
#include "px_config.h"
#include "px_scene.h"
#include "px_view.h"
#include "tool_out.h"
#include "tool_view.h"
#include "view_internal.h"

static const char usage_text[] =
	"usage: proxima-view [--port [ADDR:]PORT] [--config CFG] [--web-root DIR]\n"
	"                    [--summary FILE] [--rate HZ] TELEMETRY.csv\n"
	"       proxima-view --html OUT.html [--config CFG] [--template FILE]\n"
	"                    [--summary FILE] [--rate HZ] TELEMETRY.csv\n"
	"\n"
	"  --port [ADDR:]PORT  serve the replay there (default 127.0.0.1:8765)\n"
	"  --config CFG        the run's config: its scene is shown\n"
	"  --web-root DIR      the built page (default: build/view/web)\n"
	"  --summary FILE      the run's summary JSON (default: run-summary.json\n"
	"                      beside the CSV, when there is one)\n"
	"  --html OUT.html     write one self-contained report page and exit\n"
	"  --template FILE     the report template (default: report-template.html\n"
	"                      of the built page)\n"
	"  --rate HZ           track frames a second of loop time at most, and at\n"
	"                      every change of contact or safe state (default 60;\n"
	"                      0: every row)\n"
	"  --help              this text\n"
	"Exit status: 0 ok, 1 an input or output failed, 2 usage error.\n";

/* Frames a second of loop time in the track at most (--rate). */
#define TRACK_RATE_HZ 60.0

/* The report template's limit and the marker the data replaces. */
#define TEMPLATE_MAX (64u << 20)
static const char marker[] = "/*PX_VIEW_DATA*/null";

static struct {
	const char *port, *config, *root, *summary, *html, *templ, *csv, *rate;
} A;

static volatile sig_atomic_t stop;

static void on_signal(int sig)
{
	(void)sig;
	stop = 1;
}

static int usage_error(const char *what, const char *arg)
{
	fprintf(stderr, "proxima-view: %s%s%s\n%s", what, arg ? ": " : "",
		arg ? arg : "", usage_text);
	return 2;
}

static int parse_args(int argc, char **argv)
{
	static const struct {
		const char *flag;
		const char **value;
	} flags[] = {{"--port", &A.port},       {"--config", &A.config},
		     {"--web-root", &A.root},   {"--summary", &A.summary},
		     {"--html", &A.html},       {"--template", &A.templ},
		     {"--rate", &A.rate}};
	int i;
	size_t k;
	for (i = 1; i < argc; i++) {
		const char *a = argv[i];
		if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
			fputs(usage_text, stdout);
			return 1;
		}
		for (k = 0; k < sizeof(flags) / sizeof(flags[0]); k++) {
			size_t n = strlen(flags[k].flag);
			if (strncmp(a, flags[k].flag, n) || (a[n] && a[n] != '='))
				continue;
			if (a[n] == '=')
				*flags[k].value = a + n + 1;
			else if (i + 1 < argc)
				*flags[k].value = argv[++i];
			else
				return usage_error("a value is missing after", a);
			if (!**flags[k].value)
				return usage_error("an empty value for", a);
			break;
		}
		if (k < sizeof(flags) / sizeof(flags[0]))
			continue;
		if (a[0] == '-' && a[1])
			return usage_error("unknown option", a);
		if (A.csv)
			return usage_error("one TELEMETRY.csv only, not also", a);
		A.csv = a;
	}
	if (!A.csv)
		return usage_error("no TELEMETRY.csv given", NULL);
	if (A.html && A.port)
		return usage_error("--html writes a file; --port serves", NULL);
	if (A.rate) {
		char *end;
		double hz = strtod(A.rate, &end);
		if (*end || !(hz >= 0 && hz <= 1e6))
			return usage_error("--rate needs a number 0 .. 1000000, not", A.rate);
	}
	return 0;
}

/* What --config gives: its scene and, in avoidance mode, its arm. */
static struct {
	struct px_config *cfg;
	struct px_scene *scene;
	struct px_view_arm *arm;
} C;

/* The arm of C.cfg's robot as a config check makes it (none when the
 * config is not in avoidance mode or its robot cannot be made). */
static void load_arm(void)
{
	struct px_app_options o;
	struct px_app *app = NULL;
	struct px_app_arm arm;
	char msg[256];
	px_app_options_default(&o);
	o.name = "proxima-view";
	o.config = A.config;
	o.check = 1;
	if (px_app_create(C.cfg, &o, &app, msg, sizeof(msg)) != PX_OK)
		return;
	if (px_app_arm(app, &arm) && px_view_arm_create(&arm, &C.arm) != PX_OK)
		fprintf(stderr, "proxima-view: %s: the arm is not drawn\n", A.config);
	px_app_free(app);
}

/* The scene and arm of --config (none: no models). 0 or 1. */
static int load_config(void)
{
	static struct px_config_diag diag;
	int rc;
	if (!A.config)
		return 0;
	rc = px_config_load_file(A.config, &C.cfg, &diag);
	if (rc == PX_OK) {
		px_config_diag_init(&diag);
		rc = px_scene_config_load(C.cfg, &C.scene, &diag);
	}
	if (rc != PX_OK) {
		px_config_diag_print(&diag, stderr);
		fprintf(stderr, "proxima-view: %s: %s\n", A.config, px_strerror(rc));
		return 1;
	}
	load_arm();
	return 0;
}

/* The scene message: the config's models, the arm when the track has
 * its links. 0 or 1. */
static int scene_json(int links, char **json, size_t *len)
{
	struct px_view_scene_info info;
	int rc;
	memset(&info, 0, sizeof(info));
	info.tool_radius_m = 0.002;
	info.arm = links ? C.arm : NULL;
	rc = px_view_scene_json(C.scene, &info, json, len);
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-view: the scene: %s\n", px_strerror(rc));
		return 1;
	}
	return 0;
}

/* The summary JSON (NULL: none), checked. 0 or 1. */
static int summary_json(char **text)
{
	char path[PATH_MAX], why[PATH_MAX + 128];
	size_t len;
	const char *slash;
	*text = NULL;
	if (A.summary) {
		snprintf(path, sizeof(path), "%s", A.summary);
	} else {
		slash = strrchr(A.csv, '/');
		snprintf(path, sizeof(path), "%.*srun-summary.json",
			 slash ? (int)(slash - A.csv + 1) : 0, A.csv);
		if (access(path, R_OK) != 0)
			return 0;
	}
	if (view_read_file(path, VIEW_JSON_MAX, text, &len, why, sizeof(why)) ||
	    view_json_check(*text, len, why + strlen(why), sizeof(why) - strlen(why))) {
		if (*text)
			fprintf(stderr, "proxima-view: %s: %s\n", path, why);
		else
			fprintf(stderr, "proxima-view: %s\n", why);
		free(*text);
		*text = NULL;
		return 1;
	}
	return 0;
}

/* s into f with every "</" as "<\/" (the same JSON; never closes the
 * page's script element). */
static void put_json(FILE *f, const char *s, size_t n)
{
	size_t i, from = 0;
	for (i = 0; i + 1 < n; i++)
		if (s[i] == '<' && s[i + 1] == '/') {
			fwrite(s + from, 1, i + 1 - from, f);
			fputc('\\', f);
			from = i + 1;
		}
	fwrite(s + from, 1, n - from, f);
}

static int write_html(const char *scene, size_t scene_len, const char *track,
		      size_t track_len, size_t rows)
{
	static struct tool_out out;
	char tpath[PATH_MAX + 32], why[PATH_MAX + 128];
	char *t, *at;
	size_t tlen;
	if (A.templ) {
		snprintf(tpath, sizeof(tpath), "%s", A.templ);
	} else {
		tool_view_root(tpath, sizeof(tpath) - 24);
		strcat(tpath, "/report-template.html");
	}
	if (view_read_file(tpath, TEMPLATE_MAX, &t, &tlen, why, sizeof(why))) {
		fprintf(stderr, "proxima-view: %s (make view-web builds the page)\n",
			why);
		return 1;
	}
	at = strstr(t, marker);
	if (!at || strstr(at + 1, marker)) {
		fprintf(stderr, "proxima-view: %s: %s '%s'\n", tpath,
			at ? "more than one" : "no", marker);
		free(t);
		return 1;
	}
	tool_out_protect(A.csv, "the telemetry CSV");
	tool_out_protect(tpath, "the template");
	if (A.config)
		tool_out_protect(A.config, "the config file");
	if (tool_out_open(&out, A.html) != 0) {
		fprintf(stderr, "proxima-view: %s\n", out.why);
		free(t);
		return 1;
	}
	fwrite(t, 1, (size_t)(at - t), out.f);
	fputs("{\"scene\":", out.f);
	put_json(out.f, scene, scene_len);
	fputs(",\"track\":", out.f);
	put_json(out.f, track, track_len);
	fputc('}', out.f);
	fputs(at + strlen(marker), out.f);
	free(t);
	if (tool_out_commit(&out) != 0) {
		fprintf(stderr, "proxima-view: %s\n", out.why);
		return 1;
	}
	printf("proxima-view: %s: %zu frames\n", A.html, rows);
	return 0;
}

static int serve(const char *scene, size_t scene_len, const char *track,
		 size_t track_len, size_t rows)
{
	struct px_view_options o;
	struct px_view *v;
	struct sigaction sa;
	char addr[64] = "", root[PATH_MAX + 32], msg[320], url[128];
	int port = TOOL_VIEW_PORT, rc;
	if (A.port && tool_view_parse(A.port, addr, sizeof(addr), &port))
		return usage_error("--port needs [ADDR:]PORT, not", A.port);
	if (A.root)
		snprintf(root, sizeof(root), "%s", A.root);
	else
		tool_view_root(root, sizeof(root));
	px_view_options_default(&o);
	o.addr = addr[0] ? addr : NULL;
	o.port = port;
	o.web_root = root;
	o.mode = "replay";
	o.name = A.config ? A.config : A.csv;
	rc = px_view_create(&o, &v, msg, sizeof(msg));
	if (rc == PX_OK && (px_view_set_scene(v, scene, scene_len) != PX_OK ||
			    px_view_set_track(v, track, track_len) != PX_OK ||
			    px_view_start(v) != PX_OK)) {
		snprintf(msg, sizeof(msg), "view: out of memory");
		rc = PX_E_NOMEM;
	}
	if (rc != PX_OK) {
		fprintf(stderr, "proxima-view: %s\n", msg);
		px_view_free(v);
		return 1;
	}
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGHUP, &sa, NULL);
	tool_view_url(addr, port, url, sizeof(url));
	printf("proxima-view: %s: %zu frames at %s (Ctrl-C ends)\n", A.csv, rows,
	       url);
	fflush(stdout);
	while (!stop) {
		struct timespec ts = {0, 100000000};
		nanosleep(&ts, NULL);
	}
	px_view_free(v);
	return 0;
}

int main(int argc, char **argv)
{
	char *scene = NULL, *summary = NULL, *track = NULL;
	char why[PATH_MAX + 128];
	size_t scene_len = 0, track_len = 0, rows = 0;
	struct view_track_opts to;
	struct view_track_info ti;
	int rc = parse_args(argc, argv);
	if (rc)
		return rc == 1 ? 0 : rc;
	memset(&to, 0, sizeof(to));
	to.rate_hz = A.rate ? strtod(A.rate, NULL) : TRACK_RATE_HZ;
	if (load_config() || summary_json(&summary)) {
		rc = 1;
	} else if (to.summary = summary, to.scene = C.scene, to.arm = C.arm,
		   view_track_json(A.csv, &to, &track, &track_len, &ti, why,
				   sizeof(why))) {
		fprintf(stderr, "proxima-view: %s\n", why);
		rc = 1;
	} else if (rows = ti.frames, scene_json(ti.links, &scene, &scene_len)) {
		rc = 1;
	} else if (A.html) {
		rc = write_html(scene, scene_len, track, track_len, rows);
	} else {
		rc = serve(scene, scene_len, track, track_len, rows);
	}
	free(scene);
	free(summary);
	free(track);
	px_view_arm_free(C.arm);
	px_scene_free(C.scene);
	px_config_free(C.cfg);
	return rc;
}
