/*
 * px_base.h - what every proxima module shares: the export macro, the
 * library version, and the error codes.
 *
 * Every function in proxima that can fail returns an int: zero or a
 * positive count on success, a negative enum px_err value on failure.
 * px_strerror() maps a code to a static string, so reporting an error
 * never allocates and is safe inside a real-time cycle.
 *
 * Memory and real-time rules: nothing here allocates; everything here is
 * RT-safe.
 */
#ifndef PX_BASE_H
#define PX_BASE_H

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__) && !defined(PX_STATIC_ONLY)
#define PX_API __attribute__((visibility("default")))
#else
#define PX_API
#endif

#define PX_VERSION_MAJOR 0
#define PX_VERSION_MINOR 1
#define PX_VERSION_PATCH 0
#define PX_VERSION_STRING "0.1.0"
/* One integer that orders versions: 0x00MMmmpp. */
#define PX_VERSION_NUMBER \
	((PX_VERSION_MAJOR << 16) | (PX_VERSION_MINOR << 8) | PX_VERSION_PATCH)

/*
 * Error codes. Values are stable (they are part of the ABI and may be
 * logged); new codes are appended. PX_E__COUNT is not an error.
 */
enum px_err {
	PX_OK = 0,
	PX_E_INVAL = -1,       /* invalid argument (NULL, out of range) */
	PX_E_NOMEM = -2,       /* setup-time allocation failed */
	PX_E_NOSPC = -3,       /* caller buffer or fixed capacity too small */
	PX_E_RANGE = -4,       /* value outside its allowed range */
	PX_E_NAN = -5,         /* NaN or infinity where a finite number is needed */
	PX_E_IO = -6,          /* input/output error (file, device) */
	PX_E_PARSE = -7,       /* malformed file, config or frame */
	PX_E_UNSUPPORTED = -8, /* valid input this build cannot handle */
	PX_E_NOTFOUND = -9,    /* file, device, key or entity not found */
	PX_E_BUSY = -10,       /* resource held by someone else */
	PX_E_TIMEOUT = -11,    /* a deadline passed */
	PX_E_AGAIN = -12,      /* nothing available now; try again later */
	PX_E_PERM = -13,       /* privilege refused */
	PX_E_NODEV = -14,      /* device unplugged or absent */
	PX_E_STATE = -15,      /* object not in a state that allows the call */
	PX_E_DEGENERATE = -16, /* geometry too degenerate to answer */
	PX_E_NOCONV = -17,     /* iteration did not converge within its bound */
	PX_E_OVERFLOW = -18,   /* a counter or size would overflow */
	PX_E_CORRUPT = -19,    /* checksum, sequence or framing error */
	PX_E__COUNT = 20
};

/*
 * Static, human-readable description of an error code (negative or
 * positive form accepted). Unknown codes give "unknown error".
 * @note RT-safe.
 */
PX_API const char *px_strerror(int err);

/*
 * Symbolic name of an error code, e.g. "PX_E_NOSPC".
 * @note RT-safe.
 */
PX_API const char *px_strerror_name(int err);

/* Version of the library actually linked, as "MAJOR.MINOR.PATCH". */
PX_API const char *px_version(void);

/* PX_VERSION_NUMBER of the library actually linked. */
PX_API int px_version_number(void);

#ifdef __cplusplus
}
#endif

#endif
