-- A triaxial series on a bonded granite-like specimen (3D), PFC-style:
-- material genesis, unconfined compression (UCS), triaxial tests at three
-- confining stresses, the Mohr-Coulomb fit of the peaks, and the check that
-- the loading is quasi-static (the UCS again at half the strain rate: the
-- loading-rate control's speeds and unbalanced-force ratio halved).
--   scripts/run examples/triaxial.lua [out_dir] [diameter_m] [strain_rate]
-- Writes into out_dir (default lab-results/): the specimen (specimen.h5),
-- per test a CSV of the stress-strain history and an HDF5 snapshot with its
-- results, and the figures (series_stress.png, series_volumetric.png,
-- series_cracks.png, series_mohr.png).
local lab = require "seixo.lab"
local out = arg and arg[1] or "lab-results"
local diameter = tonumber(arg and arg[2]) or 0.03
local rate = tonumber(arg and arg[3])                 -- axial strain rate, 1/s (default: 7e-8 per step; the rate
                                                       -- control loads up to 8 times faster while no bond breaks)
local confining = {0, 5e6, 10e6, 20e6}                 -- Pa; 0 is the UCS
local tolerance = 0.02                                 -- quasi-static: the peak may move this much at half the rate
os.execute("mkdir -p '" .. out .. "'")
local t0 = seixo.clock()

-- Lac du Bonnet granite: Potyondy & Cundall's (2004) micro-parameters with
-- the moduli and bond strengths of seixo's 3D calibration (lab.rock{dim = 3};
-- docs/potyondy-cundall.md), on a coarse specimen (about 1,500 balls) so the
-- series runs in minutes
local spec = lab.specimen{dim = 3, shape = "cylinder", diameter = diameter, height = 2 * diameter,
                          radius = {0.04 * diameter, 0.0667 * diameter}, material = lab.rock{dim = 3},
                          sigma0 = 0.1e6, seed = 1, path = out .. "/specimen.h5"}

-- the tests (and the UCS again at half the rate, the quasi-static check)
-- run side by side in processes, one per core, each from the specimen's
-- file: the results are those of running them one after another
local series = lab.series(spec, {confining = confining, strain_rate = rate, quasi_static = tolerance,
                                 out = out .. "/series"})
local ucs = series.tests[1]
local slow = series.quasi_static.test

local fit = series.fit
local g = spec.genesis
print("")
print(string.format("specimen: %d balls, %d parallel bonds, porosity %.3f, %.0f mm x %.0f mm", spec.balls, spec.bonds,
                    spec.porosity, diameter * 1e3, 2 * diameter * 1e3))
print(string.format("genesis: sigma0 %.4g MPa, %d floaters eliminated (%d left), core porosity %.3f, coordination "
                    .. "%.2f, locked-in stress %.3g MPa", g.sigma / 1e6, g.floaters_found, spec.floaters,
                    g.core_porosity, g.core_coordination, g.locked_in / 1e6))
print(string.format("%-10s %12s %12s %10s %8s %16s", "test", "sigma3 MPa", "peak MPa", "E GPa", "nu", "cracks t/s"))
for _, r in ipairs(series.tests) do
  print(string.format("%-10s %12.3g %12.4g %10.4g %8.3f %10d / %-5d", r.kind, r.confining / 1e6, r.peak / 1e6,
                      r.young / 1e9, r.poisson, r.cracks.tension, r.cracks.shear))
end
print(string.format("UCS %.4g MPa, E %.4g GPa, nu %.3f", ucs.peak / 1e6, ucs.young / 1e9, ucs.poisson))
print(string.format("Mohr-Coulomb: c = %.4g MPa, phi = %.2f deg (R^2 %.4f, rms %.3g MPa over %d tests)", fit.c / 1e6,
                    fit.phi, fit.r2, fit.rms / 1e6, fit.points))
local change = series.quasi_static.change
local function rates(r) -- the rate control's range (lab.triaxial's target_ratio)
  if not r.target_ratio then return string.format("%.3g/s", r.strain_rate) end
  return string.format("%.3g to %.3g/s", r.strain_rate, r.max_rate)
end
print(string.format("quasi-static: UCS %.4g MPa at %s and %.4g MPa at %s: %.2f %% apart (tolerance %.0f %%) -- %s",
                    ucs.peak / 1e6, rates(ucs), slow.peak / 1e6, rates(slow), 100 * change, 100 * tolerance,
                    series.quasi_static.ok and "quasi-static" or "TOO FAST: lower the strain rate"))
-- Lac du Bonnet granite as Potyondy & Cundall (2004) give it, the values
-- their PFC2D and PFC3D materials of these micro-parameters were calibrated
-- to (docs/potyondy-cundall.md)
local reference = {{"E GPa", 69, ucs.young / 1e9}, {"nu", 0.26, ucs.poisson}, {"UCS MPa", 200, ucs.peak / 1e6}}
local gaps = {}
for _, q in ipairs(reference) do
  gaps[#gaps + 1] = string.format("%s %.4g (%+.0f %%)", q[1], q[3], 100 * (q[3] / q[2] - 1))
end
print(string.format("against Potyondy & Cundall (2004), E 69 GPa, nu 0.26, UCS 200 MPa: %s", table.concat(gaps, ", ")))
print(string.format("figures: %s/series_{stress,volumetric,cracks,mohr}.png; run time %.0f s", out, seixo.clock() - t0))
