/*
 * proxima-query - global closest points from a file of query points to a
 * model.
 *
 *   proxima-query [--track] [--signed] [--stats] MODEL POINTS.csv
 *
 * MODEL: Wavefront OBJ (free-form curves and surfaces, polygon faces, or
 * both: all entities form one model), STL, PLY (mesh with faces, point
 * cloud without), XYZ/CSV point clouds, STEP/IGES parts (.step, .stp,
 * .iges, .igs: the whole file as one exact B-rep in metres, px_load.h;
 * builds with OpenCASCADE only). POINTS.csv: one "x,y,z" per line
 * (at most 64 MiB, no NUL bytes, no empty fields); a first line whose
 * first field is a name, not a number, is a header ("NaN,0,0" is a point,
 * and an error). Output, one line
 * per point: "dist,cx,cy,cz,u,v" with %.17g; curves print v = 0, meshes
 * the triangle index as u and clouds the point index, with v = 0; B-rep
 * parts the closest face's surface parameters (u, v), or on an edge the
 * edge curve's parameter as u and v = 0 (px_brep.h). The distance is
 * unsigned unless --signed: then closed models (closed meshes and B-rep
 * solids) answer inside negative; any other model stays unsigned and
 * stderr says so once. --stats writes setup time, model memory and
 * per-query times to stderr.
 * --track answers the points in file order as one moving point with the
 * coherent trackers (px_track.h for curves, px_strack.h when the model
 * has surfaces: every critical distance followed, pairs created and
 * annihilated at transitions); free-form models only (no faces, meshes or
 * clouds). With --stats it also prints the tracker's counters.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "px_dist.h"
#include "px_file.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_brep_obj.h"
#include "px_obj.h"
#include "px_strack.h"
#include "px_track.h"

static const char *prog = "proxima-query";

static void usage(FILE *f)
{
	fprintf(f, "usage: %s [--track] [--signed] [--stats] MODEL POINTS.csv\n"
		   "  MODEL       .obj (free-form curves/surfaces and/or faces), .stl,\n"
		   "              .ply (mesh or point cloud), .xyz/.csv (point cloud),\n"
		   "              .step/.stp/.iges/.igs (CAD part, needs OpenCASCADE)\n"
		   "  POINTS.csv  one x,y,z per line (a first line of names is a\n"
		   "              header; NaN or inf is an error)\n"
		   "  output      dist,cx,cy,cz,u,v per point (u,v: curve/surface\n"
		   "              parameters, B-rep face parameters, or the triangle\n"
		   "              or point index as u)\n"
		   "  --signed    inside negative for closed models (closed meshes,\n"
		   "              B-rep solids); others stay unsigned (said on stderr)\n"
		   "  --stats     setup time, model memory and per-query ns to stderr\n"
		   "  --track     answer the points in order as one moving point by\n"
		   "              coherent tracking of all critical distances\n"
		   "              (free-form curves and surfaces; no faces)\n",
		   prog);
}

static int64_t now_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

static const char *ext_of(const char *path)
{
	const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
	if (!dot || (slash && dot < slash))
		return "";
	return dot + 1;
}

static int ieq(const char *a, const char *b)
{
	for (; *a && *b; a++, b++)
		if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
			return 0;
	return *a == *b;
}

struct points {
	px_vec3 *p;
	size_t n, cap;
};

/* Parse one number at *s up to a comma or the end of the field. */
static int parse_num(const char **s, double *out)
{
	char *end;
	while (**s == ' ' || **s == '\t')
		(*s)++;
	errno = 0;
	*out = strtod(*s, &end);
	if (end == *s || errno == ERANGE)
		return -1;
	*s = end;
	while (**s == ' ' || **s == '\t')
		(*s)++;
	return 0;
}

static int points_fail(const char *path, long lineno, const char *fmt, int field)
{
	fprintf(stderr, "%s: %s:%ld: ", prog, path, lineno);
	fprintf(stderr, fmt, field);
	fputc('\n', stderr);
	return -1;
}

/* The points file, read whole within the text limit (a NUL byte, as
 * from /dev/zero, is an error at its place instead of a blank line). */
static int read_points(const char *path, struct points *pts)
{
	char *data = NULL, *cur, *line, msg[1024];
	size_t len = 0;
	long lineno = 0;
	int seen = 0, rc = -1;

	if (px_file_read(path, PX_FILE_TEXT_MAX_BYTES, PX_FILE_TEXT, "points", &data,
			 &len, msg, sizeof msg) != PX_OK) {
		fprintf(stderr, "%s: %s\n", prog, msg);
		return -1;
	}
	cur = data;
	while ((line = px_file_next_line(&cur)) != NULL) {
		const char *s = line;
		double v[3];
		int k;

		lineno++;
		while (*s == ' ' || *s == '\t')
			s++;
		if (*s == 0)
			continue; /* blank line */
		if (!seen++ && px_file_is_header(s))
			continue;
		for (k = 0; k < 3; k++) {
			const char *f = s;
			while (*f == ' ' || *f == '\t')
				f++;
			if (*f == ',' || (*f == 0 && k > 0)) {
				points_fail(path, lineno, "field %d is empty", k + 1);
				goto out;
			}
			if (parse_num(&s, &v[k])) {
				points_fail(path, lineno, "field %d: expected a number", k + 1);
				goto out;
			}
			if (!isfinite(v[k])) {
				points_fail(path, lineno, "field %d: not a finite number", k + 1);
				goto out;
			}
			if (k < 2) {
				if (*s != ',') {
					points_fail(path, lineno, "expected 3 comma-separated "
						    "numbers x,y,z (field %d ends early)", k + 1);
					goto out;
				}
				s++;
			}
		}
		if (*s) {
			points_fail(path, lineno, "unexpected text after z (field %d)", 4);
			goto out;
		}
		if (pts->n == pts->cap) {
			size_t nc = pts->cap ? 2 * pts->cap : 1024;
			px_vec3 *np = realloc(pts->p, nc * sizeof(*np));
			if (!np) {
				fprintf(stderr, "%s: out of memory\n", prog);
				goto out;
			}
			pts->p = np;
			pts->cap = nc;
		}
		pts->p[pts->n++] = px_v3(v[0], v[1], v[2]);
	}
	rc = 0;
out:
	free(data);
	return rc;
}

/* The cold switch's counters of either tracker (--track --stats). */
static void print_cold(const char *name, uint64_t cold, uint64_t entered,
		       uint64_t left, double tracked_ns, double cold_ns)
{
	fprintf(stderr, "%s_cold %llu entered %llu left %llu tracked_ns %.0f "
		"cold_ns %.0f\n", name, (unsigned long long)cold,
		(unsigned long long)entered, (unsigned long long)left,
		tracked_ns, cold_ns);
}

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
	return (x > y) - (x < y);
}

/* What one run holds: the options, the model in whichever of its forms
 * the file gives (free-form entities: a global model or a tracker; faces,
 * meshes and clouds: a px_model), the points and their times. */
struct query {
	const char *model_path, *points_path;
	int track, stats, signed_dist;
	struct px_obj_model *obj;
	struct px_nurbs_curve *curves;
	struct px_nurbs_surf *surfs;
	int nc, ns;
	struct px_dist_model *m;
	struct px_model *mesh;
	struct px_track *trk;
	struct px_strack *strk;
	struct points pts;
	int64_t t_setup, *times;
};

/* Options and the two paths: 0 to go on, else the exit status (-1: 0
 * after --help). */
static int parse_args(int argc, char **argv, struct query *q)
{
	int i;
	for (i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--track"))
			q->track = 1;
		else if (!strcmp(argv[i], "--stats"))
			q->stats = 1;
		else if (!strcmp(argv[i], "--signed"))
			q->signed_dist = 1;
		else if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
			usage(stdout);
			return -1;
		} else if (argv[i][0] == '-' && argv[i][1]) {
			fprintf(stderr, "%s: unknown option '%s'\n", prog, argv[i]);
			usage(stderr);
			return 2;
		} else if (!q->model_path)
			q->model_path = argv[i];
		else if (!q->points_path)
			q->points_path = argv[i];
		else {
			fprintf(stderr, "%s: unexpected argument '%s'\n", prog, argv[i]);
			usage(stderr);
			return 2;
		}
	}
	if (!q->model_path || !q->points_path) {
		usage(stderr);
		return 2;
	}
	return 0;
}

/* The OBJ file's faces as a mesh of the same model. */
static int load_obj_faces(struct query *q)
{
	struct px_mesh_report rep;
	const struct px_obj_model *obj = q->obj;
	uint32_t *tri = malloc(3 * (size_t)obj->n_triangles * sizeof(*tri));
	int i, rc;
	if (!tri) {
		fprintf(stderr, "%s: out of memory\n", prog);
		return 1;
	}
	for (i = 0; i < 3 * obj->n_triangles; i++)
		tri[i] = (uint32_t)obj->triangles[i];
	rc = px_mesh_model(obj->vertices, (size_t)obj->n_vertices, tri,
			   (size_t)obj->n_triangles, NULL, &rep, &q->mesh);
	free(tri);
	if (rc) {
		fprintf(stderr, "%s: %s: faces: %s\n", prog, q->model_path,
			rep.message[0] ? rep.message : px_strerror(rc));
		return 1;
	}
	return 0;
}

/* trim or hole loops: one B-rep of trimmed faces (px_brep_obj.h),
 * answered by global queries. 0 or the exit status. */
static int load_trimmed(struct query *q)
{
	char msg[512];
	int rc = px_model_from_obj_brep(q->obj, q->model_path, 1.0, &q->mesh,
					msg, sizeof(msg));
	if (rc) {
		fprintf(stderr, "%s: %s\n", prog, msg);
		return 1;
	}
	if (q->track) {
		fprintf(stderr, "%s: %s: --track: trimmed surfaces are "
				"answered by global queries only; run "
				"without --track\n",
			prog, q->model_path);
		return 2;
	}
	if (msg[0] && q->stats)
		fprintf(stderr, "%s: %s\n", prog, msg);
	return 0;
}

/* An OBJ: its free-form entities as a global model or a tracker, its
 * faces as a mesh. 0 or the exit status. */
static int load_obj(struct query *q)
{
	struct px_obj_error oerr;
	const struct px_obj_model *obj;
	int i, rc = px_obj_load_file(q->model_path, &q->obj, &oerr);
	if (rc) {
		char m[600];
		fprintf(stderr, "%s: %s\n", prog,
			px_obj_error_text(&oerr, q->model_path, rc, m, sizeof(m)));
		return 1;
	}
	obj = q->obj;
	if (px_obj_trimmed(obj))
		return load_trimmed(q);
	q->curves = calloc((size_t)obj->n_entities + 1, sizeof(*q->curves));
	q->surfs = calloc((size_t)obj->n_entities + 1, sizeof(*q->surfs));
	if (!q->curves || !q->surfs) {
		fprintf(stderr, "%s: out of memory\n", prog);
		return 1;
	}
	for (i = 0; i < obj->n_entities; i++) {
		if (obj->entities[i].kind == PX_OBJ_CURVE)
			q->curves[q->nc++] = obj->entities[i].curve;
		else
			q->surfs[q->ns++] = obj->entities[i].surf;
	}
	if (q->nc + q->ns == 0 && obj->n_triangles == 0) {
		fprintf(stderr, "%s: %s: no free-form curve or surface and no "
				"face in the file\n", prog, q->model_path);
		return 1;
	}
	if (q->track && obj->n_triangles > 0) {
		fprintf(stderr, "%s: %s: --track: coherent tracking supports "
				"free-form curves and surfaces only (the model "
				"has faces); run without --track for independent "
				"global queries\n",
			prog, q->model_path);
		return 2;
	}
	rc = PX_OK;
	if (q->track && q->ns > 0)
		rc = px_strack_create(q->curves, q->nc, q->surfs, q->ns, NULL, &q->strk);
	else if (q->track)
		rc = px_track_create(q->curves, q->nc, NULL, &q->trk);
	else if (q->nc + q->ns > 0)
		rc = px_dist_model_create(q->curves, q->nc, q->surfs, q->ns, NULL, &q->m);
	if (rc) {
		fprintf(stderr, "%s: %s: cannot prepare the %s: %s\n", prog,
			q->model_path, q->track ? "tracker" : "model", px_strerror(rc));
		return 1;
	}
	return obj->n_triangles > 0 ? load_obj_faces(q) : 0;
}

/* The model, by the file's type. 0 or the exit status. */
static int load_model(struct query *q)
{
	const char *ext = ext_of(q->model_path);
	char msg[512];
	int rc;
	if (q->track && !ieq(ext, "obj")) {
		fprintf(stderr, "%s: %s: --track: coherent tracking supports "
				"free-form curves and surfaces (.obj) only; run "
				"without --track for independent global queries\n",
			prog, q->model_path);
		return 2;
	}
	if (ieq(ext, "obj"))
		return load_obj(q);
	/* meshes and point clouds */
	rc = px_model_load(q->model_path, 0.0, &q->mesh, msg, sizeof(msg));
	if (rc) {
		fprintf(stderr, "%s: %s\n", prog, msg[0] ? msg : px_strerror(rc));
		return 1;
	}
	if (msg[0] && q->stats)
		fprintf(stderr, "%s: %s\n", prog, msg);
	return 0;
}

/* --signed: signed answers only where the whole model is one closed
 * px_model; otherwise a note, once, and unsigned answers. */
static void check_signed(struct query *q)
{
	if (!q->signed_dist)
		return;
	if (q->mesh && !q->m && !q->trk && !q->strk &&
	    (px_model_caps(q->mesh) & PX_MODEL_CAP_SIGNED))
		return;
	fprintf(stderr, "%s: %s: --signed: the model is not a closed mesh or "
			"B-rep solid; distances are unsigned\n",
		prog, q->model_path);
	q->signed_dist = 0;
}

/* The output row of one point: distance, closest point, parameters. */
struct row {
	double dist;
	px_vec3 cp;
	double u, v;
};

/* One point through whichever forms the model has; the nearest answer. */
static int query_point(const struct query *q, px_vec3 p, struct row *o)
{
	int qrc = 0;
	*o = (struct row){INFINITY, px_v3(0, 0, 0), 0.0, 0.0};
	if (q->trk) {
		struct px_track_result tr;
		qrc = px_track_update(q->trk, p, &tr);
		if (!qrc)
			*o = (struct row){tr.dist, tr.point, tr.u, 0.0};
	}
	if (q->strk) {
		struct px_strack_result tr;
		qrc = px_strack_update(q->strk, p, &tr);
		if (!qrc)
			*o = (struct row){tr.dist, tr.point, tr.u, tr.v};
	}
	if (q->m) {
		struct px_dist_result r;
		qrc = px_dist_query(q->m, p, &r);
		if (!qrc)
			*o = (struct row){r.dist, r.point, r.u, r.v};
	}
	if (q->mesh && !qrc) {
		struct px_model_result r;
		qrc = px_model_query_ex(q->mesh, p, INFINITY, -1,
					q->signed_dist ? 0u : PX_QUERY_UNSIGNED, &r);
		/* u, v: a B-rep's parameters, else u the triangle or point
		 * index (signed answers come from one model alone) */
		if (qrc == 1 && (q->signed_dist || r.distance < o->dist)) {
			if (px_model_kind(q->mesh) == PX_MODEL_BREP)
				*o = (struct row){r.distance, r.point, r.u, r.v};
			else
				*o = (struct row){r.distance, r.point, (double)r.index, 0.0};
		}
		qrc = qrc < 0 ? qrc : 0;
	}
	return qrc;
}

/* Every point, one output line each, timed. 0 or the exit status. */
static int run_points(struct query *q)
{
	size_t k;
	if (read_points(q->points_path, &q->pts))
		return 1;
	q->times = malloc((q->pts.n ? q->pts.n : 1) * sizeof(*q->times));
	if (!q->times) {
		fprintf(stderr, "%s: out of memory\n", prog);
		return 1;
	}
	for (k = 0; k < q->pts.n; k++) {
		struct row o;
		int64_t t0 = now_ns();
		int qrc = query_point(q, q->pts.p[k], &o);
		q->times[k] = now_ns() - t0;
		if (qrc) {
			fprintf(stderr, "%s: %s: point %zu: %s\n", prog, q->points_path,
				k + 1, px_strerror(qrc));
			return 1;
		}
		printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", o.dist, o.cp.x,
		       o.cp.y, o.cp.z, o.u, o.v);
	}
	if (fflush(stdout) || ferror(stdout)) {
		fprintf(stderr, "%s: write error on standard output\n", prog);
		return 1;
	}
	return 0;
}

/* --track --stats: the curve tracker's counters. */
static void print_track_stats(const struct px_track *trk)
{
	struct px_track_stats st;
	struct px_track_info ti;
	px_track_get_stats(trk, &st);
	px_track_get_info(trk, &ti);
	fprintf(stderr, "track_leaves %d boxed %d tracker_bytes %zu\n",
		ti.n_leaves, ti.n_boxed_leaves, ti.bytes);
	fprintf(stderr,
		"track_updates %llu leaf_solves %llu created %llu "
		"annihilated %llu reinits %llu outside %llu fallbacks %llu\n",
		(unsigned long long)st.updates, (unsigned long long)st.leaf_solves,
		(unsigned long long)st.creations, (unsigned long long)st.annihilations,
		(unsigned long long)st.reinits, (unsigned long long)st.outside,
		(unsigned long long)st.fallbacks);
	fprintf(stderr, "track_hot %llu rested %llu rested_entities %llu\n",
		(unsigned long long)st.hot, (unsigned long long)st.rested,
		(unsigned long long)st.rested_entities);
	print_cold("track", st.cold, st.cold_entered, st.cold_left, st.tracked_ns,
		   st.cold_ns);
}

/* --track --stats: the surface tracker's counters. */
static void print_strack_stats(const struct px_strack *strk)
{
	struct px_strack_stats st;
	struct px_strack_info si;
	px_strack_get_stats(strk, &st);
	px_strack_get_info(strk, &si);
	fprintf(stderr, "strack_surfaces %d patches %d cells %d edges %d "
		"poles %d\n", si.n_surfaces, si.n_patches, si.n_cells,
		si.n_edges, si.n_poles);
	fprintf(stderr,
		"strack_updates %llu cell_solves %llu reinits %llu "
		"outside %llu fallbacks %llu\n",
		(unsigned long long)st.updates, (unsigned long long)st.cell_solves,
		(unsigned long long)st.reinits, (unsigned long long)st.outside,
		(unsigned long long)st.fallbacks);
	fprintf(stderr,
		"strack_over_budget %llu catching_up %llu "
		"curve_skips %llu\n",
		(unsigned long long)st.over_budget,
		(unsigned long long)st.rebuild_updates,
		(unsigned long long)st.curve_skips);
	fprintf(stderr, "strack_hot %llu\n", (unsigned long long)st.hot);
	print_cold("strack", st.cold, st.cold_entered, st.cold_left, st.tracked_ns,
		   st.cold_ns);
}

/* --stats: setup, memory, query times and the trackers' counters. */
static void print_stats(const struct query *q)
{
	struct px_dist_info info;
	size_t bytes = 0, n = q->pts.n;
	const struct px_dist_model *dm = q->trk ? px_track_dist_model(q->trk)
				       : q->strk ? px_strack_dist_model(q->strk) : q->m;
	if (dm) {
		px_dist_model_info(dm, &info);
		bytes += info.bytes;
	}
	if (q->mesh)
		bytes += px_model_memory_bytes(q->mesh);
	fprintf(stderr, "setup_ms %.3f\n", q->t_setup / 1e6);
	fprintf(stderr, "model_bytes %zu\n", bytes);
	if (dm)
		fprintf(stderr, "entities %d pieces %d (curve pieces %d, patches %d)\n",
			info.n_entities, info.n_pieces, info.n_curve_pieces,
			info.n_patches);
	if (q->mesh)
		fprintf(stderr, "%s model: %s\n", px_model_name(q->mesh),
			px_model_kind(q->mesh) == PX_MODEL_CLOUD ? "point cloud"
			: px_model_kind(q->mesh) == PX_MODEL_BREP ? "B-rep faces"
								   : "triangles");
	if (n) {
		long long sum = 0;
		size_t i;
		for (i = 0; i < n; i++)
			sum += (long long)q->times[i];
		qsort(q->times, n, sizeof(*q->times), cmp_i64);
		fprintf(stderr, "queries %zu query_ns min %lld median %lld p99 %lld max %lld\n",
			n, (long long)q->times[0], (long long)q->times[n / 2],
			(long long)q->times[(n * 99) / 100 < n ? (n * 99) / 100 : n - 1],
			(long long)q->times[n - 1]);
		fprintf(stderr, "query_ns_total %lld mean %.1f\n", sum, (double)sum / (double)n);
	} else {
		fprintf(stderr, "queries 0\n");
	}
	if (q->trk)
		print_track_stats(q->trk);
	if (q->strk)
		print_strack_stats(q->strk);
}

int main(int argc, char **argv)
{
	struct query q;
	int rc;

	memset(&q, 0, sizeof(q));
	rc = parse_args(argc, argv, &q);
	if (rc)
		return rc < 0 ? 0 : rc;
	q.t_setup = now_ns();
	rc = load_model(&q);
	q.t_setup = now_ns() - q.t_setup;
	if (!rc)
		check_signed(&q);
	if (!rc)
		rc = run_points(&q);
	if (!rc && q.stats)
		print_stats(&q);
	px_strack_free(q.strk);
	px_track_free(q.trk);
	px_dist_model_free(q.m);
	px_model_free(q.mesh);
	px_obj_free(q.obj);
	free(q.curves);
	free(q.surfs);
	free(q.pts.p);
	free(q.times);
	return rc;
}
