-- A triaxial series on a specimen of clumps: grains of two overlapping
-- pebbles (dimers) instead of balls, bonded with the granite-like
-- micro-parameters of examples/triaxial.lua (lab.rock()). Genesis
-- (lab.specimen{clump = ...}: random placement, compaction until the clumps
-- jam, the isotropic stress, parallel bonds between pebbles of different
-- clumps), the UCS, triaxial tests and the Mohr-Coulomb fit of the peaks.
--   scripts/run examples/clump_triaxial.lua [out_dir] [dim] [size_m] [pebble_radius_m] [confining_MPa,...]
-- 3D (default): a cylinder `size` across (default 0.01 m) and twice as
-- high, in a servo-controlled cylindrical wall; 2D: a rectangle `size` wide
-- and twice as high, biaxial tests between four walls. Pebbles of radius
-- 0.06 size by default (about 600 clumps in 3D), scaled by 0.9 to 1.1;
-- confining stresses 0, 5 and 10 MPa (0 is the UCS). Writes into out_dir
-- (default lab-results-clumps/) the specimen (specimen.h5), per test a CSV
-- and an HDF5 snapshot, and the figures (series_*.png).
local lab = require "seixo.lab"
local out = arg and arg[1] or "lab-results-clumps"
local dim = tonumber(arg and arg[2]) or 3
local size = tonumber(arg and arg[3]) or 0.01
local r = tonumber(arg and arg[4]) or 0.06 * size
local confining = {}
for s in ((arg and arg[5]) or "0,5,10"):gmatch("[^,]+") do confining[#confining + 1] = tonumber(s) * 1e6 end
os.execute("mkdir -p '" .. out .. "'")
local t0 = seixo.clock()

-- the dimer: two pebbles 1.2 r apart, so they overlap by 0.8 r
local pebbles = dim == 3 and {{-0.6 * r, 0, 0, r}, {0.6 * r, 0, 0, r}} or {{-0.6 * r, 0, r}, {0.6 * r, 0, r}}
local opts = {dim = dim, clump = {pebbles = pebbles, scale = {0.9, 1.1}}, material = lab.rock(), sigma0 = 0.1e6,
              seed = 1, path = out .. "/specimen.h5"}
if dim == 3 then
  opts.shape, opts.diameter, opts.height = "cylinder", size, 2 * size
else
  opts.shape, opts.width, opts.height = "rect", size, 2 * size
end
local spec = lab.specimen(opts)
local series = lab.series(spec, {confining = confining, out = out .. "/series"})

print("")
print(string.format("specimen: %d clumps (%d pebbles), %d parallel bonds (%.2f per clump), %d floaters, porosity %.3f",
                    spec.clumps, spec.balls, spec.bonds, 2 * spec.bonds / spec.clumps, spec.floaters, spec.porosity))
print(string.format("%-10s %12s %12s %10s %8s %16s", "test", "sigma3 MPa", "peak MPa", "E GPa", "nu", "cracks t/s"))
for _, t in ipairs(series.tests) do
  print(string.format("%-10s %12.3g %12.4g %10.4g %8.3f %10d / %-5d", t.kind, t.confining / 1e6, t.peak / 1e6,
                      t.young / 1e9, t.poisson, t.cracks.tension, t.cracks.shear))
end
local fit = series.fit
print(string.format("Mohr-Coulomb: c = %.4g MPa, phi = %.2f deg (R^2 %.4f over %d tests)", fit.c / 1e6, fit.phi, fit.r2,
                    fit.points))
print(string.format("figures: %s/series_{stress,volumetric,cracks,mohr}.png; run time %.0f s", out, seixo.clock() - t0))
