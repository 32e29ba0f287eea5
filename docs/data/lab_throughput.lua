-- One compression test of a saved specimen with the throughput options, for
-- docs/performance.md's "Lab throughput" (docs/data/lab-throughput.csv):
--   seixo docs/data/lab_throughput.lua SPECIMEN.h5 ucs|triaxial SIGMA3 FACTOR [key=value ...]
-- FACTOR scales the default strain rate (7e-8 axial strain per step of the
-- unscaled specimen, so a fixed rate in 1/s under density scaling); 0 keeps
-- the library's default (a strain per step of the test's own timestep).
-- The keys are lab.triaxial's (target_ratio=false, max_rate=, density_scale=, out=).
local lab = require "seixo.lab"
local spec = lab.open(arg[1])
local kind, sigma3, factor = arg[2], tonumber(arg[3]), tonumber(arg[4])
local opts = {log = false, plot = false, confining = sigma3}
for i = 5, #arg do
  local k, v = arg[i]:match("([%w_]+)=(.*)")
  if v == "false" then opts[k] = false else opts[k] = tonumber(v) or v end
end
local m = seixo.load(spec.path)
local dt = m:timestep()
m:close()
if factor > 0 then opts.strain_rate = factor * 7e-8 / dt end
local cpu = os.clock()
local r = kind == "ucs" and lab.ucs(spec, opts) or lab.triaxial(spec, opts)
print(string.format("%s sigma3 %g MPa, rate x %g: peak %.6g MPa, E %.6g GPa, nu %.6g, %d steps (+%d confining), "
                    .. "mean ratio %.3g, %.1f s of CPU", kind, sigma3 / 1e6, factor, r.peak / 1e6, r.young / 1e9,
                    r.poisson, r.steps, r.confine_steps, r.mean_ratio, os.clock() - cpu))
