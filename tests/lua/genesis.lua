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

-- The volume fraction of the balls of a file below radius x, with its
-- standard error (delta method: the sampling's own scatter).
local function volume_below(path, x)
  local m = seixo.load(path)
  local dim, rs = m:dim(), {}
  for b in m:balls() do rs[#rs + 1] = b.radius end
  m:close()
  local sv, sa = 0, 0
  for _, r in ipairs(rs) do
    sv = sv + r ^ dim
    if r < x then sa = sa + r ^ dim end
  end
  local frac, var = sa / sv, 0
  for _, r in ipairs(rs) do var = var + (r ^ dim * ((r < x and 1 or 0) - frac)) ^ 2 end
  return frac, math.sqrt(var / #rs) / (sv / #rs) / math.sqrt(#rs), rs
end

test("a grading curve (psd) through the genesis, walled and periodic", function()
  -- gap-graded: 60 % of the volume in 0.2-0.25 mm, the rest in 0.4-0.45 mm
  -- (a uniform draw over 0.2-0.45 mm would put 30 % below 0.32 mm)
  local psd = {{0.2e-3, 0}, {0.25e-3, 0.6}, {0.4e-3, 0.6}, {0.45e-3, 1}}
  local spec = lab.specimen{dim = 2, width = 0.008, height = 0.016, psd = psd, bonds = false, seed = 2,
                            path = dir .. "/psd.h5", log = false}
  eq(spec.psd[3][1], 0.4e-3)
  eq(spec.radius[1], 0.2e-3)
  eq(spec.radius[2], 0.45e-3)
  local frac, se, rs = volume_below(spec.path, 0.32e-3)
  -- sigma0's radius scaling moves every radius by one factor (a few %), and
  -- floaters grow: the split at 0.32 mm stays in the gap
  check(math.abs(frac - 0.6) < 4 * se, string.format("volume below 0.32 mm: %g (se %g)", frac, se))
  local in_gap = 0
  for _, r in ipairs(rs) do if r > 0.27e-3 and r < 0.37e-3 then in_gap = in_gap + 1 end end
  check(in_gap <= spec.genesis.floaters_found, string.format("%d balls in the gap", in_gap))
  local cell = lab.periodic.specimen{dim = 2, size = 0.008, psd = psd, bonds = false, seed = 2, path = dir .. "/psdcell.h5",
                                     log = false}
  frac, se = volume_below(cell.path, 0.32e-3)
  check(math.abs(frac - 0.6) < 4 * se, string.format("periodic: volume below 0.32 mm: %g (se %g)", frac, se))
  eq(lab.periodic.open(cell.path).psd[2][2], 0.6)
  -- the files hold no clock time (the same genesis saves the same file);
  -- the returned tables do
  check(spec.genesis_time > 0 and cell.genesis_time > 0, "the genesis's time is returned")
  eq(lab.open(spec.path).genesis_time, nil)
  eq(lab.periodic.open(cell.path).genesis_time, nil)
  T.raises(function() lab.specimen{dim = 2, width = 0.008, height = 0.016, psd = psd, radius = {1e-3, 2e-3}, path = dir .. "/x.h5"} end,
           "radius or psd")
  T.raises(function() lab.periodic.specimen{dim = 2, psd = {}, path = dir .. "/x.h5"} end, "psd must be a grading curve")
end)

os.execute("rm -rf '" .. dir .. "'")
T.done()
