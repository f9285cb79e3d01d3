#!/bin/sh
# Installs the Debian packages egofuse needs to build, test and run its demo
# (libdrm-dev: the KMS display output; libsdl2-dev: the SDL window output's
# headers, its library is loaded at run time; xvfb + x11-apps: the window's
# test, a virtual X server and xwd; ffmpeg, gst-launch-1.0 and python3: the
# real producers and the framing generator of tests/test_io_vsrc.c, and the
# video decoder of file cameras; the last line: the virtual machine that
# tests the camera, USB, glove and display code against the Linux kernel's
# own drivers, tests/vm/; the kernel itself is fetched by tests/vm/prepare.sh
# with apt-get download, not installed).
# Called by `make demo`, `make test` and `make bench`; safe to run again (it
# only installs what is missing). As a non-root user it prints the exact
# apt-get line and stops.
#
#   sh scripts/deps.sh              the packages above
#   sh scripts/deps.sh ci           also CI's: clang and its runtimes
#                                   (libFuzzer, sanitizers), the ARM64 cross
#                                   compiler and qemu-user (.ci/run)
#   sh scripts/deps.sh arm64 DIR    CI's ARM64 cross build: the arm64
#                                   architecture added to dpkg and cmocka
#                                   for arm64 unpacked into DIR (nothing
#                                   installed; empty DIR when the multiarch
#                                   libcmocka-dev:arm64 is installed)
#
# A package counts as installed when dpkg has it for this machine's own
# architecture (or as Architecture: all): with foreign architectures added
# (dpkg --add-architecture), dpkg-query lists one entry per architecture.
# An index that cannot be fetched (often a foreign architecture's) does not
# stop the set-up: apt-get install then works with the indexes there are,
# and only a package it cannot install is an error.
set -eu

PKGS="build-essential pkg-config
libopenimageio-dev openimageio-tools libpng-dev
libtinygltf-dev libmeshoptimizer-dev gltfpack
libv4l-dev libusb-1.0-0-dev
libdrm-dev libsdl2-dev xvfb x11-apps
libcmocka-dev
gnuplot-nox
libpixman-1-dev
libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
ffmpeg gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good python3
qemu-system-x86 busybox-static cpio kmod xz-utils"
# .ci/run: a clang build, the ARM64 cross build under qemu-user,
# scripts/rng_order.py (clang's AST, python3), and make fuzz: libFuzzer and
# clang's sanitizer runtimes (libclang-rt-dev, only a Recommends of clang,
# which apt-get install --no-install-recommends leaves out).
CI_PKGS="clang libclang-rt-dev gcc-aarch64-linux-gnu libc6-dev-arm64-cross qemu-user-static python3"

mode=${1:-}
native=$(dpkg --print-architecture)

# 0 if package $1 is installed for the native architecture (or for all).
installed() {
    dpkg-query -W -f='${Architecture} ${db:Status-Status}\n' "$1" 2>/dev/null |
        grep -Eq "^($native|all) installed\$"
}

as_root() {
    if [ "$(id -u)" != "0" ]; then
        echo "egofuse: as root, run:" >&2
        echo "  $*" >&2
        exit 1
    fi
}

apt_update() {
    if ! apt-get update -qq; then
        echo "egofuse: apt-get update could not fetch every index (a foreign" >&2
        echo "egofuse: architecture's?); installing from the indexes there are" >&2
    fi
}

install_missing() {
    missing=""
    for p in "$@"; do
        installed "$p" || missing="$missing $p"
    done
    [ -z "$missing" ] && return 0
    if [ "$(id -u)" != "0" ]; then
        echo "egofuse: these Debian packages are missing:$missing" >&2
        echo "egofuse: install them as root, then run make again:" >&2
        echo "  sudo apt-get install -y$missing" >&2
        exit 1
    fi
    echo "egofuse: installing missing Debian packages:$missing"
    export DEBIAN_FRONTEND=noninteractive
    apt_update
    # shellcheck disable=SC2086
    if ! apt-get install -y -qq --no-install-recommends $missing; then
        echo "egofuse: apt-get could not install:$missing" >&2
        exit 1
    fi
}

case "$mode" in
"")
    # shellcheck disable=SC2086
    install_missing $PKGS
    ;;
ci)
    # shellcheck disable=SC2086
    install_missing $PKGS $CI_PKGS
    ;;
arm64)
    dir=${2:?usage: deps.sh arm64 DIR}
    # shellcheck disable=SC2086
    install_missing $CI_PKGS
    if [ -e /usr/lib/aarch64-linux-gnu/libcmocka.so ]; then
        exit 0   # the multiarch package: the cross compiler finds it
    fi
    [ -e "$dir/usr/lib/aarch64-linux-gnu/libcmocka.so" ] && exit 0
    if ! dpkg --print-foreign-architectures | grep -qx arm64; then
        as_root "dpkg --add-architecture arm64 && apt-get update"
        dpkg --add-architecture arm64
        apt_update
    fi
    mkdir -p "$dir/debs"
    # apt-get download needs no lock and no root: the .debs are unpacked,
    # not installed.
    if ! (cd "$dir/debs" && apt-get download -qq libcmocka0:arm64 libcmocka-dev:arm64); then
        [ "$(id -u)" = "0" ] && apt_update
        if ! (cd "$dir/debs" && apt-get download -qq libcmocka0:arm64 libcmocka-dev:arm64); then
            echo "egofuse: cannot download libcmocka0:arm64 libcmocka-dev:arm64" >&2
            exit 1
        fi
    fi
    for d in "$dir"/debs/*.deb; do
        dpkg-deb -x "$d" "$dir"
    done
    ;;
*)
    echo "usage: deps.sh [ci | arm64 DIR]" >&2
    exit 2
    ;;
esac
