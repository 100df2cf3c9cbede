/*
 * urdf_xml.c - reading URDF files with libxml2 (the "xml" optional
 * part): the document into struct px_urdf, every attribute checked
 * where it is read, with its line; urdf_tree.c checks the references.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <libxml/parser.h>
#include <libxml/tree.h>

#include "px_file.h"
#include "robot_internal.h"

/* What one parse needs at hand. */
struct rd {
	struct px_urdf *u;
	struct px_urdf_error *err;
	char elem[128];
	long line;
};

static int is_el(const xmlNode *n, const char *name)
{
	return n->type == XML_ELEMENT_NODE && !strcmp((const char *)n->name, name);
}

static long line_of(const xmlNode *n)
{
	return (long)xmlGetLineNo(n);
}

/* The element's description for messages: <joint name='elbow'>. */
static void describe(struct rd *r, const xmlNode *n)
{
	xmlChar *nm = xmlGetProp(n, (const xmlChar *)"name");
	if (nm)
		snprintf(r->elem, sizeof(r->elem), "<%s name='%.60s'>", n->name,
			 (const char *)nm);
	else
		snprintf(r->elem, sizeof(r->elem), "<%s>", n->name);
	xmlFree(nm);
	r->line = line_of(n);
}

static int fail(struct rd *r, const xmlNode *n, int code, const char *fmt,
		const char *a, const char *b)
{
	char what[320];
	long line = n ? line_of(n) : r->line;
	snprintf(what, sizeof(what), fmt, a ? a : "", b ? b : "");
	return px__urdf_fail(r->err, code, r->u->file, line, r->elem, "%s", what);
}

/* Attribute name of n copied to the heap, NULL when absent. */
static char *attr(const xmlNode *n, const char *name)
{
	xmlChar *v = xmlGetProp(n, (const xmlChar *)name);
	char *s;
	if (!v)
		return NULL;
	s = px__urdf_strdup((const char *)v);
	xmlFree(v);
	return s;
}

/* k numbers from attribute name of n (absent: def, may be NULL then the
 * attribute is required); each finite and |x| <= limit. */
static int nums(struct rd *r, const xmlNode *n, const char *name, int k,
		const double *def, double limit, double *out)
{
	char *s = attr(n, name), *p, *end;
	int i;
	if (!s) {
		if (!def)
			return fail(r, n, PX_E_PARSE, "<%s> needs the attribute '%s'",
				    (const char *)n->name, name);
		for (i = 0; i < k; i++)
			out[i] = def[i];
		return PX_OK;
	}
	p = s;
	for (i = 0; i < k; i++) {
		errno = 0;
		out[i] = strtod(p, &end);
		if (end == p || errno == ERANGE || !isfinite(out[i]) ||
		    fabs(out[i]) > limit) {
			char v[64];
			snprintf(v, sizeof(v), "%.60s", s);
			free(s);
			return fail(r, n, end == p ? PX_E_PARSE : PX_E_RANGE,
				    k == 1 ? "'%s' must be a finite number within range, not '%s'"
					   : "'%s' must be finite numbers within range, not '%s'",
				    name, v);
		}
		p = end;
	}
	while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')
		p++;
	if (*p) {
		char v[64];
		snprintf(v, sizeof(v), "%.60s", s);
		free(s);
		return fail(r, n, PX_E_PARSE,
			    k == 1 ? "'%s' must be one number, not '%s'"
				   : "'%s' must be three numbers, not '%s'",
			    name, v);
	}
	free(s);
	return PX_OK;
}

/* <origin xyz rpy> among n's children (identity when absent). */
static int origin_of(struct rd *r, const xmlNode *n, px_pose *out)
{
	static const double zero[3] = {0, 0, 0};
	const xmlNode *c;
	double xyz[3], rpy[3];
	int rc;
	*out = px_pose_identity();
	for (c = n->children; c; c = c->next) {
		if (!is_el(c, "origin"))
			continue;
		rc = nums(r, c, "xyz", 3, zero, PX_URDF_MAX_LENGTH, xyz);
		if (rc == PX_OK)
			rc = nums(r, c, "rpy", 3, zero, 1e3, rpy);
		if (rc)
			return rc;
		*out = px_control_pose_from_xyz_rpy(px_v3(xyz[0], xyz[1], xyz[2]),
						    px_v3(rpy[0], rpy[1], rpy[2]));
		return PX_OK;
	}
	return PX_OK;
}

static const xmlNode *child(const xmlNode *n, const char *name)
{
	const xmlNode *c;
	for (c = n->children; c; c = c->next)
		if (is_el(c, name))
			return c;
	return NULL;
}

/* One <collision>: origin and geometry. */
static int read_collision(struct rd *r, const xmlNode *n, struct px_urdf_shape *s,
			  char **mesh_name)
{
	static const double one[3] = {1, 1, 1};
	const xmlNode *g = child(n, "geometry"), *c;
	int rc = origin_of(r, n, &s->origin), k = 0;
	s->line = line_of(n);
	if (rc)
		return rc;
	if (!g)
		return fail(r, n, PX_E_PARSE, "<collision> without <geometry>%s%s", NULL, NULL);
	for (c = g->children; c; c = c->next) {
		if (c->type != XML_ELEMENT_NODE)
			continue;
		k++;
		if (is_el(c, "box")) {
			s->type = PX_URDF_BOX;
			rc = nums(r, c, "size", 3, NULL, PX_URDF_MAX_LENGTH, s->size);
			if (!rc && (s->size[0] <= 0 || s->size[1] <= 0 || s->size[2] <= 0))
				rc = fail(r, c, PX_E_RANGE, "<box> size must be positive%s%s",
					  NULL, NULL);
		} else if (is_el(c, "cylinder")) {
			s->type = PX_URDF_CYLINDER;
			rc = nums(r, c, "radius", 1, NULL, PX_URDF_MAX_LENGTH, &s->size[0]);
			if (!rc)
				rc = nums(r, c, "length", 1, NULL, PX_URDF_MAX_LENGTH, &s->size[1]);
			if (!rc && (s->size[0] <= 0 || s->size[1] <= 0))
				rc = fail(r, c, PX_E_RANGE,
					  "<cylinder> radius and length must be positive%s%s",
					  NULL, NULL);
		} else if (is_el(c, "sphere")) {
			s->type = PX_URDF_SPHERE;
			rc = nums(r, c, "radius", 1, NULL, PX_URDF_MAX_LENGTH, &s->size[0]);
			if (!rc && s->size[0] <= 0)
				rc = fail(r, c, PX_E_RANGE, "<sphere> radius must be positive%s%s",
					  NULL, NULL);
		} else if (is_el(c, "mesh")) {
			s->type = PX_URDF_MESH;
			rc = nums(r, c, "scale", 3, one, PX_URDF_MAX_LENGTH, s->size);
			if (!rc && (s->size[0] == 0 || s->size[1] == 0 || s->size[2] == 0))
				rc = fail(r, c, PX_E_RANGE, "<mesh> scale must not be zero%s%s",
					  NULL, NULL);
			if (!rc) {
				*mesh_name = attr(c, "filename");
				if (!*mesh_name || !(*mesh_name)[0])
					rc = fail(r, c, PX_E_PARSE,
						  "<mesh> needs a 'filename'%s%s", NULL, NULL);
			}
		} else {
			rc = fail(r, c, PX_E_PARSE,
				  "unknown geometry <%s>%s (box, cylinder, sphere or mesh)",
				  (const char *)c->name, NULL);
		}
		if (rc)
			return rc;
	}
	if (k != 1)
		return fail(r, g, PX_E_PARSE, "<geometry> must hold exactly one shape%s%s",
			    NULL, NULL);
	return PX_OK;
}

static int read_link(struct rd *r, const xmlNode *n, struct px_urdf_link *l)
{
	struct px_urdf *u = r->u;
	const xmlNode *c;
	int rc;
	describe(r, n);
	l->name = attr(n, "name");
	l->line = line_of(n);
	l->parent_joint = -1;
	l->shapes = u->shapes + u->n_shapes;
	if (!l->name || !l->name[0])
		return fail(r, n, PX_E_PARSE, "a <link> needs a 'name'%s%s", NULL, NULL);
	for (c = n->children; c; c = c->next) {
		if (!is_el(c, "collision"))
			continue;
		rc = read_collision(r, c, &u->shapes[u->n_shapes],
				    &u->mesh_names[u->n_shapes]);
		u->n_shapes++;
		l->n_shapes++;
		if (rc)
			return rc;
	}
	return PX_OK;
}

static int read_joint(struct rd *r, const xmlNode *n, struct px_urdf_joint *j,
		      char **parent, char **child_name)
{
	static const double xaxis[3] = {1, 0, 0};
	const xmlNode *c;
	double ax[3], v;
	char *type;
	int rc;
	describe(r, n);
	j->name = attr(n, "name");
	j->line = line_of(n);
	j->parent = j->child = -1;
	if (!j->name || !j->name[0])
		return fail(r, n, PX_E_PARSE, "a <joint> needs a 'name'%s%s", NULL, NULL);
	type = attr(n, "type");
	if (!type)
		return fail(r, n, PX_E_PARSE, "a <joint> needs a 'type'%s%s", NULL, NULL);
	if (!strcmp(type, "fixed"))
		j->type = PX_URDF_FIXED;
	else if (!strcmp(type, "revolute"))
		j->type = PX_URDF_REVOLUTE;
	else if (!strcmp(type, "continuous"))
		j->type = PX_URDF_CONTINUOUS;
	else if (!strcmp(type, "prismatic"))
		j->type = PX_URDF_PRISMATIC;
	else {
		rc = fail(r, n, !strcmp(type, "floating") || !strcmp(type, "planar")
				    ? PX_E_UNSUPPORTED : PX_E_PARSE,
			  "%s joint type '%s' (revolute, continuous, prismatic or fixed)",
			  !strcmp(type, "floating") || !strcmp(type, "planar")
				  ? "unsupported" : "unknown",
			  type);
		free(type);
		return rc;
	}
	free(type);
	c = child(n, "parent");
	*parent = c ? attr(c, "link") : NULL;
	c = child(n, "child");
	*child_name = c ? attr(c, "link") : NULL;
	if (!*parent || !*child_name)
		return fail(r, n, PX_E_PARSE, "a <joint> needs <parent link=...> and "
			    "<child link=...>%s%s", NULL, NULL);
	rc = origin_of(r, n, &j->origin);
	if (rc)
		return rc;
	c = child(n, "axis");
	rc = c ? nums(r, c, "xyz", 3, xaxis, PX_URDF_MAX_LENGTH, ax)
	       : (memcpy(ax, xaxis, sizeof(ax)), PX_OK);
	if (rc)
		return rc;
	v = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
	if (j->type != PX_URDF_FIXED && !(v > 1e-12))
		return fail(r, c ? c : n, PX_E_RANGE, "the joint axis is zero%s%s", NULL, NULL);
	j->axis = v > 1e-12 ? px_v3(ax[0] / v, ax[1] / v, ax[2] / v) : px_v3(1, 0, 0);
	j->lower = -INFINITY;
	j->upper = INFINITY;
	c = child(n, "limit");
	if (c) {
		static const double zero = 0.0;
		j->has_limits = 1;
		if (j->type == PX_URDF_REVOLUTE || j->type == PX_URDF_PRISMATIC) {
			rc = nums(r, c, "lower", 1, &zero, PX_URDF_MAX_LENGTH, &j->lower);
			if (!rc)
				rc = nums(r, c, "upper", 1, &zero, PX_URDF_MAX_LENGTH, &j->upper);
			if (!rc && j->lower > j->upper)
				rc = fail(r, c, PX_E_RANGE, "lower limit above upper limit%s%s",
					  NULL, NULL);
		}
		if (!rc)
			rc = nums(r, c, "velocity", 1, &zero, 1e6, &j->velocity);
		if (!rc)
			rc = nums(r, c, "effort", 1, &zero, 1e9, &j->effort);
		if (!rc && (j->velocity < 0 || j->effort < 0))
			rc = fail(r, c, PX_E_RANGE, "velocity and effort must not be negative%s%s",
				  NULL, NULL);
		if (rc)
			return rc;
	} else if (j->type == PX_URDF_REVOLUTE || j->type == PX_URDF_PRISMATIC) {
		return fail(r, n, PX_E_PARSE, "a revolute or prismatic joint needs "
			    "<limit>%s%s", NULL, NULL);
	}
	return PX_OK;
}

/* Count what the document holds, allocate, read. */
static int read_robot(struct rd *r, const xmlNode *root, char ***parents,
		      char ***children)
{
	struct px_urdf *u = r->u;
	const xmlNode *n, *c;
	int nl = 0, nj = 0, ns = 0, rc;
	for (n = root->children; n; n = n->next) {
		if (is_el(n, "link")) {
			nl++;
			for (c = n->children; c; c = c->next)
				ns += is_el(c, "collision");
		} else if (is_el(n, "joint")) {
			nj++;
		}
	}
	if (nl > PX_URDF_MAX_LINKS || nj > PX_URDF_MAX_LINKS || ns > PX_URDF_MAX_SHAPES)
		return px__urdf_fail(r->err, PX_E_RANGE, u->file, line_of(root), "<robot>",
				     "%d links, %d joints and %d collision shapes: more "
				     "than the limits (%d, %d, %d)", nl, nj, ns,
				     PX_URDF_MAX_LINKS, PX_URDF_MAX_LINKS, PX_URDF_MAX_SHAPES);
	if (nl == 0)
		return px__urdf_fail(r->err, PX_E_PARSE, u->file, line_of(root), "<robot>",
				     "no <link>");
	u->links = calloc((size_t)nl, sizeof(*u->links));
	u->joints = calloc((size_t)nj + 1, sizeof(*u->joints));
	u->shapes = calloc((size_t)ns + 1, sizeof(*u->shapes));
	u->mesh_names = calloc((size_t)ns + 1, sizeof(*u->mesh_names));
	*parents = calloc((size_t)nj + 1, sizeof(char *));
	*children = calloc((size_t)nj + 1, sizeof(char *));
	if (!u->links || !u->joints || !u->shapes || !u->mesh_names || !*parents ||
	    !*children)
		return px__urdf_fail(r->err, PX_E_NOMEM, u->file, 0, "", "out of memory");
	for (n = root->children; n; n = n->next) {
		if (is_el(n, "link"))
			rc = read_link(r, n, &u->links[u->n_links++]);
		else if (is_el(n, "joint")) {
			rc = read_joint(r, n, &u->joints[u->n_joints], &(*parents)[u->n_joints],
					&(*children)[u->n_joints]);
			u->n_joints++;
		} else
			rc = PX_OK;
		if (rc)
			return rc;
	}
	return PX_OK;
}

/* The joints' link names into indices. */
static int link_joints(struct rd *r, char **parents, char **children)
{
	struct px_urdf *u = r->u;
	int i, k;
	for (i = 0; i < u->n_joints; i++) {
		struct px_urdf_joint *j = &u->joints[i];
		snprintf(r->elem, sizeof(r->elem), "<joint name='%.60s'>", j->name);
		for (k = 0; k < u->n_links; k++) {
			if (!strcmp(u->links[k].name, parents[i]))
				j->parent = k;
			if (!strcmp(u->links[k].name, children[i]))
				j->child = k;
		}
		if (j->parent < 0 || j->child < 0)
			return px__urdf_fail(r->err, PX_E_INVAL, u->file, j->line, r->elem,
					     "no link named '%.60s'",
					     j->parent < 0 ? parents[i] : children[i]);
	}
	return PX_OK;
}

static int parse(struct px_urdf *u, const char *xml, size_t len,
		 const struct px_urdf_opts *o, struct px_urdf_error *err)
{
	struct rd r;
	xmlParserCtxtPtr ctx;
	xmlDocPtr doc;
	const xmlNode *root;
	char **parents = NULL, **children = NULL;
	int rc, i;
	memset(&r, 0, sizeof(r));
	r.u = u;
	r.err = err;
	if (len > PX_URDF_MAX_BYTES)
		return px__urdf_fail(err, PX_E_RANGE, u->file, 0, "",
				     "larger than the %zu MiB limit for URDF files",
				     PX_URDF_MAX_BYTES >> 20);
	ctx = xmlNewParserCtxt();
	if (!ctx)
		return px__urdf_fail(err, PX_E_NOMEM, u->file, 0, "", "out of memory");
	/* No network, no entity expansion, no DTD loading: a URDF is plain
	 * elements and attributes. */
	doc = xmlCtxtReadMemory(ctx, xml, (int)len, u->file, NULL,
				XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING);
	if (!doc) {
		const xmlError *e = xmlCtxtGetLastError(ctx);
		char m[200] = "not an XML document";
		long line = 0;
		if (e && e->message) {
			snprintf(m, sizeof(m), "%s", e->message);
			m[strcspn(m, "\n")] = '\0';
			line = e->line;
		}
		xmlFreeParserCtxt(ctx);
		return px__urdf_fail(err, PX_E_PARSE, u->file, line, "", "XML: %s", m);
	}
	root = xmlDocGetRootElement(doc);
	if (!root || !is_el(root, "robot")) {
		rc = px__urdf_fail(err, PX_E_PARSE, u->file, root ? line_of(root) : 0,
				   root ? (const char *)root->name : "",
				   "the document is not a <robot>");
	} else {
		u->name = attr(root, "name");
		if (!u->name)
			u->name = px__urdf_strdup("");
		rc = read_robot(&r, root, &parents, &children);
		if (rc == PX_OK)
			rc = link_joints(&r, parents, children);
	}
	for (i = 0; parents && i <= u->n_joints; i++)
		free(parents[i]);
	for (i = 0; children && i <= u->n_joints; i++)
		free(children[i]);
	free(parents);
	free(children);
	xmlFreeDoc(doc);
	xmlFreeParserCtxt(ctx);
	if (rc == PX_OK)
		rc = px__urdf_finish(u, o, err);
	return rc;
}

int px_urdf_load_mem(const char *name, const char *xml, size_t len,
		     const struct px_urdf_opts *opts, struct px_urdf **out,
		     struct px_urdf_error *err)
{
	struct px_urdf *u;
	int rc;
	if (err)
		memset(err, 0, sizeof(*err));
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!name || !xml)
		return px__urdf_fail(err, PX_E_INVAL, name ? name : "", 0, "", "no data");
	u = px__urdf_new(name, 0);
	if (!u)
		return px__urdf_fail(err, PX_E_NOMEM, name, 0, "", "out of memory");
	rc = parse(u, xml, len, opts, err);
	if (rc) {
		px_urdf_free(u);
		return rc;
	}
	*out = u;
	return PX_OK;
}

int px_urdf_load(const char *path, const struct px_urdf_opts *opts,
		 struct px_urdf **out, struct px_urdf_error *err)
{
	struct px_urdf *u;
	char *data = NULL, msg[300];
	size_t len = 0;
	int rc;
	if (err)
		memset(err, 0, sizeof(*err));
	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!path)
		return px__urdf_fail(err, PX_E_INVAL, "", 0, "", "no file name");
	rc = px_file_read(path, PX_URDF_MAX_BYTES, PX_FILE_TEXT, "URDF", &data, &len, msg,
			  sizeof(msg));
	if (rc) {
		if (err) {
			err->code = rc;
			snprintf(err->file, sizeof(err->file), "%s", path);
			snprintf(err->msg, sizeof(err->msg), "%s", msg);
		}
		return rc;
	}
	u = px__urdf_new(path, 1);
	if (!u) {
		free(data);
		return px__urdf_fail(err, PX_E_NOMEM, path, 0, "", "out of memory");
	}
	rc = parse(u, data, len, opts, err);
	free(data);
	if (rc) {
		px_urdf_free(u);
		return rc;
	}
	*out = u;
	return PX_OK;
}
