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
set title "UCS / BTS of 2D specimens (10 x 20 mm, 10 mm disk, radii 0.4-0.66 mm, seed 3)"
set style data histograms
set style fill solid 0.6 border -1
set boxwidth 0.8
set key off
set xlabel ""
set ylabel "UCS / BTS"
set yrange [0:*]
set xrange [*:*]
set xtics rotate by -30
set bmargin 13
set rmargin 26
plot "docs/data/ucs_bts.csv" every ::1 using 4:xtic(1) title "UCS/BTS", 15 with lines dt 2 lw 2, 8 with lines dt 3 lw 2
