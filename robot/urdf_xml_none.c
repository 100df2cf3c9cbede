/*
 * urdf_xml_none.c - stands in for urdf_xml.c in builds without libxml2:
 * URDF files are refused with a message that says so.
 */
#include <stdio.h>
#include <string.h>

#include "robot_internal.h"

static int absent(const char *name, struct px_urdf **out, struct px_urdf_error *err)
{
	if (out)
		*out = NULL;
	if (err)
		memset(err, 0, sizeof(*err));
	return px__urdf_fail(err, PX_E_UNSUPPORTED, name ? name : "", 0, "",
			     "URDF files need libxml2: this build of proxima was made "
			     "without it (install libxml2-dev and rebuild)");
}

int px_urdf_load(const char *path, const struct px_urdf_opts *opts,
		 struct px_urdf **out, struct px_urdf_error *err)
{
	(void)opts;
	return absent(path, out, err);
}

int px_urdf_load_mem(const char *name, const char *xml, size_t len,
		     const struct px_urdf_opts *opts, struct px_urdf **out,
		     struct px_urdf_error *err)
{
	(void)xml;
	(void)len;
	(void)opts;
	return absent(name, out, err);
}
