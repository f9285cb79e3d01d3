#!/bin/sh
# Installs the Debian packages egofuse needs, each command only its own:
#
#   sh scripts/deps.sh demo         make demo (and make samples, make eval):
#                                   the compiler and the program's libraries
#   sh scripts/deps.sh test         make test (and make debug): also cmocka,
#                                   SDL2's headers and the tools the tests
#                                   run against (below)
#   sh scripts/deps.sh bench        make bench: also the peers measured
#                                   (pixman, Mesa llvmpipe through EGL/GLES)
#                                   and gnuplot for the charts
#   sh scripts/deps.sh              all three (make deps)
#   sh scripts/deps.sh ci           all three and CI's: clang and its
#                                   runtimes (libFuzzer, sanitizers), the
#                                   ARM64 cross compiler and qemu-user
#                                   (.ci/run)
#   sh scripts/deps.sh arm64 DIR    CI's ARM64 cross build: the arm64
#                                   architecture added to dpkg and cmocka
#                                   for arm64 unpacked into DIR (nothing
#                                   installed; empty DIR when the multiarch
#                                   libcmocka-dev:arm64 is installed)
#
# Called by `make demo`, `make test` and `make bench`; safe to run again (it
# only installs what is missing). As a non-root user it prints the exact
# apt-get line and stops. scripts/chroot_check.sh measures each command's
# set-up on a fresh Debian 12 (README, Set-up).
#
# A package counts as installed when dpkg has it for this machine's own
# architecture (or as Architecture: all): with foreign architectures added
# (dpkg --add-architecture), dpkg-query lists one entry per architecture.
# An index that cannot be fetched (often a foreign architecture's) does not
# stop the set-up: apt-get install then works with the indexes there are,
# and only a package it cannot install is an error.
set -eu

# The program and its samples (make demo): the compiler, pkg-config (the
# Makefile asks it for every library's flags), the io library's libraries,
# and OpenEXR (the samples' depth is EXR): without OpenImageIO the image
# plugin is built with OpenEXR alone (src/io/io_image_exr.cpp), which spares
# the demo OpenImageIO and the ~230 packages behind it (OpenCV, GDAL,
# OpenVDB, ffmpeg's libraries...).
# No SDL2 headers: without them the SDL window output is built as a stub
# that says so (src/io/io_display_sdl.c), and the Makefile rebuilds it once
# make test has installed them.
BUILD_PKGS="build-essential pkg-config
libpng-dev libtinygltf-dev libmeshoptimizer-dev
libv4l-dev libusb-1.0-0-dev libdrm-dev
libopenexr-dev"
# make test: OpenImageIO (the image plugin for every format; the tests
# compare it with the EXR-only one); cmocka; libsdl2-dev (the SDL window output's headers, its
# library is loaded at run time); xvfb + x11-apps: the window's test, a
# virtual X server and xwd; ffmpeg, gst-launch-1.0 and python3: the real
# producers and the framing generator of tests/test_io_vsrc.c, the NatNet
# sender of tests/test_io_natnet.c, and the independent PNG codec of
# tests/test_io_png.c; gltfpack: the quantized and meshopt variants of
# tests/test_gltf_samples.c; gnuplot: the charts of eval --report
# (tests/test_cli_output.c); libjpeg-dev: tests/test_install.c links a
# program with `pkg-config --static --libs egofuse-io`, whose libv4l2 asks
# for -ljpeg (libv4lconvert's Libs.private); the last line: the virtual
# machine that tests the camera, USB, glove and display code against the Linux kernel's
# own drivers, tests/vm/ (the kernel itself is fetched by tests/vm/prepare.sh
# with apt-get download, not installed).
TEST_PKGS="$BUILD_PKGS libopenimageio-dev
libcmocka-dev libsdl2-dev openimageio-tools gltfpack libjpeg-dev
xvfb x11-apps libegl-mesa0 libgl1-mesa-dri gnuplot-nox
ffmpeg gstreamer1.0-tools gstreamer1.0-plugins-base gstreamer1.0-plugins-good python3
qemu-system-x86 busybox-static cpio kmod xz-utils"
# make bench: the peers (pixman compositing, Mesa llvmpipe through EGL +
# GLES) and gnuplot for the charts (bench/run_bench.sh).
BENCH_PKGS="$BUILD_PKGS
libpixman-1-dev libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
gnuplot-nox"
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
    # (waits for the dpkg lock instead of failing when another apt runs)
    # shellcheck disable=SC2086
    if ! apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 $missing; then
        echo "egofuse: apt-get could not install:$missing" >&2
        exit 1
    fi
}

# One word per package, each once (a package in two lists is asked once).
uniq_words() {
    printf '%s\n' "$@" | tr ' ' '\n' | sed '/^$/d' | awk '!seen[$0]++'
}

case "$mode" in
demo | test | bench | "" | ci)
    case "$mode" in
    demo) list=$BUILD_PKGS ;;
    test) list=$TEST_PKGS ;;
    bench) list=$BENCH_PKGS ;;
    "") list="$TEST_PKGS $BENCH_PKGS" ;;
    ci) list="$TEST_PKGS $BENCH_PKGS $CI_PKGS" ;;
    esac
    # shellcheck disable=SC2046,SC2086
    install_missing $(uniq_words $list)
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
    echo "usage: deps.sh [demo | test | bench | ci | arm64 DIR]" >&2
    exit 2
    ;;
esac
