#include "px_base.h"

struct err_entry {
	const char *name;
	const char *text;
};

/* Indexed by -code; keep in step with enum px_err. */
static const struct err_entry err_table[PX_E__COUNT] = {
	{"PX_OK", "success"},
	{"PX_E_INVAL", "invalid argument"},
	{"PX_E_NOMEM", "out of memory at setup"},
	{"PX_E_NOSPC", "buffer or capacity too small"},
	{"PX_E_RANGE", "value out of range"},
	{"PX_E_NAN", "NaN or infinite value"},
	{"PX_E_IO", "input/output error"},
	{"PX_E_PARSE", "malformed input"},
	{"PX_E_UNSUPPORTED", "not supported"},
	{"PX_E_NOTFOUND", "not found"},
	{"PX_E_BUSY", "resource busy"},
	{"PX_E_TIMEOUT", "timed out"},
	{"PX_E_AGAIN", "nothing available, try again"},
	{"PX_E_PERM", "permission denied"},
	{"PX_E_NODEV", "no such device or device unplugged"},
	{"PX_E_STATE", "wrong state for this call"},
	{"PX_E_DEGENERATE", "degenerate geometry"},
	{"PX_E_NOCONV", "iteration did not converge"},
	{"PX_E_OVERFLOW", "counter or size overflow"},
	{"PX_E_CORRUPT", "corrupted data"},
};

static const struct err_entry *lookup(int err)
{
	if (err > 0)
		err = -err;
	if (err <= -PX_E__COUNT)
		return 0;
	return &err_table[-err];
}

const char *px_strerror(int err)
{
	const struct err_entry *e = lookup(err);
	return e ? e->text : "unknown error";
}

const char *px_strerror_name(int err)
{
	const struct err_entry *e = lookup(err);
	return e ? e->name : "PX_E_UNKNOWN";
}

const char *px_version(void)
{
	return PX_VERSION_STRING;
}

int px_version_number(void)
{
	return PX_VERSION_NUMBER;
}
