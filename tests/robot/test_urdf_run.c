/* PX_TEST_NEEDS: libyaml libxml2 assimp (tests/run.sh skips it in builds without them) */
/*
 * config/examples/can_avoid_urdf.yaml run by the app (app/px_app.h) in
 * virtual time: the URDF arm over the simulated CAN bus against the
 * simulated depth camera's box moving into its path. The arm is slowed
 * and never comes closer than the protective distance, goes back to
 * full speed once the box is gone, no heap call in the cycles while the
 * camera's clouds are swapped in; the same run twice gives the same
 * telemetry; and a camera whose frames stop coming trips the watchdog
 * like a silent device. The example with capsule clearances instead of
 * link models runs too. Refusals of the URDF keys name their place.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_app.h"
#include "px_config.h"
#include "px_test.h"
#include "px_test_app.h"

#define EXAMPLE "config/examples/can_avoid_urdf.yaml"

/* The example's text with one substitution (from -> to; NULL: none),
 * written next to it so that its relative paths hold. */
static const char *variant(const char *from, const char *to, const char *name)
{
	static char path[256];
	FILE *in = fopen(EXAMPLE, "r"), *out;
	char line[512];
	int hit = 0;
	PX_CHECK(in != NULL);
	snprintf(path, sizeof(path), "config/examples/.%s-%d.yaml", name, (int)getpid());
	out = fopen(path, "w");
	PX_CHECK(out != NULL);
	while (fgets(line, sizeof(line), in)) {
		char *p = from ? strstr(line, from) : NULL;
		if (p) {
			fprintf(out, "%.*s%s%s", (int)(p - line), line, to, p + strlen(from));
			hit = 1;
		} else {
			fputs(line, out);
		}
	}
	fclose(in);
	fclose(out);
	PX_CHECK(!from || hit);
	return path;
}

static int run(const char *path, double dur_s, int check, struct px_test_recs *rs,
	       struct px_app_summary *s)
{
	static struct px_config_diag diag;
	struct px_config *cfg = NULL;
	struct px_app_options o;
	struct px_app *app = NULL;
	char msg[256];
	int rc = px_config_load_file(path, &cfg, &diag);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", path, px_strerror(rc));
	px_app_options_default(&o);
	o.config = path;
	o.virtual_time = 1;
	o.duration_s = dur_s;
	o.check = check;
	o.note = px_test_app_note;
	o.heap_count = px_alloc_count_thread;
	o.record = rs ? px_test_app_record : NULL;
	o.user = rs;
	px_test_app_notes[0] = '\0';
	rc = px_app_create(cfg, &o, &app, msg, sizeof(msg));
	if (rc == PX_OK && !check) {
		PX_CHECK_INT_EQ(px_app_run(app), PX_OK);
		PX_CHECK_INT_EQ(px_app_summary(app, s), PX_OK);
	}
	px_app_free(app);
	px_config_free(cfg);
	return rc;
}

static void test_example_avoids_the_moving_box(void)
{
	static struct px_test_recs a, b;
	struct px_app_summary s;
	size_t i;
	int slowed = 0, full_after = 0;
	PX_NEEDS(YAML);
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	a.n = 0;
	PX_CHECK_MSG(run(EXAMPLE, 10.0, 0, &a, &s) == PX_OK, "%s", px_test_app_notes);
	PX_CHECK_INT_EQ(s.cycles, 10000);
	PX_CHECK_INT_EQ(s.safe_state_trips, 0);
	PX_CHECK_INT_EQ(s.allocations_after_setup, 0);
	/* protective distance 50 mm; stated tolerance 2 mm */
	PX_CHECK_MSG(s.min_clearance_m >= s.protective_distance_m - 0.002,
		     "min clearance %g m, protective %g m", s.min_clearance_m,
		     s.protective_distance_m);
	PX_CHECK_MSG(s.min_clearance_m < s.influence_distance_m, "the box never came near");
	PX_CHECK(s.min_speed_scale < 0.5);
	/* a 30 Hz camera over 10 s: every frame swapped in once */
	PX_CHECK_MSG(s.cloud_swaps >= 295 && s.cloud_swaps <= 301, "%llu frames swapped in",
		     (unsigned long long)s.cloud_swaps);
	for (i = 0; i < a.n; i++) {
		const struct px_app_record *r = &a.r[i];
		if (r->t_s > 4.0 && r->t_s < 7.0 && r->scale < 0.5)
			slowed = 1;
		/* the box leaves by 9.5 s: the swing after it at full speed */
		if (r->t_s > 9.5 && fabs(r->qdot[0]) > 0.99 && r->scale == 1.0)
			full_after = 1;
	}
	PX_CHECK_MSG(slowed, "not slowed while the box stood in the path");
	PX_CHECK_MSG(full_after, "not back to full speed once the box left");
	/* the camera runs in its own thread, waited for on the virtual
	 * clock: the same telemetry again */
	b.n = 0;
	PX_CHECK_MSG(run(EXAMPLE, 10.0, 0, &b, &s) == PX_OK, "%s", px_test_app_notes);
	PX_CHECK_INT_EQ(a.n, b.n);
	for (i = 0; i < a.n && i < b.n; i++)
		PX_CHECK_MSG(memcmp(&a.r[i], &b.r[i], sizeof(a.r[i])) == 0,
			     "record %zu differs between two runs", i);
}

/* A camera at 0.1 Hz: its second frame is 10 s away, its stamps age
 * past the 200 ms timeout: the watchdog trips as for a stale device. */
static void test_stale_camera_trips(void)
{
	struct px_app_summary s;
	const char *path;
	PX_NEEDS(YAML);
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	path = variant("rate_hz: 30", "rate_hz: 0.1", "stale");
	PX_CHECK_MSG(run(path, 1.0, 0, NULL, &s) == PX_OK, "%s", px_test_app_notes);
	unlink(path);
	PX_CHECK(s.safe_state_trips >= 1);
	PX_CHECK(s.faults_by_cause[PX_FAULT_INPUT_STALE] >= 1);
	PX_CHECK_INT_EQ(s.allocations_after_setup, 0);
}

/* The example with clearance: capsules on the URDF's chain (the
 * camera's cloud is measured only by link models, so it goes): the
 * runner runs it, kept clear of the floor, no heap call in the cycles. */
static void test_capsules_run(void)
{
	static const char caps[] =
		"    clearance: capsules\n"
		"    capsules:\n"
		"      - {link: 0, a_m: [0, 0, 0], b_m: [0, 0, 0.16], radius_m: 0.08}\n"
		"      - {link: 2, a_m: [0, 0, 0], b_m: [0.45, 0, 0], radius_m: 0.06}\n"
		"      - {link: 3, a_m: [0, 0, 0], b_m: [0.39, 0, 0], radius_m: 0.05}\n"
		"      - {link: 6, a_m: [0, 0, 0], b_m: [0.08, 0, 0], radius_m: 0.04}\n";
	struct px_app_summary s;
	char path[256], line[512];
	FILE *in, *out;
	int cut = 0;
	PX_NEEDS(YAML);
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	snprintf(path, sizeof(path), "config/examples/.caps-%d.yaml", (int)getpid());
	in = fopen(EXAMPLE, "r");
	out = fopen(path, "w");
	PX_CHECK(in && out);
	while (in && out && fgets(line, sizeof(line), in)) {
		cut |= strncmp(line, "  depth_sensor:", 15) == 0;
		if (strstr(line, "clearance: models"))
			fputs(caps, out);
		else if (!cut)
			fputs(line, out);
	}
	if (in)
		fclose(in);
	if (out)
		fclose(out);
	PX_CHECK(cut);
	PX_CHECK_MSG(run(path, 10.0, 0, NULL, &s) == PX_OK, "%s", px_test_app_notes);
	unlink(path);
	PX_CHECK_INT_EQ(s.cycles, 10000);
	PX_CHECK(s.avoiding);
	PX_CHECK_INT_EQ(s.safe_state_trips, 0);
	PX_CHECK_INT_EQ(s.allocations_after_setup, 0);
	PX_CHECK_INT_EQ(s.cloud_swaps, 0);
	PX_CHECK_MSG(s.min_clearance_m >= s.protective_distance_m, "min clearance %g m",
		     s.min_clearance_m);
}

/* Refusals name the config's place and the URDF's. */
static void test_refusals(void)
{
	static const struct {
		const char *from, *to, *says;
	} cases[] = {
		{"tip_link: tool0", "tip_link: tool9", "control.avoidance.tip_link: "},
		{"urdf: robots/arm6/arm6.urdf", "urdf: robots/arm6/none.urdf",
		 "control.avoidance.urdf: "},
		{"package_paths: [robots]", "package_paths: [nowhere]",
		 "arm6.urdf:6: <link name='base_link'>: mesh 'package://arm6/meshes/base.stl' not found"},
		{"urdf_joints: [shoulder_pan,", "urdf_joints: [shoulder_pin,",
		 "control.avoidance.urdf_joints[0]: 'shoulder_pin' is no movable joint"},
		{"{a: wrist1_link, b: wrist3_link}", "{a: wrist1_link, b: wrist9_link}",
		 "control.avoidance.allowed_collisions: allowed collision 0: no link"},
		{"clearance: models", "clearance: capsules", "needs the capsules list"},
	};
	size_t i;
	PX_NEEDS(YAML);
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	PX_CHECK_MSG(run(EXAMPLE, 0, 1, NULL, NULL) == PX_OK, "%s", px_test_app_notes);
	for (i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
		const char *path = variant(cases[i].from, cases[i].to, "bad");
		static struct px_config_diag diag;
		struct px_config *cfg = NULL;
		int rc = px_config_load_file(path, &cfg, &diag);
		if (rc == PX_OK) {
			px_config_free(cfg);
			rc = run(path, 0, 1, NULL, NULL);
		} else {
			px_test_app_notes[0] = '\0';
			if (diag.count)
				snprintf(px_test_app_notes, sizeof(px_test_app_notes), "%s", diag.errors[0].msg);
		}
		unlink(path);
		PX_CHECK_MSG(rc != PX_OK, "case %zu accepted", i);
		PX_CHECK_MSG(strstr(px_test_app_notes, cases[i].says) != NULL, "case %zu: '%s' lacks '%s'", i,
			     px_test_app_notes, cases[i].says);
	}
}

static const struct px_test tests[] = {
	PX_T(test_example_avoids_the_moving_box),
	PX_T(test_stale_camera_trips),
	PX_T(test_capsules_run),
	PX_T(test_refusals),
};
PX_TEST_MAIN(tests)
