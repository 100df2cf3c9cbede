/*
 * libFuzzer target: STL meshes (ASCII and binary) through px_mesh_load()
 * (the importer, then validation, welding, topology and the hierarchy).
 * Invariants: a file either loads or fails with PX_E_PARSE / PX_E_NAN /
 * PX_E_RANGE / PX_E_INVAL and a message naming the file; a loaded mesh
 * answers queries equal to a brute-force scan of its triangles (see
 * fuzz_model.h); nothing crashes, leaks or reads out of bounds.
 */
#include "fuzz_model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct px_mesh_report rep;
	struct px_model *m = NULL;
	const char *path = fz_file(".stl", data, size);
	int rc = px_mesh_load(path, NULL, &rep, &m);
	if (rc == PX_OK && (!m || rep.n_triangles == 0 ||
			    px_mesh_triangle_count(m) != rep.n_triangles))
		abort();
	return fzm_outcome(rc, m, rep.message, sizeof rep.message, path);
}
