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
load 'experiments/plots/integrators.gp'
# The (integrator, linear solver) pairs the CSV holds, in its order: explicit ones with "none".
pairs = system("awk -F, 'NR > 1 && !seen[$4 \",\" $5]++ { printf \"%s,%s \", $4, $5 }' ".csv)
pinteg(p) = p[1:strstrt(p, ',') - 1]
psolver(p) = p[strstrt(p, ',') + 1:]
plabel(p) = psolver(p) eq 'none' ? pinteg(p) : pinteg(p).', '.(psolver(p) eq 'cholmod' ? 'CHOLMOD' : psolver(p) eq 'cg' ? 'CG' : psolver(p))
# The first solver of an integrator in its colour, the next in its variant colour.
pfirst(p, i) = i == 1 ? 1 : pinteg(word(pairs, i - 1)) ne pinteg(p)
pcolour(p, i) = pfirst(p, i) ? colour(pinteg(p)) : variant_colour(pinteg(p))
# The first implicit pair with a factorization's share (its CHOLMOD run): its parts dashed.
split = system("awk -F, 'NR > 1 && $5 == \"cholmod\" { print $4 \",\" $5; exit }' ".csv)
set xtics (6, 8, 12, 16, 24, 32)
set xrange [5.5:36]
do for [fmt in (atlas_only ? "" : "pngcairo svg")] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 900,560 font ",10"; set output dir.'/scaling.png' } \
  else { set terminal svg size 900,560 font ",10"; set output dir.'/scaling.svg' }
  set title 'Cost against cube size (k = 10^4; explicit at 0.9 of their limit, implicit dt 0.01, cvode rtol 1e-3)'
  plot for [i=1:words(pairs)] sel(pinteg(word(pairs,i)), psolver(word(pairs,i))) using 1:12 with linespoints pt pointtype(pinteg(word(pairs,i))) lw 2 lc rgb pcolour(word(pairs,i), i) title plabel(word(pairs,i)), \
       sel(pinteg(split), psolver(split)) using 1:14 with linespoints pt 4 dt 2 lc rgb colour(pinteg(split)) title '  its factorizations', \
       sel(pinteg(split), psolver(split)) using 1:15 with linespoints pt 6 dt 3 lc rgb colour(pinteg(split)) title '  its solves'
  set output
}

# The crossover atlas from every *_atlas.csv: each integrator's wall time per simulated second at
# the largest step keeping the visible motion within the tolerance, against k, one chart per N.
atlases = dir.'/*_atlas.csv'
if (!exists("atlas_ns")) atlas_ns = '8'
asel(n, integ) = sprintf("< awk -F, '$2==\"%s\" && $4==\"%s\" && $11==\"ok\"' %s | sort -t, -k1,1g", n, integ, atlases)
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
    plot for [i=1:words(integrators)] asel(n, word(integrators,i)) using 1:8 with linespoints pt pointtype(word(integrators,i)) lw 2 lc rgb colour(word(integrators,i)) title word(integrators,i)
    set output
  }
}

# The region chart: at each (k, N) run, the cheapest integrator keeping the visible motion, with
# its cost; "none" where no integrator did within the run budget.
region = "< awk -F, 'FNR > 1 { key = $1 \" \" $2; seen[key] = 1 } FNR > 1 && $11 == \"ok\" { key = $1 \" \" $2; if (!(key in best) || $8 + 0 < best[key]) { best[key] = $8 + 0; who[key] = $4 } } END { for (key in seen) print key, (key in best ? who[key] \" \" best[key] : \"none nan\") }' ".atlases
# A colour as a number, for `lc rgb variable`: grey where no integrator kept the motion.
acolor(s) = rowof(s, 1) == 0 ? 0xdddddd : int('0x'.colour(s)[2:])
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
       for [i=1:words(integrators)] NaN with points pt 5 ps 2 lc rgb colour(word(integrators,i)) title word(integrators,i)
  set output
}
