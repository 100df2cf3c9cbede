/*
 * libFuzzer target: OBJ polygon meshes read as mesh models through
 * px_model_load() (the importer path; fuzz_obj covers the free-form
 * loader px_obj, which also reads faces).
 * Invariants: load or fail with a message naming the file; a loaded mesh
 * answers queries equal to a brute-force scan of its triangles.
 */
#include "fuzz_model.h"

#include "px_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct px_model *m = NULL;
	char msg[512];
	const char *path = fz_file(".obj", data, size);
	int rc = px_model_load(path, 0.0, &m, msg, sizeof msg);
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
