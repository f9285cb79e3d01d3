# Time per whole stereo frame against the output megapixels of the named
# HMDs (bench_frame: frame_hmd.csv; kin_sthmd_preset), egofuse and the
# memory floor (memcpy of both outputs), 2 threads.
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo size 800,620
set output dir.'/frame_hmd.png'
set datafile separator ','
set grid
set key below Left reverse
set offsets 0, 0, graph 0.1, 0
set title 'egofuse: whole stereo frame on the named HMDs (2 threads, medians)'
set xlabel 'output megapixels, both eyes (2x 1280x800, 2x 2064x2208, 2x 2880x2720)'
set ylabel 'ms per stereo frame'
set xrange [0:18]
set yrange [0:*]
plot dir.'/frame_hmd.csv' every ::1 using 6:13 with linespoints lw 2 pt 7 title 'egofuse avx2', \
     '' every ::1 using 6:15 with linespoints lw 2 pt 5 title 'egofuse, best ISA', \
     '' every ::1 using 6:23 with linespoints lw 2 dt 3 pt 6 title 'egofuse avx2, in place (V in its own buffer)', \
     '' every ::1 using 6:24 with linespoints lw 2 dt 3 pt 4 title 'egofuse best ISA, in place', \
     '' every ::1 using 6:17 with linespoints lw 2 pt 9 title 'memory floor (memcpy of both outputs)', \
     '' every ::1 using 6:13:1 with labels offset 0,1 notitle, \
     5.5 with lines dt 2 lw 2 lc rgb 'red' title 'target for the consumer HMD (5.5 ms)'
