#!/bin/sh
# The library with every optional part left out (WITH_DEVICES=0
# WITH_ASSIMP=0 WITH_YAML=0 WITH_OCCT=0 WITH_XML=0 WITH_DDS=0
# WITH_VIEW=0), built
# into its own directory and installed into a scratch DESTDIR: it needs
# libc, libm and pthread alone, its proxima.pc requires nothing,
# px_features.h says so, the examples link with only -lproxima -lm
# -lpthread and run, and each left-out part answers PX_E_UNSUPPORTED with
# a message naming its library.
# Prints a harness-style summary line.
set -u
name=test_build_minimal
if [ "${SAN:-}" = 1 ]; then
	echo "skip minimal build: sanitizer libraries cannot be linked into a plain consumer"
	echo "$name: 0 passed, 0 failed, 1 skipped"
	exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0 skip=0
check() { # description, command...
	d=$1; shift
	if "$@" >"$tmp/out" 2>&1; then
		echo "ok   $d"; pass=$((pass + 1))
	else
		echo "FAIL $d"; sed 's/^/    /' "$tmp/out"; fail=$((fail + 1))
	fi
}
full=${BUILD:-build}
min="$tmp/build"
root="$tmp/root"
off="WITH_DEVICES=0 WITH_ASSIMP=0 WITH_YAML=0 WITH_OCCT=0 WITH_XML=0 WITH_DDS=0 WITH_VIEW=0"
# The full build's objects are the same code: starting from them, only
# the parts' *_none.c files compile here.
mkdir -p "$min"
[ -d "$full/obj" ] && cp -a "$full/obj" "$min/"
# shellcheck disable=SC2086
check "make install with every optional part off" \
	env -u MAKEFLAGS -u MFLAGS ${MAKE:-make} -s install $off BUILD="$min" \
	DESTDIR="$root" PREFIX=/usr
inc="$root/usr/include" lib="$root/usr/lib"
check "px_features.h: every part 0" \
	sh -c "! grep -q 'PX_HAVE_.* 1' '$inc/proxima/px_features.h' &&
	       grep -q 'PX_HAVE_YAML 0' '$inc/proxima/px_features.h'"
check "proxima.pc requires nothing" grep -qx 'Requires.private: *' "$lib/pkgconfig/proxima.pc"
nolibs() { # the shared library needs no optional library
	ldd "$lib/libproxima.so" | grep -E 'yaml|hidapi|usb|socketcan|gpiod|assimp|libTK|stdc\+\+|xml2|ddsc' && return 1
	nm -u "$lib/libproxima.a" | grep -E ' (yaml_|hid_|libusb_|can_(do|get|set)_|gpiod_|aiImport|_Z|xml|dds_)' && return 1
	return 0
}
check "libproxima uses no optional library" nolibs
# The Python package, where this machine builds it: installed under the
# prefix's dist-packages, importable there, answering through the
# installed library (LD_LIBRARY_PATH: the rpath names /usr/lib).
py=$(${MAKE:-make} -s --no-print-directory print-PYTHON)
if [ "$(${MAKE:-make} -s --no-print-directory print-WITH_PYTHON)" = 1 ]; then
	pydir=$(ls -d "$lib"/python3.*/dist-packages 2>/dev/null | head -n 1)
	check "make install put the Python package under the prefix" test -f "$pydir/proxima/__init__.py"
	check "the installed package imports and answers" env LD_LIBRARY_PATH="$lib" \
		PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 "$py" -c \
		'import proxima; d = proxima.sphere(1.0).distance([[3.0, 0.0, 0.0]]); assert d[0] == 2.0, d; print(proxima.__file__)'
else
	echo "skip Python package: not built here (make print-WITH_PYTHON)"; skip=$((skip + 1))
fi
for ex in distance haptic_loop can_arm_distances; do
	check "examples/$ex.c links with -lproxima -lm -lpthread" \
		${CC:-cc} -std=c11 -Wall -Wextra -Werror -I"$inc" "examples/$ex.c" \
		-o "$tmp/$ex" -L"$lib" -lproxima -lm -lpthread
	check "examples/$ex runs" env LD_LIBRARY_PATH="$lib" "$tmp/$ex"
	check "examples/$ex links statically" \
		${CC:-cc} -std=c11 -Wall -Wextra -Werror -I"$inc" "examples/$ex.c" \
		-o "$tmp/$ex-static" "$lib/libproxima.a" -lm -lpthread
	check "static examples/$ex runs" "$tmp/$ex-static"
done
cat >"$tmp/parts.c" <<'C'
/* Each left-out part: PX_E_UNSUPPORTED and a message naming its library. */
#include <proxima/px.h>
#include <proxima/px_features.h>
#include <proxima/px_mesh.h>
#include <proxima/px_cad.h>
#include <proxima/px_urdf.h>
#include <proxima/px_bridge.h>
#include <proxima/px_view.h>
#include <stdio.h>
#include <string.h>
static int says(const char *what, int rc, const char *msg, const char *lib)
{
	printf("%s: %s: %s\n", what, px_strerror(rc), msg);
	return rc == PX_E_UNSUPPORTED && strstr(msg, lib) ? 0 : 1;
}
int main(int argc, char **argv)
{
	static struct px_config_diag diag;
	struct px_dev_config dc;
	struct px_hid_config hc = {0};
	struct px_usb_config uc;
	struct px_gpio_config gc;
	struct px_config *cfg;
	struct px_model *m;
	struct px_cad *cad;
	struct px_dev *d;
	char msg[256];
	int bad = 0, rc;
	(void)argc;
	memset(&uc, 0, sizeof uc);
	memset(&gc, 0, sizeof gc);
	px_dev_config_default(&dc);
	dc.name = "dev";
	rc = px_config_load_file(argv[1], &cfg, &diag);
	bad |= says("config", rc, diag.count ? diag.errors[0].msg : "", "libyaml");
	rc = px_hid_create(&dc, &hc, &d, msg, sizeof msg);
	bad |= says("hid", rc, msg, "hidapi");
	rc = px_usb_create(&dc, &uc, &d, msg, sizeof msg);
	bad |= says("usb", rc, msg, "libusb");
	rc = px_gpiod_create(&dc, &gc, &d, NULL, msg, sizeof msg);
	bad |= says("gpio", rc, msg, "libgpiod");
	rc = px_can_iface_set_bitrate("lo", 500000, 0, NULL, msg, sizeof msg);
	bad |= says("can bitrate", rc, msg, "libsocketcan");
	rc = px_mesh_load(argv[2], NULL, NULL, &m);
	bad |= rc != PX_E_UNSUPPORTED;
	printf("mesh: %s\n", px_strerror(rc));
	rc = px_cad_load(argv[3], NULL, &cad, msg, sizeof msg);
	bad |= says("cad", rc, msg, "OpenCASCADE") || cad != NULL ||
	       px_cad_desc(cad) != NULL;
	{
		struct px_urdf *u = NULL;
		struct px_urdf_error ue;
		rc = px_urdf_load_mem("arm.urdf", "<robot/>", 8, NULL, &u, &ue);
		bad |= says("urdf", rc, ue.msg, "libxml2") || u != NULL;
	}
	{
		struct px_bridge_config bc;
		struct px_bridge *b = NULL;
		px_bridge_config_default(&bc);
		rc = px_bridge_create(&bc, &b, msg, sizeof msg);
		bad |= says("bridge", rc, msg, "Cyclone DDS") || b != NULL;
	}
	{
		struct px_view_options vo;
		struct px_view *v = NULL;
		px_view_options_default(&vo);
		vo.port = 1;
		vo.web_root = ".";
		rc = px_view_create(&vo, &v, msg, sizeof msg);
		bad |= says("view", rc, msg, "libwebsockets") || v != NULL;
	}
	return bad || PX_HAVE_YAML || PX_HAVE_HIDAPI || PX_HAVE_OCCT || PX_HAVE_XML ||
	       PX_HAVE_DDS || PX_HAVE_VIEW;
}
C
check "a program using the left-out parts links" \
	${CC:-cc} -std=c11 -Wall -Wextra -Werror -I"$inc" "$tmp/parts.c" \
	-o "$tmp/parts" "$lib/libproxima.a" -lm -lpthread
check "left-out parts say PX_E_UNSUPPORTED and name their library" \
	"$tmp/parts" config/examples/haptic_sim.yaml config/examples/scenes/knob.stl \
	config/examples/parts/filleted_block.step
check "proxima-run --check names the missing YAML loader" \
	sh -c "! '$root/usr/bin/proxima-run' --check config/examples/haptic_sim.yaml >'$tmp/run.out' 2>&1;
	       grep -q 'built without libyaml' '$tmp/run.out'"
echo "$name: $pass passed, $fail failed, $skip skipped"
[ "$fail" -eq 0 ]
