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
 * double exactly.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "model_internal.h"
#include "px_base.h"

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

int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap)
{
	const struct aiScene *s;
	struct acc A;
	struct stat st;
	struct aiMatrix4x4 I;
	unsigned char *seen;
	unsigned i;
	FILE *f;

	memset(&A, 0, sizeof(A));
	A.want_tri = want_tri;
	if (msg_cap)
		msg[0] = '\0';
	if (!path || !xyz || !nv || (want_tri && (!tri || !nt))) {
		snprintf(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	*xyz = NULL;
	*nv = 0;
	if (tri)
		*tri = NULL;
	if (nt)
		*nt = 0;
	if (stat(path, &st) != 0) {
		int e = errno;
		snprintf(msg, msg_cap, "%s: %s", path, strerror(e));
		return e == ENOENT ? PX_E_NOTFOUND : PX_E_IO;
	}
	if (S_ISDIR(st.st_mode)) {
		snprintf(msg, msg_cap, "%s: is a directory", path);
		return PX_E_IO;
	}
	f = fopen(path, "rb");
	if (!f) {
		snprintf(msg, msg_cap, "%s: %s", path, strerror(errno));
		return PX_E_IO;
	}
	fclose(f);
	s = aiImportFile(path, aiProcess_Triangulate);
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
		walk(&A, s, s->mRootNode, &I, seen, 0);
	for (i = 0; i < s->mNumMeshes; i++)
		if (!seen[i])
			add_mesh(&A, s->mMeshes[i], NULL);
	free(seen);
	aiReleaseImport(s);
	if (A.err) {
		snprintf(msg, msg_cap, "%s: %s", path, px_strerror(A.err));
		free(A.xyz);
		free(A.tri);
		return A.err;
	}
	if (A.nv == 0 || (want_tri && A.nt == 0)) {
		snprintf(msg, msg_cap, "%s: no %s in the file", path,
			 want_tri ? "triangles" : "points");
		free(A.xyz);
		free(A.tri);
		return PX_E_PARSE;
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
