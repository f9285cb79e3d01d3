# Time per whole stereo frame against the output resolution per eye
# (bench_frame: frame_res.csv).
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo size 800,500
set output dir.'/frame_res.png'
set datafile separator ','
set grid
set key top left
set title 'egofuse: whole stereo frame vs output resolution (per eye; camera 640x480)'
set xlabel 'output megapixels per eye (640x400, 1280x800, 1920x1200, 2560x1600)'
set ylabel 'ms per stereo frame (median)'
set yrange [0:*]
plot dir.'/frame_res.csv' every ::1 using 3:4 with linespoints lw 2 title '1 thread', \
     '' every ::1 using 3:6 with linespoints lw 2 title '2 threads'
