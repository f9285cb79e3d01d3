# Time per whole stereo frame against the share of the camera image the
# hands cover (bench_frame: frame_cover.csv).
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo size 800,500
set output dir.'/frame_cover.png'
set datafile separator ','
set grid
set key top left
set title 'egofuse: whole stereo frame vs covered area (head moved towards the hands)'
set xlabel 'camera pixels covered by the hands (%)'
set ylabel 'ms per stereo frame (median)'
set yrange [0:*]
plot dir.'/frame_cover.csv' every ::1 using ($1*100):3 with linespoints lw 2 title '1 thread', \
     '' every ::1 using ($1*100):5 with linespoints lw 2 title '2 threads'
