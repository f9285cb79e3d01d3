#!/bin/sh
# Runs every test binary in BUILD/tests and prints one closing line
# "N passed, N failed, N skipped" for the whole suite. A binary that dies
# without reporting counts as one failure. Exit status 0 only if none failed.
# EGOFUSE_RUNNER, when set, runs each binary (a cross build under qemu:
# EGOFUSE_RUNNER="qemu-aarch64-static -L /usr/aarch64-linux-gnu").
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
export EGOFUSE_BIN="$ROOT/$BUILD/egofuse"
export EGOFUSE_ROOT="$ROOT"
export EGOFUSE_SHARED="${EGOFUSE_SHARED:-$ROOT/../shared}"
export EGOFUSE_TMP="${TMPDIR:-/tmp}/egofuse-test.$$"
mkdir -p "$EGOFUSE_TMP"
trap 'rm -rf "$EGOFUSE_TMP"' EXIT INT TERM

passed=0; failed=0; skipped=0; bad=""
for t in "$ROOT/$BUILD"/tests/test_*; do
    [ -x "$t" ] || continue
    name=$(basename "$t")
    log="$EGOFUSE_TMP/$name.log"
    # shellcheck disable=SC2086
    ${EGOFUSE_RUNNER:-} "$t" >"$log" 2>&1
    rc=$?
    # cmocka prints one summary per group: add them all up.
    sum() { sed -n "s/^\[  $1 *\] \([0-9][0-9]*\) test(s).*/\1/p" "$log" | awk '{n+=$1} END {print n+0}'; }
    p=$(sum PASSED); f=$(sum FAILED); s=$(sum SKIPPED)
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    passed=$((passed + p)); failed=$((failed + f)); skipped=$((skipped + s))
    if [ "$f" -ne 0 ]; then
        bad="$bad $name"
        echo "---- $name (exit $rc) ----"; cat "$log"
    else
        printf '%-32s %4d passed' "$name" "$p"
        [ "$s" -ne 0 ] && printf ', %d skipped' "$s"
        printf '\n'
        grep -E '^(SKIP|NOTE)' "$log" | sed 's/^/    /'
    fi
done
[ -n "$bad" ] && echo "failed:$bad"
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
