# The charts of docs/joints.md (gnuplot docs/data/joints_plot.gp, from the repository's root).
set terminal pngcairo size 1000,650 font "sans,11"
set datafile separator ","
set key top center
intact = 183.4
c_in = 10; mu_in = tan(30 * pi / 180)
c_eff = 5.80; mu_eff = 0.337 # the direct-shear peak envelope (docs/joints.md)
jaeger(b, c, mu) = (b * pi / 180 > atan(mu) && b < 90) ? 2 * c / ((1 - mu / tan(b * pi / 180)) * sin(2 * b * pi / 180)) : 1e9
cap(x) = x < intact ? x : intact
set output "docs/img/joint-angle-ucs.png"
set title "UCS of a 2D bonded specimen with a bonded smooth joint at angle beta (normal to the loading axis)"
set xlabel "beta, angle between the joint's normal and the loading axis (degrees)"
set ylabel "UCS (MPa)"
set xrange [0:90]
set yrange [0:220]
set samples 361
plot "docs/data/joints_angle.csv" every ::1 using 1:2 with linespoints pt 7 lw 2 title "seixo (smooth joint, c 10 MPa, phi_b 30 deg, mu 0.5)", \
     cap(jaeger(x, c_in, mu_in)) with lines dt 2 lw 2 title "Jaeger, the joint's input c = 10 MPa, tan 30 deg", \
     cap(jaeger(x, c_eff, mu_eff)) with lines lw 2 title sprintf("Jaeger, the joint's measured peak envelope c = %.2f MPa, mu = %.3f", c_eff, mu_eff), \
     intact with lines dt 3 title "intact UCS (183.4 MPa)"
set output "docs/img/ucs-bts.png"
# docs/data/ucs_bts.lua writes ucs_bts.csv (seeds 1-3; 3D one seed) and ucs_bts_sweep.csv (seeds 1-2)
set terminal pngcairo size 1200,820 font "sans,10"
set title "UCS / BTS, mean and sample sd over the seeds: left, the laws at the same UCS (2D: 10 x 20 mm rectangle, 10 mm disk, radii 0.2-0.33 mm;\n3D: cylinder and disc, radii 0.5-0.83 mm); right, joints.rock's sweep (2D, seeds 1-2)"
set style data histograms
set style histogram errorbars gap 1 lw 1
set style fill solid 0.6 border -1
set boxwidth 0.8
set key off
set xlabel ""
set ylabel "UCS / BTS"
set yrange [0:16]
set xrange [*:*]
set xtics rotate by -35 font "sans,9" noenhanced
set bmargin 20
set rmargin 18
set label 1 "target >= 15 (flat joint)" at graph 0.01, first 15.4
set label 2 "parallel bond < 8" at graph 0.01, first 8.4
plot newhistogram "", "docs/data/ucs_bts.csv" every ::1 using 8:9:xtic(1), \
     newhistogram "", "docs/data/ucs_bts_sweep.csv" every ::1 using 8:9:xtic(1), \
     15 with lines dt 2 lw 2, 8 with lines dt 3 lw 2
set output "docs/img/fj-ratio.png"
# docs/data/fj_ratio.lua writes fj_ratio.csv (seeds 1-3)
set terminal pngcairo size 1200,760 font "sans,10"
set title "UCS over tensile strength, mean and sample sd over seeds 1-3 (2D: 10 x 20 mm rectangle; disks of 10 and 20 mm; radii 0.2-0.33 mm)"
set style histogram errorbars gap 2 lw 1
set key top left noenhanced
set ylabel "UCS / tensile strength"
set yrange [0:40]
set bmargin 6
set xtics rotate by 0
set rmargin 4
unset label 1
unset label 2
set label 3 "target >= 15 (flat joint)" at graph 0.6, first 15.8
set label 4 "parallel bond < 8" at graph 0.6, first 8.8
plot "docs/data/fj_ratio.csv" every ::1 using 21:22:xtic(1) title "UCS / BTS, 10 mm disk, peak load (lab.brazilian)", \
     "" every ::1 using 19:20 title "UCS / BTS, 20 mm disk, load at the split (joints.split_strength)", \
     "" every ::1 using 17:18 title "UCS / direct tension (joints.direct_tension, the UCS rectangle)", \
     15 with lines dt 2 lw 2 notitle, 8 with lines dt 3 lw 2 notitle
set output "docs/img/fj-split.png"
# docs/data/fj_split.lua writes fj_split.csv (seeds 1-3, 2D disks of 10-30 mm; the UCS of fj_ratio.lua's rectangle)
set terminal pngcairo size 1100,700 font "sans,10"
set title "UCS / Brazilian strength against the disk's size, mean and sample sd over seeds 1-3\n(2D; UCS of the 10 x 20 mm rectangle; disks of radii 0.2-0.33 mm)"
unset label 3
unset label 4
set style data yerrorlines
set key top left noenhanced
set xlabel "disk diameter / mean grain diameter"
set ylabel "UCS / BTS"
set xrange [10:80]
set yrange [0:30]
set xtics auto
set bmargin 4
set label 5 "target >= 15 (flat joint)" at graph 0.7, first 15.6
set label 6 "parallel bond < 8" at graph 0.7, first 8.6
plot "docs/data/fj_split.csv" every ::1 using 4:(strcol(1) eq "cal" ? $18 : NaN):19 pt 7 lw 2 title "flat joint (calibrated), BTS at the split (lab.brazilian's split)", \
     "" every ::1 using 4:(strcol(1) eq "cal" ? $20 : NaN):21 pt 6 lw 1 dt 2 title "flat joint (calibrated), BTS at the peak load", \
     "" every ::1 using 4:(strcol(1) eq "pb" ? $18 : NaN):19 pt 5 lw 2 title "parallel bond, BTS at the split (= its peak)", \
     15 with lines dt 2 lw 2 notitle, 8 with lines dt 3 lw 2 notitle
