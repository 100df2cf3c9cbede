/*
 * libFuzzer target: XYZ / CSV point clouds (text, one point per line)
 * through px_model_load(); the first byte picks the name (.xyz, .csv,
 * .txt, .pts) and a ball radius, the rest is the file.
 * Invariants: load or fail with "file:line[:column]: what" (the line
 * inside the file); a loaded cloud answers queries equal to a
 * brute-force scan of its points (see fuzz_model.h).
 */
#include "fuzz_model.h"

#include "px_load.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static const char *const ext[] = {".xyz", ".csv", ".txt", ".pts"};
	struct px_model *m = NULL;
	char msg[512];
	unsigned sel = size ? data[0] : 0;
	const char *path;
	int rc;
	if (size)
		data++, size--;
	path = fz_file(ext[sel & 3], data, size);
	rc = px_model_load(path, sel & 4 ? 0.05 : 0.0, &m, msg, sizeof msg);
	if (rc == PX_OK) {
		if (!m || px_model_kind(m) != PX_MODEL_CLOUD)
			abort();
		fzm_check(m);
		px_model_free(m);
		return 0;
	}
	if (m)
		abort();
	if (rc != PX_E_PARSE && rc != PX_E_NAN && rc != PX_E_RANGE &&
	    rc != PX_E_NOMEM)
		abort();
	fz_check_msg(msg, sizeof msg);
	if (!strstr(msg, path))
		abort();
	return 0;
}
