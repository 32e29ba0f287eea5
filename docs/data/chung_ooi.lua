-- Chung & Ooi (2011) tests 4-6: oblique impacts of a Hertz sphere on a
-- rigid plane, and test 8, two spheres of different sizes, with the seed's incremental shear force (4-20) and
-- Mindlin's total form (total_shear = 1); writes docs/data/chung_ooi.csv
-- and, with gnuplot, docs/img/chung-ooi-*.png.
--   build/seixo docs/data/chung_ooi.lua
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local I = dofile(here .. "../../tests/lua/impact_lib.lua")
local s = I.sphere
local kappa = 2 * (1 - s.nu) / (2 - s.nu) -- Mindlin's ks over the tangent normal stiffness (Maw's scaling)

local rows = {}
local function add(test, x, o)
  local r = {}
  for form = 0, 1 do
    o.total_shear = form
    r[form] = I.run(o)
  end
  local slide = I.rigid_body(o)
  local psi1 = kappa * (o.vt - s.radius * (o.wy or 0)) / (s.friction * o.vn)
  local row = {test, x, psi1}
  for form = 0, 1 do
    local q = r[form]
    row[#row + 1] = q.vx / o.vt                       -- tangential restitution of the centre
    row[#row + 1] = q.wy                              -- spin after (rad/s)
    row[#row + 1] = math.deg(math.atan(q.vx, q.vz))   -- the centre's rebound angle
    row[#row + 1] = kappa * q.vt_after / (s.friction * o.vn) -- psi2
  end
  row[#row + 1] = slide.vx / o.vt
  row[#row + 1] = slide.wy
  row[#row + 1] = math.deg(math.atan(slide.vx, slide.vz))
  row[#row + 1] = kappa * slide.vt_after / (s.friction * o.vn)
  rows[#rows + 1] = row
  io.write(string.format("test %d  %6.2f  psi1 %7.3f  psi2 incremental %7.3f total %7.3f rigid-body %7.3f\n", test, x,
                         psi1, row[7], row[11], row[15]))
end

-- test 4: 3.9 m/s at incidence 1 ... 85 degrees from the normal
for _, deg in ipairs{1, 2, 3, 5, 7.5, 10, 12.5, 15, 17.5, 20, 22.5, 25, 27.5, 30, 32.5, 35, 40, 45, 50, 60, 70, 80, 85} do
  local a = math.rad(deg)
  add(4, deg, {vn = 3.9 * math.cos(a), vt = 3.9 * math.sin(a)})
end
-- test 5: normal speed 5 m/s, tangential speed 0.1 ... 10 m/s
for _, vt in ipairs{0.1, 0.25, 0.5, 0.75, 1, 1.5, 2, 2.5, 3, 4, 5, 7.5, 10} do add(5, vt, {vn = 5, vt = vt}) end
-- test 6: normal speed 5 m/s, no tangential speed, spin -1000 ... -50 rad/s about y (the contact point moves at -R wy)
for _, wy in ipairs{-50, -100, -200, -300, -400, -600, -800, -1000, -1500, -2000, -3000, -4000} do
  add(6, wy, {vn = 5, vt = 0, wy = wy})
end

-- test 8: spheres of 2.5 and 5 mm, head on at 5 m/s, the smaller spinning at -50 ... -8000 rad/s (slip -ra wy)
for _, wy in ipairs{-50, -100, -200, -300, -400, -600, -800, -1000, -1500, -2000, -3000, -4000, -8000} do
  local o = {ra = 0.0025, rb = 0.005, vn = 5, wy = wy}
  local r = {}
  for form = 0, 1 do
    o.total_shear = form
    r[form] = I.run_pair(o)
  end
  local c = I.rigid_pair(o)
  local scale = kappa / (s.friction * o.vn)
  local psi1 = scale * r[0].slip_before
  local rigid = psi1 > 7 * kappa and scale * c.slip_after or 0
  rows[#rows + 1] = {8, wy, psi1, r[0].vxa, r[0].wya, 0 / 0, scale * r[0].slip_after, r[1].vxa, r[1].wya, 0 / 0,
                     scale * r[1].slip_after, psi1 > 7 * kappa and c.vxa or 0 / 0, c.wya, 0 / 0, rigid}
  io.write(string.format("test 8  %6.0f  psi1 %7.3f  psi2 incremental %7.3f total %7.3f rigid-body %7.3f\n", wy, psi1,
                         scale * r[0].slip_after, scale * r[1].slip_after, rigid))
end

local out = assert(io.open(here .. "chung_ooi.csv", "w"))
out:write("# Chung & Ooi tests 4-6 and 8 (x: angle, vt or spin), seixo: Hertz sphere R 2.5 mm, E 380 GPa, nu 0.23, 4000 kg/m^3, mu 0.092, rigid plane,"
          .. " elastic; 2000 steps per contact; test 8: a second sphere of 5 mm instead of the plane (A's vx, wy)\n")
out:write("test,x,psi1,et_incr,w_incr,angle_incr,psi2_incr,et_total,w_total,angle_total,psi2_total,"
          .. "et_rigid,w_rigid,angle_rigid,psi2_rigid\n")
for _, r in ipairs(rows) do
  local t = {}
  for k, x in ipairs(r) do t[k] = x ~= x and "" or string.format(k <= 1 and "%d" or "%.6g", x) end
  out:write(table.concat(t, ","), "\n")
end
out:close()

-- the no-slip limits (friction without bound) of the three forms, for the figure
local lim = {I.no_slip("incremental"), I.no_slip("total"), I.no_slip("md")}
io.write(string.format("no slip: u_after/u_before incremental %.9f total %.9f Mindlin-Deresiewicz %.9f\n", lim[1], lim[2],
                       lim[3]))

local gp = io.popen("gnuplot", "w")
if not gp then return end
local csv, img = here .. "chung_ooi.csv", here .. "../img/"
gp:write(string.format([[
set terminal pngcairo size 900,600 font ",11"
set datafile separator ","
set key left top
set grid
set output "%schung-ooi-psi.png"
set title "Chung and Ooi tests 4-6, 8: the contact point's tangential velocity, Maw's scaling (psi = kappa v_t / (mu v_n))"
set xlabel "psi1 (before)"
set ylabel "psi2 (after)"
set xrange [0:12]
plot "%s" using ($1==4?$3:1/0):7 with linespoints pt 7 title "test 4, incremental (4-20)", \
     "%s" using ($1==4?$3:1/0):11 with linespoints pt 6 title "test 4, total form", \
     "%s" using ($1==5?$3:1/0):7 with points pt 5 title "test 5, incremental", \
     "%s" using ($1==5?$3:1/0):11 with points pt 4 title "test 5, total", \
     "%s" using ($1==6?$3:1/0):7 with points pt 9 title "test 6, incremental", \
     "%s" using ($1==6?$3:1/0):11 with points pt 8 title "test 6, total", \
     "%s" using ($1==8?$3:1/0):7 with points pt 11 title "test 8 (two spheres), incremental", \
     "%s" using ($1==8?$3:1/0):11 with points pt 10 title "test 8, total", \
     (x > %g ? x - %g : 0) with lines lw 2 dt 2 title "rigid body (gross sliding, then rolling)", \
     %g * x with lines dt 3 title "no slip: incremental = total", \
     %g * x with lines dt 4 title "no slip: Mindlin-Deresiewicz"
set output "%schung-ooi-test4.png"
set title "Chung and Ooi test 4 (aluminium oxide, 3.9 m/s): tangential restitution of the centre"
set xlabel "incidence angle (degrees)"
set ylabel "v_x after / v_x before"
set xrange [0:90]
set yrange [0.4:1.05]
set key right bottom
plot "%s" using ($1==4?$2:1/0):4 with linespoints pt 7 title "incremental (4-20)", \
     "%s" using ($1==4?$2:1/0):8 with linespoints pt 6 title "total form", \
     "%s" using ($1==4?$2:1/0):12 with lines lw 2 dt 2 title "rigid body (sliding, or rolling at the end)"
]], img, csv, csv, csv, csv, csv, csv, csv, csv, 7 * kappa, 7 * kappa,
    lim[1], lim[3], img, csv, csv, csv))
gp:close()
