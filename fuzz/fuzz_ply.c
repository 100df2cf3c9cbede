/*
 * libFuzzer target: PLY files (ASCII and binary, meshes and vertex-only
 * clouds) through px_model_load(), which checks the body against the
 * header before the importer reads it and falls back from mesh to cloud.
 * Invariants: load or fail with a message naming the file; a loaded
 * mesh or cloud answers queries equal to a brute-force scan (see
 * fuzz_model.h); nothing crashes, leaks, hangs or reads out of bounds.
 */
#include "fuzz_model.h"

#include "px_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct px_model *m = NULL;
	char msg[512];
	const char *path = fz_file(".ply", data, size);
	int rc = px_model_load(path, size & 1 ? 0.0 : 0.01, &m, msg, sizeof msg);
	if (rc == PX_OK) {
		if (!m)
			abort();
		fzm_check(m);
		px_model_free(m);
		return 0;
	}
	if (m)
		abort();
	if (rc != PX_E_PARSE && rc != PX_E_NAN && rc != PX_E_RANGE &&
	    rc != PX_E_INVAL && rc != PX_E_OVERFLOW)
		abort();
	fz_check_msg(msg, sizeof msg);
	if (!strstr(msg, path))
		abort();
	return 0;
}
