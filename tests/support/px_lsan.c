/*
 * Sanitizer builds: OpenCASCADE's readers and modelling toolkits keep
 * some allocations for the life of the process (in their libTK*
 * libraries), which LeakSanitizer would report at the exit of every
 * test or tool that read or wrote a STEP or IGES file. Those are the
 * toolkits' own; so is the small buffer libwebsockets 4.1 keeps when
 * it cannot listen (lws_create_context() failing on a port taken: the
 * view's test of that and proxima-run's). Leaks of proxima's code are
 * still reported. Linked into
 * every test, and into the tools of sanitizer builds.
 */
#if defined(__SANITIZE_ADDRESS__)
__attribute__((visibility("default"), used)) const char *
__lsan_default_suppressions(void);

const char *__lsan_default_suppressions(void)
{
	return "leak:libTK\nleak:libwebsockets.so\n";
}
#else
/* ISO C wants a translation unit to declare something. */
typedef int px_lsan_unused;
#endif
