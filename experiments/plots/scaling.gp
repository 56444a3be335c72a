# Scaling from scaling.csv: wall time per simulated second against cube resolution N.
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
