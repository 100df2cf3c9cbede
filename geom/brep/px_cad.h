/*
 * px_cad.h - CAD parts from STEP and IGES files as B-rep descriptions.
 *
 * px_cad_load() reads a STEP (.step, .stp: AP203, AP214, AP242) or IGES
 * (.iges, .igs) file with OpenCASCADE's data exchange and fills a
 * struct px_brep_desc (px_brep.h) that the returned handle owns, ready
 * for px_brep_create(). Optional part: a build without OpenCASCADE
 * (px_features.h: PX_HAVE_OCCT 0) refuses every file with
 * PX_E_UNSUPPORTED and a message naming the missing library.
 *
 * What the description holds. Every face's surface is an exact NURBS
 * surface (planes, cylinders, cones, spheres, tori, surfaces of
 * revolution and extrusion converted exactly; B-spline and Bezier
 * surfaces kept; offset surfaces are approximated by OpenCASCADE's
 * conversion). Its trimming loops (loop 0 the outer wire) are the
 * edges' curves in that surface's own parameter space, as 2D NURBS with
 * z = 0: the conversion changes the angular parameter of periodic
 * surfaces, so the curves are those OpenCASCADE projects onto the
 * converted surface, within each edge's tolerance of the 3D edge. A
 * loop curve that leaves the surface's domain (where the reader lets an
 * edge run into a pole at any u) is brought inside when the surface
 * then still follows the edge within twice its tolerance. Curves of
 * degree above PX_NURBS_MAX_DEGREE (the reader fits edge curves up to
 * degree 14) are approximated within their edge's tolerance with the
 * same parameter.
 * Edges are the 3D edge curves (exact NURBS), running from vertex v0 to
 * v1; edges collapsed to a point (poles of spheres and cones) have no 3D
 * curve and their loop curves map to edge -1. Periodic surfaces are cut
 * to the period window that holds the face. reversed is set where the
 * face is used reversed in its shell (outward normal -(Su x Sv)). Shells
 * are listed per solid, outer shell first, voids after; a shell is
 * closed when each of its edges is used exactly once in each direction.
 * ids are the file's own entity numbers (STEP #n, IGES directory entry).
 *
 * Units. The reader converts the file's length unit to millimetres:
 * coordinates in the description are millimetres and desc.scale is
 * 0.001 times opts.scale, so px_brep_create() builds in metres
 * (times the user's scale).
 *
 * Assemblies. opts.solid = -1 (the default) gives one description of
 * everything the file holds: every solid (each instance with its
 * placement), free shells and free faces. opts.solid = k >= 0 gives
 * solid k alone (file order; px_cad_solid_count() says how many).
 *
 * Refusals. A file that does not exist, is larger than opts.max_bytes,
 * fails to parse, whose reader reports a failure (syntax, an entity
 * referring to one that is missing, a transfer failure), that holds no
 * face, or a face whose surface or loops the kernel refuses (a surface
 * above PX_NURBS_MAX_DEGREE, open or self-crossing loops, zero area) is
 * refused as a whole: nothing is half-loaded. msg then names the file
 * and, where the reader tells it, the place (STEP "#entity" or
 * "line N", IGES "D<entry>"), e.g.
 * "part.step: face #17: outer loop curve 0 and hole 1 curve 0 cross or
 * touch near (0.2, 0.45)".
 *
 * Setup only: the load allocates, and it takes a process-wide lock
 * (OpenCASCADE's reader settings are global), so loads run one at a
 * time. While it reads, it sets OpenCASCADE's session unit
 * (xstep.cascade.unit) to millimetres and silences its default
 * messenger's printers (their failure messages go into msg), and puts
 * both back after. Every exception of OpenCASCADE is caught inside;
 * signals are left to the application (no OSD::SetSignal()).
 */
#ifndef PX_CAD_H
#define PX_CAD_H

#include <stddef.h>

#include "px_base.h"
#include "px_brep.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Default size limit of an input file. */
#define PX_CAD_MAX_BYTES (512u * 1024u * 1024u)

/* scale: extra factor on metres (1 default); solid: -1 all, else the
 * index of the one solid to keep; max_bytes: larger files are refused
 * (0: PX_CAD_MAX_BYTES). */
struct px_cad_opts {
	double scale;
	int solid;
	size_t max_bytes;
};

PX_API void px_cad_opts_default(struct px_cad_opts *o);

struct px_cad;

/*
 * Read path (the format from its extension, else from its first line)
 * into a new handle *out. opts NULL: defaults. msg (msg_len bytes, may
 * be NULL) receives the reason of a refusal. Returns PX_OK,
 * PX_E_INVAL (arguments, solid index beyond the file's solids),
 * PX_E_NOTFOUND, PX_E_IO, PX_E_RANGE (file too large), PX_E_PARSE
 * (syntax, reader failures, no face), PX_E_UNSUPPORTED (geometry the
 * kernel cannot hold, or a build without OpenCASCADE),
 * PX_E_DEGENERATE (zero-area face, loops enclosing nothing) or the
 * trimmed-domain check's code (px_trim_create()), PX_E_NOMEM. Setup only.
 */
PX_API int px_cad_load(const char *path, const struct px_cad_opts *opts,
		       struct px_cad **out, char *msg, size_t msg_len);

/* The description (valid until px_cad_free()); NULL for NULL. */
PX_API const struct px_brep_desc *px_cad_desc(const struct px_cad *c);

/* Solids in the file (all of them, whichever opts.solid kept). */
PX_API int px_cad_solid_count(const struct px_cad *c);

/* Release the handle and its description (NULL is fine). */
PX_API void px_cad_free(struct px_cad *c);

#ifdef __cplusplus
}
#endif

#endif
