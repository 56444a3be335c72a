# The falling scene's visible motion over time (jello-scaling --atlas-trace; issue 39, item 5):
# per cube resolution N, the height of the fitted cube's centre and the cube's own height (the
# fit's A_zz) of the RK4 reference, and of backward Euler, BDF2 and projective at their largest
# step (0.02 s), from trace CSV's rows.
# gnuplot -e "dir='experiments/results/atlas_trace'" experiments/plots/atlas_trace.gp
if (!exists("dir")) dir = 'experiments/results/atlas_trace'
csv = dir.'/scaling_trace.csv'
set datafile separator ','
load 'experiments/plots/integrators.gp'
sel(n, integ) = sprintf("< awk -F, '$2==%d && $3==\"%s\"' %s", n, integ, csv)
ns = system("awk -F, 'NR > 1 { print $2 }' ".csv." | sort -nu | tr '\\n' ' '")
k = system("awk -F, 'NR == 2 { print $1 }' ".csv)
shown = "implicit bdf2 projective"
set grid
set xlabel 't (s)'
set ylabel 'm'
set key bottom left font ",8"
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 1200,420 font ",10"; set output dir.'/atlas_trace.png' } \
  else { set terminal svg size 1200,420 font ",10"; set output dir.'/atlas_trace.svg' }
  set multiplot layout 1, words(ns) title sprintf('The falling cube at k = %g N/m: its centre height (solid) and its own height (dashed)', k + 0)
  do for [i=1:words(ns)] {
    n = word(ns, i) + 0
    set title sprintf('N = %d', n)
    plot sel(n, 'reference') using 6:7 with lines lw 2 lc rgb 'black' title 'reference (RK4)', \
         sel(n, 'reference') using 6:8 with lines lw 2 dt 2 lc rgb 'black' notitle, \
         for [m in shown] sel(n, m) using 6:7 with lines lw 1.5 lc rgb colour(m) title m.' at its largest step', \
         for [m in shown] sel(n, m) using 6:8 with lines lw 1.5 dt 2 lc rgb colour(m) notitle
  }
  unset multiplot
  set output
}
