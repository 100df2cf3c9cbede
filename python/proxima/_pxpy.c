/*
 * _pxpy.c - the C side of the Python package (see _pxpy.h). Compiled by
 * cffi into the extension module proxima._proxima against the
 * library's headers and linked with libproxima.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_base.h"
#include "px_cloud.h"
#include "px_dist.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_model.h"
#include "px_nurbs.h"
#include "px_pair.h"
#include "px_prim.h"
#include "px_scene.h"
#include "px_urdf.h"

#include "_pxpy.h"

static int say(char *msg, size_t cap, int code, const char *fmt, ...)
{
	va_list ap;
	if (msg && cap) {
		va_start(ap, fmt);
		vsnprintf(msg, cap, fmt, ap);
		va_end(ap);
	}
	return code;
}

static int ends_with(const char *s, const char *ext)
{
	size_t n = strlen(s), k = strlen(ext), i;
	if (n < k)
		return 0;
	for (i = 0; i < k; i++) {
		char c = s[n - k + i];
		if (c >= 'A' && c <= 'Z')
			c = (char)(c - 'A' + 'a');
		if (c != ext[i])
			return 0;
	}
	return 1;
}

/* ---- models ------------------------------------------------------------ */

int pxpy_load(const char *path, double cloud_radius_m, double scale,
	      struct px_model **out, char *msg, size_t msg_cap)
{
	int rc;
	*out = NULL;
	if (msg && msg_cap)
		msg[0] = '\0';
	if (ends_with(path, ".obj"))
		return px_model_load_obj(path, out, msg, msg_cap);
	if (px_model_is_cad_name(path))
		rc = px_model_load_cad(path, scale, out, msg, msg_cap);
	else
		rc = px_model_load(path, cloud_radius_m, out, msg, msg_cap);
	if (rc && msg && msg_cap && !msg[0])
		say(msg, msg_cap, rc, "%s: %s", path, px_strerror(rc));
	return rc;
}

int pxpy_mesh(const double *xyz, size_t n_vertices, const int64_t *tri,
	      size_t n_triangles, struct px_model **out, char *msg,
	      size_t msg_cap)
{
	struct px_mesh_report rep;
	uint32_t *t;
	size_t i;
	int rc;
	*out = NULL;
	if (n_triangles > SIZE_MAX / (3 * sizeof(*t)))
		return say(msg, msg_cap, PX_E_RANGE, "mesh: too many triangles");
	for (i = 0; i < 3 * n_triangles; i++)
		if (tri[i] < 0 || (uint64_t)tri[i] >= n_vertices)
			return say(msg, msg_cap, PX_E_RANGE,
				   "mesh: triangle %zu: vertex index %lld is outside "
				   "0..%zu",
				   i / 3, (long long)tri[i], n_vertices - 1);
	t = malloc(3 * n_triangles * sizeof(*t) + 1);
	if (!t)
		return say(msg, msg_cap, PX_E_NOMEM, "mesh: out of memory");
	for (i = 0; i < 3 * n_triangles; i++)
		t[i] = (uint32_t)tri[i];
	rc = px_mesh_model(xyz, n_vertices, t, n_triangles, NULL, &rep, out);
	free(t);
	if (rc)
		return say(msg, msg_cap, rc, "mesh: %s",
			   rep.message[0] ? rep.message : px_strerror(rc));
	return PX_OK;
}

int pxpy_cloud(const double *xyz, size_t n, double radius_m,
	       struct px_model **out, char *msg, size_t msg_cap)
{
	struct px_cloud_report rep;
	int rc;
	*out = NULL;
	memset(&rep, 0, sizeof(rep));
	rc = px_cloud_model(xyz, n, radius_m, &rep, out);
	if (rc)
		return say(msg, msg_cap, rc, "cloud: %s",
			   rep.message[0] ? rep.message : px_strerror(rc));
	return PX_OK;
}

int pxpy_prim(int type, double a, double b, double c, struct px_model **out,
	      char *msg, size_t msg_cap)
{
	struct px_prim p;
	int rc;
	*out = NULL;
	p.type = (enum px_prim_type)type;
	p.a = a;
	p.b = b;
	p.c = c;
	rc = px_prim_model(&p, out);
	if (rc)
		return say(msg, msg_cap, rc, "primitive (%.17g, %.17g, %.17g): %s", a,
			   b, c, px_strerror(rc));
	return PX_OK;
}

int pxpy_nurbs(int n_curves, const int *c_deg, const int *c_n,
	       const double *c_knots, const double *c_xyz, const double *c_w,
	       int n_surfs, const int *s_deg, const int *s_n,
	       const double *s_knots, const double *s_xyz, const double *s_w,
	       struct px_model **out, char *msg, size_t msg_cap)
{
	struct px_nurbs_curve *cv = NULL;
	struct px_nurbs_surf *sf = NULL;
	struct px_arena ar;
	struct px_nurbs_error ne;
	size_t bytes = 64, ko = 0, po = 0;
	int i, rc = PX_OK;
	*out = NULL;
	for (i = 0; i < n_curves; i++)
		bytes += px_nurbs_curve_bytes(c_deg[i], c_n[i]) + 64;
	for (i = 0; i < n_surfs; i++)
		bytes += px_nurbs_surf_bytes(s_deg[2 * i], s_deg[2 * i + 1], s_n[2 * i],
					     s_n[2 * i + 1]) + 64;
	if (px_arena_init_alloc(&ar, bytes) != PX_OK)
		return say(msg, msg_cap, PX_E_NOMEM, "nurbs: out of memory");
	cv = calloc((size_t)n_curves + 1, sizeof(*cv));
	sf = calloc((size_t)n_surfs + 1, sizeof(*sf));
	if (!cv || !sf) {
		rc = say(msg, msg_cap, PX_E_NOMEM, "nurbs: out of memory");
		goto done;
	}
	for (i = 0; i < n_curves; i++) {
		int nk = c_n[i] + c_deg[i] + 1;
		rc = px_nurbs_curve_init(&cv[i], &ar, c_deg[i], c_n[i], c_knots + ko, nk,
					 c_xyz + 3 * po, c_w ? c_w + po : NULL, &ne);
		if (rc) {
			say(msg, msg_cap, rc, "curve %d: %s", i, ne.msg);
			goto done;
		}
		ko += (size_t)nk;
		po += (size_t)c_n[i];
	}
	ko = po = 0;
	for (i = 0; i < n_surfs; i++) {
		int du = s_deg[2 * i], dv = s_deg[2 * i + 1];
		int nu = s_n[2 * i], nv = s_n[2 * i + 1];
		int nku = nu + du + 1, nkv = nv + dv + 1;
		rc = px_nurbs_surf_init(&sf[i], &ar, du, dv, nu, nv, s_knots + ko, nku,
					s_knots + ko + nku, nkv, s_xyz + 3 * po,
					s_w ? s_w + po : NULL, &ne);
		if (rc) {
			say(msg, msg_cap, rc, "surface %d: %s", i, ne.msg);
			goto done;
		}
		ko += (size_t)(nku + nkv);
		po += (size_t)nu * (size_t)nv;
	}
	rc = px_nurbs_model_create(n_curves ? cv : NULL, n_curves,
				   n_surfs ? sf : NULL, n_surfs, NULL, out);
	if (rc)
		say(msg, msg_cap, rc, "nurbs: cannot prepare the model: %s",
		    px_strerror(rc));
done:
	free(cv);
	free(sf);
	px_arena_fini(&ar);
	return rc;
}

void pxpy_model_free(struct px_model *m)
{
	px_model_free(m);
}

int pxpy_model_kind(const struct px_model *m)
{
	return (int)px_model_kind(m);
}

unsigned pxpy_model_caps(const struct px_model *m)
{
	return px_model_caps(m);
}

const char *pxpy_model_name(const struct px_model *m)
{
	const char *n = px_model_name(m);
	return n ? n : "";
}

void pxpy_model_box(const struct px_model *m, int world, double *box6)
{
	px_aabb b = world ? px_model_world_aabb(m) : px_model_local_aabb(m);
	box6[0] = b.min.x;
	box6[1] = b.min.y;
	box6[2] = b.min.z;
	box6[3] = b.max.x;
	box6[4] = b.max.y;
	box6[5] = b.max.z;
}

size_t pxpy_model_bytes(const struct px_model *m)
{
	return px_model_memory_bytes(m);
}

int pxpy_set_pose(struct px_model *m, const double *q4, const double *t3,
		  char *msg, size_t msg_cap)
{
	px_pose p;
	int rc;
	p.q.w = q4[0];
	p.q.x = q4[1];
	p.q.y = q4[2];
	p.q.z = q4[3];
	p.t = px_v3(t3[0], t3[1], t3[2]);
	rc = px_model_set_pose(m, p);
	if (rc)
		return say(msg, msg_cap, rc,
			   "pose (%g, %g, %g, %g | %g, %g, %g): %s", q4[0], q4[1],
			   q4[2], q4[3], t3[0], t3[1], t3[2], px_strerror(rc));
	return PX_OK;
}

void pxpy_get_pose(const struct px_model *m, double *q4, double *t3)
{
	px_pose p = px_model_pose(m);
	q4[0] = p.q.w;
	q4[1] = p.q.x;
	q4[2] = p.q.y;
	q4[3] = p.q.z;
	t3[0] = p.t.x;
	t3[1] = p.t.y;
	t3[2] = p.t.z;
}

/* ---- answers ------------------------------------------------------------ */

static void put(const struct pxpy_out *o, size_t i,
		const struct px_model_result *r, int found)
{
	if (o->found)
		o->found[i] = (int8_t)found;
	if (!found) {
		if (o->distance)
			o->distance[i] = INFINITY;
		if (o->point)
			o->point[3 * i] = o->point[3 * i + 1] = o->point[3 * i + 2] = NAN;
		if (o->direction)
			o->direction[3 * i] = o->direction[3 * i + 1] =
				o->direction[3 * i + 2] = NAN;
		if (o->u)
			o->u[i] = NAN;
		if (o->v)
			o->v[i] = NAN;
		if (o->gap)
			o->gap[i] = 0.0;
		if (o->index)
			o->index[i] = -1;
		if (o->sub)
			o->sub[i] = -1;
		if (o->feature)
			o->feature[i] = 0;
		if (o->inside)
			o->inside[i] = 0;
		if (o->certified)
			o->certified[i] = 1;
		return;
	}
	if (o->distance)
		o->distance[i] = r->distance;
	if (o->point) {
		o->point[3 * i] = r->point.x;
		o->point[3 * i + 1] = r->point.y;
		o->point[3 * i + 2] = r->point.z;
	}
	if (o->direction) {
		o->direction[3 * i] = r->direction.x;
		o->direction[3 * i + 1] = r->direction.y;
		o->direction[3 * i + 2] = r->direction.z;
	}
	if (o->u)
		o->u[i] = r->u;
	if (o->v)
		o->v[i] = r->v;
	if (o->gap)
		o->gap[i] = r->gap;
	if (o->index)
		o->index[i] = r->index;
	if (o->sub)
		o->sub[i] = r->sub;
	if (o->feature)
		o->feature[i] = r->feature;
	if (o->inside)
		o->inside[i] = (int8_t)r->inside;
	if (o->certified)
		o->certified[i] = (int8_t)r->certified;
}

static int point_error(int rc, const double *p, size_t i, size_t *bad,
		       char *msg, size_t cap)
{
	*bad = i;
	if (rc == PX_E_NAN)
		return say(msg, cap, rc, "point %zu (%g, %g, %g) is not finite", i,
			   p[0], p[1], p[2]);
	if (rc == PX_E_RANGE)
		return say(msg, cap, rc,
			   "point %zu (%g, %g, %g) is out of range (more than 1e150 "
			   "beyond the model)", i, p[0], p[1], p[2]);
	if (rc == PX_E_BUSY)
		return say(msg, cap, rc,
			   "point %zu: the model is being queried by too many "
			   "threads at once", i);
	return say(msg, cap, rc, "point %zu (%g, %g, %g): %s", i, p[0], p[1], p[2],
		   px_strerror(rc));
}

static unsigned qflags(unsigned flags)
{
	return (flags & 1u) ? PX_QUERY_UNSIGNED : 0u;
}

int pxpy_query(const struct px_model *m, const double *p, size_t n,
	       double max_dist, unsigned flags, const struct pxpy_out *o,
	       size_t *bad, char *msg, size_t msg_cap)
{
	struct px_model_result r;
	unsigned f = qflags(flags);
	size_t i;
	for (i = 0; i < n; i++) {
		const double *x = p + 3 * i;
		int rc = px_model_query_ex(m, px_v3(x[0], x[1], x[2]), max_dist, -1, f,
					   &r);
		if (rc < 0)
			return point_error(rc, x, i, bad, msg, msg_cap);
		put(o, i, &r, rc > 0);
	}
	return PX_OK;
}

/* ---- streams ------------------------------------------------------------ */

int pxpy_stream_create(const struct px_model *m, int verify_every,
		       int max_solves, int cold_switch,
		       struct px_model_stream **out, char *msg,
		       size_t msg_cap)
{
	struct px_model_stream_opts o;
	int rc;
	*out = NULL;
	px_model_stream_opts_default(&o);
	o.verify_every = verify_every;
	o.max_solves = max_solves;
	o.cold_switch = cold_switch;
	rc = px_model_stream_create(m, &o, out);
	if (rc == PX_E_UNSUPPORTED)
		return say(msg, msg_cap, rc,
			   "model '%s': this representation has no tracked streams "
			   "(NURBS models have; query the others directly)",
			   pxpy_model_name(m));
	if (rc)
		return say(msg, msg_cap, rc, "model '%s': stream: %s",
			   pxpy_model_name(m), px_strerror(rc));
	return PX_OK;
}

void pxpy_stream_free(struct px_model_stream *s)
{
	px_model_stream_free(s);
}

int pxpy_stream_query(struct px_model_stream *s, const double *p, size_t n,
		      double max_dist, unsigned flags,
		      const struct pxpy_out *o, size_t *bad, char *msg,
		      size_t msg_cap)
{
	struct px_model_result r;
	struct px_model_stream_note note;
	unsigned f = qflags(flags);
	size_t i;
	for (i = 0; i < n; i++) {
		const double *x = p + 3 * i;
		int rc = px_model_stream_query(s, px_v3(x[0], x[1], x[2]), max_dist, f,
					       &r, &note);
		if (rc < 0)
			return point_error(rc, x, i, bad, msg, msg_cap);
		put(o, i, &r, rc > 0);
		if (o->jumped)
			o->jumped[i] = (int8_t)note.jumped;
	}
	return PX_OK;
}

void pxpy_stream_stats(const struct px_model_stream *s, uint64_t *st9)
{
	struct px_model_stream_stats st;
	px_model_stream_get_stats(s, &st);
	st9[0] = st.queries;
	st9[1] = st.tracked;
	st9[2] = st.hot;
	st9[3] = st.global;
	st9[4] = st.cold;
	st9[5] = st.jumps;
	st9[6] = st.reinits;
	st9[7] = st.verifications;
	st9[8] = st.disagreements;
}

/* ---- pairs --------------------------------------------------------------- */

int pxpy_pair(const struct px_model *a, const struct px_model *b, int starts,
	      int max_iters, double *out9, double *normal3, int *ints6,
	      char *msg, size_t msg_cap)
{
	struct px_pair_opts o;
	struct px_pair_result r;
	int rc;
	memset(&o, 0, sizeof(o));
	memset(&r, 0, sizeof(r));
	o.starts = starts;
	o.max_iters = max_iters;
	rc = px_pair_distance(a, b, &o, &r);
	if (rc)
		return say(msg, msg_cap, rc, "pair '%s' / '%s': %s", pxpy_model_name(a),
			   pxpy_model_name(b), px_strerror(rc));
	out9[0] = r.distance;
	out9[1] = r.point_a.x;
	out9[2] = r.point_a.y;
	out9[3] = r.point_a.z;
	out9[4] = r.point_b.x;
	out9[5] = r.point_b.y;
	out9[6] = r.point_b.z;
	out9[7] = r.depth;
	out9[8] = r.witness_gap;
	normal3[0] = r.normal.x;
	normal3[1] = r.normal.y;
	normal3[2] = r.normal.z;
	ints6[0] = r.index_a;
	ints6[1] = r.index_b;
	ints6[2] = r.intersecting;
	ints6[3] = r.local_only;
	ints6[4] = r.converged;
	ints6[5] = r.iterations;
	return PX_OK;
}

/* ---- scenes -------------------------------------------------------------- */

int pxpy_scene_create(size_t capacity, struct px_scene **out, char *msg,
		      size_t msg_cap)
{
	int rc = px_scene_create(capacity, out);
	if (rc)
		return say(msg, msg_cap, rc, "scene of %zu models: %s", capacity,
			   px_strerror(rc));
	return PX_OK;
}

void pxpy_scene_free(struct px_scene *s)
{
	px_scene_free(s);
}

int pxpy_scene_add(struct px_scene *s, struct px_model *m, char *msg,
		   size_t msg_cap)
{
	int id = -1, rc = px_scene_add_kept(s, m, &id);
	if (rc == PX_OK)
		rc = px_scene_update(s);
	if (rc)
		return say(msg, msg_cap, rc, "scene: adding '%s': %s",
			   pxpy_model_name(m),
			   rc == PX_E_NOSPC ? "the scene is full" : px_strerror(rc));
	return id;
}

int pxpy_scene_update(struct px_scene *s)
{
	return px_scene_update(s);
}

static void put_hit(const struct pxpy_out *o, size_t i,
		    const struct px_scene_hit *h, int found)
{
	put(o, i, &h->r, found);
	if (found && o->distance)
		o->distance[i] = h->distance_m;
	if (o->model)
		o->model[i] = found ? h->model : -1;
	if (o->jumped)
		o->jumped[i] = (int8_t)(found && h->jumped);
}

int pxpy_scene_nearest(const struct px_scene *s, const double *p, size_t n,
		       double max_dist, const struct pxpy_out *o, size_t *bad,
		       char *msg, size_t msg_cap)
{
	struct px_scene_hit h;
	size_t i;
	for (i = 0; i < n; i++) {
		const double *x = p + 3 * i;
		int rc = px_scene_nearest(s, px_v3(x[0], x[1], x[2]), max_dist, &h);
		if (rc < 0)
			return point_error(rc, x, i, bad, msg, msg_cap);
		put_hit(o, i, &h, rc > 0);
	}
	return PX_OK;
}

int pxpy_scene_tracking_create(const struct px_scene *s,
			       struct px_scene_tracking **out, char *msg,
			       size_t msg_cap)
{
	int rc = px_scene_tracking_create(s, NULL, out);
	if (rc)
		return say(msg, msg_cap, rc, "scene tracking: %s", px_strerror(rc));
	return PX_OK;
}

void pxpy_scene_tracking_free(struct px_scene_tracking *t)
{
	px_scene_tracking_free(t);
}

int pxpy_scene_nearest_tracked(const struct px_scene *s,
			       struct px_scene_tracking *t, const double *p,
			       size_t n, double max_dist,
			       const struct pxpy_out *o, size_t *bad,
			       char *msg, size_t msg_cap)
{
	struct px_scene_hit h;
	size_t i;
	for (i = 0; i < n; i++) {
		const double *x = p + 3 * i;
		int rc = px_scene_nearest_tracked(s, px_v3(x[0], x[1], x[2]), max_dist,
						  t, &h);
		if (rc < 0)
			return point_error(rc, x, i, bad, msg, msg_cap);
		put_hit(o, i, &h, rc > 0);
	}
	return PX_OK;
}

/* ---- robots ---------------------------------------------------------------- */

int pxpy_robot_load(const char *path, const char *base, const char *tip,
		    const char *package_paths, struct px_urdf_robot **out,
		    char *msg, size_t msg_cap)
{
	const char *dirs[PX_URDF_MAX_PACKAGE_PATHS];
	char buf[4096];
	struct px_urdf_opts o;
	struct px_urdf_error e;
	struct px_urdf *u = NULL;
	int rc, n = 0;
	*out = NULL;
	memset(&o, 0, sizeof(o));
	if (package_paths && package_paths[0]) {
		char *p, *save = NULL;
		snprintf(buf, sizeof(buf), "%s", package_paths);
		for (p = strtok_r(buf, ":", &save); p && n < PX_URDF_MAX_PACKAGE_PATHS;
		     p = strtok_r(NULL, ":", &save))
			dirs[n++] = p;
		o.package_paths = dirs;
		o.n_package_paths = n;
	}
	rc = px_urdf_load(path, &o, &u, &e);
	if (rc == PX_OK)
		rc = px_urdf_robot_create(u, base, tip, px_pose_identity(), out, &e);
	px_urdf_free(u);
	if (rc)
		return say(msg, msg_cap, rc, "%s", e.msg[0] ? e.msg : px_strerror(rc));
	return PX_OK;
}

void pxpy_robot_free(struct px_urdf_robot *r)
{
	px_urdf_robot_free(r);
}

int pxpy_robot_dof(const struct px_urdf_robot *r)
{
	return px_urdf_robot_dof(r);
}

const char *pxpy_robot_joint_name(const struct px_urdf_robot *r, int j)
{
	return px_urdf_robot_joint_name(r, j);
}

int pxpy_robot_limits(const struct px_urdf_robot *r, int j, double *out3)
{
	return px_urdf_robot_limits(r, j, &out3[0], &out3[1], &out3[2]);
}

int pxpy_robot_body_count(const struct px_urdf_robot *r)
{
	return px_urdf_robot_body_count(r);
}

struct px_model *pxpy_robot_body(const struct px_urdf_robot *r, int i,
				 const char **link, int *frame)
{
	const struct px_urdf_body *b = px_urdf_robot_body(r, i);
	*link = px_urdf_robot_body_link(r, i);
	*frame = b ? b->frame : -1;
	return b ? b->model : NULL;
}

int pxpy_robot_set_q(struct px_urdf_robot *r, const double *q, double *frames,
		     char *msg, size_t msg_cap)
{
	px_pose f[PX_CONTROL_MAX_JOINTS + 1];
	int i, rc = px_urdf_robot_set_q(r, q, f, PX_CONTROL_MAX_JOINTS + 1);
	if (rc)
		return say(msg, msg_cap, rc, "joint positions: %s",
			   rc == PX_E_NAN ? "not finite" : px_strerror(rc));
	for (i = 0; frames && i <= px_urdf_robot_dof(r); i++) {
		double *o = frames + 7 * i;
		o[0] = f[i].q.w;
		o[1] = f[i].q.x;
		o[2] = f[i].q.y;
		o[3] = f[i].q.z;
		o[4] = f[i].t.x;
		o[5] = f[i].t.y;
		o[6] = f[i].t.z;
	}
	return PX_OK;
}

/* ---- misc ---------------------------------------------------------------- */

const char *pxpy_strerror(int code)
{
	return px_strerror(code);
}

const char *pxpy_version(void)
{
	return px_version();
}
