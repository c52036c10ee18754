set terminal pngcairo noenhanced size 960,600 font 'sans,11'
set output '../img/bench_tradeoff.png'
set title 'Speed against accuracy: each point a sample count (padding 0)'
set logscale x
set grid
set key outside below
set xlabel 'fraction of pixels whose hit differs from brute force, fallback off (0 drawn at 1e-6)'
set ylabel 'frames per second, fallback on'
plot 'plot_tradeoff.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title 'arbitrary', '' index 0 using 1:2:(sprintf('%d', $3)) with labels offset char 0.8,0.6 font ',8' notitle, \
     'plot_tradeoff.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title 'limits', '' index 1 using 1:2:(sprintf('%d', $3)) with labels offset char 0.8,0.6 font ',8' notitle, \
     'plot_tradeoff.dat' index 2 using 1:2 with linespoints lw 2 pt 7 title 'clips', '' index 2 using 1:2:(sprintf('%d', $3)) with labels offset char 0.8,0.6 font ',8' notitle, \
     'plot_tradeoff.dat' index 3 using 1:2 with linespoints lw 2 pt 7 title 'clip', '' index 3 using 1:2:(sprintf('%d', $3)) with labels offset char 0.8,0.6 font ',8' notitle
