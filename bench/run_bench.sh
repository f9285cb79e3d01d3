#!/bin/sh
# make bench: every benchmark, one after the other (never in parallel: they
# time themselves), human-readable tables on stdout and CSV files in
# bench/out/. Benchmarks report; they never pass or fail.
#
#   sh bench/run_bench.sh [BUILD]       (make bench runs it with build/)
#
# First the whole stereo frame (bench_frame: writes bench/out/bench.csv)
# and its llvmpipe peer (llvmpipe_frame, 1 and 2 threads: appends to
# bench.csv), then the per-stage benchmarks, then the charts (gnuplot,
# bench/plot/*.gp) and a summary with the ratios, bench/out/summary.md.
# bench_frame also runs the named HMDs (paper, consumer 1280x1024 ->
# 2x 2064x2208, highend 1920x1080 -> 2x 2880x2720): rows frame_hmd and
# floor_hmd of bench.csv, frame_hmd.csv, the chart frame_hmd.png.
# BENCH_FRAME_ARGS (e.g. "--quick", "--seconds 20"), LLVMPIPE_FRAMES and
# STAGE_RUNS (runs of the per-stage benchmarks) and RASTER_RUNS (of
# bench_raster and llvmpipe_raster) change the counts;
# SAMPLES the sample folder, OUT the output folder. REPORT_ONLY=1 skips
# the benchmarks and redraws the charts and the summary from the CSVs. The defaults keep the
# whole of `make bench` to about 3-4 minutes on the 2-core machine.
BUILD=${1:-build}
OUT=${OUT:-bench/out}
SAMPLES=${SAMPLES:-$BUILD/samples}
LLVMPIPE_FRAMES=${LLVMPIPE_FRAMES:-120}
STAGE_RUNS=${STAGE_RUNS:-15}
# The raster draws take well under a millisecond: more runs for a stable
# median (bench_raster and llvmpipe_raster).
RASTER_RUNS=${RASTER_RUNS:-101}
mkdir -p "$OUT"
T0=$(date +%s)
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores"
echo "compiler: $(${CC:-cc} --version | head -n 1)"
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) (the machine is shared: read ratios, not absolute times)"
echo

if [ ! -f "$SAMPLES/scene.txt" ] && [ -x "$BUILD/gen_samples" ]; then
    echo "generating the samples into $SAMPLES (once)"
    "$BUILD/gen_samples" --out "$SAMPLES" > /dev/null || echo "(gen_samples failed)"
fi

if [ -z "$REPORT_ONLY" ]; then
# ---- the whole stereo frame and its peers (one CSV)
rm -f "$OUT/bench.csv" "$OUT/llvmpipe_diff.csv"
if [ -x "$BUILD/bench/bench_frame" ]; then
    echo "==== bench_frame (whole stereo frame, memcpy floor, pixman composite, scaling)"
    # shellcheck disable=SC2086
    "$BUILD/bench/bench_frame" --samples "$SAMPLES" --out "$OUT" $BENCH_FRAME_ARGS ||
        echo "(bench_frame exited with status $?)"
    echo
fi
if [ -x "$BUILD/bench/llvmpipe_frame" ]; then
    for t in 1 2; do
        echo "==== llvmpipe_frame --threads $t (the same frame as GL shaders on Mesa llvmpipe, side by side with egofuse)"
        "$BUILD/bench/llvmpipe_frame" --samples "$SAMPLES" --threads "$t" --case both \
            --frames "$LLVMPIPE_FRAMES" --csv "$OUT/bench.csv" --diff-csv "$OUT/llvmpipe_diff.csv"
        case $? in
            0) ;;
            3) echo "(llvmpipe is not available here)" ;;
            *) echo "(llvmpipe_frame failed)" ;;
        esac
        echo
    done
fi

# ---- per-stage benchmarks
for b in "$BUILD"/bench/bench_*; do
    [ -x "$b" ] || continue
    name=$(basename "$b")
    [ "$name" = bench_frame ] && continue
    echo "==== $name"
    case $name in
        bench_kin) # its own figures and CSVs into bench/out; no --csv, no --runs
            "$b" || echo "($name exited with status $?)" ;;
        bench_reproj) # the eye reprojection against the crop on the samples'
            # frames, side by side (docs/eyeview.md)
            "$b" --samples "$SAMPLES" --runs "$STAGE_RUNS" || echo "($name exited with status $?)" ;;
        bench_aa) # anti-aliased edges against binary ones through pipe_frame
            # (issue 14 item 3): PSNR, edge flicker and ms per stereo frame
            "$b" --frames 24 --reps "$STAGE_RUNS" || echo "($name exited with status $?)" ;;
        bench_vsrc) # a V source's own speed needs a live source; here the
            # conversion of each frame format (median of 30 runs)
            "$b" --convert || echo "($name exited with status $?)" ;;
        *)
            runs=$STAGE_RUNS
            [ "$name" = bench_raster ] && runs=$RASTER_RUNS
            "$b" --runs "$runs" || echo "($name exited with status $?)"
            "$b" --csv --runs "$runs" > "$OUT/$name.csv" 2>/dev/null || true ;;
    esac
    echo
done
if [ -x "$BUILD/bench/llvmpipe_raster" ]; then
    echo "==== llvmpipe_raster (coverage agreement and speed against Mesa llvmpipe)"
    "$BUILD/bench/llvmpipe_raster" --runs "$RASTER_RUNS"
    case $? in
        0) ;;
        3) echo "(llvmpipe is not available here)" ;;
        *) echo "(llvmpipe_raster: coverage differs away from edges, see above)" ;;
    esac
    echo
fi
fi # REPORT_ONLY

# ---- charts and summary
if [ -f "$OUT/bench.csv" ]; then
    # FPS per implementation / ISA / threads, typical and worst (1000 / median)
    awk -F, 'NR > 1 && ($1 == "frame_typical" || $1 == "frame_worst") {
                 key = $2 " " $3 " " $4 "t"; if ($2 == "llvmpipe") key = "llvmpipe " $4 "t";
                 if (!(key in seen)) { seen[key] = 1; order[n++] = key }
                 v[key, $1] = 1000 / $5 }
             END { print "label,typical_fps,worst_fps";
                   for (i = 0; i < n; i++) { k = order[i];
                       t = ((k, "frame_typical") in v) ? sprintf("%.1f", v[k, "frame_typical"]) : "NaN";
                       w = ((k, "frame_worst") in v) ? sprintf("%.1f", v[k, "frame_worst"]) : "NaN";
                       print k "," t "," w } }' "$OUT/bench.csv" > "$OUT/frame_fps.csv"
    if command -v gnuplot > /dev/null 2>&1; then
        for gp in bench/plot/*.gp; do
            gnuplot -e "dir='$OUT'" "$gp" 2> /dev/null || echo "(gnuplot failed on $gp)"
        done
        echo "charts: $(cd "$OUT" && ls frame_*.png 2> /dev/null | tr '\n' ' ')"
    else
        echo "(gnuplot not installed: no charts)"
    fi
    {
        echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'), $(nproc) cores (shared);"
        echo "compiler: $(${CC:-cc} --version | head -n 1); $(date -u +%Y-%m-%d)."
        echo
        echo "Whole stereo frame, egofuse (stage medians summed over both eyes):"
        echo
        awk -F, 'NR > 1 && $2 == "egofuse" && ($1 == "frame_typical" || $1 == "frame_worst") {
                     k = $3 " | " $4; if (!(k in seen)) { seen[k] = 1; order[n++] = k }
                     if ($1 == "frame_typical") { tm[k] = $5; tp[k] = $6;
                         st[k] = sprintf("%.2f / %.3f / %.3f / %.2f / %.2f", $13, $14, $15, $16, $17) }
                     else { wm[k] = $5; wp[k] = $6 } }
                 END {
                     print "| ISA | threads | typical median ms | typical p99 ms | worst (70%) median ms | worst p99 ms | FPS typical / worst (median) | typical stages: convert / track / skin / raster / fuse ms |"
                     print "|---|---|---|---|---|---|---|---|"
                     for (i = 0; i < n; i++) { k = order[i];
                         printf "| %s | %.2f | %.2f | %.2f | %.2f | %.0f / %.0f | %s |\n", k, tm[k], tp[k], wm[k], wp[k], 1000 / tm[k], (wm[k] > 0 ? 1000 / wm[k] : 0), st[k] } }' "$OUT/bench.csv"
        echo
        echo "Where the frame's time goes (issue 17 item 1; bench.csv path_ms, outside_ms: per frame, the stages on"
        echo "the critical path and the rest of the frame, medians; docs/bench.md \"Where the frame's time goes\"):"
        echo
        awk -F, 'NR > 1 && $2 == "egofuse" && ($1 == "frame_typical" || $1 == "frame_worst") && NF >= 31 {
                     if (!hd) { hd = 1
                         print "| case | ISA | threads | frame ms | stages on the path ms | outside ms (% of the path) | raster L / R | fuse L / R | eye 1 on the worker |"
                         print "|---|---|---|---|---|---|---|---|---|" }
                     printf "| %s | %s | %s | %.3f | %.3f | %.3f (%.1f%%) | %.3f / %.3f | %.3f / %.3f | %s |\n",
                            $1, $3, $4, $5, $21, $22, ($21 > 0 ? 100 * $22 / $21 : 0), $23, $24, $25, $26,
                            ($4 > 1 ? sprintf("%.0f%%", 100 * $30) : "") }' "$OUT/bench.csv"
        echo
        echo "Every row of bench.csv but the scaling points:"
        echo
        echo "| case | impl | ISA | threads | median ms | p99 ms | max ms | FPS (median) | headroom vs 16.7 ms (p99) | hands cover | frames |"
        echo "|---|---|---|---|---|---|---|---|---|---|---|"
        awk -F, 'NR > 1 && ($1 ~ /^frame_/ || $1 == "memcpy_floor" || $1 == "composite") {
                     cov = ($12 > 0) ? sprintf("%.0f%%", 100 * $12) : "";
                     fps = ($1 ~ /^frame_/) ? sprintf("%.0f", 1000 / $5) : "";
                     head = ($1 ~ /^frame_/) ? sprintf("%.2f", 16.667 - $6) : "";
                     printf "| %s | %s | %s | %s | %.3f | %.3f | %.3f | %s | %s | %s | %s |\n",
                            $1, $2, $3, $4, $5, $6, $7, fps, head, cov, $9 }' "$OUT/bench.csv"
        echo
        awk -F, 'NR > 1 {
                     if ($1 == "frame_typical" && $2 == "egofuse" && (!(("t", $4) in be) || $5 < be["t", $4])) { be["t", $4] = $5; bi["t", $4] = $3 }
                     if ($1 == "frame_worst" && $2 == "egofuse" && (!(("w", $4) in be) || $5 < be["w", $4])) { be["w", $4] = $5; bi["w", $4] = $3 }
                     if ($1 == "frame_typical" && $2 == "llvmpipe") lp[$4] = $5
                     if ($1 == "frame_anim" && $2 == "egofuse") ea[$4] = $5
                     if ($1 == "frame_worst" && $2 == "llvmpipe") lpw[$4] = $5
                     if ($1 == "frame_worst_anim" && $2 == "egofuse") eaw[$4] = $5
                     if ($1 == "memcpy_floor") mc[$4] = $5
                     if ($1 == "composite" && $2 == "pixman") px = $5
                     if ($1 == "composite" && $2 == "egofuse" && $4 == 1 && (cb == "" || $5 < cb)) { cb = $5; ci = $3 } }
                 END {
                     for (t = 1; t <= 2; t++) {
                         if (("t", t) in be) printf "- typical, %d thread%s: best egofuse %.3f ms (%s)%s\n", t, (t > 1 ? "s" : ""), be["t", t], bi["t", t], ((t == 2) ? sprintf(" - target <= 1.0 ms: %s", (be["t", t] <= 1.0 ? "met" : "missed")) : "")
                         if (("w", t) in be) printf "- worst case, %d thread%s: best egofuse %.3f ms (%s)%s\n", t, (t > 1 ? "s" : ""), be["w", t], bi["w", t], ((t == 2) ? sprintf(" - target <= 2.0 ms: %s", (be["w", t] <= 2.0 ? "met" : "missed")) : "")
                         if ((t in lp) && (t in ea)) printf "- llvmpipe, %d thread%s: %.3f ms per frame; egofuse on the same frames, interleaved: %.3f ms; llvmpipe / egofuse = %.1fx (target >= 20x)\n", t, (t > 1 ? "s" : ""), lp[t], ea[t], lp[t] / ea[t]
                         if ((t in lpw) && (t in eaw)) printf "- llvmpipe, worst case (70%%), %d thread%s: %.3f ms per frame; egofuse interleaved: %.3f ms; llvmpipe / egofuse = %.1fx\n", t, (t > 1 ? "s" : ""), lpw[t], eaw[t], lpw[t] / eaw[t]
                         if ((t in mc) && (("t", t) in be)) printf "- memory floor (memcpy of both outputs), %d thread%s: %.3f ms; typical frame / floor = %.1fx (target <= 2.5x)\n", t, (t > 1 ? "s" : ""), mc[t], be["t", t] / mc[t]
                     }
                     if (px != "" && cb != "") printf "- composite stage: pixman %.3f ms, egofuse (%s, 1 thread) %.3f ms; pixman / egofuse = %.1fx\n", px, ci, cb, px / cb
                 }' "$OUT/bench.csv"
        if [ -f "$OUT/frame_hmd.csv" ]; then
            echo
            echo "Named HMDs (bench_frame's frame_hmd rows; kin_sthmd_preset, docs/kin.md): the typical sequence,"
            echo "ms per stereo frame (medians), against the memcpy of both outputs (chart: frame_hmd.png):"
            echo
            echo "| HMD | camera | display per eye | output MP (both eyes) | crop | viewport | hands cover | avx2 1t | avx2 2t | best ISA 2t | in place: avx2 2t / best 2t | floor 2t | avx2 2t / floor | avx2 2t stages: convert / track / skin / raster / fuse ms (raster, fuse summed over the eyes) |"
            echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
            awk -F, 'NR > 1 { printf "| %s | %dx%d | %dx%d | %.2f | %dx%d | %dx%d | %.0f%% | %.2f | %.2f | %.2f (%s) | %.2f / %.2f | %.2f | %.1fx | %.2f / %.3f / %.3f / %.2f / %.2f |\n",
                                   $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, 100 * $11, $12, $13, $15, $14, $23, $24, $17, $13 / $17, $18, $19, $20, $21, $22 }' "$OUT/frame_hmd.csv"
            echo
            awk -F, 'NR > 1 && $1 == "consumer" { printf "- consumer HMD (1280x1024 cameras, 2x 2064x2208), avx2, 2 threads: %.2f ms per stereo frame - target <= 5.5 ms: %s; %s, 2 threads: %.2f ms; in place (V composited in its own buffer): avx2 %.2f ms (%s), %s %.2f ms\n",
                                   $13, ($13 <= 5.5 ? "met" : sprintf("missed by %.1fx", $13 / 5.5)), $14, $15, $23, ($23 <= 5.5 ? "met" : sprintf("missed by %.1fx", $23 / 5.5)), $14, $24
                                   printf "- the same on a loaded machine, from the CPU time per frame (all threads; at best half of it on 2 idle cores): avx2 2 threads %.2f ms CPU, >= %.2f ms (%s); in place %.2f ms CPU, >= %.2f ms (%s)\n",
                                   $27, $27 / 2, ($27 / 2 <= 5.5 ? "met" : sprintf("missed by >= %.1fx", $27 / 11)), $29, $29 / 2, ($29 / 2 <= 5.5 ? "met" : sprintf("missed by >= %.1fx", $29 / 11)) }' "$OUT/frame_hmd.csv"
        fi
        if [ -f "$OUT/llvmpipe_diff.csv" ]; then
            awk -F, 'NR > 1 { printf "- llvmpipe output vs egofuse (%s, %d thread%s, %d stereo frames): mean |d| %.3f, max %d, %.3f%% of all pixels differ by > 8 (hand pixels: mean |d| %.2f, %.2f%% > 8)\n", $9, $1, ($1 > 1 ? "s" : ""), $2, $3, $4, $5, $7, $8 }' "$OUT/llvmpipe_diff.csv"
        fi
    } > "$OUT/summary.md"
    echo
    echo "==== summary ($OUT/summary.md)"
    cat "$OUT/summary.md"
fi
echo
echo "CSV files: $OUT/ (bench.csv: one row per measured case); total $(( $(date +%s) - T0 )) s"
