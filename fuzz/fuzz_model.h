/*
 * fuzz_model.h - what the file-format targets check on a model that
 * loaded: queries at points around its box answer finite distances equal
 * to a brute-force scan over every triangle (meshes) or point (clouds),
 * with the closest point at that distance; and the whole check of one
 * model file read through px_model_load().
 */
#ifndef PX_FUZZ_MODEL_H
#define PX_FUZZ_MODEL_H

#include "fuzz_util.h"

#include "px_cloud.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_model.h"

static double fzm_brute(const struct px_model *m, px_vec3 p, int *ok)
{
	double best = INFINITY;
	size_t i, n;
	*ok = 1;
	if (px_model_kind(m) == PX_MODEL_MESH) {
		n = px_mesh_triangle_count(m);
		for (i = 0; i < n; i++) {
			px_vec3 v[3], q;
			double d2;
			if (px_mesh_triangle(m, i, v) != PX_OK)
				abort();
			d2 = px_tri_closest(p, v[0], v[1], v[2], &q, NULL, NULL,
					    NULL, NULL);
			if (d2 < best)
				best = d2;
		}
		return sqrt(best);
	}
	if (px_model_kind(m) == PX_MODEL_CLOUD) {
		n = px_cloud_point_count(m);
		for (i = 0; i < n; i++) {
			px_vec3 q;
			double d2;
			if (px_cloud_point(m, i, &q) != PX_OK)
				abort();
			d2 = px_v3_dist2(p, q);
			if (d2 < best)
				best = d2;
		}
		return sqrt(best) - px_cloud_radius(m);
	}
	*ok = 0;
	return 0.0;
}

static void fzm_check(const struct px_model *m)
{
	px_aabb b = px_model_local_aabb(m);
	px_vec3 c = px_v3_scale(px_v3_add(b.min, b.max), 0.5);
	px_vec3 e = px_v3_sub(b.max, b.min);
	double ext = px_v3_norm(e);
	int k;
	if (!(ext >= 0.0) || !isfinite(ext))
		return; /* extents beyond double range: nothing to compare */
	for (k = 0; k < 10; k++) {
		struct px_model_result r;
		px_vec3 p;
		double want, tol;
		int ok, rc;
		/* centre, corners, and points outside along the axes */
		p.x = c.x + (k & 1 ? 0.75 : -0.6) * e.x * (k > 0);
		p.y = c.y + (k & 2 ? 0.7 : -0.55) * e.y * (k > 0);
		p.z = c.z + (k & 4 ? 0.65 : -0.8) * e.z * (k > 0);
		if (k >= 8)
			p = px_v3_add(p, px_v3_scale(e, k == 8 ? 2.0 : -3.0));
		if (!(isfinite(p.x) && isfinite(p.y) && isfinite(p.z)))
			continue;
		rc = px_model_query(m, p, &r);
		if (rc == PX_E_RANGE && ext > 1e150)
			continue; /* squared distances overflow: refused */
		if (rc != 1)
			abort();
		if (!isfinite(r.distance) || !isfinite(r.point.x) ||
		    !isfinite(r.point.y) || !isfinite(r.point.z))
			abort();
		want = fzm_brute(m, p, &ok);
		if (!ok || !isfinite(want))
			continue;
		tol = 1e-9 * (ext + fabs(want) + px_v3_norm(p)) + 1e-300;
		if (!(fabs(fabs(r.distance) - fabs(want)) <= tol))
			abort();
		/* the closest point is where the distance says */
		if (px_model_kind(m) == PX_MODEL_MESH &&
		    !(fabs(px_v3_dist(p, r.point) - fabs(r.distance)) <= tol))
			abort();
	}
}

/*
 * The outcome of loading the file at path: rc PX_OK with model m, which
 * must pass fzm_check() (then freed), or a format error, no model, and
 * a message msg (cap bytes) naming the file; anything else aborts.
 */
static inline int fzm_outcome(int rc, struct px_model *m, const char *msg,
			      size_t cap, const char *path)
{
	if (rc == PX_OK) {
		if (!m)
			abort();
		fzm_check(m);
		px_model_free(m);
		return 0;
	}
	if (m)
		abort();
	if (rc != PX_E_PARSE && rc != PX_E_NAN && rc != PX_E_RANGE &&
	    rc != PX_E_INVAL && rc != PX_E_OVERFLOW)
		abort();
	fz_check_msg(msg, cap);
	if (!strstr(msg, path))
		abort();
	return 0;
}

/* The file at path read by px_model_load() with cloud radius radius_m
 * (any kind of model), judged by fzm_outcome(). */
static inline int fzm_load_check(const char *path, double radius_m)
{
	struct px_model *m = NULL;
	char msg[512];
	int rc = px_model_load(path, radius_m, &m, msg, sizeof msg);
	return fzm_outcome(rc, m, msg, sizeof msg, path);
}

#endif
