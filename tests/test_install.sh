#!/bin/sh
# Install into a scratch DESTDIR with PREFIX=/usr, then build a tiny
# consumer through `pkg-config --cflags --libs proxima`, shared and static,
# and run it. Prints a harness-style summary line.
set -u
name=test_install
if [ "${SAN:-}" = 1 ]; then
	echo "skip install: sanitizer libraries cannot be linked into a plain consumer"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
check() { # description, command...
	d=$1; shift
	if "$@" >"$tmp/out" 2>&1; then
		echo "ok   $d"; pass=$((pass + 1))
	else
		echo "FAIL $d"; sed 's/^/    /' "$tmp/out"; fail=$((fail + 1))
	fi
}
check "make install DESTDIR PREFIX=/usr" \
	${MAKE:-make} -s install DESTDIR="$tmp/root" PREFIX=/usr BUILD="${BUILD:-build}"
# The installed tools use the system allocator: the tests' heap counter
# (libproxima-alloc-count.so) is neither linked in nor installed.
own_malloc() {
	for f in "$tmp/root/usr/bin/"proxima-*; do
		if nm "$f" | grep -qE ' [TtWw] (malloc|free)$'; then
			echo "$f defines malloc/free"; return 1; fi
	done
	! ls "$tmp/root/usr/lib/" | grep -q alloc-count
}
check "installed tools carry no heap counter" own_malloc
cat >"$tmp/consumer.c" <<'C'
#include <proxima/px.h>
#include <stdio.h>
#include <string.h>
int main(void)
{
	static unsigned char buf[256];
	struct px_arena a;
	if (strcmp(px_version(), PX_VERSION_STRING) != 0)
		return 1;
	if (px_arena_init(&a, buf, sizeof(buf)) != PX_OK)
		return 2;
	if (!px_arena_alloc(&a, 100, 0) || px_arena_alloc(&a, 1000, 0))
		return 3;
	printf("%s %s\n", px_version(), px_strerror(PX_E_NOSPC));
	return 0;
}
C
export PKG_CONFIG_SYSROOT_DIR="$tmp/root"
export PKG_CONFIG_PATH="$tmp/root/usr/lib/pkgconfig"
# The scratch tree first, then the system directories for the packages
# proxima.pc requires (Requires.private, e.g. yaml-0.1).
export PKG_CONFIG_LIBDIR="$tmp/root/usr/lib/pkgconfig:$(pkg-config --variable pc_path pkg-config)"
check "pkg-config knows proxima" pkg-config --exists proxima
cflags=$(pkg-config --cflags proxima) libs=$(pkg-config --libs proxima)
slibs=$(pkg-config --static --libs proxima)
check "consumer compiles against the shared library" \
	${CC:-cc} -std=c11 -Wall -Werror $cflags "$tmp/consumer.c" -o "$tmp/consumer" $libs
check "shared consumer runs" env LD_LIBRARY_PATH="$tmp/root/usr/lib" "$tmp/consumer"
# Every installed header stands alone as <proxima/px_*.h> (the headers
# include each other by plain name, which resolves in their own folder).
selfcheck() {
	for h in "$tmp/root/usr/include/proxima/"*.h; do
		printf '#include <proxima/%s>\n' "$(basename "$h")" >"$tmp/one.c"
		${CC:-cc} -std=c11 -Wall -Werror $cflags -c "$tmp/one.c" -o "$tmp/one.o" ||
			{ echo "$(basename "$h") does not compile alone"; return 1; }
	done
}
check "each installed header compiles alone" selfcheck
check "consumer links statically" \
	${CC:-cc} -std=c11 -Wall -Werror $cflags "$tmp/consumer.c" -o "$tmp/consumer_static" \
	"$tmp/root/usr/lib/libproxima.a" $slibs
check "static consumer runs" "$tmp/consumer_static"
# The optional parts' libraries come with the static library through
# Libs.private (OpenCASCADE and the C++ runtime have no .pc of their own).
cat >"$tmp/cad.c" <<'C'
#include <proxima/px_cad.h>
#include <proxima/px_features.h>
#include <stdio.h>
int main(int argc, char **argv)
{
	struct px_cad *c;
	char msg[256];
	int rc = px_cad_load(argc > 1 ? argv[1] : "", NULL, &c, msg, sizeof msg);
	if (!PX_HAVE_OCCT)
		return rc != PX_E_UNSUPPORTED;
	if (rc != PX_OK) {
		puts(msg);
		return 1;
	}
	printf("%d faces\n", px_cad_desc(c)->n_faces);
	px_cad_free(c);
	return 0;
}
C
check "a STEP-reading consumer links statically" \
	${CC:-cc} -std=c11 -Wall -Werror $cflags "$tmp/cad.c" -o "$tmp/cad_static" \
	"$tmp/root/usr/lib/libproxima.a" $slibs
check "static STEP-reading consumer runs" "$tmp/cad_static" config/examples/parts/filleted_block.step
check "a STEP-reading consumer links with the shared library" \
	${CC:-cc} -std=c11 -Wall -Werror $cflags "$tmp/cad.c" -o "$tmp/cad_shared" $libs
check "shared STEP-reading consumer runs" \
	env LD_LIBRARY_PATH="$tmp/root/usr/lib" "$tmp/cad_shared" config/examples/parts/filleted_block.step
check "uninstall removes everything" \
	sh -c "${MAKE:-make} -s uninstall DESTDIR='$tmp/root' PREFIX=/usr BUILD='${BUILD:-build}' &&
	       test -z \"\$(find '$tmp/root' -type f -o -type l)\""
echo "$name: $pass passed, $fail failed, 0 skipped"
[ "$fail" -eq 0 ]
