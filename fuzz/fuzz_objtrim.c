/*
 * libFuzzer target for the trimmed OBJ reader: px_obj_load_mem() with
 * curv2, trim, hole, scrv and sp, then px_brep_from_obj() (composed
 * and curve-on-surface edges, several trim loops per surface, trimmed
 * domains) and queries on the B-rep model. Any input
 * must load and answer finite distances whose closest point lies at
 * that distance, or fail with a placed message and one of the
 * documented codes; never crash, leak, hang or read out of bounds.
 * Built and run by `make fuzz`.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "px_brep_obj.h"
#include "px_model.h"

static int brep_code(int rc)
{
	return rc == PX_E_INVAL || rc == PX_E_RANGE || rc == PX_E_NAN ||
	       rc == PX_E_DEGENERATE || rc == PX_E_NOCONV || rc == PX_E_NOMEM ||
	       rc == PX_E_NOSPC || rc == PX_E_UNSUPPORTED;
}

static void exercise(struct px_model *m)
{
	px_aabb b = px_model_local_aabb(m);
	px_vec3 c = px_v3_scale(px_v3_add(b.min, b.max), 0.5);
	px_vec3 e = px_v3_sub(b.max, b.min);
	double ext = px_v3_norm(e);
	int k;
	if (!isfinite(ext))
		return;
	for (k = 0; k < 6; k++) {
		struct px_model_result r;
		px_vec3 p = px_v3(c.x + (k & 1 ? 0.7 : -0.6) * e.x * (k > 0),
				  c.y + (k & 2 ? 0.65 : -0.55) * e.y * (k > 0),
				  c.z + (k & 4 ? 0.8 : -0.75) * e.z * (k > 0) + 0.1 * ext);
		int rc = px_model_query(m, p, &r);
		if (rc == PX_E_RANGE && ext > 1e150)
			continue;
		if (rc != 1 || !isfinite(r.distance) || !isfinite(r.point.x) ||
		    !isfinite(r.point.y) || !isfinite(r.point.z))
			abort();
		if (!(fabs(px_v3_dist(p, r.point) - fabs(r.distance)) <=
		      1e-9 * (ext + px_v3_norm(p)) + 1e-300))
			abort();
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct px_obj_model *om = NULL;
	struct px_brep *b = NULL;
	struct px_model *m = NULL;
	struct px_obj_error e;
	int rc = px_obj_load_mem("fuzz.obj", (const char *)data, size, &om, &e);

	if (rc != PX_OK) {
		if (om || e.code != rc || e.line < 0 || e.column < 0 ||
		    (rc != PX_E_PARSE && rc != PX_E_UNSUPPORTED && rc != PX_E_NOMEM))
			abort();
		return 0;
	}
	if (!om)
		abort();
	if (px_obj_trimmed(om)) {
		memset(&e, 0, sizeof(e));
		rc = px_brep_from_obj(om, 1.0, &b, &e);
		if (rc != PX_OK) {
			if (b || e.code != rc || !brep_code(rc) || e.line < 0)
				abort();
			fz_check_msg(e.msg, sizeof(e.msg));
		} else {
			if (!b)
				abort();
			if (px_model_from_brep(b, &m) != PX_OK || !m)
				abort();
			exercise(m);
			px_model_free(m);
		}
	}
	px_obj_free(om);
	return 0;
}
