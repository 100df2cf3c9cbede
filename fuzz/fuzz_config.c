/*
 * libFuzzer target: YAML loading and the whole config schema from memory.
 * Every input must either load or fail with at least one one-line
 * message; nothing may crash, leak or read out of bounds.
 * Seeds: fuzz/corpus/config. By hand:
 *   clang -g -O1 -fsanitize=fuzzer,address,undefined -std=c11 -D_GNU_SOURCE \
 *     -Icore -Iconfig fuzz/fuzz_config.c config/px_config*.c core/px_*.c -lyaml -lm \
 *     -lpthread -o fuzz_config && ./fuzz_config -max_len=4096 fuzz/corpus/config
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "px_config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	static struct px_config_diag diag;
	struct px_config *cfg = NULL;
	int rc = px_config_load_mem("fuzz.yaml", data, size, &cfg, &diag);
	int i;
	if (rc == PX_OK) {
		if (!cfg || px_config_diag_total(&diag) != 0)
			abort();
		/* Touch what the loader handed out. */
		for (i = 0; (size_t)i < cfg->n_devices; i++)
			if (!cfg->devices[i].name)
				abort();
	} else {
		if (cfg || px_config_diag_total(&diag) == 0)
			abort();
		for (i = 0; i < diag.count; i++)
			if (!memchr(diag.errors[i].msg, '\0',
				    sizeof(diag.errors[i].msg)) ||
			    strchr(diag.errors[i].msg, '\n'))
				abort();
	}
	px_config_free(cfg);
	return 0;
}
