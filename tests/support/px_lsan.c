/*
 * Sanitizer builds: OpenCASCADE's readers and modelling toolkits keep
 * some allocations for the life of the process (in their libTK*
 * libraries), which LeakSanitizer would report at the exit of every
 * test or tool that read or wrote a STEP or IGES file. Those are the
 * toolkits' own; leaks of proxima's code are still reported. Linked into
 * every test, and into the tools of sanitizer builds.
 */
#if defined(__SANITIZE_ADDRESS__)
__attribute__((visibility("default"), used)) const char *
__lsan_default_suppressions(void);

const char *__lsan_default_suppressions(void)
{
	return "leak:libTK\n";
}
#else
/* ISO C wants a translation unit to declare something. */
typedef int px_lsan_unused;
#endif
