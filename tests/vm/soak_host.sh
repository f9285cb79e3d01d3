#!/bin/sh
# `make soak`: boots the test VM (tests/vm/prepare.sh, the same kernel and
# initramfs as build/tests/test_vm) with egofuse.script=tests/vm/soak.sh,
# which soaks `egofuse run` for SOAK_SECONDS (default 600) with SOAK_CYCLES
# (default 20) camera unplug/replug cycles and SOAK_STALLS (default 3) V
# stalls, then judges the result with tests/vm/soak_report.sh and prints
# its table. The guest's output is kept in BUILD/vm/soak.log, the soak's
# files in BUILD/vm/out/soak. Exit 0 when the soak passed, 3 when it could
# not run (no qemu, no kernel), 1 when it failed.
#
#   sh tests/vm/soak_host.sh [BUILD]
set -u
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
VM="$ROOT/$BUILD/vm"
OUT="$VM/out"
SECS=${SOAK_SECONDS:-600}
CYC=${SOAK_CYCLES:-20}
STALLS=${SOAK_STALLS:-3}
command -v qemu-system-x86_64 > /dev/null 2>&1 || {
    echo "SKIP: qemu-system-x86_64 missing (apt-get install qemu-system-x86)"
    exit 3
}
sh "$ROOT/tests/vm/prepare.sh" "$BUILD" || exit $?
mkdir -p "$OUT"
rm -rf "$OUT/soak"
printf 'SOAK_SECONDS=%s\nSOAK_CYCLES=%s\nSOAK_STALLS=%s\n' "$SECS" "$CYC" "$STALLS" > "$OUT/soak.conf"
# KVM where it is a real one, TCG otherwise (as tests/test_vm.c)
if [ ! -e /sys/module/kvm_pvm ] && [ -r /dev/kvm ] && [ -w /dev/kvm ]; then
    ACC=kvm CPU=host
else
    ACC=tcg CPU=max
fi
BIN=""
case ${EGOFUSE_BIN:-} in /*) BIN=" egofuse.bin=$EGOFUSE_BIN" ;; esac
echo "soak: $SECS s, $CYC camera cycles, $STALLS V stalls in the VM ($ACC); log $VM/soak.log"
t0=$(date +%s)
timeout $((SECS + 1800)) qemu-system-x86_64 -accel $ACC -cpu $CPU -m 1024 -smp 2 \
    -kernel "$VM/vmlinux" -initrd "$VM/initramfs.cpio.gz" \
    -append "console=ttyS0 quiet panic=-1 vt.global_cursor_default=0 egofuse.out=$OUT egofuse.root=$ROOT egofuse.script=tests/vm/soak.sh$BIN" \
    -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
    -virtfs "local,path=$ROOT,mount_tag=repo,security_model=none,readonly=on,multidevs=remap" \
    -virtfs "local,path=$OUT,mount_tag=out,security_model=none,multidevs=remap" \
    -device isa-debug-exit,iobase=0xf4,iosize=0x04 -vga none \
    -serial stdio -display none -monitor none -no-reboot < /dev/null > "$VM/soak.log" 2>&1
qrc=$?
echo "soak: the VM ran $(($(date +%s) - t0)) s, qemu exit $qrc (1 = the guest passed)"
grep -E '^VM(TEST|INFO soak (cameras|log|[0-9.]+ (start|warm|unplug|back|vstop|vcont|stop|exit|fail)))' "$VM/soak.log" | tr -d '\r' | sed 's/^VMINFO soak //'
if [ ! -f "$OUT/soak/events.txt" ]; then
    echo "FAIL: the soak did not start (see $VM/soak.log)"
    exit 1
fi
echo
echo "egofuse run's own summary: $(tr '\r' '\n' < "$OUT/soak/run.err" | grep 'stereo frames' | tail -n 1)"
sh "$ROOT/tests/vm/soak_report.sh" "$OUT/soak"
