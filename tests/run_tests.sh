#!/bin/sh
# Runs every test binary in BUILD/tests and prints one closing line
# "N passed, N failed, N skipped" for the whole suite. A binary that dies
# without reporting counts as one failure. Exit status 0 only if none failed.
# EGOFUSE_RUNNER, when set, runs each binary (a cross build under qemu:
# EGOFUSE_RUNNER="qemu-aarch64-static -L /usr/aarch64-linux-gnu").
# EGOFUSE_JOBS binaries run at once (default: the CPUs, at most 4); each has
# its own scratch folder and log, and the report lists them in name order
# once all have ended, so it reads the same for any number of jobs.
# EGOFUSE_ALONE (names, default test_vm) run alone, after the others.
BUILD=${1:-build}
ROOT=$(cd "$(dirname "$0")/.." && pwd)

# "run_tests.sh --one LOGDIR BINARY": one binary, its output into
# LOGDIR/NAME.log, its exit status into LOGDIR/NAME.rc (what xargs runs).
if [ "$BUILD" = "--one" ]; then
    name=$(basename "$3")
    mkdir -p "$EGOFUSE_TMP_BASE/$name"
    # shellcheck disable=SC2086
    EGOFUSE_TMP="$EGOFUSE_TMP_BASE/$name" ${EGOFUSE_RUNNER:-} "$3" >"$2/$name.log" 2>&1
    echo $? >"$2/$name.rc"
    exit 0
fi

export EGOFUSE_BIN="$ROOT/$BUILD/egofuse"
export EGOFUSE_ROOT="$ROOT"
export EGOFUSE_SHARED="${EGOFUSE_SHARED:-$ROOT/../shared}"
export EGOFUSE_TMP_BASE="${TMPDIR:-/tmp}/egofuse-test.$$"
LOGDIR="$EGOFUSE_TMP_BASE/logs"
mkdir -p "$LOGDIR"
trap 'rm -rf "$EGOFUSE_TMP_BASE"' EXIT INT TERM

jobs=${EGOFUSE_JOBS:-$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)}
case "$jobs" in '' | *[!0-9]* | 0) jobs=1 ;; esac
[ -z "${EGOFUSE_JOBS:-}" ] && [ "$jobs" -gt 4 ] && jobs=4

# The binaries of EGOFUSE_ALONE (default test_vm: the qemu VM under TCG,
# whose capture checks count the frames a guest delivers in a few seconds)
# run one at a time after the others, with the machine to themselves.
alone=" ${EGOFUSE_ALONE-test_vm} "
for t in "$ROOT/$BUILD"/tests/test_*; do
    case "$alone" in *" $(basename "$t") "*) continue ;; esac
    [ -x "$t" ] && printf '%s\n' "$t"
done | xargs -P "$jobs" -n 1 sh "$0" --one "$LOGDIR"
for t in "$ROOT/$BUILD"/tests/test_*; do
    case "$alone" in *" $(basename "$t") "*) [ -x "$t" ] && sh "$0" --one "$LOGDIR" "$t" ;; esac
done

passed=0; failed=0; skipped=0; bad=""
for t in "$ROOT/$BUILD"/tests/test_*; do
    [ -x "$t" ] || continue
    name=$(basename "$t")
    log="$LOGDIR/$name.log"
    rc=$(cat "$LOGDIR/$name.rc" 2>/dev/null || echo 127)
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
