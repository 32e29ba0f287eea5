-- The lab tests' throughput options (issue 13): the loading-rate control by
-- the unbalanced-force ratio and the cracks, and density scaling, on a
-- small 2D specimen: the control acts as documented, and neither moves the
-- strength or the modulus beyond the quasi-static tolerance (2 %).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, near, raises = T.test, T.check, T.near, T.raises
local lab = require "seixo.lab"

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.4e-3, 0.66e-3}, seed = 3,
                          path = dir .. "/spec.h5", log = false}
local function opts(over)
  local o = {log = false}
  for k, v in pairs(over) do o[k] = v end
  return o
end

local steady = lab.ucs(spec, opts{target_ratio = false})
-- the control's rule is checked at a target of 4e-3, where this small 2D
-- specimen's ratio (noisy by a factor 2 to 3 between readings) leaves it
-- room to speed up; the default (2e-3, chosen on the main job's 3D
-- specimen) is checked below for what it promises there
local controlled = lab.ucs(spec, {log = false, target_ratio = 4e-3})
local default = lab.ucs(spec, {log = false})
local col = {}
for i, name in ipairs(controlled.columns) do col[name] = i end

test("the rate control speeds the loading up within its bounds and keeps the ratio under its target", function()
  check(controlled.target_ratio == 4e-3, controlled.target_ratio)
  near(controlled.max_rate, 8 * controlled.strain_rate, 1e-12)
  local base, top, fastest, rows = controlled.strain_rate, controlled.max_rate, 0, controlled.rows
  local fast_ratio, fast_n = 0, 0
  for i, row in ipairs(rows) do
    local rate = row[col.strain_rate]
    check(rate >= base * (1 - 1e-12) and rate <= top * (1 + 1e-12), string.format("row %d: rate %g", i, rate))
    fastest = math.max(fastest, rate)
    if rate > base * (1 + 1e-12) then fast_ratio, fast_n = fast_ratio + row[col.ratio], fast_n + 1 end
    -- the rule: a ratio over the target or a new crack halves the speed (to strain_rate at least)
    local prev = rows[i - 1]
    if prev and i < #rows then
      local cracked = row[col.cracks_tension] + row[col.cracks_shear] > prev[col.cracks_tension] + prev[col.cracks_shear]
      if cracked or row[col.ratio] > controlled.target_ratio then
        near(rows[i + 1][col.strain_rate], math.max(base, 0.5 * rate), 1e-12)
      end
    end
  end
  check(fastest > 4 * base, string.format("the control never sped up: %g of %g", fastest, base))
  -- while faster than strain_rate the loading stays under the target ratio
  -- on average (a burst of cracks lifts it over for a sample or two)
  check(fast_n > 10 and fast_ratio / fast_n < controlled.target_ratio, string.format("%d samples, mean ratio %g",
                                                                                     fast_n, fast_ratio / fast_n))
  check(controlled.steps < 0.8 * steady.steps, string.format("%d steps against %d", controlled.steps, steady.steps))
  -- without the control the loading keeps strain_rate
  for _, row in ipairs(steady.rows) do near(row[col.strain_rate], steady.strain_rate, 1e-12) end
  check(steady.target_ratio == false)
end)

test("by default the control runs at a target of 2e-3, in fewer steps and within the quasi-static tolerance", function()
  check(default.target_ratio == 2e-3, default.target_ratio)
  check(default.steps < steady.steps, string.format("%d steps against %d", default.steps, steady.steps))
  near(default.peak, steady.peak, 0.02)
  near(default.young, steady.young, 0.02)
end)

test("the rate control leaves the strength and the moduli within the quasi-static tolerance", function()
  near(controlled.peak, steady.peak, 0.02)
  near(controlled.young, steady.young, 0.02)
  near(controlled.poisson, steady.poisson, 0.02)
end)

test("density scaling raises the timestep by sqrt(factor) and leaves E, nu and the peak", function()
  local scaled = lab.ucs(spec, opts{target_ratio = false, density_scale = 4})
  near(scaled.timestep / steady.timestep, 2, 1e-6)
  -- the default rate is a strain per step: the same loading in steps, the mass and the timestep scaled together
  near(scaled.steps, steady.steps, 0.02)
  near(scaled.strain_rate, 0.5 * steady.strain_rate, 1e-6)
  near(scaled.young, steady.young, 0.005)
  near(scaled.poisson, steady.poisson, 0.005)
  near(scaled.peak, steady.peak, 0.005)
  check(scaled.density_scale == 4)
end)

test("bad throughput options are refused with a message naming them", function()
  raises(function() lab.ucs(spec, opts{target_ratio = 0}) end, "target_ratio must be a ratio in (0, 1)")
  raises(function() lab.ucs(spec, opts{target_ratio = 1.5}) end, "target_ratio must be")
  raises(function() lab.ucs(spec, opts{target_ratio = "fast"}) end, "target_ratio must be")
  raises(function() lab.ucs(spec, opts{strain_rate = 1, max_rate = 0.5}) end, "max_rate must be a strain rate >= strain_rate")
  raises(function() lab.triaxial(spec, opts{confining = 1e6, max_rate = 0 / 0}) end, "max_rate must be")
  raises(function() lab.ucs(spec, opts{target_ratio = false, max_rate = 1}) end, "max_rate is the rate control's")
  raises(function() lab.ucs(spec, opts{density_scale = 0.5}) end, "density_scale must be a factor in [1, 1e6]")
  raises(function() lab.ucs(spec, opts{density_scale = "x"}) end, "density_scale must be")
end)

os.execute("rm -rf '" .. dir .. "'")
T.done()
