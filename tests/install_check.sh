#!/bin/sh
# install_check.sh BUILD MODEL TMPDIR - run by tests/test_install.c:
# installs into TMPDIR/stage (make install DESTDIR=...), builds
# examples/mask_example.c against the staged copy with pkg-config, runs it
# on MODEL and compares its mask with `egofuse mask` of the same camera.
# Exit 0 ok, 77 skip (the reason on stdout), else failure.
set -eu
B=$1 MODEL=$2 T=$3
command -v pkg-config >/dev/null 2>&1 || { echo "SKIP: pkg-config is not installed"; exit 77; }
CC=${CC:-cc}
S=$T/stage
make -s --no-print-directory BUILD="$B" install DESTDIR="$S" >"$T/install.log" 2>&1 ||
    { cat "$T/install.log"; echo "make install failed"; exit 1; }
P=/usr/local
for f in lib/libegofuse.a lib/libegofuse.so.0.1.0 lib/libegofuse_io.a lib/egofuse/libegofuse_oiio.so \
         include/egofuse/pipe_mask.h include/egofuse/io.h lib/pkgconfig/egofuse.pc lib/pkgconfig/egofuse-io.pc; do
    [ -f "$S$P/$f" ] || { echo "missing after install: $P/$f"; exit 1; }
done
[ "$(readlink "$S$P/lib/libegofuse.so.0")" = libegofuse.so.0.1.0 ] || { echo "libegofuse.so.0 link wrong"; exit 1; }
readelf -d "$S$P/lib/libegofuse.so.0.1.0" | grep -q 'SONAME.*\[libegofuse.so.0\]' || { echo "soname is not libegofuse.so.0"; exit 1; }
export PKG_CONFIG_PATH="$S$P/lib/pkgconfig" PKG_CONFIG_SYSROOT_DIR="$S"
# every installed header compiles on its own (its includes resolve there)
for h in "$S$P"/include/egofuse/*.h; do
    echo "#include <egofuse/$(basename "$h")>" |
        $CC -std=c11 $(pkg-config --cflags egofuse) -Wall -Werror -x c -fsyntax-only - ||
        { echo "installed header $(basename "$h") does not compile alone"; exit 1; }
    echo "#include <egofuse/$(basename "$h")>" |
        ${CXX:-c++} $(pkg-config --cflags egofuse) -Wall -Werror -x c++ -fsyntax-only - ||
        { echo "installed header $(basename "$h") does not compile alone as C++"; exit 1; }
done
$CC -std=c11 -Wall -Wextra -Werror -o "$T/mask_example" examples/mask_example.c \
    $(pkg-config --cflags --libs egofuse) $(pkg-config --static --cflags --libs egofuse-io) ||
    { echo "examples/mask_example.c does not build against the installed copy"; exit 1; }
readelf -d "$T/mask_example" | grep -q 'NEEDED.*\[libegofuse.so.0\]' ||
    { echo "mask_example is not linked to libegofuse.so.0"; exit 1; }
# MODEL, then (with EGOFUSE_SHARED) public samples with morph targets and
# strips; MODEL's mask stays in $T/lib.pgm for the caller.
set -- "$MODEL"
SH=${EGOFUSE_SHARED:-}
for m in AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb SimpleMorph/glTF/SimpleMorph.gltf; do
    [ -n "$SH" ] && [ -f "$SH/gltf/$m" ] && set -- "$@" "$SH/gltf/$m"
done
n=0
for m in "$@"; do
    out=$T/lib.pgm
    [ $n -gt 0 ] && out=$T/lib$n.pgm
    LD_LIBRARY_PATH="$S$P/lib" "$T/mask_example" "$m" "$out" || { echo "mask_example failed on $m"; exit 1; }
    "$B/egofuse" mask "$m" --width 160 --height 120 --fov-y 60 --eye 0,0,3 --target 0,0,0 \
        --out "$T/cli.pgm" || { echo "egofuse mask failed on $m"; exit 1; }
    cmp "$out" "$T/cli.pgm" || { echo "$m: the library's mask differs from egofuse mask's"; exit 1; }
    echo "NOTE $m: the installed library's mask equals egofuse mask's"
    n=$((n + 1))
done
exit 0
