/*
 * px_load.c - mesh or point cloud, chosen by file name and content.
 */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "px_cloud.h"
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

int px_model_load(const char *path, double cloud_radius_m,
		  struct px_model **out, char *msg, size_t msg_cap)
{
	int cloud = 0, rc;

	put(msg, msg_cap, "");
	if (!path || !out) {
		put(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	if (ends_with(path, ".xyz") || ends_with(path, ".csv") ||
	    ends_with(path, ".txt") || ends_with(path, ".pts"))
		cloud = 1;
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
