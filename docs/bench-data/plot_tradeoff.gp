set terminal pngcairo noenhanced size 1600,640 font 'sans,11'
set output '../img/bench_tradeoff.png'
set multiplot layout 1,2
set title "Work against accuracy (padding 0): each point a sample count, labelled samples / fps;\nrings and lines: each mode's Pareto front"
set logscale x
set grid
set key outside below
set xlabel 'fraction of pixels whose hit differs from brute force, fallback off (0 drawn at 1e-6)'
set ylabel 'triangle tests + kd-tree node visits per ray (deterministic)'
plot 'plot_tradeoff.dat' index 1 using 1:2 with linespoints lw 2 pt 6 ps 2 lc 1 title 'arbitrary', '' index 0 using 1:2 with points pt 7 lc 1 notitle, '' index 0 using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',7' notitle, \
     'plot_tradeoff.dat' index 3 using 1:2 with linespoints lw 2 pt 6 ps 2 lc 2 title 'limits', '' index 2 using 1:2 with points pt 7 lc 2 notitle, '' index 2 using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',7' notitle, \
     'plot_tradeoff.dat' index 5 using 1:2 with linespoints lw 2 pt 6 ps 2 lc 3 title 'clips', '' index 4 using 1:2 with points pt 7 lc 3 notitle, '' index 4 using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',7' notitle, \
     'plot_tradeoff.dat' index 7 using 1:2 with linespoints lw 2 pt 6 ps 2 lc 4 title 'clip', '' index 6 using 1:2 with points pt 7 lc 4 notitle, '' index 6 using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',7' notitle
unset logscale
set title 'Pose-space clusters, Cally at 213888 triangles: each point a K, labelled K / fps'
set key off
set xlabel 'character pack size, MB'
set ylabel 'triangle tests + kd-tree node visits per ray (deterministic)'
plot 'plot_tradeoff_clusters.dat' using 1:2 with linespoints lw 2 pt 7 lc 1, '' using 1:2:(sprintf('%d / %.0f', $3, $4)) with labels offset char 0.8,0.6 font ',8'
unset multiplot
