/* PX_TEST_NEEDS: occt (tests/run.sh skips it in builds without OpenCASCADE) */
/*
 * The STEP and IGES importer against OpenCASCADE itself: every part of
 * proxima-cadgen written in both formats and read back; each face's
 * NURBS surface at random (u, v) of its trimmed domain equals
 * OpenCASCADE's converted surface there and lies on the surface as
 * read; the trimmed domain agrees with OpenCASCADE's face classifier
 * away from the loops; the loop curves mapped through the surface lie
 * on their 3D edges, and those on the file's edges; the face
 * orientations point out of the solids; counts, closed shells, units,
 * assemblies; every part builds as a B-rep model, signed for solids;
 * malformed and faulty files refused with a message naming the file
 * and the place.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_brep.h"
#include "px_cad.h"
#include "px_features.h"
#include "px_test.h"
#include "px_test_cad.h"

#if PX_HAVE_OCCT
#include "px_occt_ref.h"

static const char *const parts[] = {"filleted_block", "plate", "bottle",
				    "sheet", "cylsphere"};
#define N_PARTS (sizeof parts / sizeof parts[0])

/* The parts, and the block in metres in the subfolder m/. */
static const char *part_dir(void)
{
	static int made;
	const char *dir = px_test_cad_dir();
	char args[600];
	if (!made) {
		snprintf(args, sizeof args, "%s/m", dir);
		PX_CHECK(mkdir(args, 0755) == 0);
		snprintf(args, sizeof args, "--unit M --format step '%s/m' filleted_block", dir);
		PX_CHECK_MSG(px_test_cadgen(args) == 0, "proxima-cadgen %s failed", args);
		made = 1;
	}
	return dir;
}

static void part_path(char *buf, size_t cap, const char *name, const char *ext)
{
	snprintf(buf, cap, "%s/%s.%s", part_dir(), name, ext);
}

static struct px_cad *load_ok(const char *path, const struct px_cad_opts *o)
{
	struct px_cad *c = NULL;
	char msg[512];
	int rc = px_cad_load(path, o, &c, msg, sizeof msg);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s (%s)", path, px_strerror(rc), msg);
	return c;
}

static struct px_occt_ref *ref_ok(const char *path, int solid)
{
	struct px_occt_ref *r = NULL;
	PX_CHECK_MSG(px_occt_ref_open(path, solid, &r) == 0, "reference: %s", path);
	return r;
}

/* A random (u, v) of face f's trimmed domain at least margin (relative
 * to the domain's box) away from its loops, with its state there:
 * PX_TRIM_INSIDE or PX_TRIM_OUTSIDE. The distance to the loops is
 * measured on dense samples of the curves. */
static int sample_uv(const struct px_brep_face_desc *f, const struct px_trim *t,
		     double margin, double *u, double *v)
{
	double u0, u1, v0, v1, d;
	int tries, l, k, i;
	px_trim_bounds(t, &u0, &u1, &v0, &v1);
	d = hypot(u1 - u0, v1 - v0) * margin;
	for (tries = 0; tries < 200; tries++) {
		double uu = px_rand_range(u0, u1), vv = px_rand_range(v0, v1);
		int near = 0;
		for (l = 0; l < f->n_loops && !near; l++)
			for (k = 0; k < f->loops[l].n_curves && !near; k++) {
				const struct px_nurbs_curve *c = &f->loops[l].curves[k];
				double t0, t1;
				px_nurbs_curve_domain(c, &t0, &t1);
				for (i = 0; i <= 400 && !near; i++) {
					px_vec3 q = px_nurbs_curve_point(c, t0 + (t1 - t0) * i / 400);
					near = hypot(q.x - uu, q.y - vv) < d;
				}
			}
		if (!near) {
			*u = uu, *v = vv;
			return px_trim_contains(t, uu, vv, NULL);
		}
	}
	return -1;
}

static struct px_trim *face_trim(const struct px_brep_face_desc *f)
{
	struct px_trim *t = NULL;
	struct px_trim_error e;
	int rc = px_trim_create(f->loops, f->n_loops, NULL, &e, &t);
	PX_CHECK_MSG(rc == PX_OK, "face %ld: %s", f->id, e.msg);
	return t;
}

/* Surfaces, trimmed domains and orientations of one file's faces. */
static void check_faces(const char *path)
{
	struct px_cad *c = load_ok(path, NULL);
	struct px_occt_ref *r = ref_ok(path, -1);
	const struct px_brep_desc *d = px_cad_desc(c);
	double size = px_occt_ref_size(r);
	int k, i, n_in = 0, n_out = 0, n_side = 0, n_off = 0;
	PX_CHECK_INT_EQ(d->n_faces, px_occt_ref_face_count(r));
	for (k = 0; k < d->n_faces; k++) {
		const struct px_brep_face_desc *f = &d->faces[k];
		struct px_trim *t = face_trim(f);
		int closed = d->shells[f->shell].closed;
		for (i = 0; i < 40; i++) {
			double u, v, p[3], q[3], eps = 1e-9 * size;
			double su0, su1, sv0, sv1;
			int where = sample_uv(f, t, 0.02, &u, &v), st;
			px_vec3 s;
			if (where < 0)
				continue;
			px_nurbs_surf_domain(&f->surf, &su0, &su1, &sv0, &sv1);
			if (u < su0 || u > su1 || v < sv0 || v > sv1) {
				/* a loop may leave the surface's domain
				 * where it meets a pole (any u is the
				 * pole there): nothing to compare */
				n_off++;
				continue;
			}
			s = px_nurbs_surf_point(&f->surf, u, v);
			p[0] = s.x, p[1] = s.y, p[2] = s.z;
			PX_CHECK(px_occt_ref_conv_point(r, k, u, v, q) == 0);
			PX_CHECK_MSG(fabs(p[0] - q[0]) + fabs(p[1] - q[1]) +
					     fabs(p[2] - q[2]) <= 3 * eps,
				     "%s face %d (%ld) at (%g, %g): (%g %g %g) vs (%g %g %g)",
				     path, k, f->id, u, v, p[0], p[1], p[2], q[0], q[1], q[2]);
			PX_CHECK_MSG(px_occt_ref_surf_dist(r, k, p) <= eps,
				     "%s face %d off its surface by %g", path, k,
				     px_occt_ref_surf_dist(r, k, p));
			st = px_occt_ref_face_state(r, k, p, 1e-7);
			PX_CHECK_MSG(st == (where == PX_TRIM_INSIDE),
				     "%s face %d (%ld) at (%.9g, %.9g): px says %d, "
				     "OpenCASCADE %d", path, k, f->id, u, v, where, st);
			if (where == PX_TRIM_INSIDE)
				n_in++;
			else
				n_out++;
			if (where == PX_TRIM_INSIDE && closed) {
				/* Outward normal: outside just off the
				 * face, inside just under it. */
				struct px_nurbs_surf_derivs sd;
				px_vec3 n;
				double h = 0.01, a[3], b[3];
				px_nurbs_surf_eval(&f->surf, u, v, 1, &sd);
				n = px_v3_cross(sd.su, sd.sv);
				n = px_v3_scale(n, (f->reversed ? -1 : 1) / px_v3_norm(n));
				a[0] = p[0] + h * n.x, a[1] = p[1] + h * n.y, a[2] = p[2] + h * n.z;
				b[0] = p[0] - h * n.x, b[1] = p[1] - h * n.y, b[2] = p[2] - h * n.z;
				PX_CHECK_MSG(px_occt_ref_solid_state(r, a, 1e-7) == 0 &&
						     px_occt_ref_solid_state(r, b, 1e-7) == 1,
					     "%s face %d: normal not outward", path, k);
				n_side++;
			}
		}
		px_trim_free(t);
	}
	printf("  %s: %d faces, %d inside, %d outside, %d sides checked, "
	       "%d off the surface's domain\n", strrchr(path, '/') + 1,
	       d->n_faces, n_in, n_out, n_side, n_off);
	PX_CHECK(n_in >= 5 * d->n_faces);
	px_occt_ref_free(r);
	px_cad_free(c);
}

/* check on every part, STEP then IGES. */
static void each_file(void (*check)(const char *path))
{
	char path[512];
	size_t i;
	for (i = 0; i < 2 * N_PARTS; i++) {
		part_path(path, sizeof path, parts[i / 2], i % 2 ? "iges" : "step");
		check(path);
	}
}

static void test_surfaces_domains(void)
{
	each_file(check_faces);
}

/* Loop curves through the surface lie on their edge, the edge on the
 * file's edges. */
static void check_edges(const char *path)
{
	struct px_cad *c = load_ok(path, NULL);
	struct px_occt_ref *r = ref_ok(path, -1);
	const struct px_brep_desc *d = px_cad_desc(c);
	double size = px_occt_ref_size(r);
	double tol = fmax(2 * px_occt_ref_edge_tol(r), 1e-9 * size), worst = 0;
	int k, l, j, i, used = 0;
	for (k = 0; k < d->n_faces; k++) {
		const struct px_brep_face_desc *f = &d->faces[k];
		for (l = 0; l < f->n_loops; l++)
			for (j = 0; j < f->loops[l].n_curves; j++) {
				const struct px_nurbs_curve *pc = &f->loops[l].curves[j];
				int e = f->coedges[l][j].edge;
				double t0, t1;
				if (e < 0)
					continue;
				PX_CHECK(e < d->n_edges);
				used++;
				px_nurbs_curve_domain(pc, &t0, &t1);
				for (i = 0; i <= 10; i++) {
					px_vec3 uv = px_nurbs_curve_point(pc, t0 + (t1 - t0) * i / 10);
					px_vec3 s = px_nurbs_surf_point(&f->surf, uv.x, uv.y);
					double p[3] = {s.x, s.y, s.z};
					double dd = px_occt_ref_curve_dist(&d->edges[e].curve, p);
					worst = fmax(worst, dd);
					PX_CHECK_MSG(dd >= 0 && dd <= tol,
						     "%s face %d loop %d curve %d: %g off edge %d (tol %g)",
						     path, k, l, j, dd, e, tol);
				}
			}
	}
	for (k = 0; k < d->n_edges; k++) {
		double t0, t1;
		px_nurbs_curve_domain(&d->edges[k].curve, &t0, &t1);
		for (i = 0; i <= 6; i++) {
			px_vec3 s = px_nurbs_curve_point(&d->edges[k].curve,
							 t0 + (t1 - t0) * i / 6);
			double p[3] = {s.x, s.y, s.z};
			PX_CHECK_MSG(px_occt_ref_edge_dist(r, p) <= 1e-9 * size,
				     "%s edge %d off the file's edges by %g", path, k,
				     px_occt_ref_edge_dist(r, p));
		}
		for (i = 0; i < 2; i++) {
			int vi = i ? d->edges[k].v1 : d->edges[k].v0;
			px_vec3 e = px_nurbs_curve_point(&d->edges[k].curve, i ? t1 : t0);
			PX_CHECK(vi >= 0 && vi < d->n_vertices);
			PX_CHECK_MSG(px_v3_norm(px_v3_sub(e, d->vertices[vi])) <= tol,
				     "%s edge %d end %d off vertex %d", path, k, i, vi);
		}
	}
	printf("  %s: %d coedges on %d edges, worst %.3g (tolerance %.3g)\n",
	       strrchr(path, '/') + 1, used, d->n_edges, worst, tol);
	PX_CHECK(used >= d->n_edges);
	px_occt_ref_free(r);
	px_cad_free(c);
}

static void test_edges(void)
{
	each_file(check_edges);
}

/* Counts, shells and solids; face ids from the file. */
static void test_topology(void)
{
	static const int faces[N_PARTS] = {27, 15, 14, 1, 3};
	char path[512];
	size_t i;
	int e, k;
	for (i = 0; i < N_PARTS; i++)
		for (e = 0; e < 2; e++) {
			struct px_cad *c;
			const struct px_brep_desc *d;
			struct px_occt_ref *r;
			int sheet = !strcmp(parts[i], "sheet"), ids = 0;
			part_path(path, sizeof path, parts[i], e ? "iges" : "step");
			c = load_ok(path, NULL);
			r = ref_ok(path, -1);
			d = px_cad_desc(c);
			PX_CHECK_INT_EQ(d->n_faces, faces[i]);
			PX_CHECK_INT_EQ(d->n_faces, px_occt_ref_face_count(r));
			PX_CHECK_INT_EQ(d->n_solids, sheet ? 0 : 1);
			PX_CHECK_INT_EQ(px_cad_solid_count(c), px_occt_ref_solid_count(r));
			PX_CHECK_INT_EQ(d->n_shells, 1);
			PX_CHECK_INT_EQ(d->shells[0].closed, !sheet);
			PX_CHECK_INT_EQ(d->shells[0].solid, sheet ? -1 : 0);
			PX_CHECK(d->scale == 0.001);
			PX_CHECK(!strcmp(d->source, path));
			for (k = 0; k < d->n_faces; k++) {
				PX_CHECK(d->faces[k].shell == 0);
				PX_CHECK(d->faces[k].n_loops >= 1);
				ids += d->faces[k].id > 0;
			}
			PX_CHECK_MSG(ids == d->n_faces, "%s: %d of %d faces with ids",
				     path, ids, d->n_faces);
			for (k = ids = 0; k < d->n_edges; k++)
				ids += d->edges[k].id > 0;
			printf("  %s: %d of %d edges with ids\n", strrchr(path, '/') + 1,
			       ids, d->n_edges);
			PX_CHECK(e || ids == d->n_edges);
			px_occt_ref_free(r);
			px_cad_free(c);
		}
}

/* Every part builds as a distance model, signed where it is a solid. */
static void check_model(const char *path)
{
	struct px_cad *c = load_ok(path, NULL);
	const struct px_brep_desc *d = px_cad_desc(c);
	struct px_brep_error err;
	struct px_brep_info info;
	struct px_brep *b = NULL;
	int rc = px_brep_create(d, NULL, &err, &b);
	PX_CHECK_MSG(rc == PX_OK, "%s: %s", path, err.msg);
	PX_CHECK_INT_EQ(px_brep_get_info(b, &info), PX_OK);
	PX_CHECK_INT_EQ(info.n_faces, d->n_faces);
	PX_CHECK_MSG(info.closed == (d->n_solids > 0), "%s: closed %d (%s)", path,
		     info.closed, info.why);
	px_brep_free(b);
	px_cad_free(c);
}

static void test_models(void)
{
	each_file(check_model);
}

/* A file in metres reads as the same part; the user's scale multiplies. */
static void test_units(void)
{
	char mm[512], m[512];
	struct px_cad *a, *b, *s;
	struct px_cad_opts o;
	const struct px_brep_desc *da, *db;
	int k;
	part_path(mm, sizeof mm, "filleted_block", "step");
	part_path(m, sizeof m, "m/filleted_block", "step");
	a = load_ok(mm, NULL);
	b = load_ok(m, NULL);
	da = px_cad_desc(a);
	db = px_cad_desc(b);
	PX_CHECK_INT_EQ(da->n_vertices, db->n_vertices);
	PX_CHECK(da->scale == 0.001 && db->scale == 0.001);
	for (k = 0; k < da->n_vertices && k < db->n_vertices; k++)
		PX_CHECK_MSG(px_v3_norm(px_v3_sub(da->vertices[k], db->vertices[k])) < 1e-9,
			     "vertex %d", k);
	px_cad_opts_default(&o);
	o.scale = 2.5;
	s = load_ok(mm, &o);
	PX_CHECK_CLOSE(px_cad_desc(s)->scale, 0.0025, 0, 1e-15);
	px_cad_free(s);
	px_cad_free(a);
	px_cad_free(b);
}

/* Two solids: all of them by default, or one of them. */
static void test_assembly(void)
{
	char path[512], msg[512];
	struct px_cad_opts o;
	struct px_cad *c;
	int e, k;
	for (e = 0; e < 2; e++) {
		part_path(path, sizeof path, "assembly", e ? "iges" : "step");
		c = load_ok(path, NULL);
		PX_CHECK_INT_EQ(px_cad_solid_count(c), 2);
		PX_CHECK_INT_EQ(px_cad_desc(c)->n_solids, 2);
		PX_CHECK_INT_EQ(px_cad_desc(c)->n_faces, 30);
		PX_CHECK_INT_EQ(px_cad_desc(c)->n_shells, 2);
		/* the file's entities survive the placement of the parts */
		for (k = 0; k < px_cad_desc(c)->n_faces; k++)
			PX_CHECK_MSG(px_cad_desc(c)->faces[k].id > 0, "%s face %d", path, k);
		for (k = 0; !e && k < px_cad_desc(c)->n_edges; k++)
			PX_CHECK_MSG(px_cad_desc(c)->edges[k].id > 0, "%s edge %d", path, k);
		px_cad_free(c);
		px_cad_opts_default(&o);
		for (k = 0; k < 2; k++) {
			struct px_occt_ref *r = ref_ok(path, k);
			o.solid = k;
			c = load_ok(path, &o);
			PX_CHECK_INT_EQ(px_cad_desc(c)->n_solids, 1);
			PX_CHECK_INT_EQ(px_cad_desc(c)->n_faces, px_occt_ref_face_count(r));
			PX_CHECK_INT_EQ(px_cad_desc(c)->n_faces, k ? 3 : 27);
			px_occt_ref_free(r);
			px_cad_free(c);
		}
		o.solid = 2;
		c = (struct px_cad *)&o;
		PX_CHECK_INT_EQ(px_cad_load(path, &o, &c, msg, sizeof msg), PX_E_INVAL);
		PX_CHECK(c == NULL && strstr(msg, path));
	}
}

static void write_file(const char *path, const char *data, size_t n)
{
	FILE *f = fopen(path, "wb");
	PX_CHECK(f != NULL);
	PX_CHECK(fwrite(data, 1, n, f) == n);
	fclose(f);
}

static char *read_all(const char *path, size_t *n)
{
	FILE *f = fopen(path, "rb");
	char *b;
	long len;
	PX_CHECK(f != NULL);
	fseek(f, 0, SEEK_END);
	len = ftell(f);
	fseek(f, 0, SEEK_SET);
	b = malloc((size_t)len + 16);
	PX_CHECK(b && fread(b, 1, (size_t)len, f) == (size_t)len);
	b[len] = 0;
	fclose(f);
	*n = (size_t)len;
	return b;
}

static void refused(const char *path, const char *why, const char *place)
{
	struct px_cad *c = (struct px_cad *)&c;
	char msg[512];
	int rc = px_cad_load(path, NULL, &c, msg, sizeof msg);
	printf("  %s: %s: %s\n", why, px_strerror(rc), msg);
	PX_CHECK_MSG(rc < 0, "%s (%s) was read", path, why);
	PX_CHECK(c == NULL);
	PX_CHECK_MSG(strstr(msg, path) != NULL, "message does not name the file: %s", msg);
	PX_CHECK_MSG(!place || strstr(msg + strlen(path), place),
		     "message does not say where (%s): %s", place, msg);
}

/* Make the first face refer to an entity the file does not have: in
 * STEP the first ADVANCED_FACE's first reference becomes #99999; in
 * IGES the first B-rep face (type 510, a parameter line that starts
 * with "510,") gets surface directory entry 99999, the line keeping its
 * 64 data columns. b has room for the few characters STEP grows by. */
static void dangle(char *b, int iges)
{
	char *p, *q;
	size_t k;
	if (!iges) {
		p = strstr(b, "ADVANCED_FACE(");
		PX_CHECK(p != NULL);
		p = strchr(p, '#');
		PX_CHECK(p != NULL);
		for (q = p + 1; *q >= '0' && *q <= '9'; q++)
			;
		PX_CHECK(q - p <= 6);
		memmove(p + 6, q, strlen(q) + 1);
		memcpy(p, "#99999", 6);
		return;
	}
	p = strstr(b, "\n510,");
	PX_CHECK(p != NULL);
	p += 5;
	for (q = p; *q >= '0' && *q <= '9'; q++)
		;
	k = (size_t)(q - p);
	PX_CHECK(k >= 1 && k <= 5);
	/* p is column 4: the number and the rest of the data columns
	 * (to 63) move right by 5 - k over trailing spaces */
	for (size_t i = 55; i < 60 - k; i++)
		PX_CHECK(q[i] == ' ');
	memmove(p + 5, q, 55);
	memcpy(p, "99999", 5);
}

/* Malformed files: each refused as a whole, naming the file. */
static void test_malformed(void)
{
	static const char *const ext[2] = {"step", "iges"};
	char src[512], bad[600];
	struct px_cad_opts o;
	struct px_cad *c;
	char msg[512];
	size_t n, i;
	int e;
	for (e = 0; e < 2; e++) {
		char *b;
		part_path(src, sizeof src, "filleted_block", ext[e]);
		b = read_all(src, &n);
		snprintf(bad, sizeof bad, "%s/empty.%s", part_dir(), ext[e]);
		write_file(bad, "", 0);
		refused(bad, "empty", NULL);
		snprintf(bad, sizeof bad, "%s/truncated.%s", part_dir(), ext[e]);
		write_file(bad, b, n / 2);
		refused(bad, "truncated", e ? ": D" : "Line ");
		snprintf(bad, sizeof bad, "%s/garbage.%s", part_dir(), ext[e]);
		for (i = 0; i < 4000; i++)
			b[i] = (char)(32 + px_rand_int(0, 94));
		write_file(bad, b, 4000);
		refused(bad, "garbage", e ? NULL : "Line ");
		free(b);
		/* An entity that refers to one the file does not have. */
		b = read_all(src, &n);
		dangle(b, e);
		snprintf(bad, sizeof bad, "%s/dangling.%s", part_dir(), ext[e]);
		write_file(bad, b, strlen(b));
		refused(bad, "missing entity", e ? ": D" : "#99999");
		free(b);
	}
	/* A face whose hole crosses its outer loop: refused naming the
	 * face's entity and the crossing. */
	for (e = 0; e < 2; e++) {
		part_path(src, sizeof src, "crossed_sheet", ext[e]);
		refused(src, "loops crossing", e ? "face D" : "face #");
		PX_CHECK_INT_EQ(px_cad_load(src, NULL, &c, msg, sizeof msg), PX_E_INVAL);
		PX_CHECK(strstr(msg, "cross") != NULL);
	}
	snprintf(bad, sizeof bad, "%s/nothing.step", part_dir());
	PX_CHECK_INT_EQ(px_cad_load(bad, NULL, &c, msg, sizeof msg), PX_E_NOTFOUND);
	PX_CHECK(strstr(msg, bad) != NULL);
	px_cad_opts_default(&o);
	o.max_bytes = 1000;
	part_path(src, sizeof src, "plate", "step");
	PX_CHECK_INT_EQ(px_cad_load(src, &o, &c, msg, sizeof msg), PX_E_RANGE);
	PX_CHECK(strstr(msg, src) != NULL);
	o.max_bytes = 0;
	o.scale = -1;
	PX_CHECK_INT_EQ(px_cad_load(src, &o, &c, msg, sizeof msg), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_cad_load(NULL, NULL, &c, msg, sizeof msg), PX_E_INVAL);
	PX_CHECK(px_cad_desc(NULL) == NULL && px_cad_solid_count(NULL) == 0);
	px_cad_free(NULL);
}

/* The part the examples ship. */
static void test_shipped_part(void)
{
	struct px_cad *c = load_ok("config/examples/parts/filleted_block.step", NULL);
	const struct px_brep_desc *d = px_cad_desc(c);
	PX_CHECK_INT_EQ(d->n_faces, 27);
	PX_CHECK_INT_EQ(d->n_solids, 1);
	PX_CHECK(d->shells[0].closed);
	PX_CHECK(!strcmp(d->name, "filleted_block.step"));
	px_cad_free(c);
}

static void test_cleanup(void)
{
	px_test_cad_cleanup();
	PX_CHECK(1);
}

static const struct px_test tests[] = {
	PX_T(test_topology),	 PX_T(test_surfaces_domains), PX_T(test_edges),
	PX_T(test_models),
	PX_T(test_units),	 PX_T(test_assembly),	      PX_T(test_malformed),
	PX_T(test_shipped_part), PX_T(test_cleanup)};
#else
static void test_cad_absent(void)
{
	PX_NEEDS(OCCT);
}
static const struct px_test tests[] = {PX_T(test_cad_absent)};
#endif
PX_TEST_MAIN(tests)
