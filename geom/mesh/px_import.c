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
 * check reads their coordinates exactly (a double at 5,000,000.123 m
 * would be 0.123 m off as a float).
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
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

/* ---- strict PLY structure check ---------------------------------------------
 *
 * The importer's PLY reader is lenient: a body shorter than its header
 * promises is padded by repeating values, so a truncated scan would load
 * as a wrong cloud without a word. Before importing, the header is read
 * and the body walked element by element, property by property (list
 * lengths included), for ASCII and both binary byte orders: every value
 * must be present and numeric, and nothing may follow the last element.
 */

#define PLY_MAX_PROPS 64
#define PLY_MAX_ELEMS 16

struct ply_prop {
	char name[64];
	int list;   /* 0: scalar */
	int csize;  /* byte size of the count (lists) */
	int size;   /* byte size of the value / list item */
	int isint;  /* item type is an integer type */
	int sgn;    /* ... a signed one */
};

static void ply_item_kind(const char *t, struct ply_prop *pp)
{
	pp->isint = strncmp(t, "float", 5) != 0 && strcmp(t, "double") != 0;
	pp->sgn = t[0] != 'u';
}

struct ply_elem {
	char name[64];
	unsigned long long count;
	int n_props;
	struct ply_prop props[PLY_MAX_PROPS];
};

static int ply_type_size(const char *t)
{
	static const struct {
		const char *name;
		int size;
	} T[] = {{"char", 1},    {"uchar", 1},  {"int8", 1},    {"uint8", 1},
		 {"short", 2},   {"ushort", 2}, {"int16", 2},   {"uint16", 2},
		 {"int", 4},     {"uint", 4},   {"int32", 4},   {"uint32", 4},
		 {"float", 4},   {"float32", 4}, {"double", 8}, {"float64", 8}};
	size_t i;
	for (i = 0; i < sizeof(T) / sizeof(T[0]); i++)
		if (strcmp(t, T[i].name) == 0)
			return T[i].size;
	return 0;
}

static unsigned long long ply_uint(const unsigned char *b, int size, int big)
{
	unsigned long long v = 0;
	int i;
	for (i = 0; i < size; i++)
		v |= (unsigned long long)b[big ? size - 1 - i : i] << (8 * i);
	return v;
}

/* A binary scalar as a double: floats widened, integers exact (every
 * PLY integer type fits a double's 53 bits). */
static double ply_value(const unsigned char *b, const struct ply_prop *pp, int big)
{
	unsigned long long u = ply_uint(b, pp->size, big);
	if (!pp->isint) {
		if (pp->size == 4) {
			uint32_t w = (uint32_t)u;
			float f;
			memcpy(&f, &w, sizeof f);
			return f;
		} else {
			uint64_t w = u;
			double d;
			memcpy(&d, &w, sizeof d);
			return d;
		}
	}
	if (pp->sgn && ((u >> (8 * pp->size - 1)) & 1u))
		return -(double)((~u + 1u) &
				 (pp->size < 8 ? (1ull << (8 * pp->size)) - 1u : ~0ull));
	return (double)u;
}

/* Next whitespace-separated token of an ASCII body; counts lines. */
static int ply_token(FILE *f, char *tok, size_t cap, long *line)
{
	int c;
	size_t n = 0;
	while ((c = fgetc(f)) != EOF && isspace(c))
		if (c == '\n')
			(*line)++;
	if (c == EOF)
		return 0;
	/* A NUL or control byte, or a token too long for tok, becomes '?' so
	 * that the token fails every check instead of passing as its prefix
	 * (the importer reads the whole token; found by fuzzing). */
	do {
		int bad = c == 0 || (c < 32) || c >= 127;
		if (n + 1 < cap)
			tok[n++] = bad ? '?' : (char)c;
		else
			tok[cap - 2] = '?';
	} while ((c = fgetc(f)) != EOF && !isspace(c));
	if (c == '\n')
		ungetc(c, f);
	tok[n] = '\0';
	return 1;
}

/* A decimal number as the importer's parser reads it: sign, digits with
 * an optional point, optional exponent; or nan / inf. strtod() alone
 * would also take hexadecimal floats. */
static int num_ok(const char *t)
{
	int digits = 0;
	if (*t == '+' || *t == '-')
		t++;
	if (strcasecmp(t, "nan") == 0 || strcasecmp(t, "inf") == 0 ||
	    strcasecmp(t, "infinity") == 0)
		return 1;
	while (isdigit((unsigned char)*t))
		t++, digits++;
	if (*t == '.')
		for (t++; isdigit((unsigned char)*t); t++)
			digits++;
	if (!digits)
		return 0;
	if (*t == 'e' || *t == 'E') {
		t++;
		if (*t == '+' || *t == '-')
			t++;
		if (!isdigit((unsigned char)*t))
			return 0;
		while (isdigit((unsigned char)*t))
			t++;
	}
	return *t == '\0';
}

/* One element instance per line: its first value on a new line, the
 * others on the same. Returns nonzero on a violation. */
static int ply_line_check(int *first, long *line, const long *last, long now)
{
	if (*first) {
		*first = 0;
		*line = now;
		return now <= *last;
	}
	return now != *line;
}

/* One PLY check (ply_validate): the file, the header read so far, the
 * vertices read, and where the body walk is (element k, instance i) for
 * the messages. */
struct ply {
	const char *path;
	FILE *f;
	char *msg;
	size_t msg_cap;
	struct ply_elem *E;
	int ne;
	int fmt;     /* 0 ASCII, 1 binary little endian, 2 big endian; -1 none */
	int vk;      /* the vertex element, -1 none */
	int ax[3];   /* its properties x, y, z, -1 none */
	long vline;  /* its header line */
	long lineno;
	unsigned long long n_vertex;
	double *V;   /* 3 per vertex */
	int k;
	unsigned long long i;
	/* ASCII: the line of the current instance, of the last one, and
	 * whether the current one has no value yet */
	long inst_line, inst_last;
	int inst_first;
};

/* What a step of the check found besides success (0) and PX_E_NOMEM:
 * a message written (PLY_BAD), the data ending early (PLY_SHORT), an
 * instance not on one line of its own (PLY_ROWS). */
#define PLY_BAD 1
#define PLY_SHORT 2
#define PLY_ROWS 3

#define ply_msg(P, ...) (snprintf((P)->msg, (P)->msg_cap, __VA_ARGS__), PLY_BAD)

/* Header: "element <name> <count>". */
static int ply_element(struct ply *P, char w[4][64])
{
	struct ply_elem *el = &P->E[P->ne];
	char *end;
	if (P->ne == PLY_MAX_ELEMS)
		return ply_msg(P, "%s:%ld: too many PLY elements", P->path, P->lineno);
	/* the importer reads a name starting with a digit as the element
	 * count (found by fuzzing: 'element 8888888face 1' took gigabytes
	 * and minutes) */
	if (!isalpha((unsigned char)w[1][0]) && w[1][0] != '_')
		return ply_msg(P, "%s:%ld: PLY element name '%s' does not start with a letter",
			       P->path, P->lineno, w[1]);
	snprintf(el->name, sizeof(el->name), "%s", w[1]);
	if (strcmp(w[1], "vertex") == 0 && P->vk < 0) {
		P->vk = P->ne;
		P->vline = P->lineno;
	}
	el->count = strtoull(w[2], &end, 10);
	if (*end || w[2][0] == '-')
		return ply_msg(P, "%s:%ld: bad element count '%s'", P->path, P->lineno, w[2]);
	P->ne++;
	return 0;
}

/* Header: "property <type> <name>" or "property list <count type>
 * <item type> <name>" of the last element. */
static int ply_property(struct ply *P, char w[4][64], int nw)
{
	struct ply_elem *el = &P->E[P->ne - 1];
	struct ply_prop *pp;
	if (el->n_props == PLY_MAX_PROPS)
		return ply_msg(P, "%s:%ld: too many PLY properties", P->path, P->lineno);
	pp = &el->props[el->n_props++];
	if (strcmp(w[1], "list") == 0) {
		pp->list = 1;
		pp->csize = nw >= 4 ? ply_type_size(w[2]) : 0;
		pp->size = nw >= 4 ? ply_type_size(w[3]) : 0;
		if (nw >= 4)
			ply_item_kind(w[3], pp);
	} else {
		pp->size = ply_type_size(w[1]);
		ply_item_kind(w[1], pp);
		snprintf(pp->name, sizeof(pp->name), "%s", w[2]);
		if (P->ne - 1 == P->vk && !w[2][1] && w[2][0] >= 'x' && w[2][0] <= 'z' &&
		    P->ax[w[2][0] - 'x'] < 0)
			P->ax[w[2][0] - 'x'] = el->n_props - 1;
	}
	if (!pp->size || (pp->list && !pp->csize))
		return ply_msg(P, "%s:%ld: bad PLY property type", P->path, P->lineno);
	return 0;
}

/* Header: "format <ascii|binary_little_endian|binary_big_endian> 1.0". */
static int ply_format(struct ply *P, char w[4][64], int nw)
{
	P->fmt = strcmp(w[1], "ascii") == 0 ? 0
		 : strcmp(w[1], "binary_little_endian") == 0 ? 1
		 : strcmp(w[1], "binary_big_endian") == 0 ? 2 : -2;
	if (P->fmt == -2)
		return ply_msg(P, "%s:%ld: unknown PLY format '%s'", P->path, P->lineno, w[1]);
	/* the importer crashed (SEGV) on a binary header with a malformed
	 * version and no elements (found by fuzzing) */
	if (nw != 3 || strcmp(w[2], "1.0") != 0)
		return ply_msg(P, "%s:%ld: PLY format line must end with version 1.0", P->path,
			       P->lineno);
	return 0;
}

/* The header up to end_header. */
static int ply_header(struct ply *P)
{
	char line[512];
	for (;;) {
		char w[4][64];
		int nw, rc = 0;
		if (!fgets(line, sizeof(line), P->f))
			return ply_msg(P, "%s:%ld: PLY header without end_header", P->path, P->lineno);
		P->lineno++;
		if (!strchr(line, '\n') && !feof(P->f))
			return ply_msg(P, "%s:%ld: PLY header line too long or with a NUL byte",
				       P->path, P->lineno);
		nw = sscanf(line, "%63s %63s %63s %63s", w[0], w[1], w[2], w[3]);
		if (P->lineno == 1) {
			if (nw < 1 || strcmp(w[0], "ply") != 0)
				return ply_msg(P, "%s:1: not a PLY file", P->path);
			continue;
		}
		if (nw <= 0 || strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0)
			continue;
		if (strcmp(w[0], "end_header") == 0)
			break;
		if (strcmp(w[0], "format") == 0 && nw >= 2)
			rc = ply_format(P, w, nw);
		else if (strcmp(w[0], "element") == 0 && nw >= 3)
			rc = ply_element(P, w);
		else if (strcmp(w[0], "property") == 0 && nw >= 3 && P->ne > 0)
			rc = ply_property(P, w, nw);
		else
			rc = ply_msg(P, "%s:%ld: unexpected PLY header line", P->path, P->lineno);
		if (rc)
			return rc;
	}
	if (P->fmt < 0)
		return ply_msg(P, "%s: PLY header without format", P->path);
	return 0;
}

/* The vertex element the header declares: present, with x, y and z, a
 * count the file's size bytes can hold; room for its coordinates. */
static int ply_vertices(struct ply *P, size_t size)
{
	int k;
	if (P->vk >= 0)
		P->n_vertex = P->E[P->vk].count;
	if (P->n_vertex == 0)
		return ply_msg(P, "%s: PLY header declares no vertices", P->path);
	/* a vertex without x, y or z loaded as 0 there: every point of a
	 * cloud without z on the plane z = 0 */
	for (k = 0; k < 3; k++)
		if (P->ax[k] < 0)
			return ply_msg(P, "%s:%ld: PLY element 'vertex' has no scalar property '%c'",
				       P->path, P->vline, "xyz"[k]);
	/* every vertex takes at least a byte a property (two in ASCII): a
	 * count the file cannot hold is refused before the allocation */
	if (P->n_vertex > size / (unsigned long long)P->E[P->vk].n_props)
		return ply_msg(P, "%s:%ld: PLY header declares %llu vertices, more than its %zu "
			       "bytes can hold", P->path, P->vline, P->n_vertex, size);
	P->V = malloc((size_t)P->n_vertex * 3 * sizeof(*P->V));
	if (!P->V) {
		snprintf(P->msg, P->msg_cap, "%s: out of memory for %llu vertices", P->path,
			 P->n_vertex);
		return PX_E_NOMEM;
	}
	return 0;
}

/* Keep value x of property j of the current instance when it is a
 * vertex coordinate. */
static void ply_keep(struct ply *P, int j, double x)
{
	int a;
	for (a = 0; a < 3; a++)
		if (P->ax[a] == j)
			P->V[3 * P->i + (size_t)a] = x;
}

/* Next ASCII value of the current instance, on its line. */
static int ply_ascii_token(struct ply *P, char tok[64])
{
	if (!ply_token(P->f, tok, 64, &P->lineno))
		return PLY_SHORT;
	if (ply_line_check(&P->inst_first, &P->inst_line, &P->inst_last, P->lineno))
		return PLY_ROWS;
	return 0;
}

/* ASCII property j of the current instance. */
static int ply_ascii_prop(struct ply *P, const struct ply_prop *pp, int j, int face)
{
	unsigned long long nitems = 1, t;
	char tok[64], *end;
	int rc;
	if (pp->list) {
		if ((rc = ply_ascii_token(P, tok)) != 0)
			return rc;
		nitems = strtoull(tok, &end, 10);
		if (*end || tok[0] == '-' || !tok[0] || (face && nitems < 3))
			return ply_msg(P, "%s:%ld: bad list length '%s'", P->path, P->lineno, tok);
	}
	for (t = 0; t < nitems; t++) {
		if ((rc = ply_ascii_token(P, tok)) != 0)
			return rc;
		if (!num_ok(tok))
			return ply_msg(P, "%s:%ld: not a number '%s'", P->path, P->lineno, tok);
		if (P->k == P->vk && !pp->list)
			ply_keep(P, j, strtod(tok, NULL));
		if (face) {
			unsigned long long vi = strtoull(tok, &end, 10);
			if (*end || tok[0] == '-' || vi >= P->n_vertex)
				return ply_msg(P, "%s:%ld: face %llu: vertex index '%s' not below %llu",
					       P->path, P->lineno, P->i, tok, P->n_vertex);
		}
	}
	return 0;
}

/* Binary property j of the current instance. */
static int ply_binary_prop(struct ply *P, const struct ply_prop *pp, int j, int face)
{
	unsigned long long nitems = 1, t;
	unsigned char b[8];
	int big = P->fmt == 2;
	if (pp->list) {
		if (fread(b, 1, (size_t)pp->csize, P->f) != (size_t)pp->csize)
			return PLY_SHORT;
		nitems = ply_uint(b, pp->csize, big);
		if (face && nitems < 3)
			return ply_msg(P, "%s: face %llu has %llu vertices", P->path, P->i, nitems);
	}
	for (t = 0; t < nitems; t++) {
		unsigned long long v;
		if (fread(b, 1, (size_t)pp->size, P->f) != (size_t)pp->size)
			return PLY_SHORT;
		if (P->k == P->vk && !pp->list)
			ply_keep(P, j, ply_value(b, pp, big));
		if (!face)
			continue;
		v = ply_uint(b, pp->size, big);
		if (!pp->isint || (pp->sgn && pp->size < 8 && (v >> (8 * pp->size - 1)) & 1u) ||
		    v >= P->n_vertex)
			return ply_msg(P, "%s: face %llu: vertex index not an integer below %llu",
				       P->path, P->i, P->n_vertex);
	}
	return 0;
}

/* The body, element by element, and nothing after it. ASCII: the
 * importer reads one element per line, so the check wants each
 * element's values on a line of their own (a row with a value too many
 * shifted the faces and aborted the importer). Face lists must be
 * polygons over existing vertices: the importer's triangulation aborts
 * the process on other indices (found by fuzzing). */
static int ply_body(struct ply *P)
{
	char tok[64];
	int j, rc;
	P->inst_last = P->lineno - 1;
	for (P->k = 0; P->k < P->ne; P->k++) {
		const struct ply_elem *el = &P->E[P->k];
		for (P->i = 0; P->i < el->count; P->i++) {
			P->inst_first = 1;
			for (j = 0; j < el->n_props; j++) {
				const struct ply_prop *pp = &el->props[j];
				int face = pp->list && strcmp(el->name, "face") == 0;
				rc = P->fmt == 0 ? ply_ascii_prop(P, pp, j, face)
						 : ply_binary_prop(P, pp, j, face);
				if (rc == PLY_ROWS)
					return ply_msg(P, "%s:%ld: PLY element '%s' %llu: not one line "
						       "of values", P->path, P->lineno, el->name, P->i);
				if (rc == PLY_SHORT)
					return ply_msg(P, "%s: PLY data ends early (element '%s' %llu of "
						       "%llu)", P->path, el->name, P->i, el->count);
				if (rc)
					return rc;
			}
			if (P->fmt == 0)
				P->inst_last = P->inst_line;
		}
	}
	if (P->fmt == 0 ? ply_token(P->f, tok, sizeof(tok), &P->lineno) : fgetc(P->f) != EOF)
		return P->fmt == 0 ? ply_msg(P, "%s:%ld: data after the last PLY element", P->path,
					     P->lineno)
				   : ply_msg(P, "%s: data after the last PLY element", P->path);
	return 0;
}

/* Check the PLY of size bytes at f (see above) and read its vertices'
 * x, y, z exactly as doubles into *xyz (malloc'ed, 3 per vertex, *nv of
 * them), which the caller frees. */
static int ply_validate(const char *path, FILE *f, size_t size, double **xyz,
			size_t *nv, unsigned long long *n_faces, char *msg,
			size_t msg_cap)
{
	struct ply P;
	int rc, k;

	*xyz = NULL;
	*nv = 0;
	*n_faces = 0;
	memset(&P, 0, sizeof(P));
	P.path = path;
	P.f = f;
	P.msg = msg;
	P.msg_cap = msg_cap;
	P.fmt = -1;
	P.vk = -1;
	P.ax[0] = P.ax[1] = P.ax[2] = -1;
	P.inst_first = 1;
	P.E = calloc(PLY_MAX_ELEMS, sizeof(*P.E));
	if (!P.E)
		return PX_E_NOMEM;
	rc = ply_header(&P);
	if (rc == 0)
		rc = ply_vertices(&P, size);
	if (rc == 0)
		rc = ply_body(&P);
	if (rc == 0) {
		for (k = 0; k < P.ne; k++)
			if (strcmp(P.E[k].name, "face") == 0)
				*n_faces += P.E[k].count;
		*xyz = P.V;
		*nv = (size_t)P.n_vertex;
		P.V = NULL;
	}
	free(P.V);
	free(P.E);
	return rc == 0 ? PX_OK : rc > 0 ? PX_E_PARSE : rc;
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

static int ends_with_ci(const char *s, const char *ext)
{
	size_t n = strlen(s), m = strlen(ext);
	return n >= m && strcasecmp(s + n - m, ext) == 0;
}

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
	return num_ok(t);
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
		unsigned long long count = ply_uint((const unsigned char *)data + 80, 4, 0);
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

static int has_ply_magic(const char *b, size_t n)
{
	return n >= 4 && memcmp(b, "ply", 3) == 0 && (b[3] == '\n' || b[3] == '\r');
}

/* A reader over the file's bytes for the structure checks (fmemopen
 * wants at least one byte; an empty file never gets that far). */
static FILE *mem_stream(const char *path, char *data, size_t len, char *msg,
			size_t msg_cap)
{
	FILE *f = len ? fmemopen(data, len, "rb") : NULL;
	if (!f)
		snprintf(msg, msg_cap, "%s: %s", path,
			 len ? strerror(errno) : "empty file");
	return f;
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

/* The structure check of a PLY file (data, len bytes). want_tri: it must
 * have faces, and its vertices pass the importer's precision check;
 * else its points are the answer, read exactly into *pv, *pn (the
 * caller's). */
static int check_ply(const char *path, char *data, size_t len, int want_tri, double **pv,
		     size_t *pn, char *msg, size_t msg_cap)
{
	unsigned long long nf = 0;
	FILE *f = mem_stream(path, data, len, msg, msg_cap);
	int rc;
	if (!f)
		return PX_E_IO;
	rc = ply_validate(path, f, len, pv, pn, &nf, msg, msg_cap);
	fclose(f);
	if (rc != PX_OK || !want_tri)
		return rc;
	if (nf == 0) {
		/* vertices only: a cloud (px_load.c looks for these words) */
		snprintf(msg, msg_cap, "%s: no triangles in the file", path);
		rc = PX_E_PARSE;
	} else {
		rc = float_loss_check(path, *pv, *pn, msg, msg_cap);
	}
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
	if (has_ply_magic(data, len) || ends_with_ci(path, ".ply")) {
		snprintf(hint, 16, "ply");
		return check_ply(path, data, len, want_tri, pv, pn, msg, msg_cap);
	}
	if (ends_with_ci(path, ".stl")) {
		FILE *f = mem_stream(path, data, len, msg, msg_cap);
		if (!f)
			return PX_E_IO;
		rc = stl_validate(path, data, len, f, msg, msg_cap);
		fclose(f);
		if (rc != PX_OK)
			return rc;
	}
	if (ends_with_ci(path, ".obj") ||
	    (ends_with_ci(path, ".stl") &&
	     !(len >= 84 && len == 84ull + 50ull * ply_uint((const unsigned char *)data + 80, 4, 0)))) {
		double *tv = NULL;
		size_t tn = 0;
		rc = text_coords(data, ends_with_ci(path, ".obj") ? "v" : "vertex", &tv, &tn);
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

int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap)
{
	struct acc A;
	char *data = NULL, hint[16] = "";
	double *pv = NULL;
	size_t len = 0, pn = 0;
	int rc;

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
	/* read once, with the limit: the checks and the importer see the
	 * same bytes, and a pipe or /dev/zero cannot grow without bound */
	rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES,
			  ends_with_ci(path, ".obj") || ends_with_ci(path, ".off")
				  ? PX_FILE_TEXT : 0u,
			  "model", &data, &len, msg, msg_cap);
	if (rc != PX_OK)
		return rc;
	if (len == 0) {
		snprintf(msg, msg_cap, "%s: empty file", path);
		free(data);
		return PX_E_PARSE;
	}
	rc = check_file(path, data, len, want_tri, hint, &pv, &pn, msg, msg_cap);
	if (rc == PX_OK && pv) {
		/* points: the file's own values, doubles kept exact */
		free(data);
		*xyz = pv;
		*nv = pn;
		if (n_skipped)
			*n_skipped = 0;
		return PX_OK;
	}
	if (rc == PX_OK)
		rc = import_scene(path, data, len, hint, &A, msg, msg_cap);
	free(data);
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
