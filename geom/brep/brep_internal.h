/*
 * brep_internal.h - private layout of the trimmed domain (px_trim.h),
 * shared by its setup (trim_setup.c, trim_check.c) and its queries
 * (trim_query.c), and of the B-rep model (px_brep.h: brep_setup.c
 * builds it, brep_sign.c signs its answers, brep_model.c queries it).
 * Not installed, not part of the API.
 */
#ifndef PX_BREP_INTERNAL_H
#define PX_BREP_INTERNAL_H

#include <stdatomic.h>

#include "px_arena.h"
#include "dist_internal.h"
#include "px_brep.h"
#include "px_dist.h"
#include "px_trim.h"

/* One Bezier piece of a loop. The homogeneous coefficients (x*w, y*w,
 * w) of its deg + 1 control points sit at coef[off ..], three runs of
 * deg + 1. The end points (ax, ay) and (ex, ey) are the values every
 * crossing count uses: the end of one piece is bit for bit the start of
 * the next. The box holds the control points and both end points and is
 * widened by the domain's rounding slack. */
struct trim_piece {
	double bx0, bx1, by0, by1;
	double ax, ay, ex, ey;
	double t0, t1;  /* curve parameters of the ends (t0 > t1: reversed) */
	int deg, off;
	int loop, curve;
	int col0, row0; /* first grid cell the box meets */
};

/* A node of the subdivision of a piece: its parameter range in [0, 1]
 * and end points. */
struct trim_node {
	double a, b;
	double ax, ay, ex, ey;
};

struct px_trim {
	struct px_arena arena;   /* owns everything below */
	int n_loops;
	int *loop_first;         /* pieces of loop k: loop_first[k] .. [k+1]-1 */
	unsigned char *reversed; /* per loop */
	double *area;            /* per loop, after orientation */
	int n_pieces;
	struct trim_piece *pc;
	double *coef;
	/* grid over [gx0, gx0 + g / ginv_x] x [gy0, ...] */
	int g;
	double gx0, gy0, ginv_x, ginv_y;
	int *cell_start;         /* g * g + 1 */
	int *cell_item;          /* piece indices */
	signed char *cell_wind;  /* winding of cells without pieces */
	double bx0, bx1, by0, by1; /* box of all control points */
	double slack;            /* rounding margin of boxes and cuts */
	double on_tol, close_tol;
};

/* Smaller / larger of two numbers that are not NaN (the queries' hot
 * loops: libm's fmin/fmax are calls). */
static inline double trim_min(double a, double b)
{
	return a < b ? a : b;
}

static inline double trim_max(double a, double b)
{
	return a > b ? a : b;
}

/* Grid column / row of a coordinate: monotone in x, clamped to the grid
 * (setup and queries must use these same functions). */
static inline int trim_cell(double x, double x0, double inv, int g)
{
	double c = (x - x0) * inv;
	if (!(c >= 0.0))
		return 0;
	if (c >= (double)(g - 1))
		return g - 1;
	return (int)c;
}

static inline int trim_col(const struct px_trim *t, double x)
{
	return trim_cell(x, t->gx0, t->ginv_x, t->g);
}

static inline int trim_row(const struct px_trim *t, double y)
{
	return trim_cell(y, t->gy0, t->ginv_y, t->g);
}

/* Cartesian point of piece p at s in [0, 1] (de Casteljau on the
 * homogeneous coefficients: the one function every split point comes
 * from, so both halves see the same value). */
void px__trim_point(const struct px_trim *t, const struct trim_piece *p,
		    double s, double *x, double *y);

/* Cartesian control points of node n of piece p (deg + 1 each), their
 * weights when w is not NULL, and their box with the node's end points,
 * unwidened. */
void px__trim_node_ctrl(const struct px_trim *t, const struct trim_piece *p,
			const struct trim_node *n, double *x, double *y,
			double *w, double box[4]);

/* Winding number of (u, v) over the pieces of loops lo..hi-1 without the
 * grid; *on set when the point is on one of them (then *pi is the piece
 * and *s its parameter). */
int px__trim_winding_range(const struct px_trim *t, int lo, int hi,
			   double u, double v, int *on, int *pi, double *s);

/* Signed crossings of the ray from (u, v) towards +u with piece p: the
 * count, with *on set (and *s the piece parameter) when (u, v) is
 * within the boundary tolerance. */
int px__trim_piece_cross(const struct px_trim *t, const struct trim_piece *p,
			 double u, double v, int *on, double *s);

/* Winding number of (u, v) from the grid: the pieces of row r in cells
 * c.. up to the first cell without pieces, plus that cell's winding.
 * *on, *pi, *s as for px__trim_winding_range(). */
int px__trim_walk(const struct px_trim *t, int r, int c, double u, double v,
		  int *on, int *pi, double *s);

/* Setup checks (trim_check.c): signed area of loop k, and the crossing
 * test over all pieces; both fill err on refusal. */
double px__trim_loop_area(const struct px_trim *t, int k);
int px__trim_check_crossings(const struct px_trim *t,
			     struct px_trim_error *err);

/* Error reporting shared by setup files. */
void px__trim_err(struct px_trim_error *err, int code,
		  enum px_trim_fault fault, int loop, int curve, int loop2,
		  int curve2, double u, double v, double value,
		  const char *fmt, ...) __attribute__((format(printf, 11, 12)));
/* "outer loop" / "hole k" */
const char *px__trim_loop_name(int k, char *buf, size_t len);

/* ---- the B-rep model ------------------------------------------------------ */

/* Kind of a point candidate's answer in px_dist_result.kind (entity is
 * then the index into pts). */
#define BREP_POINT 2

/* Kind of a curve-on-surface edge's answer (entity: its index among
 * them, u the loop curve's parameter). */
#define BREP_COS 3

/* Query workspaces of one B-rep (threads borrow one without waiting). */
#define BREP_WS 4
/* (edge parameter, loop curve parameter) pairs per coedge: the start of
 * the few Gauss-Newton steps that find a face's (u, v) at an edge point. */
#define BREP_MAP_N 33

/* One curve of one loop of a face, and the edge it runs along. */
struct brep_coedge {
	struct px_nurbs_curve pc; /* the loop curve in (u, v), copied */
	int face, loop, curve;
	int edge;                 /* -1: collapsed to a point */
	int dir;                  /* +1 / -1: along / against the oriented loop */
	double t[BREP_MAP_N], s[BREP_MAP_N]; /* edge -> curve parameters */
	int mapped;               /* the table holds (edge with a curve) */
};

struct brep_face {
	struct px_nurbs_surf surf; /* scaled copy */
	struct px_trim *trim;      /* NULL: the whole surface */
	int reversed, shell;
	long id;
};

struct brep_edge {
	struct px_nurbs_curve c; /* scaled copy */
	int v0, v1;
	long id;
	double t0, t1;           /* domain */
	int co[2], n_co;         /* its coedges (the first two) */
	int uses;                /* coedges running along it */
};

/* A point candidate: a vertex no edge ends at, or a loop curve whose
 * image is a point. */
struct brep_point {
	px_vec3 p;
	int vertex;              /* vertex id, or -1 */
	int collapsed;           /* a loop curve's image (else a free vertex) */
};

struct px_brep {
	int n_faces, n_edges, n_vertices, n_shells, n_solids, n_co, n_pts;
	int n_trimmed;
	struct brep_face *faces;
	struct brep_edge *edges;
	struct brep_coedge *co;
	px_vec3 *verts;
	struct brep_point *pts;
	int *shell_solid;          /* per shell */
	int *shell_closed;
	struct px__dist_trim *dtrim;     /* per face, for the distance core */
	struct px_dist_model *dm;
	struct brep_cos_set *cos;  /* curve-on-surface edges, or NULL */
	struct px_dist_ws *ws[BREP_WS];
	atomic_flag busy[BREP_WS];
	double *mem;               /* the copied arrays */
	px_aabb box;
	double size;               /* box diagonal */
	double on_tol;             /* closer counts as on the model */
	/* sign */
	int closed;
	px_vec3 *vnormal;          /* per vertex: angle-weighted pseudo-normal */
	/* per face: +1 / -1 when its closed form's normal (brep_sign.c:
	 * shape_normal()) is the outward one / its opposite, 0 when the
	 * surface must be evaluated; NULL for open B-reps */
	signed char *fsign;
	char why[200];
	char *name, *source;
	size_t bytes;
};

/* Sign setup (brep_sign.c): the coedge parameter tables, the vertex
 * pseudo-normals, the closedness and orientation checks; fills
 * b->closed and b->why. PX_OK or PX_E_NOMEM. */
int px__brep_sign_setup(struct px_brep *b);

/* Sign of the query point p of unsigned answer d (d->dist > on_tol) on
 * a closed B-rep: -1 inside, +1 outside. @note RT-safe. */
int px__brep_sign(const struct px_brep *b, px_vec3 p,
		  const struct px_dist_result *d);

/* Outward unit normal of face f at (u, v) (reversed faces flipped;
 * zero where Su x Sv vanishes). @note RT-safe. */
px_vec3 px__brep_face_normal(const struct px_brep *b, int f, double u,
			     double v);

/* Unsigned global answer of the B-rep (distance core + point
 * candidates + curve-on-surface edges) with workspace slot k.
 * @note RT-safe. */
int px__brep_closest(const struct px_brep *b, int k, px_vec3 p,
		     struct px_dist_result *d);

/* The same with the caller's workspace of b's core. @note RT-safe. */
int px__brep_closest_ws(const struct px_brep *b, struct px_dist_ws *ws, px_vec3 p,
			struct px_dist_result *d);

/* ---- composed edges (brep_compose.c) ----------------------------------------- */

/* Highest degree of a curve-on-surface edge's pieces (brep_cos.c). */
#define BREP_COS_MAX_DEGREE 24

/* The exact image S(c(t)) of the (u, v) curve c on s, parametrised by
 * c's t, as a NURBS curve viewing *mem (free() it). Returns PX_OK, 1
 * when c is one point of the parameter plane (nothing made), or an
 * error with why (a sentence) filled. Setup only. */
int px__brep_compose_curve(const struct px_nurbs_surf *s,
			   const struct px_nurbs_curve *c, double **mem,
			   struct px_nurbs_curve *out, char *why, size_t why_cap);

/* The image S(c(t)) as rational Bezier pieces of degree *deg (up to
 * BREP_COS_MAX_DEGREE): *n_pc pieces, (*n_pc * *deg + 1) homogeneous
 * points in *pw (consecutive pieces share their end point), the piece
 * ends in c's parameter in *brk (*n_pc + 1); free() both. Returns as
 * px__brep_compose_curve(). Setup only. */
int px__brep_compose_bezier(const struct px_nurbs_surf *s,
			    const struct px_nurbs_curve *c, int *deg, int *n_pc,
			    double **pw, double **brk, char *why, size_t why_cap);

/* ---- curve-on-surface edges (brep_cos.c) ------------------------------------ */

/* One piece of a curve-on-surface edge: loop-curve parameters [t0, t1],
 * degree, the degree of its critical-point polynomial, its box (of the
 * control points), its edge and its coefficients at off in coef. */
struct brep_cos_piece {
	px_aabb box;
	double t0, t1;
	int deg, gdeg, wconst;
	int cos;
	size_t off;
};

/* An edge: the coedge it runs along (index into px_brep.co), its face,
 * its pieces first .. first + n - 1 and its parameter range. */
struct brep_cos {
	int face, co;
	int first, n;
	double t0, t1;
};

/* The curve-on-surface edges of a B-rep, fixed after setup. */
struct brep_cos_set {
	int n_cos, n_pc;
	struct brep_cos *cos;
	struct brep_cos_piece *pc;
	double *coef;
	int cap_cos, cap_pc;
	size_t n_coef, cap_coef;
};

/* Add the edge of coedge co (face face) from the pieces of
 * px__brep_compose_bezier(), coordinates times scale. Setup only:
 * PX_OK, PX_E_NOMEM or PX_E_RANGE. */
int px__brep_cos_add(struct brep_cos_set *s, int face, int co, int deg,
		     int n_pc, const double *pw, const double *brk, double scale);
void px__brep_cos_free(struct brep_cos_set *s);

/* 1 when one of s's edges is nearer to q than d->dist (then d is that
 * answer: kind BREP_COS, and when it is no farther than d's proof's
 * lower bound (dist - gap) that proof is settled), else 0; d->certified
 * and gap take the edges' proof too, *edge_gap (may be NULL) their own
 * gap (-1: certified). s may be NULL. @note RT-safe. */
int px__brep_cos_closest(const struct brep_cos_set *s, px_vec3 q,
			 struct px_dist_result *d, double *edge_gap);

/* Tests: 1 makes every composed loop curve a curve-on-surface edge (to
 * compare both on curves the kernel's degree allows). */
PX__TEST_SWITCH(int, px__brep_force_cos, 0);

/* A squared distance from q that a point of s's edges beats (their
 * pieces' end points, widened by rounding): the bound of the core's
 * query. @note RT-safe. */
double px__brep_cos_bound2(const struct brep_cos_set *s, px_vec3 q);

/* 1 when coedge co runs along a curve-on-surface edge. */
int px__brep_cos_on(const struct brep_cos_set *s, int co);

/* A description with an own composed edge for every loop curve that has
 * none (and no single-point image): d is a copy of the caller's with
 * the faces' coedges and the edges replaced. */
struct brep_aug {
	struct px_brep_desc d;
	struct px_brep_face_desc *faces;
	struct px_brep_edge_desc *edges;
	struct px_brep_coedge *co;
	const struct px_brep_coedge **cop;
	double **mem;
	int n_mem;
	struct brep_cos_set *cos; /* loop curves of too high an image degree */
};

/* Fill g from d (g->d.faces NULL: nothing to add, use d itself).
 * PX_OK or the composition's refusal in err. */
int px__brep_compose(const struct px_brep_desc *d, struct brep_aug *g,
		     struct px_brep_error *err);
void px__brep_aug_free(struct brep_aug *g);

/* The model's answer (px_model.h) from the unsigned one d, the global
 * query's or a stream's: the sign, the feature. Returns 1, or 0 beyond
 * q->max_dist. @note RT-safe. */
struct px_model_query;
struct px_model_result;
int px__brep_answer(const struct px_brep *b, const struct px_model_query *q,
		    const struct px_dist_result *d, struct px_model_result *r);

/* The B-rep behind the px_model implementation impl (brep_model.c). */
struct px_brep *px__brep_of(const void *impl);

/* Tracked streams (brep_stream.c): the four stream operations of
 * struct px_model_ops on the implementation of px_model_from_brep(). */
struct px_model_stream_opts;
struct px_model_stream_note;
struct px_model_stream_stats;
int px__brep_stream_create(const void *impl, const struct px_model_stream_opts *o,
			   void **state);
int px__brep_stream_query(const void *impl, void *state,
			  const struct px_model_query *q, struct px_model_result *r,
			  struct px_model_stream_note *note);
void px__brep_stream_stats(const void *state, struct px_model_stream_stats *st);
void px__brep_stream_free(void *state);

#endif
