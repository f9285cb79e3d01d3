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

missing=""
for p in $PKGS; do
    st=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
    [ "$st" = "installed" ] || missing="$missing $p"
done
[ -z "$missing" ] && exit 0

if [ "$(id -u)" != "0" ]; then
    echo "egofuse: these Debian packages are missing:$missing" >&2
    echo "egofuse: install them as root, then run make again:" >&2
    echo "  sudo apt-get install -y$missing" >&2
    exit 1
fi

echo "egofuse: installing missing Debian packages:$missing"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# shellcheck disable=SC2086
apt-get install -y -qq --no-install-recommends $missing
