/*
 * px_load.c - mesh, point cloud or CAD part, chosen by file name and
 * content.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "px_brep.h"
#include "px_brep_obj.h"
#include "px_cad.h"
#include "px_cloud.h"
#include "px_dist.h"
#include "px_file.h"
#include "px_load.h"
#include "mesh_internal.h"
#include "px_mesh.h"
#include "px_obj.h"

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

static int say(char *msg, size_t cap, int rc, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
static int say(char *msg, size_t cap, int rc, const char *fmt, ...)
{
	va_list ap;
	if (msg && cap) {
		va_start(ap, fmt);
		vsnprintf(msg, cap, fmt, ap);
		va_end(ap);
	}
	return rc;
}

/* The faces of an OBJ as a mesh, its coordinates exactly as written. */
static int obj_faces(const struct px_obj_model *obj, const char *path,
		     struct px_model **out, char *msg, size_t cap)
{
	struct px_mesh_report rep;
	uint32_t *tri = malloc(3 * (size_t)obj->n_triangles * sizeof(*tri));
	int i, rc;
	if (!tri)
		return say(msg, cap, PX_E_NOMEM, "%s: out of memory", path);
	for (i = 0; i < 3 * obj->n_triangles; i++)
		tri[i] = (uint32_t)obj->triangles[i];
	rc = px_mesh_model(obj->vertices, (size_t)obj->n_vertices, tri,
			   (size_t)obj->n_triangles, NULL, &rep, out);
	free(tri);
	if (rc)
		return say(msg, cap, rc, "%s: faces: %s", path,
			   rep.message[0] ? rep.message : px_strerror(rc));
	if (!rep.closed)
		say(msg, cap, PX_OK,
		    "%s: open or non-manifold mesh, distances are unsigned (%s)",
		    path, rep.message);
	return PX_OK;
}

/* The free-form curves and surfaces of an OBJ as one NURBS model. */
static int obj_freeform(const struct px_obj_model *obj, const char *path,
			struct px_model **out, char *msg, size_t cap)
{
	size_t ne = (size_t)obj->n_entities;
	struct px_nurbs_curve *cv = calloc(ne, sizeof(*cv));
	struct px_nurbs_surf *sf = calloc(ne, sizeof(*sf));
	int i, nc = 0, ns = 0, rc;
	if (!cv || !sf) {
		rc = say(msg, cap, PX_E_NOMEM, "%s: out of memory", path);
	} else {
		for (i = 0; i < obj->n_entities; i++) {
			if (obj->entities[i].kind == PX_OBJ_CURVE)
				cv[nc++] = obj->entities[i].curve;
			else
				sf[ns++] = obj->entities[i].surf;
		}
		rc = px_nurbs_model_create(nc ? cv : NULL, nc, ns ? sf : NULL, ns,
					   NULL, out);
		if (rc)
			say(msg, cap, rc, "%s: cannot prepare the NURBS model: %s",
			    path, px_strerror(rc));
	}
	free(cv);
	free(sf);
	return rc;
}

/* An OBJ's text as a model (px_model_load_obj()). */
static int obj_model(const char *path, const char *data, size_t len,
		     struct px_model **out, char *msg, size_t cap)
{
	struct px_obj_model *obj = NULL;
	struct px_obj_error oe;
	int rc;
	memset(&oe, 0, sizeof(oe));
	rc = px_obj_load_mem(path, data, len, &obj, &oe);
	if (rc) {
		px_obj_error_text(&oe, path, rc, msg, cap);
		return rc;
	}
	if (px_obj_trimmed(obj))
		rc = px_model_from_obj_brep(obj, path, 1.0, out, msg, cap);
	else if (obj->n_entities > 0 && obj->n_triangles > 0)
		rc = say(msg, cap, PX_E_UNSUPPORTED,
			 "%s: the file has both free-form entities and faces; "
			 "load them as two models (one file each)", path);
	else if (obj->n_triangles > 0)
		rc = obj_faces(obj, path, out, msg, cap);
	else if (obj->n_entities > 0)
		rc = obj_freeform(obj, path, out, msg, cap);
	else
		rc = say(msg, cap, PX_E_NOTFOUND,
			 "%s: no free-form curve or surface and no face in the file",
			 path);
	px_obj_free(obj);
	return rc;
}

int px_model_load_obj(const char *path, struct px_model **out, char *msg,
		      size_t msg_cap)
{
	char *data = NULL;
	size_t len = 0;
	int rc;
	put(msg, msg_cap, "");
	if (!path || !out) {
		put(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	*out = NULL;
	rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES, PX_FILE_TEXT, "model",
			  &data, &len, msg, msg_cap);
	if (rc == PX_OK)
		rc = obj_model(path, data, len, out, msg, msg_cap);
	free(data);
	return rc;
}

/* 1 when an OBJ's text has a free-form statement (a curve or surface
 * needs cstype first): px_obj.h reads it, not the mesh importer. */
static int obj_text_freeform(const char *data, size_t len)
{
	size_t i = 0;
	while (i < len) {
		while (i < len && (data[i] == ' ' || data[i] == '\t'))
			i++;
		if (len - i >= 7 && memcmp(data + i, "cstype", 6) == 0 &&
		    (data[i + 6] == ' ' || data[i + 6] == '\t'))
			return 1;
		while (i < len && data[i] != '\n')
			i++;
		i++;
	}
	return 0;
}

/* A mesh file's report as px_model_load() words it. */
static void mesh_msg(const struct px_mesh_report *rep, const char *path,
		     char *msg, size_t msg_cap)
{
	if (!rep->closed && msg && msg_cap)
		snprintf(msg, msg_cap,
			 "%s: open or non-manifold mesh, distances are unsigned (%s)",
			 path, rep->message);
	else
		put(msg, msg_cap, rep->message);
}

/* An .obj read once: free-form and trimmed files by px_obj.h, polygon
 * files by the mesh importer (as px_mesh_load() reads them). */
static int load_obj_any(const char *path, struct px_model **out, char *msg,
			size_t msg_cap)
{
	struct px_mesh_report rep;
	char *data = NULL;
	size_t len = 0;
	int rc = px__import_read(path, &data, &len, msg, msg_cap);
	if (rc != PX_OK)
		return rc;
	if (px_obj_text_trimmed(data, len) || obj_text_freeform(data, len)) {
		rc = obj_model(path, data, len, out, msg, msg_cap);
	} else {
		rc = px__mesh_load_data(path, data, len, NULL, NULL, &rep, out);
		if (rc == PX_OK)
			mesh_msg(&rep, path, msg, msg_cap);
		else
			put(msg, msg_cap, rep.message);
	}
	free(data);
	return rc;
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
	if (!cloud && ends_with(path, ".obj"))
		return load_obj_any(path, out, msg, msg_cap);
	if (!cloud) {
		struct px_mesh_report rep;
		rc = px_mesh_load(path, NULL, &rep, out);
		if (rc == PX_OK) {
			mesh_msg(&rep, path, msg, msg_cap);
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
