/*
 * fuzz_util.h - helpers shared by the libFuzzer targets in fuzz/:
 * a reader that takes typed values from the fuzzer's bytes (running out
 * of bytes gives zeros, so every input is usable), and a per-process
 * scratch file for the loaders that read paths (the mesh importer, the
 * text cloud reader, candump replay).
 *
 * The targets are built two ways: with clang -fsanitize=fuzzer by
 * `make fuzz`, and with the normal compiler against fuzz/replay.c, which
 * replays fuzz/regress/<name>/ and fuzz/corpus/<name>/ inside `make test`
 * (and `make sanitize`). A target calls abort() when an invariant of the
 * library breaks, so both builds report it.
 */
#ifndef PX_FUZZ_UTIL_H
#define PX_FUZZ_UTIL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

struct fz {
	const uint8_t *p;
	size_t n;
};

static inline uint64_t fz_bits(struct fz *f, int bytes)
{
	uint64_t v = 0;
	int i;
	for (i = 0; i < bytes; i++) {
		uint8_t b = 0;
		if (f->n) {
			b = *f->p++;
			f->n--;
		}
		v |= (uint64_t)b << (8 * i);
	}
	return v;
}

static inline unsigned fz_u8(struct fz *f) { return (unsigned)fz_bits(f, 1); }
static inline unsigned fz_u16(struct fz *f) { return (unsigned)fz_bits(f, 2); }
static inline uint32_t fz_u32(struct fz *f) { return (uint32_t)fz_bits(f, 4); }

/* A double that is often one of the values parsers and codecs get wrong
 * (zero, signed zero, NaN, infinities, extremes, small scales), else the
 * raw bits of 8 bytes. */
static inline double fz_double(struct fz *f)
{
	static const double special[] = {
		0.0, -0.0, 1.0, -1.0, 0.5, 1e-3, -1e-3, 1e-6, 1e6, -1e6,
		1e300, -1e300, 5e-324, 1e-300, 4294967296.0, -2147483648.0,
		9.2233720368547758e18, 0.0 /* NaN */, 0.0 /* +inf */, 0.0 /* -inf */};
	unsigned sel = fz_u8(f);
	size_t ns = sizeof(special) / sizeof(special[0]);
	if (sel < ns) {
		if (sel == ns - 3)
			return NAN;
		if (sel == ns - 2)
			return INFINITY;
		if (sel == ns - 1)
			return -INFINITY;
		return special[sel];
	}
	if (sel < 192) /* small integers and halves */
		return ((double)(int)fz_u8(f) - 128.0) / (sel & 1 ? 2.0 : 1.0);
	{
		uint64_t b = fz_bits(f, 8);
		double d;
		memcpy(&d, &b, sizeof d);
		return d;
	}
}

/* The bytes that are left, as a NUL-terminated copy (caller frees). */
static inline char *fz_rest_str(struct fz *f, size_t *len)
{
	char *s = malloc(f->n + 1);
	if (!s)
		abort();
	memcpy(s, f->p, f->n);
	s[f->n] = '\0';
	if (len)
		*len = f->n;
	f->p += f->n;
	f->n = 0;
	return s;
}

/* Write data to this process's scratch file with the given suffix (the
 * loaders choose the format by name) and return its path. The file is
 * removed at exit. */
static char fz_path_[256];
static void fz_cleanup_(void)
{
	if (fz_path_[0])
		unlink(fz_path_);
}

static inline const char *fz_file(const char *suffix, const uint8_t *data,
				  size_t size)
{
	const char *dir = getenv("TMPDIR");
	FILE *fp;
	if (!fz_path_[0])
		atexit(fz_cleanup_);
	else
		unlink(fz_path_);
	snprintf(fz_path_, sizeof fz_path_, "%s/px_fuzz_%ld%s",
		 dir && *dir ? dir : "/tmp", (long)getpid(), suffix);
	fp = fopen(fz_path_, "wb");
	if (!fp)
		abort();
	if (size && fwrite(data, 1, size, fp) != size)
		abort();
	if (fclose(fp) != 0)
		abort();
	return fz_path_;
}

/* A message must be a terminated single line that says something. */
static inline void fz_check_msg(const char *msg, size_t cap)
{
	if (!memchr(msg, '\0', cap) || !msg[0] || strchr(msg, '\n'))
		abort();
}

#endif
