# Time per whole stereo frame against the triangle count (bench_frame:
# frame_tris.csv). Usage: gnuplot -e "dir='bench/out'" bench/plot/frame_tris.gp
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo size 800,500
set output dir.'/frame_tris.png'
set datafile separator ','
set grid
set key top left
set title 'egofuse: whole stereo frame vs triangle count (bench\_mesh arms, best ISA)'
set xlabel 'triangles'
set ylabel 'ms per stereo frame (median)'
set yrange [0:*]
set logscale x
plot dir.'/frame_tris.csv' every ::1 using 1:3 with linespoints lw 2 title '1 thread', \
     '' every ::1 using 1:5 with linespoints lw 2 title '2 threads'
