-- seixo.periodic (lab.periodic): a periodic specimen, its triaxial test
-- with the lateral stress held by the cell's servo, simple shear at
-- constant normal stress (issue 15).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local lab = require "seixo.lab"

local granular = lab.periodic.specimen{dim = 2, size = 0.008, radius = {0.4e-3, 0.66e-3}, bonds = false,
                                       path = "periodic_granular.h5", log = false}

T.test("a granular periodic specimen", function()
  T.check(granular.balls > 50, "balls: " .. granular.balls)
  T.eq(granular.bonds, 0)
  T.check(granular.porosity > 0.1 and granular.porosity < 0.3, "porosity " .. granular.porosity)
  local again = lab.open("periodic_granular.h5")
  T.check(again.periodic and again.balls == granular.balls, "lab.open reads it back")
  local ok, err = pcall(lab.triaxial, again, {confining = 1e6})
  T.check(not ok and err:find("lab.periodic", 1, true), "the walled test refuses it: " .. tostring(err))
  -- the cell holds sigma0 at rest
  local m = seixo.load("periodic_granular.h5")
  local s = m:cell_stress()
  for k = 1, 2 do T.near(s[k][k], granular.sigma0, 0.01) end
  T.check(m:wall_count() == 0, "no walls")
  m:close()
end)

T.test("periodic triaxial: the lateral stress held within 1 % while the cell is compressed", function()
  local r = lab.periodic.triaxial(granular, {confining = 1e6, strain_rate = 0.5, max_strain = 0.001, log = false})
  T.check(#r.rows > 5, "rows")
  for _, row in ipairs(r.rows) do T.near(row.sl, 1e6, 0.01) end
  T.check(r.peak_deviator > 0.3e6, "the deviator rises: " .. r.peak_deviator)
  T.check(r.young and r.young > 0 and r.poisson == r.poisson, "a modulus and a Poisson's ratio")
  T.near(r.rows[#r.rows].ea, 0.001, 0.1)
end)

T.test("periodic triaxial: ev is the cell's change of volume", function()
  local r = lab.periodic.triaxial(granular, {confining = 1e6, strain_rate = 20, max_strain = 0.08, post_peak = 0.01,
                                             log = false})
  local last = r.rows[#r.rows]
  -- 1 - V/V0 from the strains of the cell's edges (the lateral ones alike in 2D)
  local v = (1 - last.ea) * (1 - last.el)
  T.near(last.ev, 1 - v, 1e-9)
  -- the small-strain sum drifts from it by ea el at 8 %
  T.check(math.abs(last.ev - (last.ea + last.el)) > 0.5 * math.abs(last.ea * last.el), "not the small-strain sum")
end)

T.test("the periodic tests' options are checked (a sand user's findings)", function()
  local function refused(fn, opts, text)
    local ok, err = pcall(function()
      local r = fn(granular, opts) -- (not a tail call: the caller's line is this one)
      return r
    end)
    T.check(not ok and err:find(text, 1, true), tostring(err))
    -- the error points at this script's line, not into the library
    T.check(err:find("periodic_lab.lua", 1, true), "at the caller: " .. tostring(err))
  end
  -- every = 0 cycled nothing, forever
  refused(lab.periodic.triaxial, {every = 0}, "every must be a whole number of steps >= 1 (got 0)")
  refused(lab.periodic.shear, {every = 0}, "every must be a whole number of steps >= 1 (got 0)")
  refused(lab.periodic.triaxial, {post_peak = 5}, "post_peak must be in (0, 1) (got 5)")
  refused(lab.periodic.triaxial, {confinig = 1e6}, "unknown option 'confinig'")
  -- bonds = 0 gave a bonded specimen
  local ok, err = pcall(lab.periodic.specimen, {dim = 2, bonds = 0, path = "never.h5", log = false})
  T.check(not ok and err:find("bonds must be true or false", 1, true), tostring(err))
  refused(lab.periodic.shear, {max_steps = 0}, "max_steps must be a whole number of steps >= 1 (got 0)")
  -- a path that cannot be written failed at the save, after the genesis
  local t0 = seixo.clock()
  ok, err = pcall(lab.periodic.specimen, {dim = 2, path = "/nonexistent-dir/cell.h5", log = false})
  T.check(not ok and err:find("cannot write /nonexistent-dir/cell.h5", 1, true), tostring(err))
  T.check(seixo.clock() - t0 < 1, "refused before the genesis")
end)

T.test("a periodic test loaded too fast to be quasi-static says so, as the walled tests do", function()
  -- a sand user's cell at 20/s read a Poisson's ratio of 3.9 with no word
  local fast = lab.periodic.triaxial(granular, {confining = 1e5, strain_rate = 20, max_strain = 0.005, log = false})
  T.check(fast.mean_ratio > 0.01, "mean ratio " .. fast.mean_ratio)
  T.check(#fast.warnings == 1 and fast.warnings[1]:find("not near equilibrium", 1, true), table.concat(fast.warnings, "; "))
  local shear = lab.periodic.shear(granular, {normal = 1e5, shear_rate = 50, max_strain = 0.005, log = false})
  T.check(shear.warnings[1] and shear.warnings[1]:find("lower strain_rate", 1, true), table.concat(shear.warnings, "; "))
  -- the walled tests' rule, the same words (seixo.check.balance_warnings)
  local check = require "seixo.check"
  T.eq(#check.balance_warnings(0.005, 1e-4), 0)
  T.eq(#check.balance_warnings(0.02, 2e-3), 2)
end)

T.test("periodic shear stops at max_steps and says so", function()
  local r = lab.periodic.shear(granular, {normal = 1e6, shear_rate = 2, max_strain = 0.5, max_steps = 2000, log = false})
  T.eq(r.stopped, "max_steps")
  T.eq(r.steps, 2000)
  T.check(r.rows[#r.rows].gamma < 0.5, "stopped short of max_strain")
end)

T.test("periodic simple shear at constant normal stress", function()
  local r = lab.periodic.shear(granular, {normal = 1e6, shear_rate = 2, max_strain = 0.004, log = false})
  -- steps are the shearing's, and a row's step counts from its start
  T.eq(r.steps, r.rows[#r.rows].step)
  local last = r.rows[#r.rows]
  T.check(last.gamma >= 0.004, "sheared to the strain")
  T.near(last.sn, 1e6, 0.05)
  T.check(r.friction_angle > 5 and r.friction_angle < 45, "a granular friction angle: " .. r.friction_angle)
end)

T.test("a bonded periodic specimen", function()
  local spec = lab.periodic.specimen{dim = 2, size = 0.008, radius = {0.4e-3, 0.66e-3}, path = "periodic_bonded.h5",
                                     log = false}
  T.check(spec.bonds > spec.balls, "bonds: " .. spec.bonds)
  -- Potyondy & Cundall's genesis: the floaters grown until every ball has
  -- three neighbours within the bond gap, so three bonds at least (the
  -- servo alone left balls with one or none)
  T.check(spec.floaters_found > 0 and spec.floaters_left == 0,
          "floaters found " .. spec.floaters_found .. ", left " .. spec.floaters_left)
  local m = seixo.load("periodic_bonded.h5")
  local bonds = {}
  for c in m:contacts{kind = "ball-ball"} do
    if c.bond then bonds[c.a.id], bonds[c.b.id] = (bonds[c.a.id] or 0) + 1, (bonds[c.b.id] or 0) + 1 end
  end
  local fewest = math.huge
  for b in m:balls() do fewest = math.min(fewest, bonds[b.id] or 0) end
  T.check(fewest >= 3, "the fewest bonds of a ball: " .. fewest)
  m:close()
  os.remove("periodic_bonded.h5")
end)

os.remove("periodic_granular.h5")
T.done()
