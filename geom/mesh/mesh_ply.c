/*
 * mesh_ply.c - the parts of the file importer that need no importer
 * library: the file read once with its limit, the strict PLY structure
 * check that also reads a PLY's vertices exactly, and the small text
 * helpers the STL check shares. Compiled in every build, so that PLY
 * point clouds load without assimp (px_import_none.c).
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "mesh_internal.h"
#include "px_base.h"
#include "px_file.h"

int px__ends_with_ci(const char *s, const char *ext)
{
	size_t n = strlen(s), m = strlen(ext);
	return n >= m && strcasecmp(s + n - m, ext) == 0;
}

int px__import_read(const char *path, char **data, size_t *len, char *msg, size_t msg_cap)
{
	/* read once, with the limit: the checks and the importer see the
	 * same bytes, and a pipe or /dev/zero cannot grow without bound */
	int rc = px_file_read(path, PX_FILE_MODEL_MAX_BYTES,
			      px__ends_with_ci(path, ".obj") || px__ends_with_ci(path, ".off")
				      ? PX_FILE_TEXT : 0u,
			      "model", data, len, msg, msg_cap);
	if (rc != PX_OK)
		return rc;
	if (*len == 0) {
		snprintf(msg, msg_cap, "%s: empty file", path);
		free(*data);
		*data = NULL;
		return PX_E_PARSE;
	}
	return PX_OK;
}

/* Both importers (with and without assimp) read the same way. */
int px__import_file(const char *path, int want_tri, double **xyz,
		    size_t *nv, uint32_t **tri, size_t *nt, size_t *n_skipped,
		    char *msg, size_t msg_cap)
{
	char *data = NULL;
	size_t len = 0;
	int rc;
	if (msg_cap)
		msg[0] = '\0';
	if (!path || !xyz || !nv || (want_tri && (!tri || !nt))) {
		snprintf(msg, msg_cap, "invalid arguments");
		return PX_E_INVAL;
	}
	rc = px__import_read(path, &data, &len, msg, msg_cap);
	if (rc != PX_OK) {
		*xyz = NULL;
		*nv = 0;
		if (tri)
			*tri = NULL;
		if (nt)
			*nt = 0;
		if (n_skipped)
			*n_skipped = 0;
		return rc;
	}
	rc = px__import_data(path, data, len, want_tri, xyz, nv, tri, nt,
			     n_skipped, msg, msg_cap);
	free(data);
	return rc;
}

/* fmemopen wants at least one byte; an empty file never gets that far. */
FILE *px__mem_stream(const char *path, char *data, size_t len, char *msg, size_t msg_cap)
{
	FILE *f = len ? fmemopen(data, len, "rb") : NULL;
	if (!f)
		snprintf(msg, msg_cap, "%s: %s", path,
			 len ? strerror(errno) : "empty file");
	return f;
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

unsigned long long px__ply_uint(const unsigned char *b, int size, int big)
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
	unsigned long long u = px__ply_uint(b, pp->size, big);
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

int px__num_ok(const char *t)
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
		if (!px__num_ok(tok))
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
		nitems = px__ply_uint(b, pp->csize, big);
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
		v = px__ply_uint(b, pp->size, big);
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

int px__ply_file(const char *path, const char *data, size_t len)
{
	int magic = len >= 4 && memcmp(data, "ply", 3) == 0 &&
		    (data[3] == '\n' || data[3] == '\r');
	return magic || px__ends_with_ci(path, ".ply");
}

int px__ply_read(const char *path, char *data, size_t len, int want_tri, double **xyz,
		 size_t *nv, char *msg, size_t msg_cap)
{
	unsigned long long nf = 0;
	FILE *f = px__mem_stream(path, data, len, msg, msg_cap);
	int rc;
	*xyz = NULL;
	*nv = 0;
	if (!f)
		return PX_E_IO;
	rc = ply_validate(path, f, len, xyz, nv, &nf, msg, msg_cap);
	fclose(f);
	if (rc == PX_OK && want_tri && nf == 0) {
		/* vertices only: a cloud (px_load.c looks for these words) */
		snprintf(msg, msg_cap, "%s: no triangles in the file", path);
		free(*xyz);
		*xyz = NULL;
		*nv = 0;
		rc = PX_E_PARSE;
	}
	return rc;
}
