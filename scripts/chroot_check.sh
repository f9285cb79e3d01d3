#!/bin/sh
# Measures the set-up of a fresh Debian 12: `make demo`, `make test` and
# `make bench`, each from zero in its own fresh chroot, as root, with
# nothing installed but `make` (the README's Set-up table comes from here).
#
#   sudo sh scripts/chroot_check.sh [DIR] [demo] [test] [bench]
#
# DIR (default /var/tmp/egofuse-chroot) holds the chroots. Once, the base:
# `debootstrap --variant=minbase bookworm DIR/base` (Debian's mirror and
# its bookworm-updates and bookworm-security suites, as on an installed
# machine) plus `make`, kept for the next run. Then, for each command (all
# three by default), a copy of the base gets a clean `git clone` of this
# repository (its committed HEAD, not the work tree) at /root/egofuse/egofuse
# and a copy of ../shared beside it (the tests read ../shared/gltf), and the
# command runs there, timed. One line per command:
#
#   make demo: 512 s, passed; 310 packages installed, 250.1 MB downloaded;
#   load average 2.1 before, 3.0 after
#
# with the log in DIR/COMMAND.log (the test counts line is shown). The copy
# is removed afterwards unless KEEP=1.
#
# Environment: MIRROR (http://deb.debian.org/debian), SECURITY_MIRROR
# (http://deb.debian.org/debian-security), SHARED (../shared beside the
# repository), KEEP=1, EGOFUSE_VM=0 (passed to the chroot: no VM test),
# REBASE=1 (a new base). Needs root, debootstrap, unshare (util-linux) and
# the network to the mirror. Each run is in a mount namespace of its own
# (unshare), so /proc, /sys, /dev/pts, /dev/shm and /dev/kvm are mounted
# into the chroot only for it and never left behind. /dev/kvm (bound when
# the machine has it) lets the VM test of make test run with KVM; without
# it qemu emulates (TCG), slower.
set -eu

ROOT=$(cd "$(dirname "$0")/.." && pwd)
DIR=/var/tmp/egofuse-chroot
case "${1:-}" in
/* | ./* | ../*) DIR=$1; shift ;;
esac
CMDS=${*:-demo test bench}
MIRROR=${MIRROR:-http://deb.debian.org/debian}
SECURITY_MIRROR=${SECURITY_MIRROR:-http://deb.debian.org/debian-security}
SHARED=${SHARED:-$ROOT/../shared}

die() { echo "chroot_check: $*" >&2; exit 1; }
[ "$(id -u)" = 0 ] || die "run as root (debootstrap, chroot, mount)"
command -v debootstrap >/dev/null || die "debootstrap missing (apt-get install debootstrap)"
command -v unshare >/dev/null || die "unshare missing (util-linux)"
[ -d "$SHARED/gltf" ] || die "$SHARED/gltf missing (set SHARED)"
for c in $CMDS; do
    case $c in demo | test | bench) ;; *) die "unknown command '$c' (demo, test, bench)" ;; esac
done
mkdir -p "$DIR"
now() { date +%s; }
# The packages installed in chroot $1.
npkgs() {
    # shellcheck disable=SC2016
    chroot "$1" dpkg-query -W -f='${Status}\n' | grep -c ' installed$'
}

# ---- the base: minbase + the mirror's suites + make
base=$DIR/base
if [ -n "${REBASE:-}" ] || [ ! -f "$base/.egofuse-base" ]; then
    rm -rf "$base"
    t0=$(now)
    echo "debootstrap --variant=minbase bookworm $base $MIRROR"
    debootstrap --variant=minbase bookworm "$base" "$MIRROR" >"$DIR/debootstrap.log" 2>&1 ||
        die "debootstrap failed (see $DIR/debootstrap.log)"
    cat >"$base/etc/apt/sources.list" <<EOF
deb $MIRROR bookworm main
deb $MIRROR bookworm-updates main
deb $SECURITY_MIRROR bookworm-security main
EOF
    cp /etc/resolv.conf "$base/etc/resolv.conf"
    t1=$(now)
    # make: the one package a user installs to type `make demo`
    chroot "$base" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin DEBIAN_FRONTEND=noninteractive \
        sh -c 'apt-get update -qq && apt-get install -y -qq --no-install-recommends make && apt-get clean' \
        >>"$DIR/debootstrap.log" 2>&1 || die "cannot install make in the base (see $DIR/debootstrap.log)"
    t2=$(now)
    echo "base: debootstrap $((t1 - t0)) s, apt-get update + make $((t2 - t1)) s," \
        "$(npkgs "$base") packages"
    touch "$base/.egofuse-base"
fi

# ---- the source: a clean clone of the committed HEAD
src=$DIR/src
rm -rf "$src"
git clone -q --no-hardlinks "$ROOT" "$src/egofuse" || die "git clone $ROOT failed"
cp -a "$SHARED" "$src/shared"
echo "source: $(git -C "$src/egofuse" log -1 --format='%h %s' | cut -c1-70)"

# run_in ROOTDIR COMMAND: COMMAND as root in the chroot, with /proc, /sys,
# /dev/pts, /dev/shm and /dev/kvm mounted in a private mount namespace.
run_in() {
    r=$1
    shift
    unshare --mount --propagation private /bin/sh -s "$r" "$*" "${EGOFUSE_VM:-}" <<'EOF'
set -e
r=$1; cmd=$2; vm=$3
mount -t proc proc "$r/proc"
mount -t sysfs -o ro sysfs "$r/sys"
mkdir -p "$r/dev/pts" "$r/dev/shm"
mount -t devpts -o newinstance,ptmxmode=0666 devpts "$r/dev/pts"
[ -e "$r/dev/ptmx" ] || touch "$r/dev/ptmx"
mount --bind "$r/dev/pts/ptmx" "$r/dev/ptmx"
mount -t tmpfs -o mode=1777 tmpfs "$r/dev/shm"
if [ -c /dev/kvm ]; then
    [ -e "$r/dev/kvm" ] || touch "$r/dev/kvm"
    mount --bind /dev/kvm "$r/dev/kvm"
fi
set +e
exec chroot "$r" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    LANG=C.UTF-8 TERM=dumb ${vm:+EGOFUSE_VM=$vm} sh -c "cd /root/egofuse/egofuse && $cmd"
EOF
}

summary=""
for c in $CMDS; do
    r=$DIR/run-$c
    rm -rf "$r"
    cp -a "$base" "$r"
    # /etc/hosts as the Debian installer writes it (debootstrap writes
    # none, and without it "localhost" does not resolve)
    [ -e "$r/etc/hosts" ] || printf '%s\n' '127.0.0.1	localhost' \
        '::1		localhost ip6-localhost ip6-loopback' >"$r/etc/hosts"
    mkdir -p "$r/root/egofuse"
    cp -a "$src/egofuse" "$src/shared" "$r/root/egofuse/"
    n0=$(npkgs "$r")
    log=$DIR/$c.log
    echo "make $c: running in $r (log $log)"
    l0=$(cut -d' ' -f1 /proc/loadavg)
    t0=$(now)
    set +e
    run_in "$r" "make $c" >"$log" 2>&1
    rc=$?
    set -e
    t1=$(now)
    n1=$(npkgs "$r")
    # apt keeps every .deb it downloaded (the base's were cleaned)
    kb=$(find "$r/var/cache/apt/archives" -name '*.deb' -exec du -k {} + 2>/dev/null | awk '{s += $1} END {print s + 0}')
    if [ "$rc" = 0 ]; then res=passed; else res="FAILED (exit $rc)"; fi
    line=$(printf 'make %s: %d s, %s; %d packages installed, %d.%d MB downloaded; load average %s before, %s after' \
        "$c" $((t1 - t0)) "$res" $((n1 - n0)) $((kb / 1024)) $((kb % 1024 * 10 / 1024)) \
        "$l0" "$(cut -d' ' -f1 /proc/loadavg)")
    counts=$(grep -E '^[0-9]+ passed, [0-9]+ failed, [0-9]+ skipped$' "$log" | tail -1 || true)
    [ -n "$counts" ] && line="$line; $counts"
    echo "$line"
    summary="$summary$line
"
    [ "${KEEP:-}" = 1 ] || rm -rf "$r"
done
echo "---- $(nproc) cores, $(date -u '+%Y-%m-%d %H:%M UTC')"
printf '%s' "$summary"
