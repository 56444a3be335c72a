# Stability map from stability.csv: largest stable dt against k (measured points, predicted
# lines), and the same thresholds in Courant numbers h*w_max. One definition of the Courant
# number throughout: h w_max, w_max the scene's fastest mode (the dashed lines are h w_max = 1).
# gnuplot -e "dir='experiments/results'" experiments/plots/stability.gp
if (!exists("dir")) dir = 'experiments/results'
if (!exists("scenes")) scenes = 'free wall'  # the scenes the CSV holds (--quick: free)
csv = dir.'/stability.csv'
set datafile separator ','
set logscale xy
set format xy '10^{%L}'
set grid
set key below maxrows 3
set xlabel 'spring stiffness k (N/m)'
sel(scene, integ, src) = sprintf("< awk -F, '$1==\"%s\" && $2==\"%s\" && $7==\"%s\"' %s", scene, integ, src, csv)
load 'experiments/plots/integrators.gp'
nexplicit = words(explicit_integrators)
# The methods without a predicted limit: every other row, drawn only where the CSV has them.
others = ''
do for [i=1:words(integrators)] { name = word(integrators, i); if (strstrt(' '.explicit_integrators.' ', ' '.name.' ') == 0) { others = others.' '.name } }

do for [scene in scenes] {
  do for [fmt in "pngcairo svg"] {
    if (fmt eq "pngcairo") { set terminal pngcairo size 900,620 font ",10"; set output dir.'/stability_'.scene.'.png' } \
    else { set terminal svg size 900,620 font ",10"; set output dir.'/stability_'.scene.'.svg' }
    set title 'Largest stable time step, '.scene.' scene (points measured, lines predicted)'
    set ylabel 'dt (s)'
    set yrange [1e-6:0.1]
    plot for [i=1:nexplicit] sel(scene, word(explicit_integrators,i), 'predicted') using 3:8 with lines lw 2 lc rgb colour(word(explicit_integrators,i)) title word(explicit_integrators,i).' predicted', \
         for [i=1:nexplicit] sel(scene, word(explicit_integrators,i), 'measured') using 3:8 with points pt 7 ps 1.1 lc rgb colour(word(explicit_integrators,i)) title word(explicit_integrators,i).' measured', \
         for [i=1:words(others)] sel(scene, word(others,i), 'measured') using 3:8 with points pt (i == 1 ? 4 : 6 + i) ps (2.4 - 0.15 * i) lw 2 lc rgb colour(word(others,i)) title word(others,i).': largest stable dt found', \
         sel(scene, word(explicit_integrators,1), 'measured') using 3:(1/$5) with lines dt 2 lc rgb 'black' title 'Courant number 1: dt = 1/w_{max} (w_{max} of the scene, from the CSV)'
    set output
  }
  do for [fmt in "pngcairo svg"] {
    if (fmt eq "pngcairo") { set terminal pngcairo size 900,620 font ",10"; set output dir.'/courant_'.scene.'.png' } \
    else { set terminal svg size 900,620 font ",10"; set output dir.'/courant_'.scene.'.svg' }
    set title 'Thresholds in Courant numbers h w_{max}, '.scene.' scene'
    set ylabel 'h w_{max}'
    set yrange [0.005:10]
    plot for [i=1:nexplicit] sel(scene, word(explicit_integrators,i), 'predicted') using 3:9 with lines lw 2 lc rgb colour(word(explicit_integrators,i)) title word(explicit_integrators,i).' predicted', \
         for [i=1:nexplicit] sel(scene, word(explicit_integrators,i), 'measured') using 3:9 with points pt 7 ps 1.1 lc rgb colour(word(explicit_integrators,i)) title word(explicit_integrators,i).' measured', \
         1 with lines dt 2 lc rgb 'black' title 'Courant number 1: dt = 1/w_{max}'
    set output
  }
}
