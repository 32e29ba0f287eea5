-- The example scripts of examples/ (those of the Lua layer) run to the end
-- with small arguments and print what they promise.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq

local function example(name, args)
  return T.run(T.quote(T.root .. "examples/" .. name) .. " " .. (args or ""))
end

test("sample3d: generate, solve, histories, CSV", function()
  local status, out = example("sample3d.lua", "150 1e-3 0.05")
  eq(status, 0, out)
  check(out:find("sample3d: 150 balls, porosity", 1, true), out)
  check(out:find("stopped on %a+ %(ratio"), out)
  check(out:find("seixo.model 3D: 150 balls, 6 walls", 1, true), out)
  check(out:find("history rows in sample3d_histories.csv", 1, true), out)
  check(os.remove("sample3d_histories.csv"), "the histories' CSV is left for the user")
end)

test("drum: a turning mesh drum lifts its bed and holds every ball", function()
  local status, out = example("drum.lua", "0.05 150")
  eq(status, 0, out)
  check(out:find("150 balls, 0 outside the drum", 1, true), out)
  -- the bed lifted on the rising side resists the turn: a torque on the drum against its spin (+y)
  local torque = tonumber(out:match("torque about its axis ([%d.e+-]+) N m"))
  check(torque and torque < 0, out)
  local angle = tonumber(out:match("dynamic angle of repose: ([%d.]+) deg"))
  check(angle and angle > 0 and angle < 60, out)
end)

test("piston2d: a servo in a callback reaches its target load", function()
  local status, out = example("piston2d.lua", "200")
  eq(status, 0, out)
  local load = tonumber(out:match("load ([%d.]+) N/m for a target of 50"))
  check(load and math.abs(load - 50) < 1, out)
  check(out:find("200 disks left", 1, true), out)
end)

-- the floor carries most of the weight once the balls are at rest (the
-- side walls take some by friction: Janssen's silo effect)
local function floor_share(out)
  local load, weight = out:match("floor load ([%d.e+-]+) N[/m]* for a weight of ([%d.e+-]+)")
  return load and tonumber(load) / tonumber(weight)
end

test("settle2d: disks settle on the ratio", function()
  local status, out = example("settle2d.lua", "300")
  eq(status, 0, out)
  check(out:find("stopped on ratio", 1, true), out)
  local share = floor_share(out)
  check(share and share > 0.75 and share < 1.01, out)
end)

test("settle3d: spheres fall, come to bear on the floor and, with rolling resistance, settle on the ratio", function()
  local status, out = example("settle3d.lua", "300 150000")
  eq(status, 0, out)
  check(out:find("settle3d: 300 balls", 1, true), out)
  -- the README's figure: 125,700 steps to a ratio of 1e-3
  check(out:find("settle3d: stopped on ratio after 125700 steps", 1, true), out)
  -- at rest: the walls together carry the weight (the floor alone may carry
  -- more: side-wall friction locked in downward when the bed rebounded)
  local carried, floor, weight = out:match("the walls carry ([%d.e+-]+) N %(floor ([%d.e+-]+) N.-weight of ([%d.e+-]+) N")
  check(carried and math.abs(carried / weight - 1) < 0.01, out)
  check(floor and floor / weight > 0.75, out)
end)

test("bonded_break: a bonded specimen cracks and its energy balance closes", function()
  local status, out = example("bonded_break.lua")
  eq(status, 0, out)
  local cracks = tonumber(out:match("intact bonds, (%d+) cracks"))
  check(cracks and cracks > 0, out)
  local residual = tonumber(out:match("residual ([%d.e+-]+) %%"))  -- in per cent
  check(residual and math.abs(residual) < 0.1, out)
end)

test("clumps_pour: clumps poured into a box settle", function()
  local status, out = example("clumps_pour.lua", "40 2e-2")
  eq(status, 0, out)
  check(out:find("clumps_pour: 20 rice + 20 tri clumps (120 pebbles)", 1, true), out)
  -- at rest: a few caged clumps keep knocking, so the ratio may stay above
  -- 2e-2 (the run then stops on its step cap), but the pile has no energy left
  check(out:find("stopped on %a+ %(ratio"), out)
  local ke = tonumber(out:match("clump kinetic energy ([%d.e+-]+) J"))
  check(ke and ke < 1e-6, out)
  local porosity = tonumber(out:match("porosity ([%d.]+)"))
  check(porosity and porosity > 0.3 and porosity < 0.95, out)
  check(out:find("120 balls (pebbles of 40 clumps among them)", 1, true), out)
end)

test("clump_triaxial: a 2D specimen of clumps through a UCS and a biaxial test", function()
  local dir = os.tmpname()
  os.remove(dir)
  local status, out = example("clump_triaxial.lua", T.quote(dir) .. " 2 0.01 0.5e-3 0,5")
  os.execute("rm -rf " .. T.quote(dir))
  eq(status, 0, out)
  local clumps, pebbles = out:match("specimen: (%d+) clumps %((%d+) pebbles%)")
  check(clumps and tonumber(clumps) > 100 and tonumber(pebbles) == 2 * tonumber(clumps), out)
  local ucs = tonumber(out:match("\nucs +0 +([%d.]+)"))
  local triaxial = tonumber(out:match("\ntriaxial +5 +([%d.]+)"))
  check(ucs and ucs > 50 and ucs < 1000, out)                  -- MPa: a rock's
  check(triaxial and triaxial > ucs, out)
  check(out:find("Mohr-Coulomb: c = ", 1, true), out)
end)

test("calibrate: two candidates of a tiny 2D specimen in worker processes, the table and the plot", function()
  local dir = os.tmpname()
  os.remove(dir)
  local status, out = example("calibrate.lua", T.quote(dir) .. " 2 1 0.012")
  local plot = io.open(dir .. "/calibration_convergence.png", "rb")
  local log = require("seixo.util").read_csv(dir .. "/calibration.csv")
  os.execute("rm -rf " .. T.quote(dir))
  eq(status, 0, out)
  check(out:find("calibrate #2: modulus 6.2e+10, stiffness_ratio 5,", 1, true), out) -- the pilot's twin: kn/ks x 2
  check(out:find("calibrate: 2 evaluations of 1 seeds in", 1, true), out)
  check(out:find("micro-parameters:", 1, true) and out:find("material: modulus", 1, true), out)
  eq(log.rows, 2, "two runs logged")
  if require("seixo.lab").have_gnuplot() then check(plot, "the convergence plot") end
end)

T.done()
