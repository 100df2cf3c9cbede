/*
 * px_import.c - mesh and point files through the Open Asset Import
 * Library (Debian libassimp-dev): STL (ASCII and binary), OBJ, PLY and
 * the other formats it reads.
 *
 * Only aiProcess_Triangulate is asked for. Vertex welding is done by the
 * mesh module on exact positions instead of aiProcess_JoinIdenticalVertices,
 * which merges a vertex with a NaN coordinate into another one and so
 * hides exactly the corrupt data the validation must report. Coordinates
 * arrive as the library's single-precision floats; they are widened to
 * double exactly. PLY point clouds do not go through it: the structure
 * check (mesh_ply.c) reads their coordinates exactly (a double at
 * 5,000,000.123 m would be 0.123 m off as a float).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "mesh_internal.h"
#include "px_base.h"
#include "px_file.h"

struct acc {
	double *xyz;
	size_t nv, cap_v;
	uint32_t *tri;
	size_t nt, cap_t;
	size_t skipped;
	int want_tri;
	int err;
};

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
	size_t nc;
	void *q;
	if (need <= *cap)
		return 0;
	nc = *cap ? *cap : 1024;
	while (nc < need) {
		if (nc > ((size_t)-1) / 2 / elem)
			return PX_E_OVERFLOW;
		nc *= 2;
	}
	q = realloc(*p, nc * elem);
	if (!q)
		return PX_E_NOMEM;
	*p = q;
	*cap = nc;
	return 0;
}

/* row-major 4x4 (a1..d4), applied to a point */
static void xform(const struct aiMatrix4x4 *T, const struct aiVector3D *v,
		  double out[3])
{
	double x = v->x, y = v->y, z = v->z;
	out[0] = (double)T->a1 * x + (double)T->a2 * y + (double)T->a3 * z + T->a4;
	out[1] = (double)T->b1 * x + (double)T->b2 * y + (double)T->b3 * z + T->b4;
	out[2] = (double)T->c1 * x + (double)T->c2 * y + (double)T->c3 * z + T->c4;
}

static void mul(const struct aiMatrix4x4 *A, const struct aiMatrix4x4 *B,
		struct aiMatrix4x4 *C)
{
	const ai_real *a = &A->a1, *b = &B->a1;
	ai_real *c = &C->a1;
	int i, j, k;
	for (i = 0; i < 4; i++)
		for (j = 0; j < 4; j++) {
			double s = 0.0;
			for (k = 0; k < 4; k++)
				s += (double)a[4 * i + k] * b[4 * k + j];
			c[4 * i + j] = (ai_real)s;
		}
}

static void add_mesh(struct acc *A, const struct aiMesh *m,
		     const struct aiMatrix4x4 *T)
{
	size_t base = A->nv, i;
	unsigned f;

	if (A->err)
		return;
	if ((A->err = grow((void **)&A->xyz, &A->cap_v, A->nv + m->mNumVertices,
			   3 * sizeof(double))))
		return;
	for (i = 0; i < m->mNumVertices; i++) {
		if (T)
			xform(T, &m->mVertices[i], A->xyz + 3 * (A->nv + i));
		else {
			A->xyz[3 * (A->nv + i)] = m->mVertices[i].x;
			A->xyz[3 * (A->nv + i) + 1] = m->mVertices[i].y;
			A->xyz[3 * (A->nv + i) + 2] = m->mVertices[i].z;
		}
	}
	A->nv += m->mNumVertices;
	if (!A->want_tri)
		return;
	for (f = 0; f < m->mNumFaces; f++) {
		const struct aiFace *F = &m->mFaces[f];
		if (F->mNumIndices != 3) {
			A->skipped++;
			continue;
		}
		if ((A->err = grow((void **)&A->tri, &A->cap_t, A->nt + 1,
				   3 * sizeof(uint32_t))))
			return;
		for (i = 0; i < 3; i++) {
			size_t vi = base + F->mIndices[i];
			if (vi > 0xfffffffeu) {
				A->err = PX_E_OVERFLOW;
				return;
			}
			A->tri[3 * A->nt + i] = (uint32_t)vi;
		}
		A->nt++;
	}
}

static void walk(struct acc *A, const struct aiScene *s,
		 const struct aiNode *n, const struct aiMatrix4x4 *parent,
		 unsigned char *seen, int depth)
{
	struct aiMatrix4x4 T;
	unsigned i;

	if (depth > 256)
		return;
	mul(parent, &n->mTransformation, &T);
	for (i = 0; i < n->mNumMeshes; i++)
		if (n->mMeshes[i] < s->mNumMeshes) {
			seen[n->mMeshes[i]] = 1;
			add_mesh(A, s->mMeshes[n->mMeshes[i]], &T);
		}
	for (i = 0; i < n->mNumChildren; i++)
		walk(A, s, n->mChildren[i], &T, seen, depth + 1);
}


/* ---- strict STL structure check ---------------------------------------------
 *
 * The importer leaks the mesh it was building when an ASCII STL ends in
 * the middle of a facet, and accepts odd layouts silently (found by
 * fuzzing). Before importing a .stl file its structure is checked: a
 * binary STL has exactly 84 + 50 * n bytes for the n triangles its
 * header counts; anything else must be ASCII, "solid [name]" then facets
 * "facet normal x y z / outer loop / vertex x y z (three) / endloop /
 * endfacet", then "endsolid [name]" (several solids allowed), every
 * number present and numeric.
 */

/* Split a line into at most max whitespace-separated words (in place).
 * Returns the word count, max + 1 when there are more. */
static int stl_split(char *line, char **w, int max)
{
	int n = 0;
	char *p = line;
	for (;;) {
		while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
			p++;
		if (!*p)
			return n;
		if (n == max)
			return max + 1;
		w[n++] = p;
		while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\n')
			p++;
		if (*p)
			*p++ = '\0';
	}
}

static int stl_is_number(const char *t)
{
	return px__num_ok(t);
}

/* The importer reads ASCII STL line by line, so the check does too:
 * every statement on a line of its own. */
enum { STL_SOLID, STL_FACET, STL_LOOP, STL_VERTEX, STL_ENDLOOP, STL_ENDFACET };

/* The STL of size bytes at data (f reads the same bytes). */
static int stl_validate(const char *path, const char *data, size_t size, FILE *f,
			char *msg, size_t msg_cap)
{
	static const char *const want[] = {"'solid'", "'facet normal x y z' or 'endsolid'",
					   "'outer loop'", "'vertex x y z'", "'endloop'",
					   "'endfacet'"};
	char *line = NULL, *w[6];
	size_t cap = 0;
	ssize_t len;
	long lineno = 0, nul_line, nul_col;
	int rc = PX_E_PARSE, st = STL_SOLID, nv = 0, solids = 0, n;
	int nul = px_file_find_nul(data, size, &nul_line, &nul_col);

	if (size >= 84) {
		unsigned long long count = px__ply_uint((const unsigned char *)data + 80, 4, 0);
		unsigned long long need = 84ull + 50ull * count;
		if (size == need) {
			if (count == 0) {
				snprintf(msg, msg_cap, "%s: binary STL without triangles", path);
				return PX_E_PARSE;
			}
			return PX_OK;
		}
		/* not ASCII (a NUL byte, or no 'solid' to begin with): a binary
		 * STL whose count and size disagree, truncated or padded */
		if (nul || strncmp(data, "solid", 5) != 0) {
			char why[96];
			if (strncmp(data, "solid", 5) != 0)
				snprintf(why, sizeof why, "; not an ASCII STL either (no 'solid')");
			else
				snprintf(why, sizeof why, "; not an ASCII STL either (NUL byte "
					 "at %ld:%ld)", nul_line, nul_col);
			snprintf(msg, msg_cap, "%s: binary STL: header says %llu triangles "
				 "(needs %llu bytes), file has %zu bytes%s", path, count,
				 need, size, why);
			return PX_E_PARSE;
		}
	} else if (nul || strncmp(data, "solid", 5) != 0) {
		snprintf(msg, msg_cap, "%s: %zu bytes: shorter than a binary STL's 84-byte "
			 "header, and not an ASCII STL (no 'solid')", path, size);
		return PX_E_PARSE;
	}
	while ((len = getline(&line, &cap, f)) >= 0) {
		int ok;
		lineno++;
		if ((size_t)len != strlen(line)) {
			snprintf(msg, msg_cap, "%s:%ld: NUL byte in an ASCII STL", path, lineno);
			goto out;
		}
		if (len && line[len - 1] == '\n')
			line[--len] = '\0';
		if (len && line[len - 1] == '\r')
			line[--len] = '\0';
		if (strchr(line, '\r')) {
			/* the importer ends lines there (found by fuzzing) */
			snprintf(msg, msg_cap, "%s:%ld: carriage return inside a line",
				 path, lineno);
			goto out;
		}
		n = stl_split(line, w, 5);
		if (n == 0)
			continue;
		switch (st) {
		case STL_SOLID:
			ok = strcmp(w[0], "solid") == 0;
			if (ok) {
				st = STL_FACET;
				solids++;
			}
			break;
		case STL_FACET:
			if (strcmp(w[0], "endsolid") == 0) {
				ok = 1;
				st = STL_SOLID;
				break;
			}
			ok = n == 5 && strcmp(w[0], "facet") == 0 &&
			     strcmp(w[1], "normal") == 0 && stl_is_number(w[2]) &&
			     stl_is_number(w[3]) && stl_is_number(w[4]);
			st = STL_LOOP;
			break;
		case STL_LOOP:
			ok = n == 2 && strcmp(w[0], "outer") == 0 &&
			     strcmp(w[1], "loop") == 0;
			st = STL_VERTEX;
			nv = 0;
			break;
		case STL_VERTEX:
			ok = n == 4 && strcmp(w[0], "vertex") == 0 &&
			     stl_is_number(w[1]) && stl_is_number(w[2]) &&
			     stl_is_number(w[3]);
			if (++nv == 3)
				st = STL_ENDLOOP;
			break;
		case STL_ENDLOOP:
			ok = n == 1 && strcmp(w[0], "endloop") == 0;
			st = STL_ENDFACET;
			break;
		default:
			ok = n == 1 && strcmp(w[0], "endfacet") == 0;
			st = STL_FACET;
			break;
		}
		if (!ok) {
			if (lineno == 1 && solids == 0)
				snprintf(msg, msg_cap, "%s: neither a binary STL (%zu bytes, "
					 "not 84 + 50 per triangle) nor an ASCII one "
					 "(no 'solid')", path, size);
			else
				snprintf(msg, msg_cap, "%s:%ld: expected %s", path, lineno,
					 want[st == STL_LOOP && strcmp(w[0], "facet") != 0
						      ? STL_FACET : st]);
			goto out;
		}
	}
	if (st != STL_SOLID || solids == 0)
		snprintf(msg, msg_cap, "%s:%ld: ASCII STL ends early, expected %s", path,
			 lineno, want[st]);
	else
		rc = PX_OK;
out:
	free(line);
	return rc;
}

/* A mesh from the importer passes through single-precision floats: the
 * file's own values (a PLY's read exactly by its check, the decimal
 * coordinates of an ASCII STL or an OBJ) must not move by more than
 * PX_IMPORT_FLOAT_TOL of the model's largest extent, or the mesh is
 * refused rather than answered off (a model far from its origin, as
 * survey coordinates are, loses its small digits). */
#define PX_IMPORT_FLOAT_TOL 1e-5

static int float_loss_check(const char *path, const double *v, size_t nv,
			    char *msg, size_t msg_cap)
{
	double lo[3] = {INFINITY, INFINITY, INFINITY};
	double hi[3] = {-INFINITY, -INFINITY, -INFINITY}, ext = 0.0, tol;
	size_t i;
	int k;
	for (i = 0; i < nv; i++)
		for (k = 0; k < 3; k++) {
			double x = v[3 * i + (size_t)k];
			lo[k] = x < lo[k] ? x : lo[k];
			hi[k] = x > hi[k] ? x : hi[k];
		}
	for (k = 0; k < 3; k++)
		ext = fmax(ext, hi[k] - lo[k]);
	tol = PX_IMPORT_FLOAT_TOL * ext;
	for (i = 0; i < nv; i++)
		for (k = 0; k < 3; k++) {
			double x = v[3 * i + (size_t)k], lost;
			if (!isfinite(x) || fabs(x) > 3.0e38)
				continue; /* left to the mesh's own range checks */
			lost = fabs(x - (double)(float)x);
			if (lost > tol) {
				snprintf(msg, msg_cap, "%s: vertex %zu: %c = %.17g loses %g "
					 "in the importer's single precision, more than %g "
					 "(%g of the model's extent %g)", path, i, "xyz"[k], x,
					 lost, tol, PX_IMPORT_FLOAT_TOL, ext);
				return PX_E_RANGE;
			}
		}
	return PX_OK;
}

/* The coordinates of the text lines that start with the word kw
 * ("vertex" in an ASCII STL, "v" in an OBJ), three numbers each, as the
 * file writes them (the structure checks have run; a line that does not
 * read as three numbers is left to the importer). */
static int text_coords(const char *data, const char *kw, double **out, size_t *n_out)
{
	size_t kl = strlen(kw), n = 0, cap = 0;
	const char *p = data;
	double *v = NULL;
	while (*p) {
		const char *e = strchr(p, '\n');
		while (*p == ' ' || *p == '\t')
			p++;
		if (strncmp(p, kw, kl) == 0 && (p[kl] == ' ' || p[kl] == '\t')) {
			double c[3];
			char *end;
			int k;
			const char *q = p + kl;
			for (k = 0; k < 3; k++) {
				c[k] = strtod(q, &end);
				if (end == q)
					break;
				q = end;
			}
			if (k == 3) {
				if (n == cap) {
					size_t nc = cap ? 2 * cap : 1024;
					double *nv = realloc(v, 3 * nc * sizeof(*nv));
					if (!nv) {
						free(v);
						return PX_E_NOMEM;
					}
					v = nv;
					cap = nc;
				}
				memcpy(v + 3 * n, c, sizeof c);
				n++;
			}
		}
		if (!e)
			break;
		p = e + 1;
	}
	*out = v;
	*n_out = n;
	return PX_OK;
}

/* The structure check of a PLY file (data, len bytes; mesh_ply.c).
 * want_tri: it must have faces, and its vertices pass the importer's
 * precision check; else its points are the answer, read exactly into
 * *pv, *pn (the caller's). */
static int check_ply(const char *path, char *data, size_t len, int want_tri, double **pv,
		     size_t *pn, char *msg, size_t msg_cap)
{
	int rc = px__ply_read(path, data, len, want_tri, pv, pn, msg, msg_cap);
	if (rc != PX_OK || !want_tri)
		return rc;
	rc = float_loss_check(path, *pv, *pn, msg, msg_cap);
	free(*pv);
	*pv = NULL;
	return rc;
}

/* The checks before the importer: PLY and STL structure, and the
 * precision of the decimal coordinates of text meshes (a binary STL is
 * single precision already). *hint: the importer's format hint. A PLY
 * read for points is answered here: *pv, *pn. */
static int check_file(const char *path, char *data, size_t len, int want_tri, char hint[16],
		      double **pv, size_t *pn, char *msg, size_t msg_cap)
{
	const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
	int rc;

	/* A .ply name without the magic line goes to the check too: the
	 * importer's PLY reader loops forever on some such headers (found
	 * by fuzzing). */
	if (px__ply_file(path, data, len)) {
		snprintf(hint, 16, "ply");
		return check_ply(path, data, len, want_tri, pv, pn, msg, msg_cap);
	}
	if (px__ends_with_ci(path, ".stl")) {
		FILE *f = px__mem_stream(path, data, len, msg, msg_cap);
		if (!f)
			return PX_E_IO;
		rc = stl_validate(path, data, len, f, msg, msg_cap);
		fclose(f);
		if (rc != PX_OK)
			return rc;
	}
	if (px__ends_with_ci(path, ".obj") ||
	    (px__ends_with_ci(path, ".stl") &&
	     !(len >= 84 && len == 84ull + 50ull * px__ply_uint((const unsigned char *)data + 80, 4, 0)))) {
		double *tv = NULL;
		size_t tn = 0;
		rc = text_coords(data, px__ends_with_ci(path, ".obj") ? "v" : "vertex", &tv, &tn);
		if (rc == PX_OK)
			rc = float_loss_check(path, tv, tn, msg, msg_cap);
		free(tv);
		if (rc != PX_OK)
			return rc;
	}
	if (dot && (!slash || dot > slash) && strlen(dot + 1) < 16)
		snprintf(hint, 16, "%s", dot + 1);
	return PX_OK;
}

/* Run the importer on data (len bytes, format hint) and collect its
 * meshes into A: every mesh its nodes reference, with their transforms,
 * and the meshes no node references as they are. */
static int import_scene(const char *path, const char *data, size_t len, const char *hint,
			struct acc *A, char *msg, size_t msg_cap)
{
	const struct aiScene *s;
	struct aiMatrix4x4 I;
	unsigned char *seen;
	unsigned i;

	if (len > 0xffffffffu) {
		snprintf(msg, msg_cap, "%s: %zu bytes, more than the importer takes", path, len);
		return PX_E_RANGE;
	}
	s = aiImportFileFromMemory(data, (unsigned)len, aiProcess_Triangulate, hint);
	if (!s) {
		snprintf(msg, msg_cap, "%s: %s", path, aiGetErrorString());
		return PX_E_PARSE;
	}
	seen = calloc(s->mNumMeshes + 1, 1);
	if (!seen) {
		aiReleaseImport(s);
		return PX_E_NOMEM;
	}
	memset(&I, 0, sizeof(I));
	I.a1 = I.b2 = I.c3 = I.d4 = 1.0f;
	if (s->mRootNode)
		walk(A, s, s->mRootNode, &I, seen, 0);
	for (i = 0; i < s->mNumMeshes; i++)
		if (!seen[i])
			add_mesh(A, s->mMeshes[i], NULL);
	free(seen);
	aiReleaseImport(s);
	if (A->err) {
		snprintf(msg, msg_cap, "%s: %s", path, px_strerror(A->err));
		return A->err;
	}
	if (A->nv == 0 || (A->want_tri && A->nt == 0)) {
		snprintf(msg, msg_cap, "%s: no %s in the file", path,
			 A->want_tri ? "triangles" : "points");
		return PX_E_PARSE;
	}
	return PX_OK;
}

int px__import_data(const char *path, char *data, size_t len, int want_tri,
		    double **xyz, size_t *nv, uint32_t **tri, size_t *nt,
		    size_t *n_skipped, char *msg, size_t msg_cap)
{
	struct acc A;
	char hint[16] = "";
	double *pv = NULL;
	size_t pn = 0;
	int rc;

	memset(&A, 0, sizeof(A));
	A.want_tri = want_tri;
	if (msg_cap)
		msg[0] = '\0';
	if (!path || !data || !xyz || !nv || (want_tri && (!tri || !nt))) {
		snprintf(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	*xyz = NULL;
	*nv = 0;
	if (tri)
		*tri = NULL;
	if (nt)
		*nt = 0;
	rc = check_file(path, data, len, want_tri, hint, &pv, &pn, msg, msg_cap);
	if (rc == PX_OK && pv) {
		/* points: the file's own values, doubles kept exact */
		*xyz = pv;
		*nv = pn;
		if (n_skipped)
			*n_skipped = 0;
		return PX_OK;
	}
	if (rc == PX_OK)
		rc = import_scene(path, data, len, hint, &A, msg, msg_cap);
	if (rc != PX_OK) {
		free(A.xyz);
		free(A.tri);
		return rc;
	}
	*xyz = A.xyz;
	*nv = A.nv;
	if (want_tri) {
		*tri = A.tri;
		*nt = A.nt;
	} else {
		free(A.tri);
	}
	if (n_skipped)
		*n_skipped = A.skipped;
	return PX_OK;
}
