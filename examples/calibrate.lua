-- Calibration of a 2D bonded-particle specimen to granite-like targets
-- (Lac du Bonnet's lab values after Potyondy & Cundall 2004: E = 69 GPa,
-- nu = 0.26, UCS = 200 MPa): the moduli, the stiffness ratios and the bond
-- strengths are searched, the rest of lab.rock() stays. Each candidate is
-- tested on `seeds` specimens; the runs go to worker processes on every
-- core, or over the ranks of
--   mpirun -np N seixo examples/calibrate.lua
-- Killed, it resumes from its log (out_dir/calibration.csv).
--   scripts/run examples/calibrate.lua [out_dir] [maxeval] [seeds] [width_m]
local lab = require "seixo.lab"
local out = arg and arg[1] or "lab-results-calibrate"
local maxeval = tonumber(arg and arg[2]) or 16
local seeds = tonumber(arg and arg[3]) or 2
local width = tonumber(arg and arg[4]) or 0.03
os.execute("mkdir -p '" .. out .. "'") -- on every rank, as each checks a file's folder before writing it

local t0 = seixo.clock()
local r = lab.calibrate{
  targets = {E = 69e9, nu = 0.26, UCS = 200e6},
  parameters = {modulus = {20e9, 200e9}, stiffness_ratio = {1, 5}, strength = {50e6, 600e6}},
  specimen = {dim = 2, width = width, height = 2 * width},
  seeds = seeds, maxeval = maxeval, tolerance = 0.05,
  out = out .. "/calibration",
}
if seixo.rank() == 0 then
  print(string.format("calibrate: %d evaluations of %d seeds in %.0f s on %d %s; objective %.3g (%s)", r.evaluations,
                      seeds, seixo.clock() - t0, seixo.ranks() > 1 and seixo.ranks() or seixo.cores(),
                      seixo.ranks() > 1 and "ranks" or "cores", r.objective, r.status))
  print(string.format("material: modulus %.4g GPa (bond %.4g GPa), stiffness ratio %.3g, bond strengths %.4g MPa "
                      .. "(tensile) / %.4g MPa (cohesion)", r.material.modulus / 1e9, r.material.bond.modulus / 1e9,
                      r.material.stiffness_ratio, r.material.bond.tensile_strength / 1e6,
                      r.material.bond.cohesion / 1e6))
  print("log " .. r.log .. ", convergence plot " .. out .. "/calibration_convergence.png")
end
