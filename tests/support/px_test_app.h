/*
 * px_test_app.h - what the tests of the app (app/px_app.h) share: the
 * notes the app writes (px_app_options.note), collected in one buffer,
 * and the telemetry records it hands out (px_app_options.record), kept
 * with their wall-clock compute time zeroed so that runs compare.
 */
#ifndef PX_TEST_APP_H
#define PX_TEST_APP_H

#include <stddef.h>

#include "px_app.h"

#define PX_TEST_APP_RECS 4096

struct px_test_recs {
	struct px_app_record r[PX_TEST_APP_RECS];
	size_t n;
};

/* The notes of the app since the caller last emptied it. */
extern char px_test_app_notes[16384];

/* px_app_options.note: appends text to px_test_app_notes. */
void px_test_app_note(void *user, const char *text);
/* px_app_options.record with user a struct px_test_recs: keeps up to
 * PX_TEST_APP_RECS records, compute_ns zeroed (the wall clock). */
void px_test_app_record(void *user, const struct px_app_record *r);

#endif
