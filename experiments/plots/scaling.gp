# Scaling from scaling.csv: wall time per simulated second against cube resolution N; and the
# crossover atlas from scaling_atlas.csv.
# gnuplot -e "dir='experiments/results'" experiments/plots/scaling.gp
if (!exists("dir")) dir = 'experiments/results'
csv = dir.'/scaling.csv'
set datafile separator ','
set logscale xy
set grid
set key outside right top
set xlabel 'cube resolution N (N^3 points)'
set ylabel 'wall seconds per simulated second'
sel(integ, solver) = sprintf("< awk -F, '$4==\"%s\" && $5==\"%s\"' %s | sort -t, -k1,1n", integ, solver, csv)
set xtics (6, 8, 12, 16, 24, 32)
set xrange [5.5:36]
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 900,560 font ",10"; set output dir.'/scaling.png' } \
  else { set terminal svg size 900,560 font ",10"; set output dir.'/scaling.svg' }
  set title 'Cost against cube size (k = 10^4; explicit at 0.9 of their limit, implicit dt 0.01, cvode rtol 1e-3)'
  plot sel('euler','none') using 1:12 with linespoints pt 7 lw 2 lc rgb '#d62728' title 'euler', \
       sel('symplectic','none') using 1:12 with linespoints pt 7 lw 2 lc rgb '#2ca02c' title 'symplectic', \
       sel('rk4','none') using 1:12 with linespoints pt 7 lw 2 lc rgb '#1f77b4' title 'rk4', \
       sel('implicit','cholmod') using 1:12 with linespoints pt 5 lw 2 lc rgb '#9467bd' title 'implicit, CHOLMOD', \
       sel('implicit','cholmod') using 1:14 with linespoints pt 4 dt 2 lc rgb '#9467bd' title '  its factorizations', \
       sel('implicit','cholmod') using 1:15 with linespoints pt 6 dt 3 lc rgb '#9467bd' title '  its solves', \
       sel('implicit','cg') using 1:12 with linespoints pt 9 lw 2 lc rgb '#8c564b' title 'implicit, CG', \
       sel('cvode','cholmod') using 1:12 with linespoints pt 11 lw 2 lc rgb '#ff7f0e' title 'cvode, CHOLMOD', \
       sel('cvode','cg') using 1:12 with linespoints pt 13 lw 2 lc rgb '#e377c2' title 'cvode, CG'
  set output
}

# The crossover atlas from scaling_atlas.csv: each integrator's wall time per simulated second at
# the largest step keeping the visible motion within the tolerance, against k, one chart per N.
atlas = dir.'/scaling_atlas.csv'
if (!exists("atlas_ns")) atlas_ns = '8 16'
asel(n, integ) = sprintf("< awk -F, '$2==\"%s\" && $4==\"%s\" && $11==\"ok\"' %s | sort -t, -k1,1g", n, integ, atlas)
aintegrators = "euler symplectic rk4 implicit implicit-linear midpoint newmark bdf2 projective cvode"
acolors = "#d62728 #2ca02c #1f77b4 #9467bd #c5b0d5 #17becf #bcbd22 #e377c2 #7f7f7f #ff7f0e"
apoints = "7 7 7 5 5 9 9 11 13 15"
unset xtics
set xtics auto
set xrange [*:*]
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'spring stiffness k (N/m)'
do for [n in atlas_ns] {
  do for [fmt in "pngcairo svg"] {
    if (fmt eq "pngcairo") { set terminal pngcairo size 900,560 font ",10"; set output dir.'/atlas_n'.n.'.png' } \
    else { set terminal svg size 900,560 font ",10"; set output dir.'/atlas_n'.n.'.svg' }
    set title 'Crossover atlas, N = '.n.': cost at the largest step keeping the visible motion within 1 cm (a missing point: not reached)'
    plot for [i=1:10] asel(n, word(aintegrators,i)) using 1:8 with linespoints pt (word(apoints,i)+0) lw 2 lc rgb word(acolors,i) title word(aintegrators,i)
    set output
  }
}
