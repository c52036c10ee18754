set terminal pngcairo noenhanced size 1200,520 font 'sans,11'
set output '../img/bench_scaling.png'
set logscale xy
set grid
set key top right
set ylabel 'frames per second'
set multiplot layout 1,2
set title 'fps against instances'
set xlabel 'Cally instances'
plot 'plot_scaling.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title '1 thread', 'plot_scaling.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title '2 threads'
set title 'fps against image size (one Cally)'
set xlabel 'megapixels'
plot 'plot_scaling_pixels.dat' index 0 using 1:2 with linespoints lw 2 pt 7 title '1 thread', 'plot_scaling_pixels.dat' index 1 using 1:2 with linespoints lw 2 pt 7 title '2 threads'
unset multiplot
