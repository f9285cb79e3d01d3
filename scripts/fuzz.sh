#!/bin/sh
# Runs every libFuzzer target of `make fuzz` (build-fuzz/fuzz/fuzz_*) for
# SECONDS each from its seed corpus tests/fuzz/corpus/NAME/ (docs/fuzzing.md).
#
#   sh scripts/fuzz.sh [SECONDS [NAME...]]     default 10 s, every target
#
# New inputs go to a scratch corpus (FUZZ_WORK, default a temporary folder
# removed at the end), never into the repository's seeds. A crash, leak,
# UB report, timeout (FUZZ_TIMEOUT s per input, default 10) or out-of-memory
# fails the target: its reproducer is kept in FUZZ_ARTIFACTS (default
# build-fuzz/artifacts/) and named in the output. FUZZ_JOBS targets run at
# once (default: the CPUs, at most 4), each for SECONDS; the report lists them
# in the order given once all have ended. Prints one line per target and
# "fuzz: N passed, N failed"; exit status non-zero if any failed.
set -u
cd "$(dirname "$0")/.."
secs=${1:-10}
[ $# -gt 0 ] && shift
names=$*
if [ -z "$names" ]; then
    for b in build-fuzz/fuzz/fuzz_*; do
        case "$b" in *.o | *.d) continue ;; esac
        [ -x "$b" ] && names="$names ${b#build-fuzz/fuzz/fuzz_}"
    done
fi
if [ -z "$names" ]; then
    echo "fuzz: no targets in build-fuzz/fuzz/ (run make fuzz)" >&2
    exit 1
fi
work=${FUZZ_WORK:-}
own=0
if [ -z "$work" ]; then
    work=$(mktemp -d "${TMPDIR:-/tmp}/egofuse-fuzz.XXXXXX") || exit 1
    own=1
fi
art=${FUZZ_ARTIFACTS:-build-fuzz/artifacts}
mkdir -p "$art"
# UBSan: a report is an error with a stack; ASan: leaks checked.
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
jobs=${FUZZ_JOBS:-$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)}
case "$jobs" in '' | *[!0-9]* | 0) jobs=1 ;; esac
[ -z "${FUZZ_JOBS:-}" ] && [ "$jobs" -gt 4 ] && jobs=4

# run_one NAME: one target, its log in $work/NAME.log, its exit status in
# $work/NAME.rc (127: no binary or no seeds).
run_one() {
    bin=build-fuzz/fuzz/fuzz_$1
    seeds=tests/fuzz/corpus/$1
    if [ ! -x "$bin" ] || [ ! -d "$seeds" ]; then
        echo 127 >"$work/$1.rc"
        return
    fi
    mkdir -p "$work/$1"
    TMPDIR="$work" "$bin" -max_total_time="$secs" -timeout="${FUZZ_TIMEOUT:-10}" \
        -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
        -artifact_prefix="$art/${1}-" "$work/$1" "$seeds" >"$work/$1.log" 2>&1
    echo $? >"$work/$1.rc"
}

# The targets dealt round-robin into $jobs groups, each group one after the
# other in a background shell (every target takes SECONDS, so the groups end
# together).
g=0
while [ "$g" -lt "$jobs" ]; do
    (
        i=0
        for n in $names; do
            [ $((i % jobs)) -eq "$g" ] && run_one "$n"
            i=$((i + 1))
        done
    ) &
    g=$((g + 1))
done
wait

pass=0; fail=0
for n in $names; do
    log="$work/$n.log"
    rc=$(cat "$work/$n.rc" 2>/dev/null || echo 127)
    if [ ! -s "$log" ] && [ "$rc" -eq 127 ]; then
        echo "fuzz_$n: no binary build-fuzz/fuzz/fuzz_$n or no seeds tests/fuzz/corpus/$n"
        fail=$((fail + 1)); continue
    fi
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    cov=$(grep -Eo 'cov: [0-9]+' "$log" | tail -1)
    if [ "$rc" -eq 0 ]; then
        echo "fuzz_$n: ${runs:-?} runs in ${secs} s, ${cov:-cov: ?}, corpus $(ls "$work/$n" "tests/fuzz/corpus/$n" | wc -l)"
        pass=$((pass + 1))
    else
        echo "---- fuzz_$n failed (exit $rc) ----"
        grep -E '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|artifact_prefix|Test unit written)' "$log" | head -20
        tail -30 "$log"
        fail=$((fail + 1))
    fi
done
[ "$own" = 1 ] && rm -rf "$work"
echo "fuzz: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
