#!/bin/sh
# Build the guest's initramfs (an uncompressed newc cpio): static busybox,
# the prepared kernel modules, the project's device test programs and tools
# from BUILD with the shared libraries ldd names, glibc's UTF-16 gconv
# module (hidapi-libusb converts USB strings with iconv), the test runner
# and the guest scripts.
# usage: mkinitrd.sh VMDIR OUT.cpio SRC=DEST...  (programs and scripts; DEST
# is their absolute path in the guest). VMDIR/tests.list, if there, is the
# guest's list of tests to run.
set -eu
vmdir=$1 out=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
root=$(mktemp -d "$vmdir/initrd.XXXXXX")
trap 'rm -rf "$root"' EXIT
mkdir -p "$root/bin" "$root/sbin" "$root/proc" "$root/sys" "$root/dev" \
	"$root/tmp" "$root/run" "$root/lib/modules" "$root/px/vm" "$root/etc"
cp /bin/busybox "$root/bin/busybox"
ln -s busybox "$root/bin/sh"
# a console node before devtmpfs is mounted, for the kernel's first output
mknod -m 600 "$root/dev/console" c 5 1
cp "$vmdir"/kernel/modules/*.ko "$vmdir/kernel/modules/load.list" "$root/lib/modules/"
[ -f "$vmdir/kernel/no-gpio-sim" ] && cp "$vmdir/kernel/no-gpio-sim" "$root/px/vm/"
cp "$here/init" "$root/init"
chmod 755 "$root/init"
cp "$here/guest.sh" "$here/guest_probe.sh" "$here/setup_report.sh" \
	"$here/guest_e2e.sh" "$here/e2e.yaml" "$root/px/vm/"
cp "$vmdir/tests.list" "$root/px/vm/tests.list"
# the report descriptor of the USB HID gadget: the built-in "haptic" codec
# map (report 1 in: x, y, z int32, 4 buttons; report 2 out: 3 x int16)
printf '\005\001\011\010\241\001\205\001\011\060\011\061\011\062\027\000\000\000\200\047\377\377\377\177\165\040\225\003\201\002\005\011\031\001\051\004\025\000\045\001\165\001\225\004\201\002\165\004\225\001\201\001\205\002\006\000\377\011\001\026\000\200\046\377\177\165\020\225\003\221\002\300' \
	>"$root/px/vm/haptic.rd"
# a UHID_CREATE2 event (struct uhid_event, packed; the kernel zeroes what
# a short write leaves out) for a uhid device 1234:0002 with that layout
rdlen=$(wc -c <"$root/px/vm/haptic.rd")
{
	printf '\013\000\000\000proxima uhid haptic'
	head -c $((128 - 19 + 64 + 64)) /dev/zero
	printf "\\$(printf %03o $((rdlen % 256)))\\$(printf %03o $((rdlen / 256)))"
	printf '\003\000\064\022\000\000\002\000\000\000'
	head -c 8 /dev/zero
	cat "$root/px/vm/haptic.rd"
} >"$root/px/vm/uhid_create.bin"
libs=$(mktemp)
for a in "$@"; do
	f=${a%%=*} d=${a#*=}
	mkdir -p "$root$(dirname "$d")"
	cp "$f" "$root$d"
	case "$f" in
	*.sh) ;;
	*) ldd "$f" | sed -n 's/.*=> \(\/[^ ]*\).*/\1/p; s/^[[:space:]]*\(\/[^ ]*\) .*/\1/p' >>"$libs"
	   strip --strip-debug "$root$d" 2>/dev/null || true ;;
	esac
done
gconv=$(ls -d /usr/lib/x86_64-linux-gnu/gconv 2>/dev/null || true)
for l in $(sort -u "$libs") ${gconv:+$gconv/UTF-16.so}; do
	mkdir -p "$root$(dirname "$l")"
	cp -L "$l" "$root$l"
done
rm -f "$libs"
if [ -n "$gconv" ]; then
	cp "$gconv/gconv-modules" "$root$gconv/" 2>/dev/null || true
	[ -d "$gconv/gconv-modules.d" ] && cp -r "$gconv/gconv-modules.d" "$root$gconv/"
fi


(cd "$root" && find . | cpio -o -H newc --quiet) >"$out.tmp"
mv "$out.tmp" "$out"
