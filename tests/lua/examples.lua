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
  check(out:find("history rows", 1, true), out)
end)

test("piston2d: a servo in a callback reaches its target load", function()
  local status, out = example("piston2d.lua", "200")
  eq(status, 0, out)
  local load = tonumber(out:match("load ([%d.]+) N/m for a target of 50"))
  check(load and math.abs(load - 50) < 1, out)
  check(out:find("200 disks left", 1, true), out)
end)

test("clumps_pour: clumps poured into a box settle", function()
  local status, out = example("clumps_pour.lua", "40 2e-2")
  eq(status, 0, out)
  check(out:find("clumps_pour: 20 rice + 20 tri clumps (120 pebbles)", 1, true), out)
  check(out:find("stopped on ratio", 1, true), out)
  local porosity = tonumber(out:match("porosity ([%d.]+)"))
  check(porosity and porosity > 0.3 and porosity < 0.95, out)
  check(out:find("120 balls (pebbles of 40 clumps among them)", 1, true), out)
end)

T.done()
