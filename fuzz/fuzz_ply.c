/*
 * libFuzzer target: PLY files (ASCII and binary, meshes and vertex-only
 * clouds) through px_model_load(), which checks the body against the
 * header before the importer reads it and falls back from mesh to cloud.
 * Invariants: load or fail with a message naming the file; a loaded
 * mesh or cloud answers queries equal to a brute-force scan (see
 * fuzz_model.h); nothing crashes, leaks, hangs or reads out of bounds.
 */
#include "fuzz_model.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	return fzm_load_check(fz_file(".ply", data, size),
			      size & 1 ? 0.0 : 0.01);
}
