#!/bin/sh
# Prepare the VM suite once per machine: host packages, Debian's kernel
# and the modules the guest needs, and gpio-sim built out of tree (it is
# not part of Debian's 6.1 kernel). Everything lands in VMDIR (default
# build/vm); a second run finds VMDIR/kernel/ready and does nothing.
#
# Exit status: 0 ready, 77 a host facility is missing (the reason is on
# stderr and in VMDIR/skip-reason), other: a real failure.
set -u
vmdir=${1:-${BUILD:-build}/vm}
mkdir -p "$vmdir" && vmdir=$(cd "$vmdir" && pwd) || exit 1
kdir=$vmdir/kernel
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
say() { echo "vm prepare: $*" >&2; }
skip() { say "SKIP: $*"; mkdir -p "$vmdir"; echo "$*" >"$vmdir/skip-reason"; exit 77; }
die() { say "FAILED: $*"; exit 1; }

[ -f "$kdir/ready" ] && exit 0
mkdir -p "$vmdir"
rm -f "$vmdir/skip-reason"
[ "$(uname -m)" = x86_64 ] || skip "the guest is x86_64 and this host is $(uname -m)"
command -v apt-get >/dev/null 2>&1 || skip "no apt-get: the VM suite needs Debian's kernel packages"

# Host tools. tools/install-deps.sh installs as root and fails, saying
# what to run, as a user.
sh "$top/tools/install-deps.sh" qemu-system-x86 busybox-static cpio kmod ||
	skip "host packages qemu-system-x86 busybox-static cpio kmod are missing and could not be installed"

# The kernel ABI the linux-image-amd64 metapackage depends on now.
resolve_abi() {
	apt-cache depends linux-image-amd64 2>/dev/null |
		sed -n 's/^ *Depends: linux-image-\([0-9][^ ]*\)-amd64$/\1/p' | head -n 1
}
abi=$(resolve_abi)
# empty or stale package lists (a fresh container): refresh once, as root
if [ -z "$abi" ] && [ "$(id -u)" = 0 ]; then
	apt-get update -qq >/dev/null 2>&1
	abi=$(resolve_abi)
fi
[ -n "$abi" ] || skip "apt-cache knows no linux-image-amd64 (no Debian kernel packages in the apt sources)"
kver=$abi-amd64
pkgver=$(apt-cache show "linux-image-$kver" 2>/dev/null | sed -n 's/^Version: //p' | head -n 1)
[ -n "$pkgver" ] || skip "no version of linux-image-$kver is known to apt"
say "guest kernel $kver ($pkgver)"

tmp=$(mktemp -d "$vmdir/prep.XXXXXX") || die "mktemp"
trap 'rm -rf "$tmp"' EXIT
rm -rf "$kdir"
mkdir -p "$kdir/modules"

# ---- kernel and modules (downloaded and unpacked, never installed) --------
fetch() { (cd "$tmp" && apt-get download -q "$1" >/dev/null 2>"$tmp/dl.err"); }
# a 404 from lists older than the mirror: refresh once, as root
fetch "linux-image-$kver=$pkgver" ||
	{ [ "$(id -u)" = 0 ] && apt-get update -qq >/dev/null 2>&1 &&
		fetch "linux-image-$kver=$pkgver"; } ||
	{ cat "$tmp/dl.err" >&2; skip "apt-get download linux-image-$kver failed (no network or mirror?)"; }
dpkg -x "$tmp"/linux-image-*.deb "$tmp/root" || die "dpkg -x linux-image-$kver"
rm -f "$tmp"/linux-image-*.deb
cp "$tmp/root/boot/vmlinuz-$kver" "$kdir/vmlinuz" || die "no vmlinuz-$kver in the package"
# Debian ships no modules.dep; depmod builds it so modprobe can order them.
depmod -b "$tmp/root" "$kver" || die "depmod -b"
: >"$kdir/modules/load.list"
for m in configfs can can-raw can-dev vcan hid uhid hid-generic usb-common \
	usbcore usbhid udc-core dummy_hcd libcomposite usb_f_hid; do
	modprobe -d "$tmp/root" -S "$kver" --show-depends "$m" >"$tmp/dep" 2>&1 ||
		die "module $m: $(cat "$tmp/dep")"
	# "builtin x" lines need nothing; "insmod /path/x.ko opts" in order
	sed -n 's/^insmod \([^ ]*\).*/\1/p' "$tmp/dep" | while read -r ko; do
		b=$(basename "$ko")
		grep -qx "$b" "$kdir/modules/load.list" && continue
		cp "$ko" "$kdir/modules/$b" || exit 1
		echo "$b" >>"$kdir/modules/load.list"
	done || die "copying the modules of $m"
done
rm -rf "$tmp/root"

# ---- gpio-sim, out of tree -------------------------------------------------
# Needs the exact headers of this kernel and its source. When those cannot
# be had the guest runs without gpio-sim and says so (its gpio checks skip).
gpio_note=""
if ! sh "$top/tools/install-deps.sh" "linux-headers-$kver" make gcc; then
	gpio_note="linux-headers-$kver could not be installed"
else
	srcver=$pkgver
	apt-cache show "linux-source-6.1=$srcver" >/dev/null 2>&1 ||
		srcver=$(apt-cache show linux-source-6.1 2>/dev/null | sed -n 's/^Version: //p' | head -n 1)
	if [ -z "$srcver" ]; then
		gpio_note="apt knows no linux-source-6.1"
	elif ! fetch "linux-source-6.1=$srcver"; then
		gpio_note="apt-get download linux-source-6.1=$srcver failed: $(tail -n 1 "$tmp/dl.err")"
	else
		[ "$srcver" = "$pkgver" ] || say "note: linux-source-6.1 $srcver with kernel $pkgver"
		say "building gpio-sim from linux-source-6.1 $srcver"
		mkdir -p "$tmp/src" "$tmp/mod"
		dpkg-deb --fsys-tarfile "$tmp"/linux-source-6.1_*.deb |
			tar -xO ./usr/src/linux-source-6.1.tar.xz |
			tar -xJ -C "$tmp/src" --strip-components=1 \
				linux-source-6.1/drivers/gpio/gpio-sim.c \
				linux-source-6.1/drivers/gpio/gpiolib.h \
				linux-source-6.1/kernel/irq/irq_sim.c ||
			die "extracting gpio-sim from linux-source-6.1"
		rm -f "$tmp"/linux-source-6.1_*.deb
		cp "$tmp/src/drivers/gpio/gpio-sim.c" "$tmp/mod/gpio-sim-main.c"
		cp "$tmp/src/drivers/gpio/gpiolib.h" "$tmp/mod/"
		# irq_to_desc is not exported to modules: the one call that needs it
		# becomes generic_handle_irq, which does the same lookup and handling.
		sed 's/handle_simple_irq(irq_to_desc(\([a-z_]*\)));/generic_handle_irq(\1);/' \
			"$tmp/src/kernel/irq/irq_sim.c" >"$tmp/mod/irq_sim.c"
		grep -q 'irq_to_desc' "$tmp/mod/irq_sim.c" &&
			die "irq_sim.c of linux-source-6.1 $srcver: irq_to_desc use not where expected"
		printf 'obj-m += gpio-sim.o\ngpio-sim-y := gpio-sim-main.o irq_sim.o\n' >"$tmp/mod/Kbuild"
		make -s -C "/usr/src/linux-headers-$kver" M="$tmp/mod" modules >"$tmp/mod.log" 2>&1 ||
			{ cat "$tmp/mod.log" >&2; die "building gpio-sim.ko"; }
		cp "$tmp/mod/gpio-sim.ko" "$kdir/modules/" || die "no gpio-sim.ko"
		echo gpio-sim.ko >>"$kdir/modules/load.list"
	fi
fi
[ -n "$gpio_note" ] && { say "no gpio-sim: $gpio_note"; echo "$gpio_note" >"$kdir/no-gpio-sim"; }
echo "$kver" >"$kdir/ready"
say "ready in $kdir"
