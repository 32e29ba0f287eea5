-- Lua-level checks of bonds, cracks and energies (m:bond, m:cracks, m:energy).
local passed, failed = 0, 0
local function check(name, ok, msg)
  if ok then passed = passed + 1 else failed = failed + 1; print("FAIL " .. name .. ": " .. tostring(msg)) end
end

-- two disks joined by a parallel bond, pulled apart by an applied force
local function pair(force)
  local m = seixo.model{dim = 2}
  m:material("r", {density = 1000, damping = 0.7, kn = 1e9, ks = 1e9,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                           tensile_strength = 1e7, cohesion = 1e7}})
  local a = m:ball{pos = {0, 0}, radius = 1}
  local b = m:ball{pos = {2, 0}, radius = 1}
  a.fix = "all"
  local n = m:bond{gap = 1e-6}
  b.applied_force = {force, 0}
  m:track_energy(true)
  m:cycle(20000)
  return m, b, n
end

do
  -- closed form: axial stiffness kn_bar * A = Ec/(RA+RB) * 2R_bar = 1e9/2 * 2 = 1e9 N/m
  local m, b, n = pair(1e5)
  check("one bond installed", n == 1 and m:bond_count() == 1, n)
  local disp = b.pos[1] - 2
  check("axial stiffness", math.abs(disp - 1e-4) < 1e-4 * 1e-6, disp)
  check("no crack below strength", m:crack_count() == 0, m:crack_count())
  local e = m:energy()
  local balance = e.boundary_work - (e.kinetic + e.strain + e.bond_strain + e.slip + e.local_damping + e.viscous + e.bond_released)
  check("energy closes", math.abs(balance) < 1e-3 * e.boundary_work, balance)
end

do
  -- break load: sigma_max = -Fn/A >= sigma_c, i.e. F >= 1e7 * 2 = 2e7 N
  local m = pair(2.02e7)
  check("bond breaks in tension", m:crack_count() == 1 and m:crack_count("tension") == 1 and m:bond_count() == 0,
        m:crack_count())
  local c = m:cracks()[1]
  -- the contact point is the middle of the opened gap; the bond failed at or past its strength sigma_c A
  check("crack record", c and c.mode == "tension" and c.kind == "parallel" and c.a == 1 and c.b == 2
        and c.pos[1] > 1 and c.pos[1] < 1.05 and c.fn <= -2e7 and c.step > 0, c and c.pos[1])
end

do
  local m = seixo.model{dim = 3}
  m:material("h", {model = "hertz", shear_modulus = 1e9, poisson = 0.2})
  m:ball{pos = {0, 0, 0}, radius = 1}
  m:ball{pos = {2, 0, 0}, radius = 1}
  local ok, err = pcall(m.bond, m, {kind = "contact", gap = 1e-6, normal_strength = 1, shear_strength = 1})
  check("hertz refuses bonds", not ok and tostring(err):find("Hertz"), err)
  ok, err = pcall(m.bond, m, {gapp = 1})
  check("unknown key named", not ok and tostring(err):find("gapp"), err)
  ok, err = pcall(m.material, m, "x", {model = "plastic"})
  check("unknown model named", not ok and tostring(err):find("plastic"), err)
end

do
  -- a material switched to Hertz after its balls were bonded is refused when cycled
  local m = seixo.model{dim = 3}
  m:material("r", {kn = 1e7, ks = 1e7, density = 2500})
  m:ball{pos = {0, 0, 0}, radius = 1}
  m:ball{pos = {2, 0, 0}, radius = 1}
  m:bond{kind = "contact", gap = 1e-6, normal_strength = 1e3, shear_strength = 1e3}
  m:material("r", {model = "hertz", shear_modulus = 1e9, poisson = 0.2, density = 2500})
  local ok, err = pcall(m.cycle, m, 1)
  check("hertz after bonding refused", not ok and tostring(err):find("Hertz") and tostring(err):find("bonded"), err)
end

do
  -- The stability guard counts the strain held by bonds: two bonded balls
  -- stopped at their largest stretch hold all the energy in the bond, and
  -- cycling them on at a tenth of the critical timestep is stable.
  local m = seixo.model{dim = 3, timestep = 1e-7}
  m:material("a", {kn = 1e7, ks = 1e7, density = 2500, friction = 0.5})
  local R = 0.01
  local a = m:ball{pos = {0, 0, 0}, radius = R}
  local b = m:ball{pos = {2 * R + 1e-5, 0, 0}, radius = R}
  m:ball{pos = {1, 1, 1}, radius = R, vel = {1e-4, 0, 0}}
  m:bond{kind = "parallel", gap = 1e-4, radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 1,
         tensile_strength = 1e15, cohesion = 1e15}
  a.vel = {-0.005, 0, 0}; b.vel = {0.005, 0, 0}
  local prev = math.huge
  for _ = 1, 200000 do  -- until the balls turn back: the bond's largest stretch
    m:cycle(1)
    local rel = math.abs(b.vel[1] - a.vel[1])
    if rel > prev then break end
    prev = rel
  end
  a.vel = {0, 0, 0}; b.vel = {0, 0, 0}   -- a user change: a new energy baseline
  local strain = m:energy().bond_strain
  local ok, err = pcall(m.cycle, m, 50000)
  check("guard counts bond strain", ok and strain > 0 and m:timestep() < 0.2 * m:critical_timestep(), err)
end

do
  -- The average stress counts parallel-bond forces (4-32): two fixed disks
  -- joined by a bond stretched by u carry the tension T = kn_bar A u, and
  -- sigma_xx = -(1/V) sum F (x_c - x) = -T L / V with L the branch length.
  local m = seixo.model{dim = 2, timestep = 1e-6}
  m:material("s", {kn = 1e7, ks = 1e7, density = 2500, bond = {radius_multiplier = 1, modulus = 1e8,
             stiffness_ratio = 1, tensile_strength = 1e12, cohesion = 1e12}})
  local a = m:ball{pos = {0, 0}, radius = 1e-3}
  local b = m:ball{pos = {2e-3, 0}, radius = 1e-3}
  m:bond{kind = "parallel", gap = 1e-6}
  a.fix = "all"; b.fix = "all"; b.vel = {1e-3, 0}
  m:cycle(100)
  local u = b.pos[1] - 2e-3
  local T = 1e8 / 2e-3 * 2e-3 * u        -- kn_bar = Ec/(RA+RB), A = 2 R_bar (unit thickness)
  local lo, hi = {-2e-3, -2e-3}, {4e-3, 2e-3}
  local r = m:measure{box = {min = lo, max = hi}}
  local V = (hi[1] - lo[1]) * (hi[2] - lo[2])
  local expect = -T * 2e-3 / V
  check("stress counts parallel bonds", u > 0 and math.abs(r.stress[1][1] - expect) < 1e-3 * math.abs(expect),
        string.format("%g vs %g", r.stress[1][1], expect))
end

do
  -- a bond without strengths would break at once: refused, and nothing installed
  local m = seixo.model{dim = 2}
  m:material("r", {kn = 1e7, ks = 1e7, density = 2500})
  m:ball{pos = {0, 0}, radius = 1}
  m:ball{pos = {2, 0}, radius = 1}
  local ok, err = pcall(m.bond, m, {kind = "parallel", gap = 1e-6, radius_multiplier = 1, modulus = 1e9,
                                    stiffness_ratio = 1, cohesion = 1e6})
  check("parallel bond without tensile strength refused", not ok and tostring(err):find("tensile_strength"), err)
  ok, err = pcall(m.bond, m, {kind = "contact", gap = 1e-6, normal_strength = 10})
  check("contact bond without shear strength refused", not ok and tostring(err):find("shear_strength"), err)
  check("nothing installed by refused calls", m:bond_count() == 0, m:bond_count())
end

do
  -- the bond kinds and their keys come from the registry (src/core/laws/bonds.h): every kind's
  -- micro-parameters, flat joint's included, are saved with the material and restored
  local m = seixo.model{dim = 2}
  m:material("r", {kn = 1e7, ks = 1e7, density = 2500,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2, tensile_strength = 1e6,
                           cohesion = 2e6, normal_strength = 3, shear_strength = 4, friction_angle = 30,
                           friction = 0.6, elements = 3, sectors = 5, unbonded_fraction = 0.25, initial_gap = 1e-6}})
  m:ball{pos = {0, 0}, radius = 1}
  local path = "bonds_registry.h5"
  m:save(path)
  local l = seixo.load(path)
  check("every bond micro-parameter survives a save and load", l:hash() == m:hash(), l:hash() .. " vs " .. m:hash())
  os.remove(path)
  local ok, err = pcall(m.bond, m, {kind = "glue", gap = 1e-6})
  check("an unknown kind lists the registry's", not ok and tostring(err):find("'parallel', 'contact', 'flatjoint'", 1, true), err)
  ok, err = pcall(m.material, m, "q", {bond = {unbonded_fraction = 1.5}})
  check("a key's range comes from its kind", not ok and tostring(err):find("unbonded_fraction must be in [0, 1]", 1, true), err)
  ok, err = pcall(m.material, m, "q", {bond = {elements = 2.5}})
  check("element counts are whole", not ok and tostring(err):find("elements must be a whole number", 1, true), err)
end

-- A generated lattice's neighbours touch to a few ulps either way: the
-- default gap (0) bonds every one of them (87 of 274 were bonded, as the
-- rounding fell: a new user's finding)
do
  local m = seixo.model{dim = 2}
  m:material("r", {density = 2600, kn = 1e9, ks = 1e9,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                           cohesion = 1e6}})
  m:generate{packing = "hex", radius = 1e-3, region = {box = {{0, 0}, {0.02, 0.02}}}}
  local touching = 0
  for i = 1, m:ball_count() do
    for j = i + 1, m:ball_count() do
      if (m:ball(i).pos - m:ball(j).pos):norm() < 2e-3 * (1 + 1e-9) then touching = touching + 1 end
    end
  end
  local n = m:bond{kind = "parallel"}
  check("a lattice's touching pairs all bonded", n == touching and n > 250, n .. " of " .. touching)
  -- a gapped flat joint between touching balls is a closed face, every element bonded
  local g = seixo.model{dim = 2}
  g:material("r", {density = 2600, kn = 1e9, ks = 1e9,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                           cohesion = 1e6}})
  local a = g:ball{pos = {0, 0}, radius = 1e-3}
  local b = g:ball{pos = {0.002 * (1 + 1e-12), 0}, radius = 1e-3}
  local open = 0
  check("a touching pair takes a gapped flat joint", g:bond{kind = "flatjoint", gapped = true} == 1, "")
  for _, e in ipairs(g:flatjoint(a.id, b.id)) do if e.state ~= "bonded" then open = open + 1 end end
  check("a touching pair's gapped face is closed", open == 0, open)
  -- a gap below the touching tolerance bonds what gap 0 bonds (it shrank the broad phase's skin to itself)
  local t = seixo.model{dim = 2}
  t:material("r", {density = 2600, kn = 1e9, ks = 1e9,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                           cohesion = 1e6}})
  t:ball{pos = {0, 0}, radius = 1e-3}
  t:ball{pos = {0.002 * (1 + 1e-12), 0}, radius = 1e-3}
  check("a gap of 1e-18 m bonds touching balls", t:bond{gap = 1e-18} == 1, "")
end

-- a parallel-bonded pair spinning rigidly, its balls apart (no contact
-- spring): the bond's normal force follows the distance between the centres,
-- -kn_bar A (d - d0), turn after turn. The stretch taken as the half-step
-- velocity along the step's normal, not the mid normal, gathered pi w d dt
-- a turn (1.2e-4 m here).
for dim = 2, 3 do
  local function v(x, y) return dim == 3 and {x, y, 0} or {x, y} end
  local R, gap, w = 0.01, 1e-4, 100
  local m = seixo.model{dim = dim}
  m:material("r", {density = 2650, kn = 1e7, ks = 1e7,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5,
                           tensile_strength = 1e12, cohesion = 1e12}})
  local d0 = 2 * R + gap
  local a = m:ball{pos = v(-d0 / 2, 0), radius = R, vel = v(0, -w * d0 / 2), spin = dim == 3 and {0, 0, w} or w}
  local b = m:ball{pos = v(d0 / 2, 0), radius = R, vel = v(0, w * d0 / 2), spin = dim == 3 and {0, 0, w} or w}
  m:bond{gap = 2 * gap}
  local knA = 1e9 / (2 * R) * (dim == 3 and math.pi * R ^ 2 or 2 * R)
  local turn = math.floor(2 * math.pi / (w * m:timestep()))
  local worst = 0
  for _ = 1, 3 do
    m:cycle(turn)
    local c, dt = m:contacts()(), m:timestep()
    -- the last force pass saw the positions a step back: x - v dt
    local dx = (b.pos[1] - b.vel[1] * dt) - (a.pos[1] - a.vel[1] * dt)
    local dy = (b.pos[2] - b.vel[2] * dt) - (a.pos[2] - a.vel[2] * dt)
    worst = math.max(worst, math.abs(-c.pb_fn / knA - (math.sqrt(dx * dx + dy * dy) - d0)))
  end
  check(dim .. "D spinning bonded pair: no false stretch", worst < 1e-12, worst)
end

print(string.format("%d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
