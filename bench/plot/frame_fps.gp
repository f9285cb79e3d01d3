# Frames per second (1000 / median ms) of the whole stereo frame per
# implementation, ISA and thread count, against the 60 FPS line
# (run_bench.sh derives frame_fps.csv from bench.csv).
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo size 1000,520
set output dir.'/frame_fps.png'
set datafile separator ','
set grid ytics
set key inside top left
set title 'Whole stereo frame (2 x 1280x800): frames per second from the median, vs 60 FPS'
set ylabel 'FPS (log scale)'
set logscale y
set yrange [1:3000]
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set boxwidth 0.9
set xtics rotate by -30 noenhanced
set arrow 1 from graph 0, first 60 to graph 1, first 60 nohead lw 2 lc rgb 'red'
set label 1 '60 FPS (16.7 ms)' at graph 0.99, first 66 right tc rgb 'red'
plot dir.'/frame_fps.csv' every ::1 using 2:xtic(1) title 'typical pose', \
     '' every ::1 using 3 title 'worst case (70% covered)'
