-- lab.rock's micro-parameter sets (docs/potyondy-cundall.md): Potyondy &
-- Cundall's PFC2D set, the set calibrated in 3D, and the BPM scaling the
-- 3D set rests on (E proportional to Ec = Ec-bar at fixed stiffness ratios).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local lab = require "seixo.lab"

test("lab.rock() is P&C's PFC2D set, and lab.rock{dim = 2} the same", function()
  for _, r in ipairs{lab.rock(), lab.rock{dim = 2}} do
    eq(r.density, 2630)
    eq(r.modulus, 62e9)
    eq(r.stiffness_ratio, 2.5)
    eq(r.friction, 0.5)
    eq(r.bond.radius_multiplier, 1)
    eq(r.bond.modulus, 62e9)
    eq(r.bond.stiffness_ratio, 2.5)
    eq(r.bond.tensile_strength, 157e6)
    eq(r.bond.tensile_strength_sd, 36e6)
    eq(r.bond.cohesion, 157e6)
    eq(r.bond.cohesion_sd, 36e6)
    eq(r.dim, nil, "dim chooses the set and is not a material field")
  end
end)

test("lab.rock{dim = 3}: the 3D calibration, P&C's ratios and coefficient of variation kept", function()
  local r, p = lab.rock{dim = 3}, lab.rock()
  eq(r.modulus, 87e9)
  eq(r.bond.modulus, r.modulus)
  eq(r.bond.tensile_strength, 227e6)
  eq(r.bond.cohesion, r.bond.tensile_strength)
  eq(r.dim, nil)
  for _, k in ipairs{"density", "stiffness_ratio", "friction", "damping"} do eq(r[k], p[k], k) end
  eq(r.bond.stiffness_ratio, p.bond.stiffness_ratio)
  eq(r.bond.radius_multiplier, p.bond.radius_multiplier)
  near(r.bond.tensile_strength_sd / r.bond.tensile_strength, p.bond.tensile_strength_sd / p.bond.tensile_strength, 0.02)
  eq(r.bond.cohesion_sd, r.bond.tensile_strength_sd)
  -- overrides apply on top of the chosen set
  local o = lab.rock{dim = 3, friction = 0.3, bond = {cohesion = 1e8}}
  eq(o.friction, 0.3)
  eq(o.bond.cohesion, 1e8)
  eq(o.bond.tensile_strength, 227e6)
  eq(o.modulus, 87e9)
  raises(function() lab.rock{dim = 4} end, "dim must be 2 or 3")
  raises(function() lab.rock("pfc3d") end, "a table of overrides expected")
end)

test("on one packing E scales with Ec = Ec-bar at fixed ratios (the 3D set's calibration step), nu does not move", function()
  local dir = os.tmpname()
  os.remove(dir)
  os.execute("mkdir -p '" .. dir .. "'")
  local rmin = 0.8e-3
  local spec = lab.specimen{dim = 3, shape = "cylinder", diameter = 0.01, height = 0.02, radius = {rmin, 1.66 * rmin},
                            seed = 2, material = lab.rock(), path = dir .. "/e62.h5", log = false}
  -- its twin: the same balls with lab.rock{dim = 3}, bonded again at the genesis's gap (Rmin / 1000); a
  -- genesis of the stiffer material would make another packing, whose E differs by more than the scaling
  local mat3 = lab.rock{dim = 3}
  local m1 = seixo.load(spec.path)
  local m2 = seixo.model{dim = 3}
  m2:material("rock", mat3)
  for b in m1:balls() do m2:ball{pos = b.pos, radius = b.radius, material = "rock"} end
  m1:close()
  eq(m2:bond{kind = "parallel", gap = rmin / 1000, seed = 2}, spec.bonds, "the twin's bonds are the specimen's")
  m2:solve{ratio = 1e-4, steps = 20000} -- its new bonds start unstressed: it relaxes as the specimen did
  m2:save(dir .. "/e87.h5")
  m2:close()
  local twin = {}
  for k, v in pairs(spec) do twin[k] = v end
  twin.path, twin.material, twin.wall_kn = dir .. "/e87.h5", mat3, spec.wall_kn * mat3.modulus / 62e9
  -- elastic only: to an axial strain of 3e-4, a third of the way to the peak
  local res = {}
  for i, s in ipairs{spec, twin} do
    res[i] = lab.ucs(s, {max_strain = 3e-4, log = false})
    eq(res[i].cracks.tension + res[i].cracks.shear, 0, "elastic: no bond broke")
  end
  os.execute("rm -rf '" .. dir .. "'")
  near(res[2].young / res[1].young, mat3.modulus / 62e9, 0.02)
  near(res[2].poisson, res[1].poisson, 0.02)
end)

T.done()
