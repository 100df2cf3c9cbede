/*
 * px_occt_ref.h - OpenCASCADE as the reference of the CAD importer's
 * tests (built into the tests only where OpenCASCADE is; the tests that
 * use it need the "occt" part).
 *
 * A reference reads the file itself, in millimetres, and lists its
 * faces in the importer's order (solids in file order, each outer shell
 * first, then free shells, then free faces), so that face k of the
 * importer's description is face k here. Points are in millimetres.
 * Functions return negative numbers on a bad index or a failure.
 */
#ifndef PX_OCCT_REF_H
#define PX_OCCT_REF_H

#include "px_nurbs.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_occt_ref;

/* Read path keeping solid `solid` alone (-1: everything). 0 on success. */
int px_occt_ref_open(const char *path, int solid, struct px_occt_ref **out);
void px_occt_ref_free(struct px_occt_ref *r);

int px_occt_ref_face_count(const struct px_occt_ref *r);
int px_occt_ref_solid_count(const struct px_occt_ref *r);
/* Diagonal of the shape's box. */
double px_occt_ref_size(const struct px_occt_ref *r);
/* Largest edge tolerance once converted to NURBS (pcurves within it). */
double px_occt_ref_edge_tol(const struct px_occt_ref *r);

/* Point (u, v) of face k's surface as OpenCASCADE converts it to NURBS
 * (BRepBuilderAPI_NurbsConvert, BRep_Tool::Surface). */
int px_occt_ref_conv_point(const struct px_occt_ref *r, int k, double u,
			   double v, double p[3]);
/* Distance from p to face k's surface as read (analytic surfaces
 * unconverted, unbounded). */
double px_occt_ref_surf_dist(const struct px_occt_ref *r, int k,
			     const double p[3]);
/* Face k as read against p (projected onto its surface): 0 outside,
 * 1 inside, 2 on its boundary within tol (BRepClass_FaceClassifier). */
int px_occt_ref_face_state(const struct px_occt_ref *r, int k,
			   const double p[3], double tol);
/* Distance from p to the nearest edge curve of the shape as read. */
double px_occt_ref_edge_dist(const struct px_occt_ref *r, const double p[3]);
/* p against the solids (BRepClass3d_SolidClassifier): 1 inside one,
 * 2 on one within tol, else 0. */
int px_occt_ref_solid_state(const struct px_occt_ref *r, const double p[3],
			    double tol);
/* How far p is from the trimmed shape as read, by local projection
 * only: the least of the distances to the feet of p on each face's
 * surface (GeomAPI_ProjectPointOnSurf, every extremum) that lie in the
 * face (BRepClass_FaceClassifier at the foot's (u, v), within tol) and
 * of px_occt_ref_edge_dist(). Small for a point of the shape: tells a
 * real closest point from one that is not (no global search). */
double px_occt_ref_gap(const struct px_occt_ref *r, const double p[3], double tol);
/* Distance from p to a NURBS curve (projection on OpenCASCADE's copy). */
double px_occt_ref_curve_dist(const struct px_nurbs_curve *c,
			      const double p[3]);

#ifdef __cplusplus
}
#endif

#endif
