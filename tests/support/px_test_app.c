#include "px_test_app.h"

#include <stdio.h>
#include <string.h>

char px_test_app_notes[16384];

void px_test_app_note(void *user, const char *text)
{
	size_t n = strlen(px_test_app_notes);
	(void)user;
	snprintf(px_test_app_notes + n, sizeof(px_test_app_notes) - n, "%s", text);
}

void px_test_app_record(void *user, const struct px_app_record *r)
{
	struct px_test_recs *rs = user;
	if (rs->n < PX_TEST_APP_RECS) {
		rs->r[rs->n] = *r;
		rs->r[rs->n].compute_ns = 0; /* wall clock: not compared */
		rs->n++;
	}
}
