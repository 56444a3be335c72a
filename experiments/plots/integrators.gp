# The integrators as the charts draw them, read from the integrator table (scripts/closed_sets.py
# reads src/world/integrator_table.h): every chart draws each integrator its CSV holds, in the
# table's order, and each row's colour and point type come from its position, so a new row gets
# the next ones and nothing here lists integrators. Loaded by the other scripts, which run from
# the project directory (scripts/run-experiments.sh): load 'experiments/plots/integrators.gp'
integrators = system("python3 scripts/closed_sets.py integrators --field name")
explicit_integrators = system("python3 scripts/closed_sets.py integrators --field name --where explicit")
implicit_integrators = system("python3 scripts/closed_sets.py integrators --field name --where implicit")
fixed_step_integrators = system("python3 scripts/closed_sets.py integrators --field name --where fixed_step")
palette = "#d62728 #2ca02c #1f77b4 #9467bd #ff7f0e #c5b0d5 #17becf #bcbd22 #e377c2 #7f7f7f #8c564b #aec7e8 #98df8a #ffbb78 #c49c94 #f7b6d2"
pointtypes = "7 7 7 5 15 5 9 9 11 13 4 6 8 10 12 14"
rowof(name, i) = i > words(integrators) ? 0 : word(integrators, i) eq name ? i : rowof(name, i + 1)
colour(name) = word(palette, rowof(name, 1))
pointtype(name) = word(pointtypes, rowof(name, 1)) + 0
# A second colour for an integrator's second variant (its other linear solver, CVODE's Adams).
variant_palette = "#aec7e8 #98df8a #ffbb78 #8c564b #843c39 #c49c94 #f7b6d2 #dbdb8d #9edae5 #c7c7c7 #393b79 #637939 #8c6d31 #e7969c #7b4173 #3182bd"
variant_colour(name) = word(variant_palette, rowof(name, 1))
