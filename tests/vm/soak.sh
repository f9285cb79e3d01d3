#!/bin/sh
# The soak of the live path, inside the test VM (tests/vm/init runs it
# chrooted into the host's file system when booted with
# egofuse.script=tests/vm/soak.sh by tests/vm/soak_host.sh, i.e. `make
# soak`; tests/vm/guest.sh runs a short one). `egofuse run` composites
# vivid's two cameras with a NatNet tracker (`egofuse replay-track --loop`
# on the loopback) over V from gst-launch-1.0 through a FIFO, while:
#   - the cameras are taken away and brought back CYCLES times: vivid's
#     platform devices are unbound from the driver and bound again through
#     sysfs (the driver's real remove and probe: the nodes disappear under
#     the open descriptors, which then fail with ENODEV, and are created
#     anew) in odd cycles: both cameras go, since vivid's one platform
#     device carries all its instances; in even cycles one camera (left,
#     then right) fails alone through vivid's "Disconnect" control;
#   - the V producer is stopped (SIGSTOP) for 8 s and resumed (SIGCONT)
#     STALLS times, spread over the run.
# Every few seconds the run's VmRSS and descriptor count are sampled.
# Everything goes to OUT/soak (events.txt, samples.csv, frames.csv,
# run.err); tests/vm/soak_report.sh judges it.
#
#   soak.sh ROOT OUT [SECONDS CYCLES STALLS TAG]
# without SECONDS.., OUT/soak.conf gives SOAK_SECONDS, SOAK_CYCLES,
# SOAK_STALLS (written by soak_host.sh).
ROOT=$1
OUT=$2
SECS=$3
CYC=$4
STALLS=$5
TAG=${6:-soak}
if [ -z "$SECS" ] && [ -f "$OUT/soak.conf" ]; then
    . "$OUT/soak.conf"
    SECS=$SOAK_SECONDS
    CYC=$SOAK_CYCLES
    STALLS=$SOAK_STALLS
fi
SECS=${SECS:-600}
CYC=${CYC:-20}
STALLS=${STALLS:-3}
VM=$(dirname "$OUT")
S="$VM/samples"
D="$OUT/$TAG"
EGOFUSE=${EGOFUSE_BIN:-$ROOT/build/egofuse}
cd "$ROOT" || exit 1
rm -rf "$D"
mkdir -p "$D"
up() { cut -d" " -f1 /proc/uptime; }
ev() {
    t=$(up)
    echo "$t $*" >> "$D/events.txt"
    echo "VMINFO $TAG $t $*"
}
die() {
    echo "VMTEST ${TAG}_setup FAIL $*"
    exit 1
}
[ -x "$EGOFUSE" ] || die "$EGOFUSE is not built"
[ -f "$S/scene.txt" ] || die "$S/scene.txt missing (tests/vm/prepare.sh makes it)"
command -v gst-launch-1.0 > /dev/null 2>&1 || die "gst-launch-1.0 is not installed (scripts/deps.sh installs it)"
DRV=/sys/bus/platform/drivers/vivid
[ -d "$DRV" ] || die "no vivid platform driver in sysfs"
# vivid's one platform device carries all its instances (the four nodes)
PDEV=$(basename "$(readlink -f /sys/class/video4linux/video0/device)")
[ -n "$PDEV" ] && [ -e "$DRV/$PDEV" ] || die "/dev/video0 has no vivid device in sysfs"
[ "$(basename "$(readlink -f /sys/class/video4linux/video1/device)")" = "$PDEV" ] ||
    die "/dev/video1 is not on $PDEV"
echo "VMINFO $TAG cameras /dev/video0, /dev/video1 on $PDEV (driver $DRV)"

export GST_REGISTRY=/tmp/gst-registry.bin XDG_CACHE_HOME=/tmp
gst-inspect-1.0 videotestsrc > /dev/null 2>&1 # the plugin registry, once
FIFO=/tmp/$TAG.v.fifo
rm -f "$FIFO"
mkfifo "$FIFO" || die "mkfifo $FIFO"

"$EGOFUSE" replay-track "$S/track.txt" --to natnet:127.0.0.1:1510 --loop > "$D/replay.log" 2>&1 &
RP=$!
gst-launch-1.0 -q videotestsrc is-live=true pattern=ball ! \
    video/x-raw,format=I420,width=640,height=200,framerate=10/1 ! y4menc ! fdsink fd=1 \
    > "$FIFO" 2> "$D/gst.err" &
GP=$!
"$EGOFUSE" run --scene "$S/scene.txt" --left /dev/video0 --right /dev/video1 --input 0 \
    --fps 10 --virt-source "stream:$FIFO" --natnet 127.0.0.1 --raw --stats "$D/frames.csv" \
    > /dev/null 2> "$D/run.err" &
RUN=$!
ev start run $RUN gst $GP replay $RP seconds $SECS cycles $CYC stalls $STALLS

# the sampler, every 3 s: time, VmRSS and its parts RssAnon (the heap),
# RssFile (mapped files, and the cameras' mapped buffers), RssShmem (kB),
# open descriptors
(
    echo "t_s,rss_kb,fds,anon_kb,file_kb,shmem_kb" > "$D/samples.csv"
    while [ -d /proc/$RUN ]; do
        m=$(awk '/^VmRSS:/ { r = $2 } /^RssAnon:/ { a = $2 } /^RssFile:/ { f = $2 }
            /^RssShmem:/ { s = $2 } END { if (r != "") print r, a, f, s }' /proc/$RUN/status 2>/dev/null)
        fds=$(ls /proc/$RUN/fd 2>/dev/null | wc -l)
        set -- $m
        [ -n "$m" ] && echo "$(up),$1,$fds,$2,$3,$4" >> "$D/samples.csv"
        sleep 3
    done
) &
SP=$!

alive() { [ -d /proc/$RUN ] && ! grep -q '^State:.*Z' /proc/$RUN/status 2>/dev/null; }
# lines of run.err (status updates end in \r) matching $1
count() { tr '\r' '\n' < "$D/run.err" | grep -c "$1"; }
# waits up to $2 s for more than $3 lines matching $1
wait_count() {
    wend=$(awk -v n="$(up)" -v s="$2" 'BEGIN { printf "%.2f", n + s }')
    while alive && [ "$(count "$1")" -le "$3" ] &&
        awk -v a="$wend" -v n="$(up)" 'BEGIN { exit !(n < a) }'; do
        sleep 0.5
    done
    [ "$(count "$1")" -gt "$3" ]
}
# frames composited so far (the newest status line)
frames_now() {
    f=$(tr '\r' '\n' < "$D/run.err" | sed -n 's/^egofuse run: \([0-9]*\) frames, .*/\1/p' | tail -n 1)
    echo "${f:-0}"
}
# the camera nodes and the vivid instances behind them
nodes() {
    for f in /sys/class/video4linux/video*; do
        [ -e "$f/name" ] && printf '%s=%s ' "${f##*/}" "$(cat "$f/name")"
    done
}

# warm-up: the first composited frames (starting under TCG takes a while)
if ! wait_count ' frames, ' 300 0; then
    ev fail run produced no frame
    kill -INT $RUN 2> /dev/null
fi
ev warm
echo "VMINFO $TAG nodes $(nodes)"
T0=$(up)
i=1
while [ $i -le "$CYC" ] && alive; do
    # cycle i starts at T0 + (i - 1) * SECS / CYC
    at=$(awk -v t0="$T0" -v i=$i -v s="$SECS" -v c="$CYC" 'BEGIN { printf "%.2f", t0 + (i - 1) * s / c }')
    while alive && awk -v a="$at" -v n="$(up)" 'BEGIN { exit !(n < a) }'; do sleep 0.5; done
    backs=$(count 'camera back')
    if [ $((i % 2)) -eq 1 ]; then
        # both cameras: the driver unbound (all of vivid's nodes go), 4 s
        # away, bound again (new nodes, the same numbers once the old
        # descriptors are closed)
        lost=$(count 'camera lost')
        ev gone $i 0 1
        echo "$PDEV" > $DRV/unbind || ev fail unbind $PDEV
        sleep 4
        # back only once egofuse has seen both go (and closed their nodes):
        # a node still held open keeps its number, the camera would come
        # back as another /dev/videoN, which a /dev/videoN selector does
        # not follow (serial: and port: selectors do, docs/devices.md);
        # under TCG a frame can take 10 s, so this wait can be long
        wait_count 'camera lost' 90 $((lost + 1)) || ev fail cycle $i: egofuse did not see both cameras go within 90 s
        echo "$PDEV" > $DRV/bind || ev fail bind $PDEV
        n=2
    else
        # one camera: vivid's "Disconnect" button (the node fails with
        # ENODEV as an unplugged USB camera does; vivid connects it again
        # once its last descriptor is closed, i.e. when egofuse reopens it)
        e=$(((i / 2) % 2))
        ev gone $i $e
        "$VM/vm_devices" vivid-disconnect /dev/video$e 2>> "$D/events.err" || ev fail disconnect /dev/video$e
        n=1
    fi
    ev replug $i
    if wait_count 'camera back' 90 $((backs + n - 1)); then
        ev back $i
    else
        ev fail cycle $i: not back within 90 s: $(nodes)
    fi
    # the next cycle only after 4 more frames (soak_report.sh wants 3 from
    # both returned cameras; under TCG a frame can take seconds)
    f0=$(frames_now)
    fend=$(awk -v n="$(up)" 'BEGIN { printf "%.2f", n + 120 }')
    while alive && [ "$(frames_now)" -lt $((f0 + 4)) ] &&
        awk -v a="$fend" -v n="$(up)" 'BEGIN { exit !(n < a) }'; do
        sleep 0.5
    done
    # a V stall in cycles spread over the run (the middle of the cycle)
    if awk -v i=$i -v s="$STALLS" -v c="$CYC" \
        'BEGIN { for (k = 1; k <= s; k++) if (int(k * c / (s + 1) + 0.5) == i) exit 0; exit 1 }'; then
        sleep 2
        ev vstop $i
        kill -STOP $GP
        sleep 8
        kill -CONT $GP
        ev vcont $i
    fi
    i=$((i + 1))
done
# the last stretch: a whole period after the last return
end=$(awk -v t0="$T0" -v s="$SECS" 'BEGIN { printf "%.2f", t0 + s }')
while alive && awk -v a="$end" -v n="$(up)" 'BEGIN { exit !(n < a) }'; do sleep 0.5; done
ev stop
alive_at_end=0
alive && alive_at_end=1
kill -INT $RUN 2> /dev/null
wait $RUN
rc=$?
ev exit $rc alive $alive_at_end
kill $SP $GP $RP 2> /dev/null
kill -CONT $GP 2> /dev/null
wait 2> /dev/null
rm -f "$FIFO"
# the log without the status lines (and the retries' status while both
# cameras are away)
tr '\r' '\n' < "$D/run.err" | grep -v '^egofuse run: [0-9]* frames, ' | grep -v '(retrying) *$' | grep . |
    sed "s/^/VMINFO $TAG log /" | tail -n 120
# the judgement (also run on the host by soak_host.sh)
sh "$ROOT/tests/vm/soak_report.sh" "$D" | sed "s/^/VMINFO $TAG /"
if sh "$ROOT/tests/vm/soak_report.sh" "$D" > /dev/null; then
    echo "VMTEST ${TAG} PASS $(sh "$ROOT/tests/vm/soak_report.sh" "$D" | tail -n 1)"
else
    echo "VMTEST ${TAG} FAIL $(sh "$ROOT/tests/vm/soak_report.sh" "$D" | tail -n 1)"
    exit 1
fi
exit 0
