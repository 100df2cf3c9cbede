/*
 * px_obj.h - Wavefront OBJ loader for free-form geometry (rational
 * B-spline curves and surfaces) and polygon faces.
 *
 * What is read:
 *  - "v x y z [w]": vertices; w is the weight of a rational control
 *    point (default 1). "v x y z r g b" (vertex colours, a common
 *    extension) is accepted and the colours are ignored.
 *  - "cstype [rat] bspline", "deg degu [degv]", "curv u0 u1 v1 v2 ...",
 *    "surf s0 s1 t0 t1 v1 v2 ...", "parm u ...", "parm v ...", "end".
 *    Surface control points are listed with u varying fastest (the
 *    order of the OBJ specification, and of px_nurbs_surf). Control
 *    point counts follow from the knot counts: n = knots - degree - 1.
 *    For a non-rational cstype the weights of the vertices are ignored
 *    (the specification's 3D control points). The entity is the curve or
 *    surface restricted to the statement's parameter range
 *    (u0 u1 [v0 v1]); when that range is narrower than the knot domain
 *    the loader extracts the sub-curve / sub-patch, so the entity's own
 *    domain is always exactly the declared range.
 *  - "f v1 v2 v3 ..." (v, v/vt, v//vn, v/vt/vn forms): polygons, split
 *    into triangles as a fan from the first vertex and stored as 0-based
 *    vertex indices, for the mesh module.
 *  - Negative (relative) vertex indices everywhere; a vertex must be
 *    defined before it is used.
 *  - Comments (#), blank lines, CRLF line ends, continuation lines (a
 *    backslash at the end of a line joins the next one).
 *  - Trimming: "vp u [v [w]]" parameter vertices (v 0, w 1 when left
 *    out); "curv2 vp1 vp2 ..." with the current cstype and deg, its
 *    "parm u" and "end" (a 2D curve (u, v, 0) over the whole knot domain,
 *    w its weight when rational; in px_obj_model.curv2, not among the
 *    entities); inside a surf body "trim u0 u1 c ..." (outer loops, each
 *    bounding one region of the surface) and "hole u0 u1 c ..." (holes):
 *    loops of curv2 curves c (1-based or negative, defined before) on [u0, u1]
 *    within their domains, in px_obj_model.loops and trim_curves (the
 *    B-rep is built by px_brep_obj.h). "scrv" (same form) and "sp vp ..."
 *    (in a curve or surface body) are checked (references, ranges) and
 *    not kept: they only guide tessellation.
 *  - Accepted and ignored because they do not change the geometry:
 *    vt, vn, g, o, s, mg, usemtl, mtllib, maplib, usemap, bevel,
 *    c_interp, d_interp, lod, shadow_obj, trace_obj, ctech, stech.
 *
 * Rejected with an error that names the file, line and column:
 * malformed statements (PX_E_PARSE) and valid OBJ this loader does not
 * handle (PX_E_UNSUPPORTED): Bezier, Cardinal, Taylor and basis-matrix
 * types, bmat, step, con, points (p) and lines (l), the superseded 2.11
 * patch statements, trim, hole and
 * scrv outside a surf body, sp outside a body, curv2 before any cstype;
 * unknown statements.
 * NURBS data errors (knot order, multiplicity, weights...) come from
 * px_nurbs validation and are reported at the statement that holds the
 * offending value, with the NURBS detail in px_obj_error.nurbs.
 *
 * Memory: loading is setup-time and allocates. The model owns all of its
 * memory (entity table, one arena holding every curve and surface,
 * vertex and triangle arrays) and is released by px_obj_free(). Nothing
 * here is RT-safe, but the curves and surfaces it returns are evaluated
 * with the RT-safe px_nurbs functions.
 */
#ifndef PX_OBJ_H
#define PX_OBJ_H

#include <stddef.h>

#include "px_arena.h"
#include "px_base.h"
#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

enum px_obj_kind { PX_OBJ_CURVE = 1, PX_OBJ_SURF = 2, PX_OBJ_CURVE2 = 3 };

/* One free-form entity of the file. */
struct px_obj_entity {
	enum px_obj_kind kind;
	int line;                    /* line of its curv/surf statement */
	int rational;                /* cstype was "rat bspline" */
	double range[4];             /* declared u0 u1 (v0 v1) */
	struct px_nurbs_curve curve; /* kind == PX_OBJ_CURVE */
	struct px_nurbs_surf surf;   /* kind == PX_OBJ_SURF */
	char name[64];               /* name of the last "o" or "g", or "" */
};

/* One curve of a trimming loop: curv2 number curv2 (0-based index into
 * px_obj_model.curv2) on its parameters t0..t1 (t0 > t1: run from t0
 * down to t1), as the trim or hole statement gives it. */
struct px_obj_trim_curve {
	int curv2;
	double t0, t1;
};

/* A trim (hole == 0, the outer loop) or hole statement of the surface
 * entities[entity]: its curves trim_curves[first .. first + n - 1] in
 * order, and the statement's place. */
struct px_obj_loop {
	int entity;
	int hole;
	int line, column;
	int first, n;
};

/* A loaded file. Read-only for the caller. */
struct px_obj_model {
	int n_entities;
	struct px_obj_entity *entities; /* curves and surfaces (no curv2) */
	int n_curv2;
	struct px_obj_entity *curv2;    /* kind PX_OBJ_CURVE2: (u, v, 0) curves */
	int n_loops;
	struct px_obj_loop *loops;      /* in file order */
	int n_trim_curves;
	struct px_obj_trim_curve *trim_curves;
	int n_vertices;     /* every "v" of the file */
	double *vertices;   /* 3 * n_vertices (x, y, z) */
	int n_triangles;    /* from the "f" statements */
	int *triangles;     /* 3 * n_triangles 0-based vertex indices */
	size_t memory_bytes; /* heap bytes held by the model */
	struct px_arena arena_; /* private: holds the NURBS data */
};

/* Where and why loading failed. msg is the message without the place;
 * print as "%s:%d:%d: %s" with file, line, column, msg. line/column are
 * 1-based, 0 when the error has no place (I/O, memory). */
struct px_obj_error {
	int code;
	int line;
	int column;
	char file[256];
	char msg[256];
	struct px_nurbs_error nurbs; /* detail of NURBS data errors */
};

/*
 * Load an OBJ file. On success *out is a new model (free it with
 * px_obj_free()). On failure *out is NULL and err (optional) says why.
 * The file is read whole, at most PX_FILE_MODEL_MAX_BYTES (1 GiB,
 * px_file.h; a larger regular file is refused from its size, a pipe or
 * device when the count passes it), and a NUL byte is a parse error at
 * its line and column.
 * Returns PX_OK, PX_E_INVAL (NULL arguments), PX_E_IO (cannot read),
 * PX_E_RANGE (over the size limit), PX_E_PARSE, PX_E_UNSUPPORTED,
 * PX_E_NOMEM.
 */
PX_API int px_obj_load_file(const char *path, struct px_obj_model **out,
			    struct px_obj_error *err);

/*
 * Load OBJ text from memory (data need not be NUL-terminated; embedded
 * NUL bytes are a parse error). name is used in error messages.
 */
PX_API int px_obj_load_mem(const char *name, const char *data, size_t len,
			   struct px_obj_model **out,
			   struct px_obj_error *err);

/* Release a model; NULL is a no-op. */
PX_API void px_obj_free(struct px_obj_model *m);

/* The message of a failed load, for users: "FILE:LINE:COL: MSG" where
 * the error has a place, else "PATH: MSG" (px_strerror(rc) when err has
 * no message). Written into buf (cap bytes); returns buf. */
PX_API const char *px_obj_error_text(const struct px_obj_error *err,
				     const char *path, int rc, char *buf,
				     size_t cap);

#ifdef __cplusplus
}
#endif

#endif
