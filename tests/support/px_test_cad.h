/*
 * px_test_cad.h - the CAD parts of the tests: proxima-cadgen (built next
 * to the test binaries, $(BUILD)/bin/) writes them once per test process
 * into a temporary folder, removed by px_test_cad_cleanup(). Tests that
 * use them need the "occt" part (the generator is built with
 * OpenCASCADE only). Failures are test failures (PX_CHECK).
 */
#ifndef PX_TEST_CAD_H
#define PX_TEST_CAD_H

#include <stddef.h>

/* The folder holding every part of proxima-cadgen as STEP and IGES, in
 * millimetres (written on the first call). */
const char *px_test_cad_dir(void);
/* buf = px_test_cad_dir()/name.ext */
void px_test_cad_path(char *buf, size_t cap, const char *name, const char *ext);
/* Run proxima-cadgen with args (a shell word list); its exit status. */
int px_test_cadgen(const char *args);
/* Remove the folder (nothing when it was not made). */
void px_test_cad_cleanup(void);

#endif
