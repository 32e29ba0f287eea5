# The charts of docs/performance.md, "Lab throughput" (gnuplot docs/data/lab_throughput.gp, from the repository's root).
set terminal pngcairo size 1000,650 font "sans,11"
set datafile separator ","
ref_peak = 143.200; ref_E = 49.8476; ref_nu = 0.254042   # the default run: constant rate, 7e-8 axial strain per step
set output "docs/img/lab-throughput.png"
set title "UCS test of the main job's specimen (1,507 balls): change against the default run, by the axial strain per step"
set xlabel "axial strain per step / 7e-8 (density scaling at 0.952/s: sqrt(density factor))"
set ylabel "change against the default run (%)"
set logscale x 2
set xrange [0.4:5]
set yrange [-3:6]
set grid
set key top left
plot 2 with lines dt 2 lc rgb "gray40" title "quasi-static tolerance (2 %)", \
     -2 with lines dt 2 lc rgb "gray40" notitle, \
     "docs/data/lab-throughput.csv" every ::1::4 using 3:(100 * ($4 / ref_peak - 1)) with linespoints pt 7 lw 2 lc rgb "#1f77b4" title "UCS, constant strain rate x 0.5 ... 4", \
     "docs/data/lab-throughput.csv" every ::5::7 using 3:(100 * ($4 / ref_peak - 1)) with linespoints pt 5 ps 1.3 lw 2 dt 3 lc rgb "#d62728" title "UCS, density x 2, 4, 16 at the default's 0.952/s", \
     "docs/data/lab-throughput.csv" every ::5::7 using 3:(100 * ($5 / ref_E - 1)) with linespoints pt 4 lw 1 lc rgb "#2ca02c" title "E, density scaling", \
     "docs/data/lab-throughput.csv" every ::5::7 using 3:(100 * ($6 / ref_nu - 1)) with linespoints pt 6 lw 1 lc rgb "#9467bd" title "nu, density scaling", \
     "docs/data/lab-throughput.csv" every ::8::8 using 3:(100 * ($4 / ref_peak - 1)) with points pt 9 ps 2.5 lc rgb "black" title "UCS, rate control (mean speed-up in steps 1.51)"

set output "docs/img/rate-control.png"
unset logscale x
set title "The loading-rate control on the main job's UCS: speed, ratio and cracks against the axial strain"
set xlabel "axial strain"
set ylabel "deviator (MPa); cracks"
set y2label "strain-rate factor; 1000 x unbalanced-force ratio"
set y2tics
set ytics nomirror
set autoscale x
set yrange [0:160]
set y2range [0:10]
set key top left
plot "docs/data/rate-control-ucs.csv" every ::1 using 2:3 with lines lw 2 lc rgb "#1f77b4" title "deviator, rate control", \
     "docs/data/constant-rate-ucs.csv" every ::1 using 2:3 with lines lw 1 dt 2 lc rgb "black" title "deviator, constant rate", \
     "docs/data/rate-control-ucs.csv" every ::1 using 2:4 with lines lw 1 lc rgb "#d62728" title "cracks, rate control", \
     "docs/data/rate-control-ucs.csv" every ::1 using 2:6 axes x1y2 with steps lw 2 lc rgb "#2ca02c" title "strain-rate factor (right)", \
     "docs/data/rate-control-ucs.csv" every ::1 using 2:(1000 * $5) axes x1y2 with lines lw 1 lc rgb "#ff7f0e" title "1000 x ratio (right)"
