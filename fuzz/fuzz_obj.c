/*
 * libFuzzer target for the Wavefront OBJ loader: any input must either
 * load into a model whose entities evaluate, or fail with a placed error;
 * never crash, leak, or read out of bounds. Built and run by `make fuzz`.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "px_nurbs.h"
#include "px_obj.h"

static void exercise(const struct px_obj_model *m)
{
	int i;
	for (i = 0; i < m->n_entities; i++) {
		const struct px_obj_entity *e = &m->entities[i];
		double *work;
		size_t len;
		px_aabb box;
		if (e->kind == PX_OBJ_CURVE) {
			const struct px_nurbs_curve *c = &e->curve;
			double u0, u1;
			px_vec3 d[4];
			px_nurbs_curve_domain(c, &u0, &u1);
			if (px_nurbs_curve_eval(c, u0, 3, d) ||
			    px_nurbs_curve_eval(c, u1, 3, d) ||
			    px_nurbs_curve_eval(c, 0.5 * (u0 + u1), 3, d))
				abort();
			len = PX_NURBS_CURVE_WORK_LEN(c->degree, c->n_ctrl);
			work = malloc(len * sizeof(double));
			if (work && u0 < 0.5 * (u0 + u1) &&
			    px_nurbs_curve_sub_aabb(c, u0, 0.5 * (u0 + u1), work,
						    len, &box))
				abort();
			free(work);
		} else if (e->kind == PX_OBJ_SURF) {
			const struct px_nurbs_surf *s = &e->surf;
			struct px_nurbs_surf_derivs d;
			double u0, u1, v0, v1, um, vm;
			px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
			um = 0.5 * (u0 + u1);
			vm = 0.5 * (v0 + v1);
			if (px_nurbs_surf_eval(s, u0, v1, 3, &d) ||
			    px_nurbs_surf_eval(s, um, vm, 2, &d))
				abort();
			len = PX_NURBS_SURF_WORK_LEN(s->degree[0], s->degree[1],
						     s->n_ctrl[0], s->n_ctrl[1]);
			work = malloc(len * sizeof(double));
			if (work && u0 < um && v0 < vm &&
			    px_nurbs_surf_sub_aabb(s, u0, um, v0, vm, work, len,
						   &box))
				abort();
			free(work);
		} else {
			abort();
		}
	}
	for (i = 0; i < 3 * m->n_triangles; i++)
		if (m->triangles[i] < 0 || m->triangles[i] >= m->n_vertices)
			abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	struct px_obj_model *m = NULL;
	struct px_obj_error e;
	int rc = px_obj_load_mem("fuzz.obj", (const char *)data, size, &m, &e);
	if (rc == PX_OK) {
		if (!m)
			abort();
		exercise(m);
		px_obj_free(m);
	} else {
		if (m || e.code != rc || e.line < 0 || e.column < 0 ||
		    (rc != PX_E_PARSE && rc != PX_E_UNSUPPORTED &&
		     rc != PX_E_NOMEM))
			abort();
	}
	return 0;
}
