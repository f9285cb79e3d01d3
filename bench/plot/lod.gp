# Levels of detail of the sample model: raster stage time per eye against
# the mask's accuracy against the full model, per level and for the rule
# at 0.5-4 px (bench_lod: bench_lod.csv). Usage:
#   gnuplot -e "dir='bench/out'" bench/plot/lod.gp
if (!exists("dir")) dir = 'bench/out'
set terminal pngcairo noenhanced size 1300,520 font ',10'
set output dir.'/lod.png'
set datafile separator ','
set grid
set multiplot layout 1,2 title 'Levels of detail of the sample arms (bench_lod: 24 poses x 2 eyes, 640x400, cold cache, thread CPU time)'
set title 'Raster stage per eye against the mask IoU with the full model'
set xlabel 'ms per eye (clear + transforms + draw; median)'
set ylabel 'IoU against the full model (mean)'
set key bottom right
plot dir.'/bench_lod.csv' using (strcol(6) eq 'none' ? $9 : 1/0):11 with points pt 7 ps 1.4 title 'cull none (the pipe default)', \
     '' using (strcol(6) eq 'back' ? $9 : 1/0):11 with points pt 5 ps 1.4 title 'cull back', \
     '' using (strcol(6) eq 'none' ? $9 : 1/0):11:(strcol(2)) with labels offset 0,0.9 font ',8' notitle
set title 'Triangles submitted against the draw time'
set xlabel 'triangles submitted per eye'
set ylabel 'ms per eye (draw only; median)'
set key top left
set yrange [0:*]
plot dir.'/bench_lod.csv' using (strcol(6) eq 'none' ? $7 : 1/0):10 with points pt 7 ps 1.4 title 'cull none', \
     '' using (strcol(6) eq 'back' ? $7 : 1/0):10 with points pt 5 ps 1.4 title 'cull back', \
     '' using (strcol(6) eq 'none' ? $7 : 1/0):10:(strcol(2)) with labels offset 0,0.9 font ',8' notitle
unset multiplot
