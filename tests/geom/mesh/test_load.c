/*
 * px_model_load: the right representation for each kind of file, and
 * messages that name the file. CAD parts: the shipped STEP block as one
 * signed B-rep in metres, its scale, refusals naming the file, and the
 * build without OpenCASCADE saying so.
 */
#include <math.h>
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

static void test_cad_names(void)
{
	PX_CHECK(px_model_is_cad_name("part.step"));
	PX_CHECK(px_model_is_cad_name("dir.x/PART.STP"));
	PX_CHECK(px_model_is_cad_name("a.iges"));
	PX_CHECK(px_model_is_cad_name("a.IGS"));
	PX_CHECK(!px_model_is_cad_name("a.stl"));
	PX_CHECK(!px_model_is_cad_name("step"));
	PX_CHECK(!px_model_is_cad_name(NULL));
}

/* The shipped block: 60 x 40 x 20 mm from the origin, filleted (r 3), a
 * 12 mm hole along z through (30, 20) mm; written in millimetres. */
static void test_cad_parts(void)
{
	struct px_model *m = NULL;
	struct px_model_result r;
	char block[512], msg[512], bad[64];
	FILE *f;

	px_test_data_path(block, sizeof(block), "../../config/examples/parts/filleted_block.step");
	if (!PX_HAVE_OCCT) {
		PX_CHECK_INT_EQ(px_model_load(block, 0, &m, msg, sizeof(msg)), PX_E_UNSUPPORTED);
		PX_CHECK(m == NULL);
		PX_CHECK_MSG(strstr(msg, "filleted_block.step") &&
			     strstr(msg, "built without OpenCASCADE"), "%s", msg);
	}
	PX_NEEDS(OCCT);
	PX_CHECK_MSG(px_model_load(block, 0, &m, msg, sizeof(msg)) == PX_OK, "%s", msg);
	PX_CHECK_MSG(msg[0] == '\0', "%s", msg);
	PX_CHECK_INT_EQ(px_model_kind(m), PX_MODEL_BREP);
	PX_CHECK(px_model_caps(m) & PX_MODEL_CAP_SIGNED);
	/* metres: 10 mm inside the bottom face, then 6 mm from the hole's
	 * wall on its axis (outside) */
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.01, 0.02, 0.01), &r), 1);
	PX_CHECK_MSG(r.is_signed && fabs(r.distance + 0.01) < 1e-12, "%.17g", r.distance);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.03, 0.02, 0.01), &r), 1);
	PX_CHECK_MSG(fabs(r.distance - 0.006) < 1e-12, "%.17g", r.distance);
	px_model_free(m);

	PX_CHECK_MSG(px_model_load_cad(block, 2.0, &m, msg, sizeof(msg)) == PX_OK, "%s", msg);
	PX_CHECK_INT_EQ(px_model_query(m, px_v3(0.02, 0.04, 0.02), &r), 1);
	PX_CHECK_MSG(fabs(r.distance + 0.02) < 1e-12, "%.17g", r.distance);
	px_model_free(m);
	PX_CHECK_INT_EQ(px_model_load_cad(block, 0.0, &m, msg, sizeof(msg)), PX_E_INVAL);
	PX_CHECK_INT_EQ(px_model_load_cad(block, NAN, &m, msg, sizeof(msg)), PX_E_INVAL);

	PX_CHECK_INT_EQ(px_model_load("/nonexistent/part.stp", 0, &m, msg, sizeof(msg)),
			PX_E_NOTFOUND);
	PX_CHECK_MSG(strstr(msg, "part.stp") != NULL, "%s", msg);
	snprintf(bad, sizeof(bad), "/tmp/px_load_cad_%d.step", (int)getpid());
	f = fopen(bad, "w");
	PX_CHECK(f != NULL);
	fputs("this is no STEP file\n", f);
	fclose(f);
	PX_CHECK(px_model_load(bad, 0, &m, msg, sizeof(msg)) < 0);
	PX_CHECK(m == NULL);
	PX_CHECK_MSG(strstr(msg, bad) != NULL, "%s", msg);
	unlink(bad);
}

static const struct px_test tests[] = {PX_T(test_kinds), PX_T(test_cad_names),
				       PX_T(test_cad_parts)};
PX_TEST_MAIN(tests)
