/* The view's JSON messages (px_view.h, docs/view.md): the scene from the
 * models, a frame from a telemetry record. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "px_tess.h"
#include "px_view.h"
#include "view_internal.h"

void px_view_options_default(struct px_view_options *o)
{
	memset(o, 0, sizeof(*o));
	o->mode = "live";
	o->period_ns = 1000000;
	o->rate_hz = 30;
	o->max_clients = 8;
	o->queue_frames = 16;
	o->stall_ms = 5000;
}

void view_buf_fixed(struct view_buf *b, char *p, size_t cap)
{
	memset(b, 0, sizeof(*b));
	b->p = p;
	b->cap = cap;
	if (cap)
		p[0] = '\0';
}

static int reserve(struct view_buf *b, size_t more)
{
	size_t c;
	char *q;
	if (b->err)
		return -1;
	if (b->n + more + 1 <= b->cap)
		return 0;
	if (!b->growable) {
		b->err = PX_E_NOSPC;
		return -1;
	}
	c = b->cap ? b->cap : 4096;
	while (c < b->n + more + 1)
		c *= 2;
	q = realloc(b->p, c);
	if (!q) {
		b->err = PX_E_NOMEM;
		return -1;
	}
	b->p = q;
	b->cap = c;
	return 0;
}

void view_buf_put(struct view_buf *b, const char *s, size_t n)
{
	if (reserve(b, n))
		return;
	memcpy(b->p + b->n, s, n);
	b->n += n;
	b->p[b->n] = '\0';
}

void view_buf_puts(struct view_buf *b, const char *s)
{
	view_buf_put(b, s, strlen(s));
}

void view_buf_printf(struct view_buf *b, const char *fmt, ...)
{
	char tmp[256];
	va_list ap;
	int n;
	va_start(ap, fmt);
	n = vsnprintf(tmp, sizeof(tmp), fmt, ap);
	va_end(ap);
	if (n < 0 || (size_t)n >= sizeof(tmp)) {
		if (!b->err)
			b->err = PX_E_NOSPC;
		return;
	}
	view_buf_put(b, tmp, (size_t)n);
}

void view_buf_num(struct view_buf *b, double v, int digits)
{
	if (!isfinite(v))
		view_buf_put(b, "null", 4);
	else if (v == 0.0)
		view_buf_put(b, "0", 1); /* also -0 */
	else
		view_buf_printf(b, "%.*g", digits, v);
}

void view_buf_str(struct view_buf *b, const char *s)
{
	view_buf_put(b, "\"", 1);
	for (; s && *s; s++) {
		unsigned char c = (unsigned char)*s;
		if (c == '"' || c == '\\')
			view_buf_printf(b, "\\%c", c);
		else if (c < 0x20)
			view_buf_printf(b, "\\u%04x", c);
		else
			view_buf_put(b, s, 1);
	}
	view_buf_put(b, "\"", 1);
}

void view_buf_floats(struct view_buf *b, const double *v, size_t n,
		     double scale, int digits)
{
	size_t k;
	view_buf_put(b, "[", 1);
	for (k = 0; k < n; k++) {
		if (k)
			view_buf_put(b, ",", 1);
		view_buf_num(b, scale * v[k], digits);
	}
	view_buf_put(b, "]", 1);
}

void view_tess_indices(struct view_buf *b, const struct px_tess *t)
{
	size_t k;
	view_buf_puts(b, "\"indices\":[");
	for (k = 0; k < 3 * t->n_triangles; k++)
		view_buf_printf(b, k ? ",%u" : "%u", (unsigned)t->tri[k]);
	view_buf_puts(b, "]}");
}

static void vec3(struct view_buf *b, const double *v, int digits)
{
	view_buf_put(b, "[", 1);
	view_buf_num(b, v[0], digits);
	view_buf_put(b, ",", 1);
	view_buf_num(b, v[1], digits);
	view_buf_put(b, ",", 1);
	view_buf_num(b, v[2], digits);
	view_buf_put(b, "]", 1);
}

/* The rows of a frame's array field: ,"key":[[...],...] (none: left out). */
static void rows(struct view_buf *b, const char *key, const double *v, int n,
		 int width, int digits)
{
	int i;
	if (n <= 0)
		return;
	view_buf_printf(b, ",\"%s\":[", key);
	for (i = 0; i < n; i++) {
		if (i)
			view_buf_put(b, ",", 1);
		view_buf_floats(b, v + (size_t)i * (size_t)width, (size_t)width, 1.0,
				digits);
	}
	view_buf_put(b, "]", 1);
}

int px_view_frame_json(const struct px_app_record *r, int with_type, char *buf,
		       size_t cap)
{
	return px_view_frame_json_extra(r, NULL, with_type, buf, cap);
}

int px_view_frame_json_extra(const struct px_app_record *r,
			     const struct px_view_frame_extra *x, int with_type,
			     char *buf, size_t cap)
{
	struct view_buf b;
	if (!r || !buf)
		return PX_E_INVAL;
	view_buf_fixed(&b, buf, cap);
	view_buf_puts(&b, with_type ? "{\"type\":\"frame\",\"t_s\":" : "{\"t_s\":");
	view_buf_num(&b, r->t_s, 9);
	view_buf_printf(&b, ",\"cycle\":%llu,\"tool\":",
			(unsigned long long)r->cycle);
	vec3(&b, r->dev_m, 9);
	view_buf_puts(&b, ",\"proxy\":");
	vec3(&b, r->proxy_m, 9);
	view_buf_puts(&b, ",\"closest\":");
	if (x && x->has_closest)
		vec3(&b, x->closest_m, 9);
	else
		view_buf_puts(&b, "null");
	view_buf_puts(&b, ",\"distance_m\":");
	view_buf_num(&b, r->distance_m, 9);
	view_buf_puts(&b, ",\"force_n\":");
	vec3(&b, r->force_n, 6);
	view_buf_puts(&b, ",\"penetration_m\":");
	view_buf_num(&b, r->penetration_m, 9);
	view_buf_printf(&b, ",\"contact\":%s,\"safe\":%s,\"latency_us\":",
			r->contact ? "true" : "false", r->safe ? "true" : "false");
	view_buf_num(&b, (double)r->latency_ns / 1e3, 6);
	view_buf_puts(&b, ",\"compute_us\":");
	view_buf_num(&b, (double)r->compute_ns / 1e3, 6);
	view_buf_puts(&b, ",\"scale\":");
	view_buf_num(&b, r->scale, 6);
	if (x) {
		/* ids are small integers: exact at any digits */
		rows(&b, "models", &x->models[0][0], x->n_models, 8, 9);
		rows(&b, "links", &x->links[0][0], x->n_links, 7, 7);
		rows(&b, "clearances", &x->clearances[0][0], x->n_clearances, 7, 9);
	}
	view_buf_puts(&b, "}");
	return b.err ? b.err : (int)b.n;
}

static const char *kind_name(enum px_model_kind k)
{
	switch (k) {
	case PX_MODEL_MESH:
		return "mesh";
	case PX_MODEL_NURBS:
		return "nurbs";
	case PX_MODEL_BREP:
		return "brep";
	case PX_MODEL_CLOUD:
		return "cloud";
	default:
		return "prim";
	}
}

/* One model of the scene message; its world vertices widen bounds. */
static int model_json(struct view_buf *b, const struct px_scene *s, size_t i,
		      double *bounds)
{
	const struct px_model *m = px_scene_model(s, i), *inner;
	struct px_tess t;
	px_pose P = px_model_pose(m);
	const char *name = px_scene_name(s, i);
	double sc = px_scene_model_scale(m, &inner);
	size_t k;
	int rc = px_model_tessellate(inner, NULL, &t);
	if (rc != PX_OK && rc != PX_E_UNSUPPORTED) {
		px_tess_free(&t);
		return rc;
	}
	view_buf_printf(b, "%s{\"id\":%zu,\"name\":", i ? "," : "", i);
	view_buf_str(b, name ? name : "");
	view_buf_printf(b, ",\"kind\":\"%s\",\"pose\":[",
			kind_name(px_model_kind(m)));
	for (k = 0; k < 7; k++) {
		const double pose[7] = {P.t.x, P.t.y, P.t.z, P.q.w,
					P.q.x, P.q.y, P.q.z};
		if (k)
			view_buf_put(b, ",", 1);
		view_buf_num(b, pose[k], 9);
	}
	view_buf_puts(b, "],\"positions\":[");
	for (k = 0; k < t.n_vertices; k++) {
		px_vec3 l = {sc * t.xyz[3 * k], sc * t.xyz[3 * k + 1],
			     sc * t.xyz[3 * k + 2]};
		px_vec3 w = px_pose_transform_point(P, l);
		const double wv[3] = {w.x, w.y, w.z};
		int d;
		if (k)
			view_buf_put(b, ",", 1);
		view_buf_num(b, l.x, 7);
		view_buf_put(b, ",", 1);
		view_buf_num(b, l.y, 7);
		view_buf_put(b, ",", 1);
		view_buf_num(b, l.z, 7);
		for (d = 0; d < 3; d++)
			if (isfinite(wv[d])) {
				if (wv[d] < bounds[d])
					bounds[d] = wv[d];
				if (wv[d] > bounds[3 + d])
					bounds[3 + d] = wv[d];
			}
	}
	view_buf_puts(b, "],");
	view_tess_indices(b, &t);
	px_tess_free(&t);
	return b->err;
}

int px_view_scene_json(const struct px_scene *s,
		       const struct px_view_scene_info *info, char **json,
		       size_t *len)
{
	struct view_buf b;
	double bounds[6] = {INFINITY, INFINITY, INFINITY,
			    -INFINITY, -INFINITY, -INFINITY};
	size_t i, n = s ? px_scene_count(s) : 0;
	int rc = PX_OK, d;
	if (!json || !len)
		return PX_E_INVAL;
	memset(&b, 0, sizeof(b));
	b.growable = 1;
	view_buf_puts(&b, "{\"type\":\"scene\",\"models\":[");
	for (i = 0; i < n && rc == PX_OK; i++)
		rc = model_json(&b, s, i, bounds);
	if (rc == PX_OK && info && info->cloud_name) {
		/* the cloud obstacle: points from "cloud" messages */
		view_buf_printf(&b, "%s{\"id\":%zu,\"name\":", n ? "," : "", n);
		view_buf_str(&b, info->cloud_name);
		view_buf_puts(&b, ",\"kind\":\"cloud\",\"pose\":[0,0,0,1,0,0,0],"
				  "\"positions\":[],\"indices\":[]}");
	}
	view_buf_puts(&b, "],\"tool\":{\"radius_m\":");
	view_buf_num(&b, info ? info->tool_radius_m : 0.0, 9);
	view_buf_puts(&b, "},\"robot\":");
	if (info && info->arm) {
		size_t alen;
		const char *aj = view_arm_json(info->arm, &alen);
		view_buf_put(&b, aj, alen);
	} else {
		view_buf_puts(&b, "null");
	}
	view_buf_puts(&b, ",\"bounds\":[");
	if (!(bounds[0] <= bounds[3]))
		for (d = 0; d < 3; d++) {
			bounds[d] = -0.1;
			bounds[3 + d] = 0.1;
		}
	for (d = 0; d < 6; d++) {
		if (d)
			view_buf_put(&b, ",", 1);
		view_buf_num(&b, bounds[d], 9);
	}
	view_buf_puts(&b, "]}");
	if (rc == PX_OK)
		rc = b.err;
	if (rc != PX_OK) {
		free(b.p);
		return rc;
	}
	*json = b.p;
	*len = b.n;
	return PX_OK;
}

int px_view_cloud_json(int id, double t_s, const float *xyz, size_t n,
		       char **json, size_t *len)
{
	struct view_buf b;
	size_t step = n > PX_VIEW_CLOUD_MAX
		? (n + PX_VIEW_CLOUD_MAX - 1) / PX_VIEW_CLOUD_MAX : 1, i;
	if (!json || !len || (n && !xyz) || id < 0)
		return PX_E_INVAL;
	memset(&b, 0, sizeof(b));
	b.growable = 1;
	view_buf_printf(&b, "{\"type\":\"cloud\",\"id\":%d,\"t_s\":", id);
	view_buf_num(&b, t_s, 9);
	view_buf_puts(&b, ",\"positions\":[");
	for (i = 0; i < n; i += step) {
		if (i)
			view_buf_put(&b, ",", 1);
		view_buf_num(&b, xyz[3 * i], 6);
		view_buf_put(&b, ",", 1);
		view_buf_num(&b, xyz[3 * i + 1], 6);
		view_buf_put(&b, ",", 1);
		view_buf_num(&b, xyz[3 * i + 2], 6);
	}
	view_buf_puts(&b, "]}");
	if (b.err) {
		free(b.p);
		return b.err;
	}
	*json = b.p;
	*len = b.n;
	return PX_OK;
}
