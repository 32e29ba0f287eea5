-- A biaxial series in 2D (disks of unit thickness): genesis of a bonded
-- rectangle, unconfined compression and biaxial tests at two confining
-- stresses (four servo-controlled walls), and the Mohr-Coulomb fit.
--   scripts/run examples/biaxial2d.lua [out_dir]
local lab = require "seixo.lab"
local out = arg and arg[1] or "lab-results-2d"
os.execute("mkdir -p '" .. out .. "'")
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.02, height = 0.04, radius = {0.4e-3, 0.66e-3},
                          seed = 1, path = out .. "/specimen.h5"}
local s = lab.series(spec, {confining = {0, 5e6, 10e6}, out = out .. "/series"})
for _, r in ipairs(s.tests) do
  print(string.format("%-9s sigma3 %5.3g MPa: peak %7.4g MPa, E %6.4g GPa, nu %.3f", r.kind, r.confining / 1e6,
                      r.peak / 1e6, r.young / 1e9, r.poisson))
end
print(string.format("Mohr-Coulomb: c = %.4g MPa, phi = %.2f deg (R^2 %.4f)", s.fit.c / 1e6, s.fit.phi, s.fit.r2))
