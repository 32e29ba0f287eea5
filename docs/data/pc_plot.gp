# The charts of docs/potyondy-cundall.md (gnuplot docs/data/pc_plot.gp, from the repository's root):
# stress-strain curves (docs/data/pc-curves.csv) and the resolution study (docs/data/pc-resolution.csv).
set terminal pngcairo size 1000,650 font "sans,11" noenhanced
set datafile separator ","
E = 69e3; ucs = 200 # the granite (MPa)

set output "docs/img/pc-stress-strain.png"
set title "UCS tests against the granite: deviator against axial (right) and lateral (left) strain"
set xlabel "strain (compression positive, 1e-3)"
set ylabel "deviator stress (MPa)"
set key bottom right
set xrange [-4:4]
set yrange [0:230]
set xzeroaxis
set yzeroaxis
f(x) = x > 0 && E * x / 1e3 < ucs ? E * x / 1e3 : 1/0
# curve: 1 = 2D at P&C's resolution, P&C's PFC2D set; 2 = 3D, the PFC2D set; 3 = 3D, the 3D set
c(k, v) = column(1) == k ? v : 1/0
plot "docs/data/pc-curves.csv" every ::1 using (c(1, $2 * 1e3)):($4) with lines lw 2 lc 1 title "2D, Rmin 0.27 mm, P&C's PFC2D set", \
     "" every ::1 using (c(1, $3 * 1e3)):($4) with lines lw 2 lc 1 notitle, \
     "" every ::1 using (c(2, $2 * 1e3)):($4) with lines lw 2 lc 2 title "3D, Rmin 1.2 mm, P&C's PFC2D set", \
     "" every ::1 using (c(2, $3 * 1e3)):($4) with lines lw 2 lc 2 notitle, \
     "" every ::1 using (c(3, $2 * 1e3)):($4) with lines lw 2 lc 3 title "3D, Rmin 1.2 mm, lab.rock{dim = 3}", \
     "" every ::1 using (c(3, $3 * 1e3)):($4) with lines lw 2 lc 3 notitle, \
     f(x) with lines dt 2 lc 0 title "granite: E = 69 GPa up to its UCS = 200 MPa", \
     ucs with lines dt 3 lc 0 notitle

set output "docs/img/pc-resolution.png"
set multiplot layout 1,3 title "E, nu and UCS against the balls across the specimen's width (one specimen a point; band: the granite within 10 %)"
set xlabel "width / mean ball diameter"
set xrange [0:50]
set key bottom right font ",9"
set style fill transparent solid 0.15 noborder
unset xzeroaxis
unset yzeroaxis
# columns: dim, set, rmin, seed, test, balls, across, young, poisson, ucs
s(d, name, v) = column(1) == d && strcol(2) eq name && strcol(5) eq "ucs" ? v : 1/0
do for [panel = 1:3] {
  col = panel == 1 ? 8 : panel == 2 ? 9 : 10
  scale = panel == 1 ? 1e9 : panel == 2 ? 1 : 1e6
  target = panel == 1 ? 69 : panel == 2 ? 0.26 : 200
  set title panel == 1 ? "E (GPa)" : panel == 2 ? "nu" : "UCS (MPa)"
  set ylabel ""
  set yrange [panel == 1 ? 30 : panel == 2 ? 0.15 : 80:panel == 1 ? 90 : panel == 2 ? 0.40 : 260]
  plot "+" using 1:(0.9 * target):(1.1 * target) with filledcurves lc rgb "gray" notitle, \
       target with lines dt 2 lc 0 notitle, \
       "docs/data/pc-resolution.csv" every ::1 using 7:(s(2, "2d", column(col) / scale)) with points pt 7 ps 1.2 lc 1 title "2D, PFC2D set", \
       "" every ::1 using 7:(s(3, "2d", column(col) / scale)) with points pt 5 ps 1.2 lc 2 title "3D, PFC2D set", \
       "" every ::1 using 7:(s(3, "3d", column(col) / scale)) with points pt 9 ps 1.4 lc 3 title "3D, lab.rock{dim = 3}"
}
unset multiplot
