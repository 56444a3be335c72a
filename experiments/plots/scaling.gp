# Scaling from scaling.csv: wall time per simulated second against cube resolution N; and the
# crossover atlas from every *_atlas.csv (scaling_atlas.csv and the atlas-only runs').
# gnuplot -e "dir='experiments/results'; atlas_ns='8 16 32'" experiments/plots/scaling.gp
# A directory of atlas-only runs (the free scene's) draws the atlas alone:
# gnuplot -e "dir='experiments/results/atlas_free'; atlas_ns='8'; atlas_only=1; scene=' (free flight)'" ...
if (!exists("dir")) dir = 'experiments/results'
if (!exists("atlas_only")) atlas_only = 0
if (!exists("scene")) scene = ''
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
do for [fmt in (atlas_only ? "" : "pngcairo svg")] {
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

# The crossover atlas from every *_atlas.csv: each integrator's wall time per simulated second at
# the largest step keeping the visible motion within the tolerance, against k, one chart per N.
atlases = dir.'/*_atlas.csv'
if (!exists("atlas_ns")) atlas_ns = '8'
asel(n, integ) = sprintf("< awk -F, '$2==\"%s\" && $4==\"%s\" && $11==\"ok\"' %s | sort -t, -k1,1g", n, integ, atlases)
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
    set title 'Crossover atlas'.scene.', N = '.n.': cost at the largest step keeping the visible motion within 1 cm'."\n".'(a missing point: not reached)'
    plot for [i=1:10] asel(n, word(aintegrators,i)) using 1:8 with linespoints pt (word(apoints,i)+0) lw 2 lc rgb word(acolors,i) title word(aintegrators,i)
    set output
  }
}

# The region chart: at each (k, N) run, the cheapest integrator keeping the visible motion, with
# its cost; "none" where no integrator did within the run budget.
region = "< awk -F, 'FNR > 1 { key = $1 \" \" $2; seen[key] = 1 } FNR > 1 && $11 == \"ok\" { key = $1 \" \" $2; if (!(key in best) || $8 + 0 < best[key]) { best[key] = $8 + 0; who[key] = $4 } } END { for (key in seen) print key, (key in best ? who[key] \" \" best[key] : \"none nan\") }' ".atlases
acolor(s) = s eq 'euler' ? 0xd62728 : s eq 'symplectic' ? 0x2ca02c : s eq 'rk4' ? 0x1f77b4 : \
  s eq 'implicit' ? 0x9467bd : s eq 'implicit-linear' ? 0xc5b0d5 : s eq 'midpoint' ? 0x17becf : \
  s eq 'newmark' ? 0xbcbd22 : s eq 'bdf2' ? 0xe377c2 : s eq 'projective' ? 0x7f7f7f : \
  s eq 'cvode' ? 0xff7f0e : 0xdddddd
cost(t) = t < 1 ? sprintf('%.3g ms', 1e3 * t) : sprintf('%.3g s', t)
set datafile separator whitespace
set logscale x
set logscale y 2
set xrange [30:3e8]
set yrange [5.5:46]
set ytics (8, 16, 32)
set format y '%g'
set ylabel 'cube resolution N'
unset grid
do for [fmt in (atlas_only ? "" : "pngcairo svg")] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 1000,420 font ",10"; set output dir.'/atlas_region.png' } \
  else { set terminal svg size 1000,420 font ",10"; set output dir.'/atlas_region.svg' }
  set title 'Crossover atlas: the cheapest integrator keeping the visible motion within 1 cm, and its wall time per simulated second'
  plot region using 1:2:(acolor(strcol(3))) with points pt 5 ps 7 lc rgb variable notitle, \
       region using 1:2:(strcol(3) eq 'none' ? "none within\nthe budget" : strcol(3)."\n".cost(column(4))) with labels font ",8" notitle, \
       for [i=1:10] NaN with points pt 5 ps 2 lc rgb word(acolors,i) title word(aintegrators,i)
  set output
}
