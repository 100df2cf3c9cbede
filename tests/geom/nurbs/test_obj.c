/* Wavefront OBJ loader: shipped example files evaluated against their
 * known geometry, every error kind with its place, and robustness on
 * truncated and mutated input. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_nurbs.h"
#include "px_obj.h"
#include "px_test.h"

static struct px_obj_model *load(const char *name)
{
	char path[512];
	struct px_obj_error e;
	struct px_obj_model *m = NULL;
	int rc;
	px_test_data_path(path, sizeof(path), name);
	rc = px_obj_load_file(path, &m, &e);
	PX_CHECK_MSG(rc == PX_OK, "%s:%d:%d: %s (%s)", e.file, e.line,
		     e.column, e.msg, px_strerror_name(rc));
	PX_CHECK(m != NULL);
	PX_CHECK(m->memory_bytes > sizeof(*m));
	return m;
}

static char *slurp(const char *name, size_t *len)
{
	char path[512];
	FILE *f;
	char *buf;
	long n;
	px_test_data_path(path, sizeof(path), name);
	f = fopen(path, "rb");
	PX_CHECK_MSG(f != NULL, "cannot open %s", path);
	fseek(f, 0, SEEK_END);
	n = ftell(f);
	fseek(f, 0, SEEK_SET);
	buf = malloc((size_t)n + 1);
	PX_CHECK(buf != NULL);
	PX_CHECK_INT_EQ(fread(buf, 1, (size_t)n, f), n);
	fclose(f);
	buf[n] = '\0';
	*len = (size_t)n;
	return buf;
}

static void test_circle_file(void)
{
	struct px_obj_model *m = load("circle.obj");
	const struct px_obj_entity *e;
	double u0, u1;
	int i;
	PX_CHECK_INT_EQ(m->n_entities, 1);
	e = &m->entities[0];
	PX_CHECK_INT_EQ(e->kind, PX_OBJ_CURVE);
	PX_CHECK_INT_EQ(e->line, 15);
	PX_CHECK(e->rational && e->curve.rational);
	PX_CHECK_INT_EQ(e->curve.degree, 2);
	PX_CHECK_INT_EQ(e->curve.n_ctrl, 9);
	px_nurbs_curve_domain(&e->curve, &u0, &u1);
	PX_CHECK(u0 == 0.0 && u1 == 1.0);
	for (i = 0; i <= 500; i++) {
		px_vec3 p = px_nurbs_curve_point(&e->curve, i / 500.0);
		PX_CHECK_NEAR(px_v3_dist(p, px_v3(1, -1, 0.5)), 2.0, 1e-14);
		PX_CHECK_NEAR(p.z, 0.5, 1e-15);
	}
	PX_CHECK(px_nurbs_curve_seam(&e->curve, 1e-12, 1e-9) >= 1);
	PX_CHECK_INT_EQ(m->n_triangles, 0);
	PX_CHECK_INT_EQ(m->n_vertices, 9);
	px_obj_free(m);
}

static void test_bicubic_file(void)
{
	struct px_obj_model *m = load("bicubic.obj");
	const struct px_nurbs_surf *s;
	int i;
	PX_CHECK_INT_EQ(m->n_entities, 1);
	PX_CHECK_INT_EQ(m->entities[0].kind, PX_OBJ_SURF);
	s = &m->entities[0].surf;
	PX_CHECK(!s->rational);
	PX_CHECK_INT_EQ(s->n_ctrl[0], 5);
	PX_CHECK_INT_EQ(s->n_ctrl[1], 4);
	for (i = 0; i < 300; i++) {
		double u = px_rand_unit(), v = px_rand_unit();
		struct px_nurbs_surf_derivs d;
		if (i == 0)
			u = v = 1.0;
		PX_CHECK_INT_EQ(px_nurbs_surf_eval(s, u, v, 2, &d), PX_OK);
		PX_CHECK(px_v3_dist(d.s, px_v3(u, v, u * u + 0.5 * v)) < 1e-14);
		PX_CHECK(px_v3_dist(d.su, px_v3(1, 0, 2 * u)) < 1e-13);
		PX_CHECK(px_v3_dist(d.sv, px_v3(0, 1, 0.5)) < 1e-13);
		PX_CHECK(px_v3_dist(d.suu, px_v3(0, 0, 2)) < 1e-12);
		PX_CHECK(px_v3_norm(d.suv) < 1e-12 && px_v3_norm(d.svv) < 1e-12);
	}
	px_obj_free(m);
}

/* A surf range narrower than the knot domain selects that sub-patch. */
static void test_sub_patch_range(void)
{
	size_t len;
	char *buf = slurp("bicubic.obj", &len), *text;
	struct px_obj_model *m;
	struct px_obj_error e;
	const struct px_nurbs_surf *s;
	double u0, u1, v0, v1;
	int i;
	char *at = strstr(buf, "surf 0 1 0 1 ");
	PX_CHECK(at != NULL);
	text = malloc(len + 32);
	PX_CHECK(text != NULL);
	/* same length replacement keeps the rest of the file */
	memcpy(text, buf, (size_t)(at - buf));
	len = (size_t)(at - buf) +
	      (size_t)sprintf(text + (at - buf), "surf 0.25 0.75 0.5 1 %s",
			      at + strlen("surf 0 1 0 1 "));
	PX_CHECK_INT_EQ(px_obj_load_mem("sub", text, len, &m, &e), PX_OK);
	s = &m->entities[0].surf;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	PX_CHECK(u0 == 0.25 && u1 == 0.75 && v0 == 0.5 && v1 == 1);
	for (i = 0; i < 100; i++) {
		double u = px_rand_range(0.25, 0.75), v = px_rand_range(0.5, 1);
		PX_CHECK(px_v3_dist(px_nurbs_surf_point(s, u, v),
				    px_v3(u, v, u * u + 0.5 * v)) < 1e-14);
	}
	{
		px_aabb b = px_nurbs_surf_aabb(s);
		PX_CHECK(b.min.x >= 0.25 - 1e-15 && b.max.x <= 0.75 + 1e-15);
		PX_CHECK(b.min.y >= 0.5 - 1e-15);
	}
	px_obj_free(m);
	free(text);
	free(buf);
}

static void test_sphere_file(void)
{
	struct px_obj_model *m = load("sphere.obj");
	const struct px_nurbs_surf *s;
	int i;
	PX_CHECK_INT_EQ(m->n_entities, 1);
	PX_CHECK(strcmp(m->entities[0].name, "sphere") == 0);
	s = &m->entities[0].surf;
	PX_CHECK(s->rational);
	PX_CHECK_INT_EQ(s->degree[0], 2);
	PX_CHECK_INT_EQ(s->n_ctrl[0], 9);
	PX_CHECK_INT_EQ(s->n_ctrl[1], 5);
	for (i = 0; i < 500; i++) {
		px_vec3 p = px_nurbs_surf_point(s, px_rand_unit(), px_rand_unit());
		PX_CHECK_NEAR(px_v3_norm(p), 1.5, 1e-14);
	}
	PX_CHECK(px_nurbs_surf_closed(s, 0, 1e-12));
	PX_CHECK(px_nurbs_surf_edge_collapsed(s, 2, 1e-12));
	PX_CHECK(px_nurbs_surf_edge_collapsed(s, 3, 1e-12));
	px_obj_free(m);
}

static void test_multi_entity_file(void)
{
	struct px_obj_model *m = load("multi.obj");
	const struct px_obj_entity *e;
	double u0, u1;
	int i;
	static const int tri[9] = {15, 16, 17, 15, 17, 18, 0, 1, 2};
	PX_CHECK_INT_EQ(m->n_entities, 3);
	/* a straight segment */
	e = &m->entities[0];
	PX_CHECK(strcmp(e->name, "segment") == 0);
	PX_CHECK_INT_EQ(e->kind, PX_OBJ_CURVE);
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(&e->curve, 0.3),
			    px_v3(0.9, 1.2, 0)) < 1e-15);
	/* the quarter of the circle the curv range selects */
	e = &m->entities[1];
	PX_CHECK(strcmp(e->name, "quarter") == 0);
	PX_CHECK_INT_EQ(e->line, 24);
	px_nurbs_curve_domain(&e->curve, &u0, &u1);
	PX_CHECK(u0 == 0.25 && u1 == 0.5);
	PX_CHECK(e->range[0] == 0.25 && e->range[1] == 0.5);
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(&e->curve, u0), px_v3(0, 1, 0)) <
		 1e-15);
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(&e->curve, u1), px_v3(-1, 0, 0)) <
		 1e-15);
	for (i = 0; i <= 100; i++) {
		px_vec3 p = px_nurbs_curve_point(&e->curve, 0.25 + 0.25 * i / 100);
		PX_CHECK_NEAR(px_v3_norm(p), 1.0, 1e-14);
		PX_CHECK(p.x <= 1e-15 && p.y >= -1e-15);
	}
	{
		/* its guaranteed box is the quadrant's */
		px_aabb b = px_nurbs_curve_aabb(&e->curve);
		PX_CHECK(b.min.x >= -1 - 1e-15 && b.max.x <= 1e-15);
		PX_CHECK(b.min.y >= -1e-15 && b.max.y <= 1 + 1e-15);
	}
	/* bilinear patch z = 5 + u v, vertex references with /vt/vn */
	e = &m->entities[2];
	PX_CHECK(strcmp(e->name, "patch") == 0);
	PX_CHECK_INT_EQ(e->kind, PX_OBJ_SURF);
	for (i = 0; i < 50; i++) {
		double u = px_rand_unit(), v = px_rand_unit();
		PX_CHECK(px_v3_dist(px_nurbs_surf_point(&e->surf, u, v),
				    px_v3(u, v, 5 + u * v)) < 1e-14);
	}
	/* faces: a quad as two triangles, and a triangle */
	PX_CHECK_INT_EQ(m->n_vertices, 19);
	PX_CHECK_INT_EQ(m->n_triangles, 3);
	for (i = 0; i < 9; i++)
		PX_CHECK_INT_EQ(m->triangles[i], tri[i]);
	PX_CHECK(m->vertices[3 * 16] == 11 && m->vertices[3 * 17 + 1] == 1);
	px_obj_free(m);
}

static void test_continuation_file(void)
{
	struct px_obj_model *m = load("continuation.obj");
	const struct px_nurbs_curve *c;
	PX_CHECK_INT_EQ(m->n_entities, 1);
	PX_CHECK_INT_EQ(m->n_vertices, 4);
	c = &m->entities[0].curve;
	PX_CHECK_INT_EQ(m->entities[0].line, 13);
	PX_CHECK(!c->rational); /* weights of a non-rational type are 1 */
	PX_CHECK_INT_EQ(c->degree, 2);
	PX_CHECK_INT_EQ(c->n_ctrl, 4);
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(c, 0), px_v3(0, 0, 0)) == 0);
	PX_CHECK(px_v3_dist(px_nurbs_curve_point(c, 1), px_v3(0, 1, 0)) == 0);
	PX_CHECK(px_v3_dist(px_nurbs_curve_ctrl(c, 2, NULL), px_v3(1, 1, 0)) == 0);
	px_obj_free(m);
}

struct bad {
	const char *text;
	int code, line, col;
	const char *needle;
};

#define CURVE_HEAD "v 0 0 0\nv 1 0 0\nv 2 1 0\ncstype bspline\ndeg 2\n"

static const struct bad bad_inputs[] = {
	{"v 0 0 0\nfoo 1 2\n", PX_E_PARSE, 2, 1, "unknown statement 'foo'"},
	{"cstype bezier\n", PX_E_UNSUPPORTED, 1, 8, "'bezier' is not supported"},
	{"cstype rat cardinal\n", PX_E_UNSUPPORTED, 1, 12, "cardinal"},
	{"cstype taylor\n", PX_E_UNSUPPORTED, 1, 8, "taylor"},
	{"cstype bmatrix\n", PX_E_UNSUPPORTED, 1, 8, "bmatrix"},
	{"cstype nurbs\n", PX_E_PARSE, 1, 8, "unknown curve/surface type"},
	{"cstype\n", PX_E_PARSE, 1, 1, "cstype"},
	{"bmat u 1 0 0 1\n", PX_E_UNSUPPORTED, 1, 1, "'bmat'"},
	{"\n\nstep 2 2\n", PX_E_UNSUPPORTED, 3, 1, "'step'"},
	{"vp 0.5\ncurv2 1\n", PX_E_UNSUPPORTED, 2, 1, "'curv2'"},
	{"trim 0 1 1\n", PX_E_UNSUPPORTED, 1, 1, "'trim'"},
	{"hole 0 1 1\n", PX_E_UNSUPPORTED, 1, 1, "'hole'"},
	{"scrv 0 1 1\n", PX_E_UNSUPPORTED, 1, 1, "'scrv'"},
	{"sp 1\n", PX_E_UNSUPPORTED, 1, 1, "'sp'"},
	{"con 1 0 1 1 2 0 1 1\n", PX_E_UNSUPPORTED, 1, 1, "'con'"},
	{"v 0 0 0\np 1\n", PX_E_UNSUPPORTED, 2, 1, "'p'"},
	{"v 0 0 0\nv 1 1 1\nl 1 2\n", PX_E_UNSUPPORTED, 3, 1, "'l'"},
	{"deg 0\n", PX_E_PARSE, 1, 5, "degree 0 outside"},
	{"deg 3 11\n", PX_E_UNSUPPORTED, 1, 7, "degree 11 outside"},
	{"deg x\n", PX_E_PARSE, 1, 5, "expected an integer"},
	{"deg 1 2 3\n", PX_E_PARSE, 1, 1, "deg"},
	{"v 1 2\n", PX_E_PARSE, 1, 1, "got 2 values"},
	{"v 1 2 nan\n", PX_E_PARSE, 1, 7, "not finite"},
	{"v 1 2 1e999\n", PX_E_PARSE, 1, 7, "not finite"},
	{"v 1 abc 3\n", PX_E_PARSE, 1, 5, "expected a number, got 'abc'"},
	{"v 1 2 3\ncurv 0 1 1 1\n", PX_E_PARSE, 2, 1, "before any 'cstype'"},
	{"cstype bspline\ncurv 0 1 1 1\n", PX_E_PARSE, 2, 1, "needs 'deg"},
	{"cstype bspline\ndeg 2\nsurf 0 1 0 1 1 1\n", PX_E_PARSE, 3, 1,
	 "needs 'deg degu degv'"},
	{CURVE_HEAD "curv 0 1 1 0 3\n", PX_E_PARSE, 6, 12, "vertex index 0"},
	{CURVE_HEAD "curv 0 1 1 2 4\n", PX_E_PARSE, 6, 14,
	 "vertex 4 is not defined (3 vertices so far)"},
	{CURVE_HEAD "curv 0 1 -1 -2 -4\n", PX_E_PARSE, 6, 16,
	 "reaches before the first vertex"},
	{CURVE_HEAD "curv 0 1 1 2.5 3\n", PX_E_PARSE, 6, 12,
	 "expected an integer"},
	{CURVE_HEAD "curv 0 1 1\n", PX_E_PARSE, 6, 1, "at least two"},
	{CURVE_HEAD "curv 1 1 1 2 3\n", PX_E_PARSE, 6, 6, "empty parameter range"},
	{"parm u 0 1\n", PX_E_PARSE, 1, 1, "outside a curv/surf body"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm v 0 0 0 1 1 1\n", PX_E_PARSE, 7, 6,
	 "'parm v' in the body of a curve"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm w 0 1\n", PX_E_PARSE, 7, 1,
	 "takes u|v"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nparm u 0 1\n",
	 PX_E_PARSE, 8, 1, "second 'parm u'"},
	{"end\n", PX_E_PARSE, 1, 1, "'end' without"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend now\n", PX_E_PARSE,
	 8, 5, "no arguments"},
	{CURVE_HEAD "curv 0 1 1 2 3\nend\n", PX_E_PARSE, 7, 1, "no 'parm u'"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm u 0 0 0 1 1\nend\n", PX_E_PARSE, 8, 1,
	 "has 5 knots; 3 control points of degree 2 need 6"},
	/* knot 4 on a continuation line, column of its token */
	{CURVE_HEAD "curv 0 1 1 2 3 1\nparm u 0 0 0 0.6 \\\n  0.5 1 1\nend\n",
	 PX_E_PARSE, 8, 3, "knot 4 decreases (0.5 < 0.59999"},
	{CURVE_HEAD "curv 0 1 1 2 3 1 2 3\nparm u 0 0 0 0.5 0.5 0.5 1 1 1\nend\n",
	 PX_E_PARSE, 7, 14, "multiplicity 3 > degree 2"},
	{"v 0 0 0\nv 1 0 0 -2\nv 2 1 0\ncstype rat bspline\ndeg 2\n"
	 "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\nend\n",
	 PX_E_PARSE, 6, 12, "control point 1 has weight -2"},
	{CURVE_HEAD "curv 0 2 1 2 3\nparm u 0 0 0 1 1 1\nend\n", PX_E_PARSE, 6,
	 1, "range 0..2 lies outside the knot domain 0..1"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\n", PX_E_PARSE, 6, 1,
	 "has no 'end' before the end of the file"},
	{CURVE_HEAD "curv 0 1 1 2 3\nparm u 0 0 0 1 1 1\ncurv 0 1 1 2 3\n",
	 PX_E_PARSE, 8, 1, "missing 'end'"},
	{CURVE_HEAD "deg 1 1\nsurf 0 1 0 1 1 2 3\nparm u 0 0 1 1\n"
		    "parm v 0 0 1 1\nend\n",
	 PX_E_PARSE, 10, 1, "3 control points, but the knot vectors"},
	{CURVE_HEAD "deg 1 1\nsurf 0 1 0 1 1 2 3 1\nparm u 0 0 1 1\nend\n",
	 PX_E_PARSE, 9, 1, "no 'parm v'"},
	{CURVE_HEAD "deg 1 1\nsurf 0 1 0 1 1 2 3 1\nparm u 0 0 1 1\n"
		    "parm v 0 0.5 0.4 1\nend\n",
	 PX_E_PARSE, 9, 14, "v knot 2 decreases (0.4"},
	{"v 0 0 0\nv 1 1 1\nf 1 2\n", PX_E_PARSE, 3, 1, "at least 3"},
	{"v 0 0 0\nf 1 1 x\n", PX_E_PARSE, 2, 7, "expected an integer"},
};

static void test_error_kinds(void)
{
	size_t i;
	for (i = 0; i < sizeof(bad_inputs) / sizeof(bad_inputs[0]); i++) {
		const struct bad *b = &bad_inputs[i];
		struct px_obj_model *m = (struct px_obj_model *)1;
		struct px_obj_error e;
		int rc = px_obj_load_mem("bad.obj", b->text, strlen(b->text), &m,
					 &e);
		PX_CHECK_MSG(rc == b->code, "case %zu: rc %s expected %s (%d:%d: %s)",
			     i, px_strerror_name(rc), px_strerror_name(b->code),
			     e.line, e.column, e.msg);
		PX_CHECK(m == NULL);
		PX_CHECK_INT_EQ(e.code, b->code);
		PX_CHECK(strcmp(e.file, "bad.obj") == 0);
		PX_CHECK_MSG(e.line == b->line && e.column == b->col,
			     "case %zu: at %d:%d, expected %d:%d (%s)", i, e.line,
			     e.column, b->line, b->col, e.msg);
		PX_CHECK_MSG(strstr(e.msg, b->needle) != NULL,
			     "case %zu: '%s' lacks '%s'", i, e.msg, b->needle);
	}
}

static void test_nurbs_detail_in_error(void)
{
	const char *t = CURVE_HEAD "curv 0 1 1 2 3 1\nparm u 0 0 0 0.6 0.5 1 1\nend\n";
	struct px_obj_model *m;
	struct px_obj_error e;
	PX_CHECK_INT_EQ(px_obj_load_mem("x", t, strlen(t), &m, &e), PX_E_PARSE);
	PX_CHECK_INT_EQ(e.nurbs.fault, PX_NURBS_FAULT_KNOT_ORDER);
	PX_CHECK_INT_EQ(e.nurbs.index, 4);
	PX_CHECK(e.nurbs.value == 0.5 && e.nurbs.value2 == 0.6);
}

static void test_special_bytes(void)
{
	static const char nul[] = "v 0 0 0\nv 1\0 2 3\n";
	char longtok[600];
	struct px_obj_model *m;
	struct px_obj_error e;
	PX_CHECK_INT_EQ(px_obj_load_mem("n", nul, sizeof(nul) - 1, &m, &e),
			PX_E_PARSE);
	PX_CHECK_INT_EQ(e.line, 2);
	PX_CHECK_INT_EQ(e.column, 4);
	PX_CHECK(strstr(e.msg, "NUL") != NULL);
	memset(longtok, '1', sizeof(longtok));
	memcpy(longtok, "v ", 2);
	PX_CHECK_INT_EQ(px_obj_load_mem("l", longtok, sizeof(longtok), &m, &e),
			PX_E_PARSE);
	PX_CHECK(strstr(e.msg, "longer than") != NULL);
	PX_CHECK_INT_EQ(e.column, 3);
	/* empty input and input without geometry are valid, empty models */
	PX_CHECK_INT_EQ(px_obj_load_mem("e", NULL, 0, &m, &e), PX_OK);
	PX_CHECK(m && m->n_entities == 0 && m->n_triangles == 0);
	px_obj_free(m);
	PX_CHECK_INT_EQ(px_obj_load_mem("c", "# only\n\n  \\\n", 12, &m, &e),
			PX_OK);
	px_obj_free(m);
	px_obj_free(NULL);
	PX_CHECK_INT_EQ(px_obj_load_mem("x", "v 0 0 0", 7, NULL, &e), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_obj_load_mem("x", NULL, 3, &m, NULL), PX_E_INVAL);
	/* no trailing newline, CR line ends */
	{
		const char *t = "v 0 0 0\r\nv 1 0 0\r\ncstype bspline\r\ndeg 1\r\n"
				"curv 0 1 1 2\r\nparm u 0 0 1 1\r\nend";
		PX_CHECK_INT_EQ(px_obj_load_mem("t", t, strlen(t), &m, &e), PX_OK);
		PX_CHECK_INT_EQ(m->n_entities, 1);
		px_obj_free(m);
	}
}

static void test_missing_file(void)
{
	struct px_obj_model *m = (struct px_obj_model *)1;
	struct px_obj_error e;
	PX_CHECK_INT_EQ(px_obj_load_file("/nonexistent/dir/x.obj", &m, &e),
			PX_E_IO);
	PX_CHECK(m == NULL);
	PX_CHECK(strcmp(e.file, "/nonexistent/dir/x.obj") == 0);
	PX_CHECK(strstr(e.msg, "cannot open") != NULL);
	PX_CHECK_INT_EQ(e.line, 0);
}

static int count_lines(const char *s, size_t n)
{
	size_t i;
	int l = 1;
	for (i = 0; i < n; i++)
		l += s[i] == '\n';
	return l;
}

static void check_outcome(int rc, struct px_obj_model *m,
			  const struct px_obj_error *e, const char *buf,
			  size_t n)
{
	if (rc == PX_OK) {
		int i;
		PX_CHECK(m != NULL);
		/* whatever loaded is valid and evaluable */
		for (i = 0; i < m->n_entities; i++) {
			const struct px_obj_entity *en = &m->entities[i];
			if (en->kind == PX_OBJ_CURVE)
				(void)px_nurbs_curve_point(&en->curve, 0.5);
			else
				(void)px_nurbs_surf_point(&en->surf, 0.5, 0.5);
		}
		for (i = 0; i < 3 * m->n_triangles; i++)
			PX_CHECK(m->triangles[i] >= 0 &&
				 m->triangles[i] < m->n_vertices);
		px_obj_free(m);
		return;
	}
	PX_CHECK_MSG(rc == PX_E_PARSE || rc == PX_E_UNSUPPORTED,
		     "unexpected %s", px_strerror_name(rc));
	PX_CHECK(m == NULL);
	PX_CHECK(e->line >= 1 && e->line <= count_lines(buf, n));
	PX_CHECK(e->column >= 1);
	PX_CHECK(e->msg[0] != '\0');
}

static void test_truncation_never_crashes(void)
{
	static const char *files[] = {"circle.obj", "bicubic.obj", "sphere.obj",
				      "multi.obj", "continuation.obj"};
	size_t f;
	for (f = 0; f < sizeof(files) / sizeof(files[0]); f++) {
		size_t len, n;
		char *buf = slurp(files[f], &len);
		for (n = 0; n <= len; n++) {
			struct px_obj_model *m = NULL;
			struct px_obj_error e;
			/* a private copy so that reading past n is caught by
			 * the sanitizer */
			char *cp = malloc(n ? n : 1);
			int rc;
			memcpy(cp, buf, n);
			rc = px_obj_load_mem(files[f], cp, n, &m, &e);
			check_outcome(rc, m, &e, cp, n);
			free(cp);
		}
		free(buf);
	}
}

static void test_random_garbage_never_crashes(void)
{
	static const char *files[] = {"circle.obj", "bicubic.obj", "sphere.obj",
				      "multi.obj", "continuation.obj"};
	static const char alphabet[] = "v \n\\#-/0123456789.e+curvsfpmdgt\r\t";
	int trial;
	for (trial = 0; trial < 3000; trial++) {
		size_t len, n, k;
		char *buf = slurp(files[trial % 5], &len);
		char *cp = malloc(len + 64);
		struct px_obj_model *m = NULL;
		struct px_obj_error e;
		int edits = px_rand_int(1, 8), i, rc;
		memcpy(cp, buf, len);
		n = len;
		for (i = 0; i < edits; i++) {
			int op = px_rand_int(0, 2);
			k = (size_t)px_rand_int(0, (int)n - 1);
			if (op == 0) {
				cp[k] = px_rand_int(0, 3) == 0
						? (char)px_rand_int(0, 255)
						: alphabet[px_rand_int(
							  0, (int)sizeof(alphabet) - 2)];
			} else if (op == 1 && n > 1) {
				memmove(cp + k, cp + k + 1, n - k - 1);
				n--;
			} else if (n < len + 60) {
				memmove(cp + k + 1, cp + k, n - k);
				cp[k] = alphabet[px_rand_int(0, (int)sizeof(alphabet) - 2)];
				n++;
			}
		}
		rc = px_obj_load_mem("garbage", cp, n, &m, &e);
		check_outcome(rc, m, &e, cp, n);
		free(cp);
		free(buf);
	}
}

static const struct px_test tests[] = {
	PX_T(test_circle_file),
	PX_T(test_bicubic_file),
	PX_T(test_sub_patch_range),
	PX_T(test_sphere_file),
	PX_T(test_multi_entity_file),
	PX_T(test_continuation_file),
	PX_T(test_error_kinds),
	PX_T(test_nurbs_detail_in_error),
	PX_T(test_special_bytes),
	PX_T(test_missing_file),
	PX_T(test_truncation_never_crashes),
	PX_T(test_random_garbage_never_crashes),
};

PX_TEST_MAIN(tests)
