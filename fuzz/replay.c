/*
 * replay.c - runs a fuzz target's LLVMFuzzerTestOneInput on saved inputs
 * without libFuzzer, built with the normal compiler (and so also under
 * ASan/UBSan by `make sanitize`). `make test` runs one such program per
 * target, build/fuzz-replay/fuzz_<name>, which replays every file of
 * fuzz/regress/<name>/ (inputs that once crashed or hung) and
 * fuzz/corpus/<name>/ (the seeds), relative to the current directory.
 * With arguments it replays those files or directories instead.
 *
 * A target aborts on a broken invariant; a crash or a hang (each input
 * has PX_FUZZ_REPLAY_TIMEOUT seconds, default 20) names the input on
 * stderr before the program dies. The last line is the harness summary
 * "fuzz_<name>: N passed, N failed, 0 skipped" (one per input).
 */
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char current[1024];
static unsigned timeout_s = 20;

static void on_signal(int sig)
{
	static const char pre[] = "\nreplay: input ";
	const char *what = sig == SIGALRM ? " hung (timeout)\n"
					  : " crashed (signal)\n";
	ssize_t r;
	r = write(2, pre, sizeof pre - 1);
	r = write(2, current, strlen(current));
	r = write(2, what, strlen(what));
	(void)r;
	signal(sig, SIG_DFL);
	raise(sig == SIGALRM ? SIGABRT : sig);
}

static int replay_file(const char *path)
{
	FILE *f = fopen(path, "rb");
	uint8_t *buf = NULL;
	size_t cap = 0, n = 0;
	if (!f) {
		fprintf(stderr, "replay: %s: %s\n", path, strerror(errno));
		return -1;
	}
	for (;;) {
		size_t got;
		if (n == cap) {
			uint8_t *q;
			cap = cap ? 2 * cap : 4096;
			q = realloc(buf, cap);
			if (!q) {
				fclose(f);
				free(buf);
				return -1;
			}
			buf = q;
		}
		got = fread(buf + n, 1, cap - n, f);
		n += got;
		if (got == 0)
			break;
	}
	fclose(f);
	snprintf(current, sizeof current, "%s", path);
	alarm(timeout_s);
	/* An exact-size copy, so ASan sees a read past the input's end. */
	{
		uint8_t *exact = malloc(n ? n : 1);
		if (!exact) {
			free(buf);
			return -1;
		}
		memcpy(exact, buf, n);
		free(buf);
		LLVMFuzzerTestOneInput(exact, n);
		free(exact);
	}
	alarm(0);
	return 0;
}

static int cmp(const void *a, const void *b)
{
	return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Files of a directory in name order; a missing directory is empty. */
static int replay_path(const char *path, int *passed, int *failed)
{
	struct stat st;
	DIR *d;
	struct dirent *e;
	char **names = NULL;
	size_t nn = 0, cn = 0, i;

	if (stat(path, &st) != 0)
		return 0;
	if (!S_ISDIR(st.st_mode)) {
		if (replay_file(path) == 0)
			(*passed)++;
		else
			(*failed)++;
		return 0;
	}
	d = opendir(path);
	if (!d)
		return -1;
	while ((e = readdir(d))) {
		char full[1024];
		if (e->d_name[0] == '.')
			continue;
		snprintf(full, sizeof full, "%s/%s", path, e->d_name);
		if (stat(full, &st) != 0 || !S_ISREG(st.st_mode))
			continue;
		if (nn == cn) {
			char **q;
			cn = cn ? 2 * cn : 64;
			q = realloc(names, cn * sizeof *names);
			if (!q)
				abort();
			names = q;
		}
		names[nn] = strdup(full);
		if (!names[nn])
			abort();
		nn++;
	}
	closedir(d);
	if (nn)
		qsort(names, nn, sizeof *names, cmp);
	for (i = 0; i < nn; i++) {
		if (replay_file(names[i]) == 0)
			(*passed)++;
		else
			(*failed)++;
		free(names[i]);
	}
	free(names);
	return 0;
}

int main(int argc, char **argv)
{
	const char *base = strrchr(argv[0], '/');
	const char *name, *env = getenv("PX_FUZZ_REPLAY_TIMEOUT");
	int passed = 0, failed = 0, i;

	base = base ? base + 1 : argv[0];
	name = strncmp(base, "fuzz_", 5) == 0 ? base + 5 : base;
	if (env && atoi(env) > 0)
		timeout_s = (unsigned)atoi(env);
	signal(SIGALRM, on_signal);
	signal(SIGSEGV, on_signal);
	signal(SIGBUS, on_signal);
	signal(SIGFPE, on_signal);
	signal(SIGABRT, on_signal);
	if (argc > 1) {
		for (i = 1; i < argc; i++)
			replay_path(argv[i], &passed, &failed);
	} else {
		char dir[512];
		int before;
		snprintf(dir, sizeof dir, "fuzz/regress/%s", name);
		before = passed;
		replay_path(dir, &passed, &failed);
		printf("%s: %d regression inputs replayed\n", base, passed - before);
		snprintf(dir, sizeof dir, "fuzz/corpus/%s", name);
		before = passed;
		replay_path(dir, &passed, &failed);
		printf("%s: %d seed inputs replayed\n", base, passed - before);
		if (passed + failed == 0) {
			printf("%s: no inputs under fuzz/regress/%s or fuzz/corpus/%s "
			       "(run from the source tree)\n", base, name, name);
			failed = 1;
		}
	}
	printf("%s: %d passed, %d failed, 0 skipped\n", base, passed, failed);
	return failed ? 1 : 0;
}
