/*
 * brep_stream.c - tracked streams on B-rep models (px_model.h): a
 * surface tracker (px_strack.h) over the faces' surfaces, untrimmed, and
 * the edges as its curves, which follows every critical point of each
 * surface but answers only with those inside the face's trimmed domain
 * (an in-domain test on the tracked extrema: the global minimum over a
 * face is such a point, or on a trimming edge, or at a vertex). Its
 * global query, where the tracked set cannot prove an answer, is the
 * distance core over the trimmed faces, as the model's own. The point
 * candidates (free vertices, loops collapsed to a point) are checked
 * directly every answer. Answers go through the model's own signing
 * (px__brep_answer()), so they are the global query's, sign included.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "brep_internal.h"
#include "px_model.h"
#include "strack_internal.h"

struct brep_stream {
	struct px_strack *st;
	int last;       /* last answer: -1 the tracker's, else a point candidate */
	int feature, index; /* the last answer's (feature -1: none yet) */
	uint64_t tracked, global, cold, jumps;
};

/* (u, v) in the closed trimmed domain ctx (a px_trim). */
static int dom_in(const void *ctx, double u, double v)
{
	return px_trim_contains(ctx, u, v, NULL) > 0;
}

void px__brep_stream_free(void *state)
{
	struct brep_stream *s = state;
	if (!s)
		return;
	px_strack_free(s->st);
	free(s);
}

int px__brep_stream_create(const void *impl, const struct px_model_stream_opts *o,
			   void **state)
{
	const struct px_brep *b = px__brep_of(impl);
	struct px_nurbs_curve *cv = NULL;
	struct px_nurbs_surf *sf;
	struct px_strack_opts so;
	struct brep_stream *s;
	int i, rc;

	*state = NULL;
	if (b->n_faces == 0)
		return PX_E_UNSUPPORTED;
	s = calloc(1, sizeof(*s));
	sf = malloc((size_t)b->n_faces * sizeof(*sf));
	if (b->n_edges)
		cv = malloc((size_t)b->n_edges * sizeof(*cv));
	if (!s || !sf || (b->n_edges && !cv)) {
		rc = PX_E_NOMEM;
		goto out;
	}
	for (i = 0; i < b->n_faces; i++)
		sf[i] = b->faces[i].surf;
	for (i = 0; i < b->n_edges; i++)
		cv[i] = b->edges[i].c;
	px_strack_opts_default(&so);
	so.verify_every = o->verify_every;
	so.max_solves = o->max_solves;
	so.cold_switch = o->cold_switch;
	/* the entities as the model's: edges, then faces */
	rc = px__strack_create_trimmed(cv, b->n_edges, sf, b->n_faces, b->dtrim,
				       dom_in, &so, &s->st);
	if (rc == PX_OK) {
		s->last = -1;
		s->feature = -1;
		*state = s;
		s = NULL;
	}
out:
	free(sf);
	free(cv);
	px__brep_stream_free(s);
	return rc;
}

/* The point candidate nearer to p than dist (-1 when none). */
static int point_nearer(const struct px_brep *b, px_vec3 p, double dist)
{
	double best = dist * dist;
	int i, bi = -1;
	for (i = 0; i < b->n_pts; i++) {
		double d2 = px_v3_dist2(b->pts[i].p, p);
		if (d2 < best) {
			best = d2;
			bi = i;
		}
	}
	return bi;
}

int px__brep_stream_query(const void *impl, void *state,
			  const struct px_model_query *q, struct px_model_result *r,
			  struct px_model_stream_note *note)
{
	const struct px_brep *b = px__brep_of(impl);
	struct brep_stream *s = state;
	struct px_strack_result sr;
	struct px_dist_result d;
	int rc, pi;

	rc = px_strack_update(s->st, q->p, &sr);
	if (rc != PX_OK)
		return rc;
	memset(&d, 0, sizeof(d));
	note->source = sr.source;
	note->n_crit = sr.n_crit;
	pi = point_nearer(b, q->p, sr.dist);
	if (pi >= 0) {
		/* the same fields as the global query's point answer */
		px_vec3 v = px_v3_sub(q->p, b->pts[pi].p);
		d.dist = px_v3_norm(v);
		d.point = b->pts[pi].p;
		d.dir = d.dist > 0.0 ? px_v3_scale(v, 1.0 / d.dist) : px_v3(0, 0, 0);
		d.entity = pi;
		d.kind = BREP_POINT;
		note->jumped = s->last != pi;
	} else {
		d.dist = sr.dist;
		d.point = sr.point;
		d.dir = sr.dir;
		d.u = sr.u;
		d.v = sr.v;
		d.entity = sr.entity;
		d.kind = sr.entity < b->n_edges ? PX_DIST_CURVE : PX_DIST_SURFACE;
		note->jumped = s->last >= 0 || sr.jumped;
	}
	s->last = pi;
	d.piece = -1;
	d.certified = 1;
	rc = px__brep_answer(b, q, &d, r);
	/* a face, an edge and its end vertex are features of their own
	 * (the tracker's curve answer may run into an edge's end) */
	if (rc == 1) {
		note->jumped |= r->feature != s->feature || r->index != s->index;
		s->feature = r->feature;
		s->index = r->index;
	}
	if (note->source == PX_TRACK_COLD)
		s->cold++;
	else if (note->source == PX_TRACK_GLOBAL || note->source == PX_TRACK_REINIT)
		s->global++;
	else
		s->tracked++;
	s->jumps += note->jumped != 0;
	return rc;
}

void px__brep_stream_stats(const void *state, struct px_model_stream_stats *st)
{
	const struct brep_stream *s = state;
	struct px_strack_stats ss;
	st->tracked = s->tracked;
	st->global = s->global;
	st->cold = s->cold;
	st->jumps = s->jumps;
	px_strack_get_stats(s->st, &ss);
	st->hot = ss.hot;
	st->reinits = ss.reinits;
	st->verifications = ss.verifications;
	st->disagreements = ss.disagreements;
}
