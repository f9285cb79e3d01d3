#!/bin/sh
# Runs inside the test VM (chrooted into the host's file system, see
# tests/vm/init): device tests against vivid, qemu's USB devices and a fake
# glove gadget, then `egofuse run` on the two vivid cameras. Lines starting
# with VMTEST / VMMEASURE / VMSYNC are read by tests/test_vm.c.
ROOT=$1
OUT=$2
VM=$(dirname "$OUT")
BIN="$VM/vm_devices"
cd "$ROOT" || exit 1
fail=0
step() { echo "VMSTEP $* at $(cut -d" " -f1 /proc/uptime) s"; }

step capture
"$BIN" capture || fail=1

step vsrc
# the V source (io_vsrc) on vivid's video2 + video3: formats, unplug, reopen
"$BIN" vsrc || fail=1

step usb
# hotplug is seen by io_usb_watch's sysfs rescans (libusb's own events
# would need a udev daemon, which this VM does not run)
"$BIN" usb-list "$OUT/usb_before.txt" || fail=1
sed 's/^/VMINFO usb /' "$OUT/usb_before.txt"
"$BIN" usb-assign serial:CAM-L-0001 serial:CAM-R-0002 CAM-L-0001 CAM-R-0002 || fail=1
# the host unplugs the right camera (QMP device_del) when it reads VMSYNC
"$BIN" usb-watch 30000 usb-unplug || fail=1
"$BIN" usb-assign serial:CAM-L-0001 serial:CAM-R-0002 CAM-L-0001 - || fail=1
# ... and plugs it back into another port
"$BIN" usb-watch 30000 usb-replug || fail=1
"$BIN" usb-list "$OUT/usb_after.txt" || fail=1
sed 's/^/VMINFO usb /' "$OUT/usb_after.txt"
"$BIN" usb-assign serial:CAM-L-0001 serial:CAM-R-0002 CAM-L-0001 CAM-R-0002 || fail=1

step glove
# a fake 5DT Data Glove 5 Ultra (left, 5d70:0011): configfs HID gadget on dummy_hcd
G=/sys/kernel/config/usb_gadget/glove
if mkdir -p $G/strings/0x409 $G/configs/c.1 $G/functions/hid.usb0 2>/dev/null; then
    echo 0x5d70 > $G/idVendor
    echo 0x0011 > $G/idProduct
    echo 0x0200 > $G/bcdUSB
    echo GLOVE-L-0001 > $G/strings/0x409/serialnumber
    echo 5DT > $G/strings/0x409/manufacturer
    echo "Data Glove 5 Ultra (fake)" > $G/strings/0x409/product
    echo 0 > $G/functions/hid.usb0/protocol
    echo 0 > $G/functions/hid.usb0/subclass
    echo 64 > $G/functions/hid.usb0/report_length
    # vendor page, 64 input bytes and 64 output bytes
    printf '\006\000\377\011\001\241\001\025\000\046\377\000\165\010\225\100\011\001\201\002\225\100\011\001\221\002\300' \
        > $G/functions/hid.usb0/report_desc
    ln -s $G/functions/hid.usb0 $G/configs/c.1/
    ls /sys/class/udc | head -n1 > $G/UDC
    i=0
    while [ ! -e /dev/hidg0 ] && [ $i -lt 50 ]; do sleep 0.1; i=$((i + 1)); done
    sleep 1
    "$BIN" glove /dev/hidg0 serial:GLOVE-L-0001 || fail=1
else
    echo "VMTEST glove_gadget FAIL cannot create the configfs gadget"
    fail=1
fi

step display
# KMS on qemu's bochs-display: the host takes a screendump when it reads
# "VMSYNC display-dump FILE" and answers with FILE.ack
"$VM/vm_display" "$OUT" || fail=1
# layout two: virtio-gpu's two outputs, one eye each
"$VM/vm_display" two "$OUT" || fail=1

step run
# the live pipeline on both vivid cameras, HDMI input at 60 FPS
EGOFUSE=${EGOFUSE_BIN:-$ROOT/build/egofuse}
if [ ! -x "$EGOFUSE" ]; then
    echo "VMTEST run_pipeline FAIL $EGOFUSE is not built"
    fail=1
elif [ ! -f "$(dirname "$OUT")/samples/scene.txt" ]; then
    echo "VMTEST run_pipeline FAIL $(dirname "$OUT")/samples/scene.txt missing (tests/vm/prepare.sh makes it)"
    fail=1
else
    # raw rgb24 stream, left above right (PNG encoding is slow under TCG)
    "$EGOFUSE" run --scene "$(dirname "$OUT")/samples/scene.txt" --left /dev/video0 --right /dev/video1 \
        --input 1 --dv --fps 60 --frames 8 --raw > "$OUT/run.rgb" 2> "$OUT/run.err"
    rc=$?
    tr '\r' '\n' < "$OUT/run.err" | grep . | tail -n 3 | sed 's/^/VMINFO run /'
    bytes=$(wc -c < "$OUT/run.rgb")
    want=$((8 * 1280 * 1600 * 3))
    line=$(tr '\r' '\n' < "$OUT/run.err" | grep 'stereo frames' | tail -n 1)
    if [ $rc -eq 0 ] && [ "$bytes" -eq $want ]; then
        echo "VMTEST run_pipeline PASS $line; $bytes bytes = 8 composited 1280x1600 rgb24 frames"
    else
        echo "VMTEST run_pipeline FAIL exit $rc, $bytes of $want bytes: $line $(tail -c 300 "$OUT/run.err")"
        fail=1
    fi
    rm -f "$OUT/run.rgb"
fi

step cockpit
# The live cockpit end to end: vivid's video0/video1 as the HMD cameras,
# video2/video3 as the remote scene V, NatNet from `egofuse replay-track`
# on the loopback, the composite on the KMS display (bochs). The host takes
# a screendump of the held last frame ("VMSYNC cockpit-dump FILE", answered
# with FILE.ack) and compares it with `egofuse render` of the inputs that
# `run --dump` wrote (tests/test_vm.c, test_vm_cockpit). Then a second run
# with V from a gst-launch-1.0 pipe that ends mid-run and a tracker that
# stops mid-run: both reported, the run goes on to its last frame.
S="$VM/samples"
CK="$OUT/cockpit"
rm -rf "$CK"
mkdir -p "$CK"
wait_file() { i=0; while [ ! -e "$1" ] && [ $i -lt "$2" ]; do sleep 0.2; i=$((i + 1)); done; [ -e "$1" ]; }
wait_grep() { i=0; while ! tr '\r' '\n' < "$1" 2>/dev/null | grep -q "$2" && [ $i -lt "$3" ]; do sleep 0.2; i=$((i + 1)); done; tr '\r' '\n' < "$1" | grep -q "$2"; }
if [ ! -x "$EGOFUSE" ] || [ ! -f "$S/scene.txt" ]; then
    echo "VMTEST cockpit_kms FAIL $EGOFUSE or $S/scene.txt missing"
    fail=1
else
    "$EGOFUSE" replay-track "$S/track.txt" --to natnet:127.0.0.1:1510 --loop > "$CK/replay.log" 2>&1 &
    RP=$!
    # --virt-stale 5000: under TCG on a loaded host vivid's V can be a few
    # hundred ms old when the run ends; the check is that V is live, not fast
    "$EGOFUSE" run --scene "$S/scene.txt" --left /dev/video0 --right /dev/video1 --input 1 --dv \
        --fps 60 --virt-source v4l2:/dev/video2,/dev/video3 --virt-stale 5000 --natnet 127.0.0.1 \
        --display kms --frames 6 --hold --dump "$CK/dump" --stats "$CK/frames.csv" \
        > "$CK/run.out" 2> "$CK/run.err" &
    RUN=$!
    if wait_grep "$CK/run.err" "holding frame" 900; then
        tr '\r' '\n' < "$CK/run.err" | grep . | tail -n 4 | sed 's/^/VMINFO cockpit /'
        rm -f "$CK/screen.ppm.ack"
        echo "VMSYNC cockpit-dump $CK/screen.ppm"
        if wait_file "$CK/screen.ppm.ack" 300; then
            echo "VMTEST cockpit_dump_ack PASS the host took the screendump of the held frame"
        else
            echo "VMTEST cockpit_dump_ack FAIL no answer from the host"
            fail=1
        fi
    else
        echo "VMTEST cockpit_kms FAIL run did not reach its held last frame: $(tr '\r' '\n' < "$CK/run.err" | tail -n 3)"
        fail=1
    fi
    kill -INT $RUN 2>/dev/null
    wait $RUN
    rc=$?
    kill $RP 2>/dev/null
    wait $RP 2>/dev/null
    sum=$(grep 'stereo frames' "$CK/run.out" | tail -n 1)
    echo "VMINFO cockpit summary $sum"
    grep 'display ' "$CK/run.out" | sed 's/^/VMINFO cockpit /'
    if [ $rc -eq 0 ] && echo "$sum" | grep -q '^egofuse run: 6 stereo frames' && echo "$sum" | grep -q 'V live' &&
        echo "$sum" | grep -q 'tracker ' && ! echo "$sum" | grep -q 'no pose yet' && [ -f "$CK/dump/scene.txt" ] &&
        [ -f "$CK/dump/track.txt" ] && [ "$(wc -l < "$CK/frames.csv")" -eq 7 ]; then
        echo "VMTEST cockpit_kms PASS exit 0 after Ctrl-C; 6 frames logged; V live; NatNet pose; dump written"
    else
        echo "VMTEST cockpit_kms FAIL exit $rc: $sum $(tail -c 300 "$CK/run.err")"
        fail=1
    fi

    # second run: V from a real producer on a pipe, ending after 4 frames
    # of its own; the tracker replays 2 samples and stops (40 frames: at
    # least 0.67 s at 60 Hz, past the tracker's 0.5 s staleness, however
    # fast the guest runs)
    if command -v gst-launch-1.0 >/dev/null 2>&1; then
        export GST_REGISTRY=/tmp/gst-registry.bin XDG_CACHE_HOME=/tmp
        # the plugin registry once, before the timed pipeline (slow under TCG)
        gst-inspect-1.0 videotestsrc > /dev/null 2>&1
        # gst-launch-1.0 writes its 4 frames first and a pipe carries them:
        # started live beside the run, its start-up under TCG on a busy host
        # outlasted the run's 16 frames once (CI, "V waiting"), a race
        gst-launch-1.0 -q videotestsrc num-buffers=4 pattern=smpte ! \
            video/x-raw,format=I420,width=640,height=200,framerate=30/1 ! y4menc ! \
            filesink location="$CK/v.y4m" 2> "$CK/gst.err"
        "$EGOFUSE" replay-track "$S/track.txt" --to natnet:127.0.0.1:1510 > "$CK/replay2.log" 2>&1 &
        RP=$!
        cat "$CK/v.y4m" |
            "$EGOFUSE" run --scene "$S/scene.txt" --left /dev/video0 --right /dev/video1 --input 1 --dv \
            --fps 60 --virt-source stream:- --natnet 127.0.0.1 --frames 40 --raw \
            > /dev/null 2> "$CK/run2.err"
        rc=$?
        kill $RP 2>/dev/null
        wait $RP 2>/dev/null
        sum=$(tr '\r' '\n' < "$CK/run2.err" | grep 'stereo frames' | tail -n 1)
        echo "VMINFO cockpit2 $sum"
        if [ $rc -eq 0 ] && echo "$sum" | grep -q '^egofuse run: 40 stereo frames' &&
            echo "$sum" | grep -q 'V ended (last good held' && echo "$sum" | grep -q 'tracker stale'; then
            echo "VMTEST cockpit_sources_end PASS V from gst-launch-1.0 ended and the tracker stopped mid-run: reported, 40 frames composited"
        else
            echo "VMTEST cockpit_sources_end FAIL exit $rc: $sum $(tail -c 300 "$CK/run2.err") $(cat "$CK/gst.err")"
            fail=1
        fi
    else
        echo "VMTEST cockpit_sources_end FAIL gst-launch-1.0 is not installed (scripts/deps.sh installs it)"
        fail=1
    fi
fi

step end
exit $fail
