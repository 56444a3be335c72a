# Work-precision from work_precision.csv (errors over the whole window against wall time, the
# median of the repeats with their spread as horizontal bars), the artificial damping of
# backward Euler, BDF2 and midpoint against the linear theory (work_precision_damping.csv) and
# the long-run drift (work_precision_drift.csv).
# gnuplot -e "dir='experiments/results'" experiments/plots/work_precision.gp
if (!exists("dir")) dir = 'experiments/results'
if (!exists("scenes")) scenes = 'soft drop stiff'  # the scenes the CSV holds (--quick: soft)
csv = dir.'/work_precision.csv'
set datafile separator ','
set datafile missing 'nan'
set logscale xy
set grid
set key outside right top
sel(scene, integ, method) = sprintf("< awk -F, '$1==\"%s\" && $2==\"%s\" && $3==\"%s\" && $22==\"ok\"' %s | sort -t, -k4,4g -k5,5g", scene, integ, method, csv)
load 'experiments/plots/integrators.gp'
# Adaptive integrators (CVODE) run each of its methods: a line per method, in the variant colour.
adaptive = ''
do for [i=1:words(integrators)] { name = word(integrators, i); if (strstrt(' '.fixed_step_integrators.' ', ' '.name.' ') == 0) { adaptive = adaptive.' '.name } }
nfixed = words(fixed_step_integrators)

do for [scene in scenes] {
  do for [q in "position energy"] {
    col = (q eq "position") ? 13 : 15
    do for [fmt in "pngcairo svg"] {
      if (fmt eq "pngcairo") { set terminal pngcairo size 980,600 font ",10"; set output dir.'/work_precision_'.scene.'_'.q.'.png' } \
      else { set terminal svg size 980,600 font ",10"; set output dir.'/work_precision_'.scene.'_'.q.'.svg' }
      set title 'Work-precision, '.scene.' scene: '.(q eq "position" ? 'largest position error over the window (m)' : 'largest energy error over the window, relative to E(0)')
      set xlabel 'wall time of the steps (s; median, bars: min to max of the repeats)'
      set ylabel (q eq "position" ? 'max_t max_i |x_i - x_{ref}| (m)' : 'max_t |E - E_{ref}| / E_{ref}(0)')
      plot for [i=1:nfixed] sel(scene, word(fixed_step_integrators,i), 'none') using 10:col:11:12 with xerrorlines pt pointtype(word(fixed_step_integrators,i)) lw 2 lc rgb colour(word(fixed_step_integrators,i)) title word(fixed_step_integrators,i), \
           for [i=1:words(adaptive)] sel(scene, word(adaptive,i), 'bdf') using 10:col:11:12 with xerrorlines pt 5 lw 2 lc rgb colour(word(adaptive,i)) title word(adaptive,i).', BDF', \
           for [i=1:words(adaptive)] sel(scene, word(adaptive,i), 'adams') using 10:col:11:12 with xerrorlines pt 9 lw 2 lc rgb variant_colour(word(adaptive,i)) title word(adaptive,i).', Adams'
      set output
    }
  }
}

damping = dir.'/work_precision_damping.csv'
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 760,480 font ",10"; set output dir.'/implicit_damping.png' } \
  else { set terminal svg size 760,480 font ",10"; set output dir.'/implicit_damping.svg' }
  set title "Artificial damping: undamped stiff cube (k = 10^4), first 0.02 s; lines: linear theory on its modes"
  set xlabel 'dt (s)'
  set ylabel 'energy decay rate ln(E_0/E)/T (1/s)'
  set logscale x
  unset logscale y
  set format x '10^{%L}'
  set key inside right top
  dmp(integ) = sprintf("< awk -F, '$2==\"%s\"' %s | sort -t, -k3,3g", integ, damping)
  # The integrators the CSV holds (one per A-stable linear model), in its order.
  damped = system("awk -F, 'NR > 1 && !seen[$2]++ { printf \"%s \", $2 }' ".damping)
  plot for [i=1:words(damped)] dmp(word(damped,i)) using 3:12 with lines lw 2 lc rgb colour(word(damped,i)) title word(damped,i).', theory', \
       for [i=1:words(damped)] dmp(word(damped,i)) using 3:9 with points pt pointtype(word(damped,i)) ps 1.2 lc rgb colour(word(damped,i)) title word(damped,i).', measured'
  set output
  set format x
}

# Long-run drift (work_precision_drift.csv): the undamped spinning cube's energy and angular
# momentum over the whole run, per integrator (forward Euler's run ends where it diverged).
drift = dir.'/work_precision_drift.csv'
dsel(integ) = sprintf("< awk -F, '$1==\"%s\"' %s", integ, drift)
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 980,820 font ",10"; set output dir.'/work_precision_drift.png' } \
  else { set terminal svg size 980,820 font ",10"; set output dir.'/work_precision_drift.svg' }
  set multiplot layout 2,1 title "Long-run drift: undamped spinning cube, k = 10^3, touching nothing; explicit methods at half their limit, the others at dt = 0.01 s\n(euler diverges within 0.02 s; projective's lines cover implicit's)"
  unset title
  unset logscale
  set format y '10^{%L}' 
  set logscale y
  set key outside right top
  set xlabel 't (s)'
  set ylabel 'total energy E(t) / E(0)'
  set yrange [1e-6:10]
  plot for [i=1:nfixed] dsel(word(fixed_step_integrators,i)) using 3:5 with lines lw 2 lc rgb colour(word(fixed_step_integrators,i)) title word(fixed_step_integrators,i)
  set ylabel '|L(t) - L(0)| / |L(0)|'
  set yrange [1e-16:10]
  plot for [i=1:nfixed] dsel(word(fixed_step_integrators,i)) using 3:($6 > 0 ? $6 : 1/0) with lines lw 2 lc rgb colour(word(fixed_step_integrators,i)) title word(fixed_step_integrators,i)
  set format y
  unset multiplot
  set output
}
