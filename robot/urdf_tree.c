/*
 * urdf_tree.c - a read URDF's checks (names, references, one root, no
 * cycle, mesh files found) and its accessors; no XML here.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "robot_internal.h"

int px__urdf_fail(struct px_urdf_error *err, int code, const char *file,
		  long line, const char *element, const char *fmt, ...)
{
	char what[384];
	va_list ap;
	if (!err)
		return code;
	va_start(ap, fmt);
	vsnprintf(what, sizeof(what), fmt, ap);
	va_end(ap);
	err->code = code;
	snprintf(err->file, sizeof(err->file), "%s", file ? file : "");
	err->line = line;
	snprintf(err->element, sizeof(err->element), "%s", element ? element : "");
	if (line > 0 && element && element[0])
		snprintf(err->msg, sizeof(err->msg), "%.160s:%ld: %.100s: %.220s",
			 err->file, line, element, what);
	else if (line > 0)
		snprintf(err->msg, sizeof(err->msg), "%.160s:%ld: %.320s", err->file,
			 line, what);
	else if (err->file[0])
		snprintf(err->msg, sizeof(err->msg), "%.160s: %.340s", err->file, what);
	else
		snprintf(err->msg, sizeof(err->msg), "%.380s", what);
	return code;
}

char *px__urdf_strdup(const char *s)
{
	size_t n = strlen(s) + 1;
	char *d = malloc(n);
	if (d)
		memcpy(d, s, n);
	return d;
}

struct px_urdf *px__urdf_new(const char *file, int with_dir)
{
	struct px_urdf *u = calloc(1, sizeof(*u));
	const char *slash;
	if (!u)
		return NULL;
	u->file = px__urdf_strdup(file);
	slash = with_dir ? strrchr(file, '/') : NULL;
	u->dir = slash ? malloc((size_t)(slash - file) + 2) : px__urdf_strdup("");
	if (u->dir && slash) {
		memcpy(u->dir, file, (size_t)(slash - file) + 1);
		u->dir[slash - file + 1] = '\0';
	}
	u->root = -1;
	if (!u->file || !u->dir) {
		px_urdf_free(u);
		return NULL;
	}
	return u;
}

void px_urdf_free(struct px_urdf *u)
{
	int i;
	if (!u)
		return;
	for (i = 0; u->links && i < u->n_links; i++)
		free((char *)u->links[i].name);
	for (i = 0; u->joints && i < u->n_joints; i++)
		free((char *)u->joints[i].name);
	for (i = 0; u->shapes && i < u->n_shapes; i++)
		free((char *)u->shapes[i].mesh);
	for (i = 0; u->mesh_names && i < u->n_shapes; i++)
		free(u->mesh_names[i]);
	free(u->links);
	free(u->joints);
	free(u->shapes);
	free(u->mesh_names);
	free(u->name);
	free(u->file);
	free(u->dir);
	free(u);
}

static int is_file(const char *p)
{
	struct stat st;
	return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* The file a <mesh filename> names, or NULL (tried says what was). */
static char *resolve(const struct px_urdf *u, const struct px_urdf_opts *o,
		     const char *name, char *tried, size_t cap)
{
	char buf[4096];
	int i;
	tried[0] = '\0';
	if (!strncmp(name, "package://", 10)) {
		const char *rest = name + 10;
		int n = o ? o->n_package_paths : 0;
		if (n > PX_URDF_MAX_PACKAGE_PATHS)
			n = PX_URDF_MAX_PACKAGE_PATHS;
		if (n == 0)
			snprintf(tried, cap, "no package path is configured");
		for (i = 0; i < n; i++) {
			if (!o->package_paths[i])
				continue;
			snprintf(buf, sizeof(buf), "%s/%s", o->package_paths[i], rest);
			if (i == 0)
				snprintf(tried, cap, "tried %.500s", buf);
			else if (strlen(tried) + strlen(buf) + 8 < cap)
				strcat(strcat(tried, ", "), buf);
			if (is_file(buf))
				return px__urdf_strdup(buf);
		}
		return NULL;
	}
	if (!strncmp(name, "file://", 7))
		name += 7;
	if (name[0] == '/')
		snprintf(buf, sizeof(buf), "%s", name);
	else
		snprintf(buf, sizeof(buf), "%s%s", u->dir, name);
	snprintf(tried, cap, "tried %.500s", buf);
	return is_file(buf) ? px__urdf_strdup(buf) : NULL;
}

static int check_names(struct px_urdf *u, struct px_urdf_error *err)
{
	char el[128];
	int i, k;
	for (i = 0; i < u->n_links; i++)
		for (k = 0; k < i; k++)
			if (!strcmp(u->links[i].name, u->links[k].name)) {
				snprintf(el, sizeof(el), "<link name='%.60s'>", u->links[i].name);
				return px__urdf_fail(err, PX_E_INVAL, u->file, u->links[i].line, el,
						     "a second link of this name (the first is "
						     "on line %ld)", u->links[k].line);
			}
	for (i = 0; i < u->n_joints; i++)
		for (k = 0; k < i; k++)
			if (!strcmp(u->joints[i].name, u->joints[k].name)) {
				snprintf(el, sizeof(el), "<joint name='%.60s'>", u->joints[i].name);
				return px__urdf_fail(err, PX_E_INVAL, u->file, u->joints[i].line, el,
						     "a second joint of this name (the first is "
						     "on line %ld)", u->joints[k].line);
			}
	return PX_OK;
}

/* Parents, one root, no cycle. */
static int check_tree(struct px_urdf *u, struct px_urdf_error *err)
{
	char el[128];
	int i, k;
	for (i = 0; i < u->n_joints; i++) {
		struct px_urdf_joint *j = &u->joints[i];
		struct px_urdf_link *c = &u->links[j->child];
		snprintf(el, sizeof(el), "<joint name='%.60s'>", j->name);
		if (j->parent == j->child)
			return px__urdf_fail(err, PX_E_INVAL, u->file, j->line, el,
					     "joins link '%.60s' to itself", c->name);
		if (c->parent_joint >= 0)
			return px__urdf_fail(err, PX_E_INVAL, u->file, j->line, el,
					     "link '%.60s' already has a parent (joint '%.60s')",
					     c->name, u->joints[c->parent_joint].name);
		c->parent_joint = i;
	}
	for (i = 0; i < u->n_links; i++) {
		if (u->links[i].parent_joint >= 0)
			continue;
		if (u->root >= 0) {
			snprintf(el, sizeof(el), "<link name='%.60s'>", u->links[i].name);
			return px__urdf_fail(err, PX_E_INVAL, u->file, u->links[i].line, el,
					     "a second root (no joint leads to it; the first "
					     "root is '%.60s'): the links are not one tree",
					     u->links[u->root].name);
		}
		u->root = i;
	}
	if (u->root < 0)
		return px__urdf_fail(err, PX_E_INVAL, u->file, 0, "<robot>",
				     "no root link: the joints form a cycle");
	/* every link reaches the root within n_links steps */
	for (i = 0; i < u->n_links; i++) {
		int l = i;
		for (k = 0; k <= u->n_links && u->links[l].parent_joint >= 0; k++)
			l = u->joints[u->links[l].parent_joint].parent;
		if (l != u->root) {
			snprintf(el, sizeof(el), "<link name='%.60s'>", u->links[i].name);
			return px__urdf_fail(err, PX_E_INVAL, u->file, u->links[i].line, el,
					     "its joints form a cycle");
		}
	}
	return PX_OK;
}

int px__urdf_finish(struct px_urdf *u, const struct px_urdf_opts *o,
		    struct px_urdf_error *err)
{
	int rc = check_names(u, err), i, l;
	if (rc == PX_OK)
		rc = check_tree(u, err);
	for (l = 0; rc == PX_OK && l < u->n_links; l++)
		for (i = 0; i < u->links[l].n_shapes; i++) {
			struct px_urdf_shape *s = (struct px_urdf_shape *)&u->links[l].shapes[i];
			size_t k = (size_t)(s - u->shapes);
			char tried[600], el[128];
			if (s->type != PX_URDF_MESH)
				continue;
			if (o && o->skip_mesh_check) {
				s->mesh = px__urdf_strdup(u->mesh_names[k]);
				continue;
			}
			s->mesh = resolve(u, o, u->mesh_names[k], tried, sizeof(tried));
			if (!s->mesh) {
				snprintf(el, sizeof(el), "<link name='%.60s'>", u->links[l].name);
				rc = px__urdf_fail(err, PX_E_NOTFOUND, u->file, s->line, el,
						   "mesh '%.200s' not found (%s)",
						   u->mesh_names[k], tried);
			}
		}
	return rc;
}

const char *px_urdf_name(const struct px_urdf *u)
{
	return u && u->name ? u->name : "";
}

int px_urdf_link_count(const struct px_urdf *u)
{
	return u ? u->n_links : 0;
}

const struct px_urdf_link *px_urdf_link(const struct px_urdf *u, int i)
{
	return u && i >= 0 && i < u->n_links ? &u->links[i] : NULL;
}

int px_urdf_find_link(const struct px_urdf *u, const char *name)
{
	int i;
	for (i = 0; u && name && i < u->n_links; i++)
		if (!strcmp(u->links[i].name, name))
			return i;
	return -1;
}

int px_urdf_joint_count(const struct px_urdf *u)
{
	return u ? u->n_joints : 0;
}

const struct px_urdf_joint *px_urdf_joint(const struct px_urdf *u, int i)
{
	return u && i >= 0 && i < u->n_joints ? &u->joints[i] : NULL;
}

int px_urdf_find_joint(const struct px_urdf *u, const char *name)
{
	int i;
	for (i = 0; u && name && i < u->n_joints; i++)
		if (!strcmp(u->joints[i].name, name))
			return i;
	return -1;
}

int px_urdf_root(const struct px_urdf *u)
{
	return u ? u->root : -1;
}
