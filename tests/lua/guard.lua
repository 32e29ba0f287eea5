-- The energy guard (src/core/guard.c) must not stop a valid run: three
-- scenes it stopped with "unstable ... the mechanical energy of an
-- unforced system grew", each at a timestep well below the critical
-- estimate (a review's findings). The periodic chute is periodic.lua's.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

-- A ball placed 1 % of its radius into a floor: a mesh's overlaps are its
-- contact pass's, so the baseline taken before the first step had no
-- strain, and 64 steps later the strain counted as growth (7,070 times
-- the scale). The same ball on a plane never tripped.
T.test("a ball placed into a mesh floor settles as on a plane floor", function()
  local function settle(kind)
    local R, L = 0.001, 0.003
    local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}, timestep = 5e-8}
    m:material("rock", {kn = 1e8, ks = 1e8, friction = 0.5, damping = 0.7})
    if kind == "mesh" then
      m:wall{kind = "mesh", triangles = {{{-L, -L, 0}, {L, -L, 0}, {L, L, 0}}, {{-L, -L, 0}, {L, L, 0}, {-L, L, 0}}}}
    else
      m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
    end
    local b = m:ball{pos = {0, 0, 0.99 * R}, radius = R, material = "rock"}
    local ok, err = pcall(m.cycle, m, 640)
    T.check(ok, kind .. ": " .. tostring(err))
    T.check(m:timestep() < 0.3 * m:critical_timestep(), "well below the critical timestep")
    return b.pos[3]
  end
  local z_mesh, z_plane = settle("mesh"), settle("plane")
  T.check(math.abs(z_mesh - z_plane) < 1e-6 * 0.001, string.format("height %.9g on the mesh, %.9g on the plane", z_mesh,
                                                                    z_plane))
end)

-- Contact bonds installed across a gap start in tension: the strain jumps
-- from 1e-6 to 2.3e-4 J when m:bond installs them, which took no new
-- baseline, so the undamped row's motion tripped the guard. Its
-- mechanical energy is conserved.
T.test("bonds installed across a gap take a new baseline: an undamped bonded row runs on", function()
  local R = 0.001
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, damping = 0,
                      bond = {normal_strength = 100, shear_strength = 100}})
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  for i = 0, 9 do m:ball{pos = {i * (2 * R + 1e-5), 0, R}, radius = R, material = "rock"} end
  m:cycle(2000)
  local function mechanical()
    local e = m:energy()
    return e.kinetic + e.gravitational + e.strain + e.bond_strain
  end
  T.eq(m:bond{kind = "contact", gap = 2e-5}, 9)
  local e0 = mechanical()
  local ok, err = pcall(m.cycle, m, 2000)
  T.check(ok, tostring(err))
  T.check(math.abs(mechanical() - e0) < 0.1 * e0, string.format("mechanical energy %.6g after, %.6g at bonding",
                                                                 mechanical(), e0))
end)

-- A Hertz contact about to separate: its shear spring's energy, 1/2 |Fs|^2
-- / ks, took ks from the overlap after the step (1.7e-18 m here, so ks
-- near 0) and Fs from the pass before it; the strain read 1.77 J of a
-- bounce carrying 0.011 J, and the guard stopped the run. The start gap
-- puts the check at step 64 on that overlap.
T.test("a Hertz bounce separating at a check keeps its strain energy bounded", function()
  local R = 0.01
  local m = seixo.model{dim = 3, timestep = 2e-6}
  m:material("h", {model = "hertz", shear_modulus = 29e9, poisson = 0.15, friction = 0.5, density = 2650})
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, material = "h"}
  m:ball{pos = {0, 0, R + 4.4316058556503885e-05}, radius = R, vel = {1, 0, -1}, material = "h"}
  local e0 = m:energy().kinetic
  local ok, err = pcall(m.cycle, m, 64)
  T.check(ok, tostring(err))
  local e = m:energy()
  T.check(e.strain < 0.01 * e0, string.format("strain %.6g J of a bounce carrying %.6g J", e.strain, e0))
end)

-- The guard's other side: a load applied and then removed leaves the
-- system unforced, and the guard on. It stayed off for the model's life
-- (the loads' array, once made, stays): a bonded pair at 5 times the
-- critical timestep ran on to 1.9e6 m/s with no error.
T.test("a load set back to zero leaves the guard on: an unstable bonded pair is stopped", function()
  local m = seixo.model{dim = 2}
  m:material("rock", {kn = 1e7, ks = 1e7, friction = 0.5, damping = 0, density = 2500,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 1, tensile_strength = 1e12,
                              cohesion = 1e12}})
  m:ball{pos = {0, 0}, radius = 0.01, material = "rock"}
  local b = m:ball{pos = {0.0199, 0}, radius = 0.01, material = "rock"}
  T.eq(m:bond{kind = "parallel", gap = 1e-3}, 1)
  b.applied_force = {1, 0}
  m:cycle(10)
  b.applied_force = {0, 0}
  m:set_timestep(5 * m:critical_timestep())
  T.raises(function() m:cycle(2000) end, "the mechanical energy of an unforced system grew")
end)
