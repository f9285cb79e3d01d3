#!/bin/sh
# Judges a soak of `egofuse run` (tests/vm/soak.sh wrote DIR) and prints its
# figures as a table; exit 0 when it passed. Runs in the guest and on the
# host (POSIX sh and awk only).
#
#   soak_report.sh DIR
#
# Passes when:
#   - `egofuse run` was alive at the end and exited 0 on SIGINT;
#   - it logged every disconnect ("camera lost") and reconnect ("camera
#     back"): as many of each as cameras were taken away;
#   - after every return, frames were composited from fresh images of BOTH
#     cameras (the frames.csv rows whose two camera time stamps are later
#     than the return) before the next disconnect, at least MIN_FRAMES
#     (default 3);
#   - every V stall was seen (frames composited with V stale, the last good
#     V held) and V came back live after it;
#   - resident memory and descriptors stayed flat after the warm-up (the
#     first WARM_PCT percent of the soak, default 20), sampled every few
#     seconds from /proc/PID/status and /proc/PID/fd:
#       VmRSS max - min at most RSS_RANGE_KB (default 8192: VmRSS counts
#       the cameras' mapped buffers, 2 x 4 x 600 kB at 640x480 YUYV, only
#       while they are mapped and touched, so it steps by up to 4.7 MiB as
#       cameras go and come);
#       the process's own memory, RssAnon + RssShmem (the heap, where a
#       leak accumulates): max - min at most OWN_RANGE_KB (default 2048),
#       and its least-squares slope over time, projected over the window,
#       at most RSS_GROWTH_KB (default 1024; a leak of 50 kB per camera
#       return would add 1 MiB over 20 returns);
#     descriptors max - min at most 2 (the two cameras' own, closed while
#     they are away), never more than at the first frame (both cameras
#     streaming) and as many at the end (the cameras back) as then.
D=${1:?usage: soak_report.sh DIR}
MIN_FRAMES=${MIN_FRAMES:-3}
WARM_PCT=${WARM_PCT:-20}
RSS_RANGE_KB=${RSS_RANGE_KB:-8192}
OWN_RANGE_KB=${OWN_RANGE_KB:-2048}
RSS_GROWTH_KB=${RSS_GROWTH_KB:-1024}
for f in events.txt samples.csv run.err; do
    [ -f "$D/$f" ] || {
        echo "FAIL: $D/$f missing"
        exit 1
    }
done
CSV="$D/frames.csv"
[ -f "$CSV" ] || CSV=$(ls "$D"/frames.csv.tmp.* 2> /dev/null | head -n 1)
[ -n "$CSV" ] && [ -f "$CSV" ] || {
    echo "FAIL: $D/frames.csv missing"
    exit 1
}
LOST=$(tr '\r' '\n' < "$D/run.err" | grep -c 'camera lost')
BACK=$(tr '\r' '\n' < "$D/run.err" | grep -c 'camera back')

awk -v lost="$LOST" -v back="$BACK" -v minf="$MIN_FRAMES" -v warm_pct="$WARM_PCT" \
    -v rss_range="$RSS_RANGE_KB" -v rss_growth="$RSS_GROWTH_KB" -v own_range="$OWN_RANGE_KB" '
FILENAME ~ /events.txt$/ {
    t = $1 + 0
    if ($2 == "warm") t_warm = t
    else if ($2 == "stop") t_stop = t
    else if ($2 == "exit") { rc = $3; alive = $5; have_exit = 1 }
    else if ($2 == "gone") { nu++; u_t[nu] = t; eyes_away += NF - 3 }
    else if ($2 == "replug") { nr++; r_t[nr] = t }
    else if ($2 == "vstop") { ns++; s_t[ns] = t }
    else if ($2 == "vcont") { nc++; c_t[nc] = t }
    else if ($2 == "fail") { nfail++; fails = fails "; " substr($0, index($0, "fail")) }
    next
}
FILENAME ~ /samples.csv$/ {
    if (FNR == 1) next
    split($0, a, ",")
    ns_++; st[ns_] = a[1] + 0; srss[ns_] = a[2] + 0; sfd[ns_] = a[3] + 0
    sown[ns_] = (a[4] != "") ? a[4] + a[6] : a[2] # RssAnon + RssShmem
    next
}
{   # frames.csv: frame,t_cam_l_ns,t_cam_r_ns,t_dequeue_ns,...,v_state (19th)
    if (FNR == 1) next
    split($0, a, ",")
    nf_++; fl[nf_] = a[2] / 1e9; fr[nf_] = a[3] / 1e9; fd_[nf_] = a[4] / 1e9; fv[nf_] = a[19] + 0
}
END {
    bad = ""
    if (!t_warm) bad = bad "; no warm event (no frame?)"
    if (!have_exit) bad = bad "; no exit event"
    else if (alive != 1 || rc != 0) bad = bad sprintf("; egofuse run exited (alive at the end %d, exit %d)", alive, rc)
    if (nfail) bad = bad fails
    # disconnects and reconnects logged
    if (lost != eyes_away) bad = bad sprintf("; %d cameras taken away, %d \"camera lost\" logged", eyes_away, lost)
    if (back != eyes_away) bad = bad sprintf("; %d cameras taken away, %d \"camera back\" logged", eyes_away, back)
    # frames after every return, from both cameras
    minafter = -1
    for (i = 1; i <= nr; i++) {
        lim = (i < nu) ? u_t[i + 1] : t_stop
        c = 0
        for (k = 1; k <= nf_; k++)
            if (fl[k] > r_t[i] && fr[k] > r_t[i] && fd_[k] < lim) c++
        if (minafter < 0 || c < minafter) minafter = c
        if (c < minf) bad = bad sprintf("; cycle %d: %d frames from both returned cameras (< %d)", i, c, minf)
    }
    # V stalls: held (stale) during, live after
    vseen = 0
    for (i = 1; i <= ns; i++) {
        stale = 0; live = 0
        for (k = 1; k <= nf_; k++) {
            if (fd_[k] > s_t[i] && fd_[k] < c_t[i] && fv[k] == 2) stale++
            if (fd_[k] > c_t[i] && (i == ns || fd_[k] < s_t[i + 1]) && fv[k] == 1) live++
        }
        if (stale && live) vseen++
        else bad = bad sprintf("; V stall %d: %d frames with V stale during it, %d with V live after", i, stale, live)
    }
    # frames in all, per minute of soak
    frames = nf_
    t_end = t_stop ? t_stop : st[ns_]
    minutes = (t_end - t_warm) / 60
    # RSS and descriptors after the warm-up
    tw = t_warm + (t_end - t_warm) * warm_pct / 100
    n = 0; sx = sy = sxx = sxy = 0
    for (k = 1; k <= ns_; k++) {
        if (!f_warm && st[k] >= t_warm) f_warm = sfd[k] # both cameras streaming
        if (st[k] < tw || st[k] > t_end) continue
        n++
        if (n == 1) { rmin = rmax = srss[k]; fmin = fmax = sfd[k]; f_first = sfd[k]; r_first = srss[k]; x0 = st[k] }
        if (srss[k] < rmin) rmin = srss[k]
        if (srss[k] > rmax) rmax = srss[k]
        if (sfd[k] < fmin) fmin = sfd[k]
        if (sfd[k] > fmax) fmax = sfd[k]
        f_last = sfd[k]; r_last = srss[k]; x1 = st[k]
        x = st[k] - x0
        y = sown[k]
        sx += x; sy += y; sxx += x * x; sxy += x * y
        sy2 += srss[k]; sxy2 += x * srss[k]
        if (n == 1 || y < omin) omin = y
        if (n == 1 || y > omax) omax = y
    }
    slope = slope_rss = 0
    if (n >= 3 && n * sxx - sx * sx > 0) {
        slope = (n * sxy - sx * sy) / (n * sxx - sx * sx)
        slope_rss = (n * sxy2 - sx * sy2) / (n * sxx - sx * sx)
    }
    growth = slope * (x1 - x0)
    if (n < 3) bad = bad sprintf("; %d samples after the warm-up", n)
    else {
        if (rmax - rmin > rss_range) bad = bad sprintf("; VmRSS range %d kB > %d kB", rmax - rmin, rss_range)
        if (omax - omin > own_range) bad = bad sprintf("; RssAnon + RssShmem range %d kB > %d kB", omax - omin, own_range)
        if (growth > rss_growth) bad = bad sprintf("; RssAnon + RssShmem grows %.0f kB over the window (slope %.1f kB/min) > %d kB", growth, slope * 60, rss_growth)
        if (fmax - fmin > 2) bad = bad sprintf("; descriptors %d..%d", fmin, fmax)
        if (f_warm && fmax > f_warm) bad = bad sprintf("; descriptors up to %d, %d at the first frame", fmax, f_warm)
        if (f_warm && f_last != f_warm) bad = bad sprintf("; descriptors %d at the end (cameras back), %d at the first frame", f_last, f_warm)
    }
    printf "| minutes | disconnects | reconnects | frames | min frames after a return | V stalls held/back | VmRSS min / max (kB) | VmRSS slope (kB/min) | RssAnon+Shmem min / max (kB) | its slope (kB/min) | fds min / max |\n"
    printf "|---|---|---|---|---|---|---|---|---|---|---|\n"
    printf "| %.1f | %d | %d | %d | %d | %d/%d | %d / %d | %+.1f | %d / %d | %+.1f | %d / %d |\n", minutes, lost, back, frames,
        minafter, vseen, ns, rmin, rmax, slope_rss * 60, omin, omax, slope * 60, fmin, fmax
    printf "RSS and fds over %.1f min after a %.1f min warm-up, %d samples: VmRSS %d kB at its start, %d kB at its end; fds %d at the first frame, %d at the window start, %d at its end\n",
        (x1 - x0) / 60, (tw - t_warm) / 60, n, r_first, r_last, f_warm, f_first, f_last
    if (bad != "") { print "FAIL: " substr(bad, 3); exit 1 }
    printf "PASS: %.1f min, %d cameras taken away and back (%d cycles), %d V stalls, %d frames, VmRSS %d..%d kB, RssAnon+Shmem %d..%d kB (%+.1f kB/min), fds %d..%d\n",
        minutes, eyes_away, nr, ns, frames, rmin, rmax, omin, omax, slope * 60, fmin, fmax
}' "$D/events.txt" "$D/samples.csv" "$CSV"
