/*
 * px_model_load: the right representation for each kind of file, and
 * messages that name the file.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "px_cloud.h"
#include "px_load.h"
#include "px_mesh.h"
#include "px_test.h"

static char dir[64];

static const char *path(const char *name)
{
	static char buf[4][160];
	static int k;
	k = (k + 1) % 4;
	snprintf(buf[k], sizeof(buf[k]), "%s/%s", dir, name);
	return buf[k];
}

static void put(const char *name, const char *text)
{
	FILE *f = fopen(path(name), "w");
	PX_CHECK(f != NULL);
	fputs(text, f);
	fclose(f);
}

static void test_kinds(void)
{
	PX_NEEDS(ASSIMP);
	/* a closed tetrahedron as ASCII STL (outward faces) */
	static const char *tet =
		"solid t\n"
		"facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
		"facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
		"facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
		"facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
		"endsolid t\n";
	static const char *tri =
		"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
		"endloop\nendfacet\nendsolid t\n";
	const char *names[] = {"tet.stl", "tri.stl", "pts.ply", "pts.xyz", "bad.stl"};
	struct px_model *m;
	struct px_model_result r;
	char msg[256];
	size_t k;

	snprintf(dir, sizeof(dir), "/tmp/px_load_XXXXXX");
	PX_CHECK(mkdtemp(dir) != NULL);
	put("tet.stl", tet);
	put("tri.stl", tri);
	put("pts.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
		       "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n");
	put("pts.xyz", "0 0 0\n1 0 0\n");
	put("bad.stl", "not a mesh at all\n");

	PX_CHECK_INT_EQ(px_model_load(path("tet.stl"), 0, &m, msg, sizeof(msg)), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_MESH);
	PX_CHECK(px_mesh_is_closed(m));
	PX_CHECK_MSG(msg[0] == '\0', "%s", msg);
	px_model_query(m, px_v3(0.1, 0.1, 0.1), &r);
	PX_CHECK(r.inside && r.distance < 0);
	px_model_free(m);

	PX_CHECK_INT_EQ(px_model_load(path("tri.stl"), 0, &m, msg, sizeof(msg)), PX_OK);
	PX_CHECK(!px_mesh_is_closed(m));
	PX_CHECK_MSG(strstr(msg, "tri.stl") && strstr(msg, "unsigned"), "%s", msg);
	px_model_free(m);

	PX_CHECK_INT_EQ(px_model_load(path("pts.ply"), 0.1, &m, msg, sizeof(msg)), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_CLOUD);
	PX_CHECK_INT_EQ(px_cloud_point_count(m), 2);
	PX_CHECK(px_cloud_radius(m) == 0.1);
	px_model_free(m);

	PX_CHECK_INT_EQ(px_model_load(path("pts.xyz"), 0, &m, msg, sizeof(msg)), PX_OK);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_CLOUD);
	px_model_query(m, px_v3(1, 1, 0), &r);
	PX_CHECK_INT_EQ(r.index, 1);
	PX_CHECK(r.distance == 1.0);
	px_model_free(m);

	PX_CHECK_INT_EQ(px_model_load(path("bad.stl"), 0, &m, msg, sizeof(msg)), PX_E_PARSE);
	PX_CHECK_MSG(strstr(msg, "bad.stl") != NULL, "%s", msg);
	PX_CHECK_INT_EQ(px_model_load(path("none.stl"), 0, &m, msg, sizeof(msg)), PX_E_NOTFOUND);
	PX_CHECK_MSG(strstr(msg, "none.stl") != NULL, "%s", msg);
	PX_CHECK_INT_EQ(px_model_load(path("none.xyz"), 0, &m, msg, sizeof(msg)), PX_E_NOTFOUND);
	PX_CHECK_INT_EQ(px_model_load(NULL, 0, &m, msg, sizeof(msg)), PX_E_INVAL);
	for (k = 0; k < sizeof(names) / sizeof(names[0]); k++)
		unlink(path(names[k]));
	rmdir(dir);
}

static const struct px_test tests[] = {PX_T(test_kinds)};
PX_TEST_MAIN(tests)
