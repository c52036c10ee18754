set terminal pngcairo noenhanced size 960,600 font 'sans,11'
set output '../img/bench_fps_vs_triangles.png'
set title 'Cally at 1024x1024: Sinew and the paper (Table 2)'
set logscale xy
set grid
set key outside below
set xlabel 'triangles (iterative subdivision of Cally)'
set ylabel 'frames per second'
plot 'plot_fps_vs_triangles.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title 'Sinew, 1 thread, primary rays', \
     '' index 0 using 1:3 with linespoints lw 2 pt 5 title 'Sinew, 1 thread, primary + shadow rays', \
     '' index 0 using 1:4 with linespoints lw 2 pt 9 title 'Sinew, 2 threads, primary rays', \
     '' index 0 using 1:5 with linespoints lw 2 pt 11 title 'Sinew, 2 threads, primary + shadow rays', \
     '' index 1 using 1:2 with linespoints lw 2 dt 2 pt 6 lc rgb 'black' title 'paper: one 2.4 GHz Opteron core, primary rays'
