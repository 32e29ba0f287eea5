-- seixo.lab.plots: the lab's figures, PNG files drawn by gnuplot: a
-- compression test's, a Brazilian test's and a series' (lab.calibrate's
-- convergence plot runs gnuplot through plots.gnuplot too).
local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local pool = require "seixo.pool"
local plots = {}

--- Whether gnuplot can be run (the plots are skipped, with a note, if not).
function plots.have_gnuplot()
  local ok = os.execute("command -v gnuplot > /dev/null 2>&1")
  return ok == true or ok == 0
end

-- Runs a gnuplot script writing the PNG files outs (each to a temporary
-- name, renamed when gnuplot succeeded).
function plots.gnuplot(script, outs)
  if not plots.have_gnuplot() then
    io.stderr:write("lab: gnuplot not found (apt-get install gnuplot-nox): no plots\n")
    return false
  end
  local tag = pool.tag() -- no draw of math.random: rank 0 alone may plot (a calibration's)
  for _, o in ipairs(outs) do script = script:gsub("@" .. o.key .. "@", o.path .. ".tmp" .. tag) end
  local gp = os.tmpname()
  -- under mpirun, ranks sharing the models get here alike (the same draw, rank
  -- 0's os.tmpname): rank 0 draws the figures (with seixo.decompose(false)
  -- each rank its own)
  if seixo.rank() > 0 and seixo.decompose() then return true end
  local f = assert(io.open(gp, "w"))
  f:write(script)
  f:close()
  local ok = os.execute("gnuplot " .. gp .. " 2> " .. gp .. ".err")
  local err = io.open(gp .. ".err"):read("a")
  os.remove(gp)
  os.remove(gp .. ".err")
  if not (ok == true or ok == 0) then
    for _, o in ipairs(outs) do os.remove(o.path .. ".tmp" .. tag) end
    io.stderr:write("lab: gnuplot failed: " .. err .. "\n")
    return false
  end
  for _, o in ipairs(outs) do os.rename(o.path .. ".tmp" .. tag, o.path) end
  return true
end

local terminal = "set terminal pngcairo size 900,600 font ',11'\nset datafile separator ','\nset key autotitle columnhead\nset grid\n"

--- The figures of one compression test: stress-strain with volumetric
--- strain, and cracks against strain (PNG beside the CSV).
function plots.test(r, out)
  local csv = out .. ".csv"
  local script = terminal .. string.format([[
set output '@s@'
set title '%s%s, confining %.4g MPa'
set xlabel 'axial strain (%%)'
set ylabel 'deviator stress (MPa)'
set y2label 'volumetric strain (%%)'
set y2tics
plot '%s' using ($3*100):($8/1e6) with lines lw 2 title 'deviator', '' using ($3*100):($5*100) axes x1y2 with lines dt 2 title 'volumetric strain'
set output '@c@'
set title 'cracks'
set ylabel 'cracks'
unset y2label
unset y2tics
plot '%s' using ($3*100):9 with lines lw 2 title 'tension', '' using ($3*100):10 with lines lw 2 title 'shear'
]], r.name and r.name:gsub("'", "''") .. ": " or "", r.kind, r.confining / 1e6, csv, csv) -- (gnuplot's quote in quotes)
  return plots.gnuplot(script, {{key = "s", path = out .. "_stress.png"}, {key = "c", path = out .. "_cracks.png"}})
end

--- The figure of a Brazilian test: its tensile stress and cracks against
--- the platens' displacement, and the split (PNG beside the CSV).
function plots.brazilian(r, out)
  local csv = out .. ".csv"
  local script = terminal .. string.format([[
set output '@s@'
set title 'Brazilian test'
set xlabel 'platen displacement (mm)'
set ylabel 'sigma_t = 2F/(pi D t) (MPa)'
set y2label 'cracks'
set y2tics
plot '%s' using ($3*1e3):($5/1e6) with lines lw 2 title 'tensile stress', '' using ($3*1e3):($6+$7) axes x1y2 with lines dt 2 title 'cracks'%s
]], csv, r.split and string.format(", %.6g with lines dt 3 title 'the split'", r.split / 1e6) or "")
  return plots.gnuplot(script, {{key = "s", path = out .. "_stress.png"}})
end

--- The figures of a series: the stress-strain curves and volumetric
--- strains of every test (csvs[i]: the CSV s.tests[i] wrote), their crack
--- counts, and the Mohr circles with the fitted envelope tau = c + sigma
--- tan(phi).
function plots.series(s, out, csvs)
  local curves, vol, cracks = {}, {}, {}
  for i, r in ipairs(s.tests) do
    local csv = csvs[i]
    local name = r.confining > 0 and string.format("{/Symbol s}_3 = %g MPa", r.confining / 1e6) or "UCS"
    curves[#curves + 1] = string.format("'%s' using ($3*100):($8/1e6) with lines lw 2 title '%s'", csv, name)
    vol[#vol + 1] = string.format("'%s' using ($3*100):($5*100) with lines lw 2 title '%s'", csv, name)
    cracks[#cracks + 1] = string.format("'%s' using ($3*100):($9+$10) with lines lw 2 title '%s'", csv, name)
  end
  local circles, smax = {}, 0
  for _, r in ipairs(s.tests) do
    local c, rad = 0.5 * (r.peak + r.confining) / 1e6, 0.5 * (r.peak - r.confining) / 1e6
    circles[#circles + 1] = string.format("set object circle at %.6g,0 size %.6g fc rgb '#1f77b4' lw 2", c, rad)
    smax = math.max(smax, c + rad)
  end
  local fit = s.fit
  local env = fit.phi == fit.phi and string.format(
    "plot [0:%.6g] %.6g + x * tan(%.6g * pi / 180) lw 2 dt 2 title sprintf('c = %.3g MPa, phi = %.1f deg')",
    smax * 1.05, fit.c / 1e6, fit.phi, fit.c / 1e6, fit.phi) or "plot [0:1] 1/0 notitle"
  local script = terminal .. string.format([[
set output '@s@'
set title 'stress-strain'
set xlabel 'axial strain (%%)'
set ylabel 'deviator stress (MPa)'
set key left top
plot %s
set output '@v@'
set title 'volumetric strain (compression positive)'
set ylabel 'volumetric strain (%%)'
plot %s
set output '@c@'
set title 'cracks'
set ylabel 'cracks (tension + shear)'
plot %s
set output '@m@'
set title 'Mohr circles at failure and the Mohr-Coulomb envelope'
set xlabel 'normal stress (MPa)'
set ylabel 'shear stress (MPa)'
set size ratio -1
set xrange [0:%.6g]
set yrange [0:%.6g]
%s
%s
]], table.concat(curves, ", "), table.concat(vol, ", "), table.concat(cracks, ", "), smax * 1.05, smax * 0.6,
      table.concat(circles, "\n"), env)
  return plots.gnuplot(script, {{key = "s", path = out .. "_stress.png"}, {key = "v", path = out .. "_volumetric.png"},
                          {key = "c", path = out .. "_cracks.png"}, {key = "m", path = out .. "_mohr.png"}})
end

return plots
