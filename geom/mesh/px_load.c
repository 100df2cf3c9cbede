/*
 * px_load.c - mesh, point cloud or CAD part, chosen by file name and
 * content.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "px_brep.h"
#include "px_brep_obj.h"
#include "px_cad.h"
#include "px_cloud.h"
#include "px_file.h"
#include "px_load.h"
#include "px_mesh.h"

static int ends_with(const char *s, const char *ext)
{
	size_t n = strlen(s), m = strlen(ext);
	return n >= m && strcasecmp(s + n - m, ext) == 0;
}

static void put(char *msg, size_t cap, const char *text)
{
	if (msg && cap)
		snprintf(msg, cap, "%s", text);
}

int px_model_is_cad_name(const char *path)
{
	return path && (ends_with(path, ".step") || ends_with(path, ".stp") ||
			ends_with(path, ".iges") || ends_with(path, ".igs"));
}

/* The importer's description becomes a B-rep that owns its own copy, so
 * the importer's handle goes before the model is made. */
int px_model_load_cad(const char *path, double scale, struct px_model **out,
		      char *msg, size_t msg_cap)
{
	struct px_cad_opts o;
	struct px_cad *c = NULL;
	struct px_brep *b = NULL;
	struct px_brep_error err;
	struct px_brep_info info;
	int rc;

	put(msg, msg_cap, "");
	if (out)
		*out = NULL;
	if (!path || !out || !(scale > 0.0) || !isfinite(scale)) {
		put(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	px_cad_opts_default(&o);
	o.scale = scale;
	o.max_bytes = PX_FILE_MODEL_MAX_BYTES;
	rc = px_cad_load(path, &o, &c, msg, msg_cap);
	if (rc != PX_OK) {
		if (msg && msg_cap && !msg[0])
			snprintf(msg, msg_cap, "%s: %s", path, px_strerror(rc));
		return rc;
	}
	memset(&err, 0, sizeof(err));
	rc = px_brep_create(px_cad_desc(c), NULL, &err, &b);
	px_cad_free(c);
	if (rc != PX_OK) {
		if (msg && msg_cap)
			snprintf(msg, msg_cap, "%s: %s", path,
				 err.msg[0] ? err.msg : px_strerror(rc));
		return rc;
	}
	px_brep_get_info(b, &info);
	rc = px_model_from_brep(b, out);
	if (rc != PX_OK) {
		if (msg && msg_cap)
			snprintf(msg, msg_cap, "%s: %s", path, px_strerror(rc));
		return rc;
	}
	if (!info.closed && msg && msg_cap)
		snprintf(msg, msg_cap, "%s: open B-rep, distances are unsigned (%s)",
			 path, info.why);
	return PX_OK;
}

int px_model_load(const char *path, double cloud_radius_m,
		  struct px_model **out, char *msg, size_t msg_cap)
{
	int cloud = 0, rc;

	put(msg, msg_cap, "");
	if (!path || !out) {
		put(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	if (px_model_is_cad_name(path))
		return px_model_load_cad(path, 1.0, out, msg, msg_cap);
	if (ends_with(path, ".xyz") || ends_with(path, ".csv") ||
	    ends_with(path, ".txt") || ends_with(path, ".pts"))
		cloud = 1;
	if (!cloud && ends_with(path, ".obj")) {
		/* trimmed free-form surfaces: a B-rep (px_brep_obj.h) */
		int trimmed = 0;
		rc = px_model_load_obj_brep(path, 1.0, &trimmed, out, msg, msg_cap);
		if (trimmed)
			return rc;
	}
	if (!cloud) {
		struct px_mesh_report rep;
		rc = px_mesh_load(path, NULL, &rep, out);
		if (rc == PX_OK) {
			if (!rep.closed && msg && msg_cap)
				snprintf(msg, msg_cap,
					 "%s: open or non-manifold mesh, distances are unsigned (%s)",
					 path, rep.message);
			else
				put(msg, msg_cap, rep.message);
			return PX_OK;
		}
		/* a PLY with vertices only is a point cloud */
		if (!(rc == PX_E_PARSE && ends_with(path, ".ply") &&
		      strstr(rep.message, "no triangles"))) {
			put(msg, msg_cap, rep.message);
			return rc;
		}
	}
	{
		struct px_cloud_report rep;
		rc = px_cloud_load(path, cloud_radius_m, &rep, out);
		put(msg, msg_cap, rep.message);
		return rc;
	}
}
