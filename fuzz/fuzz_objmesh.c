/*
 * libFuzzer target: OBJ polygon meshes read as mesh models through
 * px_model_load() (the importer path; fuzz_obj covers the free-form
 * loader px_obj, which also reads faces).
 * Invariants: load or fail with a message naming the file; a loaded mesh
 * answers queries equal to a brute-force scan of its triangles.
 */
#include "fuzz_model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	return fzm_load_check(fz_file(".obj", data, size), 0.0);
}
