#!/bin/sh
# make bench: every benchmark, one after the other (never in parallel: they
# time themselves), human-readable tables on stdout and CSV files in
# bench/out/. Benchmarks report; they never pass or fail.
BUILD=${1:-build}
OUT=bench/out
mkdir -p "$OUT"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores"
echo "compiler: $(${CC:-cc} --version | head -n 1)"
echo
for b in "$BUILD"/bench/bench_*; do
    [ -x "$b" ] || continue
    name=$(basename "$b")
    echo "==== $name"
    "$b" || echo "($name exited with status $?)"
    "$b" --csv > "$OUT/$name.csv" 2>/dev/null || true
    echo
done
if [ -x "$BUILD/bench/llvmpipe_raster" ]; then
    echo "==== llvmpipe_raster (coverage agreement and speed against Mesa llvmpipe)"
    "$BUILD/bench/llvmpipe_raster"
    case $? in
        0) ;;
        3) echo "(llvmpipe is not available here)" ;;
        *) echo "(llvmpipe_raster: coverage differs away from edges, see above)" ;;
    esac
fi
echo "CSV files: $OUT/"
