#!/bin/sh
# tests/vm/prepare.sh BUILD - prepares what the VM tests need, cached under
# BUILD/vm: Debian's kernel (uncompressed vmlinux, the modules the tests
# load), an initramfs (busybox-static + tests/vm/init), and the guest test
# program BUILD/vm/vm_devices. The guest runs the project's binaries from
# the host's own file system, shared read-only over 9p, so nothing else is
# copied. Prints "SKIP: reason" and exits 3 when something is missing.
set -eu
# Byte patterns below (the xz magic) need the C locale: in a UTF-8 locale
# grep -P does not match the raw bytes.
export LC_ALL=C
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
VM="$ROOT/$BUILD/vm"
mkdir -p "$VM"

skip() { echo "SKIP: $*"; exit 3; }
command -v qemu-system-x86_64 >/dev/null 2>&1 || skip "qemu-system-x86_64 missing (apt-get install qemu-system-x86)"
[ -x /bin/busybox ] || skip "/bin/busybox missing (apt-get install busybox-static)"
busybox 2>&1 | grep -q 'Currently defined functions' || skip "busybox is not usable"
command -v cpio >/dev/null 2>&1 || skip "cpio missing (apt-get install cpio)"
command -v depmod >/dev/null 2>&1 || [ -x /sbin/depmod ] || skip "depmod missing (apt-get install kmod)"
PATH="$PATH:/sbin:/usr/sbin"

# ---- kernel: the versioned package behind linux-image-amd64
if [ ! -s "$VM/kver" ]; then
    KPKG=$(apt-cache depends linux-image-amd64 2>/dev/null | sed -n 's/.*Depends: \(linux-image-[0-9][^ ]*\)/\1/p' | head -n1)
    [ -n "$KPKG" ] || skip "cannot resolve linux-image-amd64 (run apt-get update)"
    echo "$KPKG" | sed 's/^linux-image-//' > "$VM/kver.tmp"
    mv "$VM/kver.tmp" "$VM/kver"
fi
KV=$(cat "$VM/kver")
if [ ! -s "$VM/vmlinux" ] || [ ! -d "$VM/kernel/lib/modules/$KV" ]; then
    deb=$(ls "$VM"/linux-image-"$KV"_*.deb 2>/dev/null | head -n1 || true)
    if [ -z "$deb" ]; then
        (cd "$VM" && apt-get download "linux-image-$KV" >/dev/null 2>&1) ||
            skip "cannot download linux-image-$KV"
        deb=$(ls "$VM"/linux-image-"$KV"_*.deb | head -n1)
    fi
    rm -rf "$VM/kernel"
    dpkg-deb -x "$deb" "$VM/kernel"
    depmod -b "$VM/kernel" "$KV"
    # the uncompressed kernel (an ELF with a PVH note) boots fastest
    off=$(grep -obUaP '\xfd7zXZ\x00' "$VM/kernel/boot/vmlinuz-$KV" | head -n1 | cut -d: -f1)
    [ -n "$off" ] || skip "no xz payload in vmlinuz-$KV"
    tail -c +"$((off + 1))" "$VM/kernel/boot/vmlinuz-$KV" | xz -dc > "$VM/vmlinux.tmp" 2>/dev/null || true
    [ -s "$VM/vmlinux.tmp" ] || skip "cannot decompress vmlinuz-$KV"
    mv "$VM/vmlinux.tmp" "$VM/vmlinux"
    rm -f "$deb"
fi

# ---- a short sample sequence for `egofuse run` in the guest (the scene's
# model, animation, lighting and virtual images; the cameras are vivid's)
if [ ! -s "$VM/samples/scene.txt" ]; then
    [ -x "$ROOT/$BUILD/gen_samples" ] || skip "$BUILD/gen_samples is not built"
    "$ROOT/$BUILD/gen_samples" --out "$VM/samples" --frames 2 >/dev/null ||
        skip "cannot generate the samples for the guest"
fi

# ---- initramfs
IR="$VM/initramfs"
rm -rf "$IR"
mkdir -p "$IR/bin" "$IR/proc" "$IR/sys" "$IR/dev" "$IR/tmp" "$IR/host" "$IR/lib/modules"
cp /bin/busybox "$IR/bin/busybox"
cp "$ROOT/tests/vm/init" "$IR/init"
chmod +x "$IR/init"
: > "$IR/modules.list"
# bochs, virtio-gpu: the DRM drivers of qemu's -device bochs-display and
# virtio-gpu-pci (the display tests; bochs first, so it is card0)
for m in virtio_pci 9pnet_virtio 9p vivid xhci_pci dummy_hcd usb_f_hid bochs virtio-gpu; do
    modprobe -d "$VM/kernel" -S "$KV" --show-depends "$m" | while read -r cmd path rest; do
        [ "$cmd" = insmod ] || continue
        base=$(basename "$path")
        grep -qx "$base" "$IR/modules.list" 2>/dev/null && continue
        cp "$path" "$IR/lib/modules/$base"
        echo "$base" >> "$IR/modules.list"
    done
done
(cd "$IR" && find . | cpio -o -H newc 2>/dev/null | gzip -1 > "$VM/initramfs.cpio.gz.tmp")
mv "$VM/initramfs.cpio.gz.tmp" "$VM/initramfs.cpio.gz"

# ---- the guest test program (links only what it needs)
PKGL=$(pkg-config --libs libusb-1.0 libv4l2)
PKGC=$(pkg-config --cflags libusb-1.0 libv4l2)
cc -std=c11 -O2 -g -Wall -Wextra -D_GNU_SOURCE -ffp-contract=off $PKGC -o "$VM/vm_devices" \
    "$ROOT/tests/vm/vm_devices.c" "$ROOT"/src/io/io_v4l2.c "$ROOT"/src/io/io_dummy.c \
    "$ROOT"/src/io/io_usb.c "$ROOT"/src/io/io_glove.c "$ROOT"/src/io/io_common.c \
    "$ROOT"/src/io/io_vsrc.c "$ROOT"/src/io/io_vstream.c "$ROOT"/src/io/io_pixfmt.c \
    "$ROOT/$BUILD/libegofuse.a" $PKGL -lm -lpthread
# ---- the guest display test (KMS through libdrm on the bochs driver)
DRMC=$(pkg-config --cflags libdrm sdl2)
DRML=$(pkg-config --libs libdrm)
cc -std=c11 -O2 -g -Wall -Wextra -D_GNU_SOURCE -ffp-contract=off $DRMC -o "$VM/vm_display" \
    "$ROOT/tests/vm/vm_display.c" "$ROOT"/src/io/io_display.c "$ROOT"/src/io/io_display_common.c "$ROOT"/src/io/io_display_kms.c \
    "$ROOT"/src/io/io_display_sdl.c "$ROOT"/src/io/io_common.c $DRML
echo "prepared: kernel $KV, initramfs $(du -k "$VM/initramfs.cpio.gz" | cut -f1) KiB"
