-- The material genesis of lab.specimen (Potyondy & Cundall 2004, section
-- 2.3) on cheap specimens, 2D and 3D: no floater left, sigma0 installed
-- within its tolerance, a dense packing (its porosity in the core below
-- that of the old genesis, 0.42 in 3D), small locked-in stresses, and a
-- missed sigma0 reported as a warning.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq
local lab = require "seixo.lab"

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")

-- The bonds of every ball of a specimen's file, and whether the ball lies
-- in the core of the specimen (its centre farther than 2 rmax from every
-- side of the box of the balls; a cylinder: from its curved side too).
local function bonds_per_ball(spec)
  local m = seixo.load(spec.path)
  local dim, n, core = m:dim(), {}, {}
  for b in m:balls() do n[b.id] = 0 end
  for c in m:contacts{kind = "ball-ball"} do
    if c.bond then n[c.a.id], n[c.b.id] = n[c.a.id] + 1, n[c.b.id] + 1 end
  end
  local margin = 2 * spec.rmax
  for b in m:balls() do
    local p, inside = b.pos, true
    for k = 1, dim do
      if p[k] < spec.lo[k] + margin or p[k] > spec.hi[k] - margin then inside = false end
    end
    if spec.shape == "cylinder" then
      local cx, cy = 0.5 * (spec.lo[1] + spec.hi[1]), 0.5 * (spec.lo[2] + spec.hi[2])
      local rad = 0.25 * (spec.hi[1] - spec.lo[1] + spec.hi[2] - spec.lo[2])
      if math.sqrt((p[1] - cx) ^ 2 + (p[2] - cy) ^ 2) > rad - margin then inside = false end
    end
    core[b.id] = inside
  end
  m:close()
  return n, core
end

local function check_genesis(spec, max_core_porosity)
  local g = spec.genesis
  eq(spec.floaters, 0)
  check(g.floaters_found > 0, "the packing had floaters to eliminate")
  -- sigma0 within the 2 % tolerance of the radius scaling
  check(math.abs(g.sigma / spec.sigma0 - 1) < 0.02, string.format("wall stress %g Pa", g.sigma))
  eq(#g.warnings, 0)
  -- every ball bonded; in the core, to three neighbours or more (a
  -- floater's fewer than three neighbours would give it fewer bonds)
  local n, core = bonds_per_ball(spec)
  local cored = 0
  for id, k in pairs(n) do
    check(k >= 1, string.format("ball %d has no bond", id))
    if core[id] then
      cored = cored + 1
      check(k >= 3, string.format("ball %d in the core has %d bonds", id, k))
    end
  end
  check(cored > 0.2 * spec.balls, string.format("%d balls in the core", cored))
  check(g.core_porosity < max_core_porosity, string.format("core porosity %g", g.core_porosity))
  -- the relaxation leaves locked-in stresses far below sigma0
  check(math.abs(g.locked_in) < 0.1 * spec.sigma0, string.format("locked-in mean stress %g Pa", g.locked_in))
end

test("2D genesis: no floaters, sigma0 within 2 %, a dense packing", function()
  local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.27e-3, 0.45e-3},
                            seed = 3, path = dir .. "/g2.h5", log = false}
  -- random close packing of disks: a porosity of about 0.16
  check_genesis(spec, 0.18)
end)

test("3D genesis: no floaters, sigma0 within 2 %, a dense packing", function()
  local spec = lab.specimen{dim = 3, shape = "cylinder", diameter = 0.012, height = 0.024, radius = {0.8e-3, 1.33e-3},
                            seed = 2, path = dir .. "/g3.h5", log = false}
  -- random close packing of spheres: about 0.36; the old genesis left 0.42
  check_genesis(spec, 0.38)
end)

test("a sigma0 that the steps allowed cannot install is a warning in the log", function()
  local lines = {}
  local spec = lab.specimen{dim = 2, shape = "rect", width = 0.006, height = 0.012, radius = {0.27e-3, 0.45e-3},
                            seed = 1, path = dir .. "/short.h5", max_steps = 400,
                            log = function(s) lines[#lines + 1] = s end}
  check(#spec.genesis.warnings > 0, "a warning in the result")
  local logged = false
  for _, s in ipairs(lines) do if s:find("warning: sigma0") then logged = true end end
  check(logged, table.concat(lines, "\n"))
end)

os.execute("rm -rf '" .. dir .. "'")
T.done()
