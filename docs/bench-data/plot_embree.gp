set terminal pngcairo noenhanced size 1280,600 font 'sans,11'
set output '../img/bench_embree.png'
set style data histograms
set style histogram rowstacked
set style fill solid 0.85 border -1
set boxwidth 0.8
set grid ytics
set ylabel 'ms per frame (median)'
set xtics rotate by -40 scale 0 font ',9'
set key top left
set bmargin 9
set multiplot layout 1,2
set title 'Cally, 3342 triangles'
plot newhistogram "walk\n1 thread" lt 1, 'plot_embree.dat' index 0 using 2:xtic(1) title 'skinning', ''  index 0 using 3 title 'build / refit', ''  index 0 using 4 title 'primary rays', ''  index 0 using 5 title 'shadow rays', ''  index 0 using 6 title 'shading', \
     newhistogram "walk\n2 threads" lt 1, 'plot_embree.dat' index 1 using 2:xtic(1) notitle, ''  index 1 using 3 notitle, ''  index 1 using 4 notitle, ''  index 1 using 5 notitle, ''  index 1 using 6 notitle, \
     newhistogram "tornado_kick\n1 thread" lt 1, 'plot_embree.dat' index 2 using 2:xtic(1) notitle, ''  index 2 using 3 notitle, ''  index 2 using 4 notitle, ''  index 2 using 5 notitle, ''  index 2 using 6 notitle, \
     newhistogram "tornado_kick\n2 threads" lt 1, 'plot_embree.dat' index 3 using 2:xtic(1) notitle, ''  index 3 using 3 notitle, ''  index 3 using 4 notitle, ''  index 3 using 5 notitle, ''  index 3 using 6 notitle
set title 'Cally subdivided, 855552 triangles'
plot newhistogram "walk\n1 thread" lt 1, 'plot_embree_large.dat' index 0 using 2:xtic(1) title 'skinning', ''  index 0 using 3 title 'build / refit', ''  index 0 using 4 title 'primary rays', ''  index 0 using 5 title 'shadow rays', ''  index 0 using 6 title 'shading', \
     newhistogram "walk\n2 threads" lt 1, 'plot_embree_large.dat' index 1 using 2:xtic(1) notitle, ''  index 1 using 3 notitle, ''  index 1 using 4 notitle, ''  index 1 using 5 notitle, ''  index 1 using 6 notitle
unset multiplot
