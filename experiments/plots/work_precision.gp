# Work-precision from work_precision.csv (error at the fixed time against wall time) and
# backward Euler's artificial damping from work_precision_damping.csv.
# gnuplot -e "dir='experiments/results'" experiments/plots/work_precision.gp
if (!exists("dir")) dir = 'experiments/results'
if (!exists("scenes")) scenes = 'soft stiff'  # the scenes the CSV holds (--quick: soft)
csv = dir.'/work_precision.csv'
set datafile separator ','
set logscale xy
set grid
set key outside right top
sel(scene, integ, order) = sprintf("< awk -F, '$1==\"%s\" && $2==\"%s\" && $3==%d' %s | sort -t, -k4,4g -k5,5g", scene, integ, order, csv)
integrators = "euler symplectic rk4 implicit"
colors = "#d62728 #2ca02c #1f77b4 #9467bd"

do for [scene in scenes] {
  do for [q in "position energy"] {
    col = (q eq "position") ? 8 : 9
    do for [fmt in "pngcairo svg"] {
      if (fmt eq "pngcairo") { set terminal pngcairo size 900,560 font ",10"; set output dir.'/work_precision_'.scene.'_'.q.'.png' } \
      else { set terminal svg size 900,560 font ",10"; set output dir.'/work_precision_'.scene.'_'.q.'.svg' }
      set title 'Work-precision, '.scene.' scene: '.(q eq "position" ? 'max position error (m)' : 'relative energy error').' at the fixed time'
      set xlabel 'wall time (s)'
      set ylabel (q eq "position" ? 'max |x - x_{ref}| (m)' : '|E - E_{ref}| / E_{ref}')
      plot for [i=1:4] sel(scene, word(integrators,i), 0) using 7:col with linespoints pt 7 lw 2 lc rgb word(colors,i) title word(integrators,i), \
           sel(scene, 'cvode', 2) using 7:col with linespoints pt 5 lw 2 lc rgb '#ff7f0e' title 'cvode, order <= 2', \
           sel(scene, 'cvode', 5) using 7:col with linespoints pt 9 lw 2 lc rgb '#8c564b' title 'cvode, order <= 5'
      set output
    }
  }
}

damping = dir.'/work_precision_damping.csv'
do for [fmt in "pngcairo svg"] {
  if (fmt eq "pngcairo") { set terminal pngcairo size 760,480 font ",10"; set output dir.'/implicit_damping.png' } \
  else { set terminal svg size 760,480 font ",10"; set output dir.'/implicit_damping.svg' }
  set title "Backward Euler's artificial damping: undamped stiff cube (k = 10^4), first 0.02 s"
  set xlabel 'dt (s)'
  set ylabel 'energy decay rate ln(E_0/E)/T (1/s)'
  unset key
  plot damping every ::1 using 3:9 with linespoints pt 7 lw 2 lc rgb '#9467bd'
  set output
}
