# The friction scene's implicit errors against their step (scripts/run-experiments.sh
# slide-steps): each integrator's largest corner distance from the reference over the 2 s
# against h w_max (w_max: static friction's damping rate), from the finished runs of every
# NAME_tries.csv there; the 1 cm tolerance and h w_max = 1 drawn in.
# gnuplot -e "dir='experiments/results/slide_steps'" experiments/plots/slide_steps.gp
if (!exists("dir")) dir = 'experiments/results/slide_steps'
tries = dir.'/*_tries.csv'
cells = dir.'/*_atlas.csv'
set datafile separator ','
load 'experiments/plots/integrators.gp'
shown = system("awk -F, 'FNR > 1 { print $3 }' ".tries." | awk '!seen[$0]++' | tr '\\n' ' '")
w_max = system("awk -F, 'FNR == 2 { print $3; exit }' ".cells) + 0
k = system("awk -F, 'FNR == 2 { print $1; exit }' ".tries) + 0
tolerance = 0.01
sel(integ) = sprintf("< awk -F, '$3==\"%s\" && $9==1' %s", integ, tries)
set logscale xy
set grid
set format x '10^{%L}'
set format y '10^{%L}'
set xlabel 'h w_{max}'
set ylabel 'largest corner distance from the reference over 2 s (m)'
set key bottom right font ",9"
set arrow 1 from 1, graph 0 to 1, graph 1 nohead dt 3 lc rgb 'gray40'
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 900,560 font ",10"; set output dir.'/slide_steps.png' } \
  else { set terminal svg size 900,560 font ",10"; set output dir.'/slide_steps.svg' }
  set title sprintf('Sliding to rest with friction (N = 8, k = %g N/m): the error against the step', k)
  plot for [m in shown] sel(m) using ($4 * w_max):8 with linespoints lw 1.5 pt pointtype(m) \
         lc rgb colour(m) title m, \
       tolerance with lines dt 2 lw 1.5 lc rgb 'black' title '1 cm'
  set output
}
