/*
 * Tracked streams on B-rep models (px_model_stream_*, brep_stream.c):
 * along smooth paths over the parts of tests/support/brep_gen.h and the
 * shipped STEP block that slide over faces, cross trimming edges, holes
 * and a crease, and dive through thin walls, every answer equals the
 * global query's (distance, sign, point), the jumped flag is set
 * whenever the answering feature changes, most answers come from the
 * tracked set, and stream queries make no heap calls.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "brep_gen.h"
#include "px_alloc_count.h"
#include "px_brep.h"
#include "px_features.h"
#include "px_load.h"
#include "px_model.h"
#include "px_test.h"
#include "px_test_paths.h"

/* A path: the point at s in [0, 1]. */
typedef px_vec3 (*path_fn)(double s);

struct tally {
	int steps, jumps, point_off;
	double max_rel;   /* largest distance difference / (size + |d|) */
	struct px_model_stream_stats st;
};

/* Follow path over n steps with a stream on m (opts o) and check every
 * answer against the global query; size: the part's box diagonal. */
static void follow(struct px_model *m, const char *name, path_fn path, int n,
		   const struct px_model_stream_opts *o, struct tally *t)
{
	struct px_model_stream *s;
	int i, pf = -1, pi = -1;
	uint64_t a0;
	px_aabb box = px_model_local_aabb(m);
	double size = px_aabb_diagonal(&box);

	PX_CHECK_INT_EQ(px_model_stream_create(m, o, &s), PX_OK);
	a0 = px_alloc_region_begin();
	for (i = 0; i <= n; i++) {
		px_vec3 p = path((double)i / n);
		struct px_model_result a, c;
		struct px_model_stream_note note;
		double tol;
		PX_CHECK_INT_EQ(px_model_stream_query(s, p, INFINITY, 0, &a, &note), 1);
		PX_CHECK_INT_EQ(px_model_query(m, p, &c), 1);
		tol = 1e-11 * (size + fabs(c.distance));
		if (fabs(a.distance - c.distance) > t->max_rel * (size + fabs(c.distance)))
			t->max_rel = fabs(a.distance - c.distance) / (size + fabs(c.distance));
		PX_CHECK_MSG(fabs(a.distance - c.distance) <= tol,
			     "%s step %d (%.17g, %.17g, %.17g): tracked %.17g (feature %d "
			     "index %d source %d), global %.17g (feature %d index %d)",
			     name, i, p.x, p.y, p.z, a.distance, a.feature, a.index, note.source,
			     c.distance, c.feature, c.index);
		PX_CHECK_INT_EQ(a.is_signed, c.is_signed);
		PX_CHECK_MSG(a.inside == c.inside, "%s step %d: inside %d, global %d", name, i,
			     a.inside, c.inside);
		PX_CHECK(a.certified);
		/* the point is the model's, at that distance; the global
		 * one unless two features are equally near */
		PX_CHECK(fabs(px_v3_dist(p, a.point) - fabs(a.distance)) <= 1e-12 * size + tol);
		if (px_v3_dist(a.point, c.point) > 1e-7 * size)
			t->point_off++;
		if (i > 0 && (a.feature != pf || a.index != pi))
			PX_CHECK_MSG(note.jumped, "%s step %d: feature %d/%d -> %d/%d, not jumped",
				     name, i, pf, pi, a.feature, a.index);
		t->jumps += note.jumped != 0;
		pf = a.feature;
		pi = a.index;
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a0), 0);
	t->steps += n + 1;
	px_model_stream_get_stats(s, &t->st);
	px_model_stream_free(s);
}

/* Both stream settings: deterministic (no cold switch) and the
 * defaults. A quarter of the answers at least tracked (the rest the
 * global query's: over the work budget near thin walls and where a
 * crease leaves its face's domain), hardly a point away from the global
 * one (equally near features). */
static void follow_both(struct px_model *m, const char *name, path_fn path, int n)
{
	struct px_model_stream_opts o;
	struct tally t;
	memset(&t, 0, sizeof(t));
	px_model_stream_opts_default(&o);
	o.cold_switch = 0;
	follow(m, name, path, n, &o, &t);
	printf("    %-28s %5llu of %5llu tracked, %4d jumps, %d points off, "
	       "distances within %.1e\n",
	       name, (unsigned long long)t.st.tracked, (unsigned long long)t.st.queries,
	       t.jumps, t.point_off, t.max_rel);
	PX_CHECK_MSG(t.st.tracked * 4 >= t.st.queries,
		     "%s: %llu of %llu answers tracked (%llu global)", name,
		     (unsigned long long)t.st.tracked, (unsigned long long)t.st.queries,
		     (unsigned long long)t.st.global);
	PX_CHECK_MSG(t.point_off <= t.steps / 100, "%s: %d points off the global ones", name,
		     t.point_off);
	px_model_stream_opts_default(&o);
	memset(&t, 0, sizeof(t));
	follow(m, name, path, n, &o, &t);
	PX_CHECK(t.st.queries == (uint64_t)n + 1);
}

/* One path over a part: its name, the path and its steps. */
struct leg {
	const char *name;
	path_fn path;
	int n;
};

/* The part g (released here) as a model, signed when closed, followed
 * along each of the n legs. */
static void run_part(struct brep_gen *g, int closed, const struct leg *legs, int n)
{
	struct px_brep *b;
	struct px_model *m;
	struct px_brep_error err;
	int i;
	PX_CHECK_MSG(px_brep_create(&g->d, NULL, &err, &b) == PX_OK, "%s: %s", g->d.name,
		     err.msg);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	PX_CHECK_INT_EQ(!!(px_model_caps(m) & PX_MODEL_CAP_SIGNED), closed);
	for (i = 0; i < n; i++)
		follow_both(m, legs[i].name, legs[i].path, legs[i].n);
	px_model_free(m);
	free(g);
}

/* A Lissajous figure through the box about c of half widths h. */
static px_vec3 lissajous(px_vec3 c, px_vec3 h, double s)
{
	double w = 2.0 * M_PI * s;
	return px_v3(c.x + h.x * sin(3.0 * w + 0.3), c.y + h.y * sin(2.0 * w + 1.1),
		     c.z + h.z * sin(5.0 * w));
}

/* ---- sheet with a hole (open): over the face, across the hole, through
 * the sheet ---- */

static px_vec3 sheet_across(double s)
{
	return px_v3(-0.2 + 1.4 * s, 0.5 + 0.05 * sin(6.0 * s), 0.03 + 0.02 * sin(9.0 * s));
}

static px_vec3 sheet_dive(double s)
{
	return px_v3(0.2 + 0.6 * s, 0.25 + 0.1 * s, 0.1 * cos(M_PI * s));
}

static px_vec3 sheet_liss(double s)
{
	return lissajous(px_v3(0.5, 0.5, 0.0), px_v3(0.7, 0.7, 0.3), s);
}

static void test_sheet_hole(void)
{
	static const struct leg legs[] = {
		{"sheet_hole across", sheet_across, 2000},
		{"sheet_hole dive", sheet_dive, 1000},
		{"sheet_hole lissajous", sheet_liss, 4000}};
	run_part(brep_gen_sheet_hole(), 0, legs, (int)(sizeof(legs) / sizeof(legs[0])));
}

/* ---- roof with a hole: the crease crosses the hole ---- */

static px_vec3 roof_along(double s)
{
	return px_v3(0.5 + 0.02 * sin(11.0 * s), -0.2 + 1.4 * s, 0.35);
}

static void test_roof_hole(void)
{
	static const struct leg legs[] = {
		{"roof_hole along the crease", roof_along, 2000},
		{"roof_hole lissajous", sheet_liss, 4000}};
	run_part(brep_gen_roof_hole(), 0, legs, (int)(sizeof(legs) / sizeof(legs[0])));
}

/* ---- cube with a drilled hole (closed, signed): round it, down the
 * bore, through the solid ---- */

static px_vec3 cube_round(double s)
{
	double w = 2.0 * M_PI * s;
	return px_v3(0.5 + 0.8 * cos(w), 0.5 + 0.8 * sin(w), 0.5 + 0.6 * sin(3.0 * w));
}

static px_vec3 cube_bore(double s)
{
	return px_v3(0.5 + 0.1 * cos(4.0 * s), 0.5 + 0.1 * sin(4.0 * s), -0.3 + 1.6 * s);
}

static px_vec3 cube_through(double s)
{
	return px_v3(-0.2 + 1.4 * s, 0.25 + 0.3 * s, 0.3 + 0.1 * sin(5.0 * s));
}

static px_vec3 cube_liss(double s)
{
	return lissajous(px_v3(0.5, 0.5, 0.5), px_v3(0.8, 0.8, 0.8), s);
}

static void test_cube_hole(void)
{
	static const struct leg legs[] = {
		{"cube_hole round", cube_round, 3000},
		{"cube_hole bore", cube_bore, 2000},
		{"cube_hole through", cube_through, 2000},
		{"cube_hole lissajous", cube_liss, 4000}};
	run_part(brep_gen_cube_hole(), 1, legs, (int)(sizeof(legs) / sizeof(legs[0])));
}

/* ---- free-form sheet trimmed by a spline loop with a hole ---- */

static px_vec3 free_liss(double s)
{
	return lissajous(px_v3(0.55, 0.5, 0.05), px_v3(0.6, 0.6, 0.4), s);
}

static px_vec3 free_across(double s)
{
	return px_v3(-0.1 + 1.2 * s, 0.45 + 0.1 * sin(7.0 * s), 0.15 * cos(3.0 * s));
}

static void test_freeform(void)
{
	static const struct leg legs[] = {
		{"freeform lissajous", free_liss, 4000},
		{"freeform across", free_across, 2000}};
	run_part(brep_gen_freeform(), 0, legs, (int)(sizeof(legs) / sizeof(legs[0])));
}

/* ---- closed box with 1 mm walls: through a wall into the void and
 * out, round the void ---- */

static px_vec3 thin_through(double s)
{
	return px_v3(-0.01 + 0.03 * s, 0.05 + 0.01 * sin(4.0 * s), 0.05);
}

static px_vec3 thin_corner(double s)
{
	return px_v3(-0.005 + 0.012 * s, -0.0042 + 0.0125 * s, 0.03 + 0.02 * s);
}

static px_vec3 thin_liss(double s)
{
	return lissajous(px_v3(0.05, 0.05, 0.05), px_v3(0.06, 0.06, 0.06), s);
}

static void test_thin_box(void)
{
	static const struct leg legs[] = {
		{"thin_box through", thin_through, 3000},
		{"thin_box corner", thin_corner, 2000},
		{"thin_box lissajous", thin_liss, 4000}};
	run_part(brep_gen_thin_box(), 1, legs, (int)(sizeof(legs) / sizeof(legs[0])));
}

/* ---- the shipped STEP part (filleted block with a drilled hole) ---- */

static px_aabb step_box;

static px_vec3 step_liss(double s)
{
	px_vec3 c = px_v3_scale(px_v3_add(step_box.min, step_box.max), 0.5),
		h = px_v3_scale(px_v3_sub(step_box.max, step_box.min), 0.65);
	return lissajous(c, h, s);
}

static px_vec3 step_through(double s)
{
	px_vec3 a = step_box.min, b = step_box.max, d = px_v3_sub(b, a);
	return px_v3(a.x - 0.2 * d.x + 1.4 * d.x * s, a.y + 0.37 * d.y + 0.05 * d.y * sin(5.0 * s),
		     a.z + 0.41 * d.z);
}

static void test_step_block(void)
{
	struct px_model *m;
	char path[512], msg[256];

	PX_NEEDS(OCCT);
	px_test_data_path(path, sizeof(path), "../../config/examples/parts/filleted_block.step");
	PX_CHECK_MSG(px_model_load(path, 0.0, &m, msg, sizeof(msg)) == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_BREP);
	step_box = px_model_local_aabb(m);
	follow_both(m, "filleted_block lissajous", step_liss, 3000);
	follow_both(m, "filleted_block through", step_through, 2000);
	px_model_free(m);
}

/* ---- closed-form faces: answered ahead of the tracker, from a bound on
 * everything else; across a face edge, and across the bore's axis (the
 * closest point jumps while the face stays the same) ---- */

static px_vec3 top_to_edge(double s)
{
	return px_v3(0.2 + 1.1 * s, 0.2, 1.1 - 0.05 * s);
}

static px_vec3 bore_across(double s)
{
	return px_v3(0.5, 0.4 + 0.2 * s, 0.5);
}

static void test_closed_form(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_model_stream_opts o;
	int cs;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	for (cs = 0; cs <= 1; cs++) {
		struct px_model_stream *s;
		struct tally t;
		int i, n = 400, jumps = 0, at = -1;
		px_vec3 prev = px_v3(0, 0, 0);
		px_model_stream_opts_default(&o);
		o.cold_switch = cs;
		/* over the top face (about the first 70 % of the path) and
		 * past its edge: the face's answers come from the bound;
		 * follow() checks every answer and the jumped flag at the
		 * face-to-edge change */
		memset(&t, 0, sizeof(t));
		follow(m, "cube_hole top to edge", top_to_edge, n, &o, &t);
		PX_CHECK_MSG(t.st.hot * 2 >= t.st.queries, "cold_switch %d: %llu of %llu by the bound",
			     cs, (unsigned long long)t.st.hot, (unsigned long long)t.st.queries);
		PX_CHECK(t.jumps >= 2);
		/* through the bore's axis (no step on it, away from its
		 * seam): one jump, where the point crosses it */
		PX_CHECK_INT_EQ(px_model_stream_create(m, &o, &s), PX_OK);
		n = 401;
		for (i = 0; i <= n; i++) {
			px_vec3 p = bore_across((double)i / n);
			struct px_model_result a, c;
			struct px_model_stream_note note;
			PX_CHECK_INT_EQ(px_model_stream_query(s, p, INFINITY, 0, &a, &note), 1);
			PX_CHECK_INT_EQ(px_model_query(m, p, &c), 1);
			PX_CHECK(fabs(a.distance - c.distance) <= 1e-12 * (2.0 + fabs(c.distance)));
			PX_CHECK_INT_EQ(a.feature, PX_FEATURE_SURFACE);
			if (i > 0 && note.jumped) {
				jumps++;
				at = i;
				PX_CHECK(px_v3_dist(a.point, prev) > 0.3);
			}
			prev = a.point;
		}
		px_model_stream_get_stats(s, &t.st);
		px_model_stream_free(s);
		PX_CHECK_INT_EQ(jumps, 1);
		PX_CHECK(at == n / 2 || at == n / 2 + 1);
		PX_CHECK_MSG(t.st.hot * 2 >= t.st.queries, "bore, cold_switch %d: %llu of %llu by the bound",
			     cs, (unsigned long long)t.st.hot, (unsigned long long)t.st.queries);
	}
	px_model_free(m);
	free(g);
}

/* ---- smooth random paths and sums of sines through the parts of
 * closed-form faces and their box, at steps of 0.1 % and 1 % of their
 * size: the bound is kept, moved and made afresh at every kind of step,
 * with and without the tracker behind it ---- */

#define NRAND 3000
static px_vec3 rand_q[NRAND + 1];

static px_vec3 rand_path(double s)
{
	return rand_q[(int)lround(s * NRAND)];
}

static void random_legs(struct px_model *m, const char *name)
{
	static const struct px_path_opts po = {px_rand_unit, px_rand_normal, 0.97, 0.25, 1.2};
	px_aabb box = px_model_local_aabb(m);
	double size = px_aabb_diagonal(&box), step;
	int kind, cs;
	box = px_aabb_inflate(&box, 0.1 * size);
	for (kind = 0; kind < 2; kind++)
		for (step = 1e-3; step < 2e-2; step *= 10.0)
			for (cs = 0; cs <= 1; cs++) {
				struct px_model_stream_opts o;
				struct tally t;
				px_test_path(rand_q, NRAND + 1, kind, box, step * size, &po);
				px_model_stream_opts_default(&o);
				o.cold_switch = cs;
				memset(&t, 0, sizeof(t));
				follow(m, name, rand_path, NRAND, &o, &t);
				PX_CHECK_MSG(t.point_off <= t.steps / 100,
					     "%s: %d points off the global ones", name, t.point_off);
			}
}

static void test_random_paths(void)
{
	struct brep_gen *(*gen[3])(void) = {brep_gen_cube_hole, brep_gen_thin_box,
					    brep_gen_sheet_hole};
	int k;
	for (k = 0; k < 3; k++) {
		struct brep_gen *g = gen[k]();
		struct px_brep *b;
		struct px_model *m;
		PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
		PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
		random_legs(m, g->d.name);
		px_model_free(m);
		free(g);
	}
}

/* A B-rep stream follows the model's pose, as any stream. */
static void test_pose(void)
{
	struct brep_gen *g = brep_gen_cube_hole();
	struct px_brep *b;
	struct px_model *m;
	struct px_model_stream *s;
	px_pose pose = px_pose_identity();
	int i;
	PX_CHECK_INT_EQ(px_brep_create(&g->d, NULL, NULL, &b), PX_OK);
	PX_CHECK_INT_EQ(px_model_from_brep(b, &m), PX_OK);
	PX_CHECK_INT_EQ(px_model_stream_create(m, NULL, &s), PX_OK);
	for (i = 0; i < 500; i++) {
		struct px_model_result a, c;
		px_vec3 p = cube_round(i / 500.0);
		pose.t = px_v3(0.001 * i, 0.0, 0.5);
		PX_CHECK_INT_EQ(px_model_set_pose(m, pose), PX_OK);
		PX_CHECK_INT_EQ(px_model_stream_query(s, p, INFINITY, 0, &a, NULL), 1);
		PX_CHECK_INT_EQ(px_model_query(m, p, &c), 1);
		PX_CHECK(fabs(a.distance - c.distance) <= 1e-12 * (2.0 + fabs(c.distance)));
	}
	px_model_stream_free(s);
	px_model_free(m);
	free(g);
}

static const struct px_test tests[] = {
	PX_T(test_sheet_hole), PX_T(test_roof_hole), PX_T(test_cube_hole),
	PX_T(test_freeform),   PX_T(test_thin_box),  PX_T(test_step_block),
	PX_T(test_closed_form), PX_T(test_random_paths), PX_T(test_pose)};
PX_TEST_MAIN(tests)
