-- Lua-level checks of the flat joint: m:bond{kind = "flatjoint"} with the
-- parameters from the material's bond table, the per-element draws from the
-- recorded seed, m:flatjoint and m:flatjoint_unbond, the crack log's
-- elements and clear errors.
local passed, failed = 0, 0
local function check(name, ok, msg)
  if ok then passed = passed + 1 else failed = failed + 1; print("FAIL " .. name .. ": " .. tostring(msg)) end
end

-- two balls joined by a flat joint whose parameters come from the material
local function pair(dim, bond, over)
  local m = seixo.model{dim = dim}
  local mat = {density = 1000, damping = 0.3, kn = 1e9, ks = 1e9, friction = 0.5,
               bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                       tensile_strength_sd = 2e5, cohesion = 2e6, cohesion_sd = 4e5, friction_angle = 30,
                       friction = 0.6, elements = 4, sectors = 3}}
  for k, v in pairs(over or {}) do mat.bond[k] = v end
  m:material("r", mat)
  local a = m:ball{pos = dim == 3 and {0, 0, 0} or {0, 0}, radius = 1}
  local b = m:ball{pos = dim == 3 and {2, 0, 0} or {2, 0}, radius = 1}
  local n = m:bond(bond or {kind = "flatjoint", gap = 1e-6, seed = 5})
  return m, a, b, n
end

for _, dim in ipairs{2, 3} do
  local m, a, b, n = pair(dim)
  check(dim .. "D one joint", n == 1 and m:bond_count() == 1, n)
  local els = m:flatjoint(a.id, b.id)
  check(dim .. "D elements from the material", els and #els == (dim == 3 and 12 or 4), els and #els)
  local same, spread = true, false
  local m2, a2, b2 = pair(dim)
  local els2 = m2:flatjoint(a2.id, b2.id)
  for k, e in ipairs(els) do
    same = same and e.tensile_strength == els2[k].tensile_strength and e.cohesion == els2[k].cohesion
    spread = spread or e.tensile_strength ~= els[1].tensile_strength
    check(dim .. "D element bonded", e.state == "bonded", e.state)
  end
  check(dim .. "D draws repeat from the seed", same, "")
  check(dim .. "D draws spread (sd > 0)", spread, "")
  local area = 0
  for _, e in ipairs(els) do area = area + e.area end
  local want = dim == 3 and math.pi or 2
  check(dim .. "D elements tile the face", math.abs(area - want) < 1e-12 * want, area)
  m:flatjoint_unbond(a.id, b.id, 1)
  check(dim .. "D slit", m:flatjoint(a.id, b.id)[1].state == "unbonded", m:flatjoint(a.id, b.id)[1].state)
  local ok, err = pcall(m.flatjoint_unbond, m, a.id, b.id, 99)
  check(dim .. "D bad element named", not ok and tostring(err):find("element"), err)
  -- the element past the end and element 0 in the user's numbering, by the
  -- method's name (once "element 4 out of range (the joint has 4)" for 5,
  -- and "bad argument #4 to '?'" for 0)
  local range = string.format("elements 1 to %d", #els)
  for _, e in ipairs{#els + 1, 0, -1} do
    ok, err = pcall(m.flatjoint_unbond, m, a.id, b.id, e)
    local want = string.format("m:flatjoint_unbond: element %d out of range: the joint between balls %d and %d has %s",
                               e, a.id, b.id, range)
    check(dim .. "D element " .. e .. " refused by name", not ok and tostring(err):find(want, 1, true), err)
  end
  ok, err = pcall(m.flatjoint_unbond, m, a.id, b.id, 2.5)
  check(dim .. "D a fraction refused by name", not ok and tostring(err):find("m:flatjoint_unbond: the element must be a "
                                                                            .. "whole number (got 2.5)", 1, true), err)
  m:flatjoint_unbond(a.id, b.id, #els) -- the last is in range
  check(dim .. "D last element slit", m:flatjoint(a.id, b.id)[#els].state == "unbonded", "")
  check(dim .. "D no joint elsewhere", m:flatjoint(a.id, 77) == nil, "")
  m:close()
  m2:close()
end

do -- bad parameters are named
  local ok, err = pcall(pair, 2, nil, {friction_angle = 95})
  check("friction_angle range", not ok and tostring(err):find("friction_angle"), err)
  ok, err = pcall(pair, 2, nil, {elements = 2.5})
  check("whole elements", not ok and tostring(err):find("elements"), err)
  ok, err = pcall(pair, 2, {kind = "flatjoint", gap = 1e-6, unbonded_fraction = 2})
  check("fraction range", not ok and tostring(err):find("unbonded_fraction"), err)
  ok, err = pcall(pair, 2, {kind = "glue", gap = 1e-6})
  check("kind named", not ok and tostring(err):find("flatjoint"), err)
  local m = pair(2)
  ok, err = pcall(m.bond, m, {kind = "parallel", gap = 1e-6})
  check("no parallel bond on a flat joint", not ok and tostring(err):find("flat joint"), err)
end

-- Partial breakage: B is pressed on A and bent by a moment ramped up beyond
-- the outer elements' strength, so some elements break (in the crack log with
-- their element), slit elements close, and the face holds on in compression.
-- The work of the loads closes with the stored, dissipated and released
-- energies within 1 % (tests/bpm/energy.c has the specimens' balance).
for _, dim in ipairs{2, 3} do
  local m, a, b = pair(dim, {kind = "flatjoint", gap = 1e-6, seed = 3, unbonded_fraction = 0.25})
  a.fix = "all"
  m:track_energy(true)
  local mz = dim == 3 and 1.8e6 or 1.5e6
  for k = 1, 100 do
    b.applied_force = dim == 3 and {-1e6 * k / 100, 0, 0} or {-1e6 * k / 100, 0}
    b.applied_moment = dim == 3 and {0, mz * k / 100, 0} or mz * k / 100
    m:cycle(100)
  end
  m:cycle(5000)
  local els = m:flatjoint(a.id, b.id)
  check(dim .. "D the joint holds on", els ~= nil and m:bond_count() == 1, m:bond_count())
  local broken, logged = 0, 0
  for _, e in ipairs(els or {}) do if e.state == "tension" or e.state == "shear" then broken = broken + 1 end end
  for _, c in ipairs(m:cracks()) do
    local e = els and c.element and els[c.element]
    if c.kind == "flatjoint" and e and e.state == c.mode then logged = logged + 1 end
  end
  check(dim .. "D some elements broke, not all", broken > 0 and broken < #(els or {}), broken)
  check(dim .. "D each break logged with its element and mode", logged == broken and m:crack_count() == broken,
        logged .. " of " .. broken)
  local e = m:energy()
  check(dim .. "D breaks release energy", e.bond_released > 0, e.bond_released)
  local balance = e.boundary_work - (e.kinetic + e.strain + e.bond_strain + e.slip + e.local_damping + e.viscous
                                     + e.bond_released)
  print(string.format("%dD: %d of %d elements broke; work %.5g J, released %.4g J, balance %.2e of the work", dim,
                      broken, #(els or {}), e.boundary_work, e.bond_released, balance / e.boundary_work))
  check(dim .. "D energy closes within 1 %", math.abs(balance) < 0.01 * e.boundary_work, balance)
end

-- Elements much stronger in shear than in tension (c = 10 sigma_c, the
-- flat-jointed rock's choice): pulled apart, the face breaks in tension at
-- sigma_c; pressed by sigma and sheared, it breaks in shear at
-- tau = c + sigma tan(phi) (Coulomb with cohesion), the pressure adding
-- 2.7 c at phi = 60 deg. Both balls move at set velocities (fix = "all").
for _, dim in ipairs{2, 3} do
  local function load(sn, phi)
    local m, a, b = pair(dim, {kind = "flatjoint", gap = 1e-6, seed = 1},
                         {tensile_strength_sd = 0, cohesion = 10e6, cohesion_sd = 0, friction_angle = phi})
    a.fix, b.fix = "all", "all"
    local els = m:flatjoint(a.id, b.id)
    local dt = m:timestep()
    local function v(x, y) return dim == 3 and {x, y, 0} or {x, y} end
    b.vel = v(-sn / 0.5e9 / (1000 * dt), 0) -- kn = modulus / (RA + RB) = 0.5e9 Pa/m
    m:cycle(1000)
    local n = 0
    while m:crack_count() == 0 and n < 40000 do
      b.vel = v(0, sn > 0 and 0.2 / (20000 * dt) or 0)
      m:cycle(10)
      n = n + 10
    end
    local c = m:cracks()[1]
    local area = c and els[c.element].area or 1
    m:close()
    return c and c.mode, c and c.fn / area, c and c.fs / area
  end
  local mode, sigma = load(-2e6, 60)
  check(dim .. "D c >> sigma_c: tension break at sigma_c", mode == "tension" and math.abs(sigma + 1e6) < 1e-6 * 1e6,
        tostring(mode) .. " " .. tostring(sigma))
  local mode2, s2, tau = load(20e6, 60)
  local want = s2 and 10e6 + s2 * math.tan(math.rad(60))
  check(dim .. "D pressed and sheared: shear break at c + sigma tan(phi)",
        mode2 == "shear" and s2 > 10e6 and math.abs(tau - want) < 1e-3 * want,
        string.format("%s sigma %s tau %s want %s", tostring(mode2), tostring(s2), tostring(tau), tostring(want)))
end

-- A face installed on overlapping balls (overlap u0 = 0.01) and broken in
-- tension opens before the balls part: it stays, carrying nothing, until
-- they part, and only then does the contact law take over (at zero
-- overlap). Removing it at the first opening handed the pair to the
-- contact law with an overlap, a force kn u0 out of nowhere.
for _, dim in ipairs{2, 3} do
  local m = seixo.model{dim = dim}
  m:material("r", {density = 1000, kn = 1e9, ks = 1e9, friction = 0.5,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                           cohesion = 10e6, friction = 0.6, elements = 4, sectors = 3}})
  local function v(x) return dim == 3 and {x, 0, 0} or {x, 0} end
  local a = m:ball{pos = v(0), radius = 1}
  local b = m:ball{pos = v(2 - 0.01), radius = 1}
  m:bond{kind = "flatjoint", gap = 1e-6, seed = 2}
  a.fix, b.fix = "all", "all"
  local dt = m:timestep()
  b.vel = v(0.005 / (1000 * dt)) -- opened by 0.005: broken (at 0.002), the balls still overlap by 0.005
  m:cycle(1000)
  b.vel = v(0)
  m:cycle(1)
  local f = b.force
  check(dim .. "D broken face open, balls overlapping: kept", m:crack_count() > 0 and m:bond_count() == 1,
        m:crack_count() .. " cracks, " .. m:bond_count() .. " joints")
  check(dim .. "D ... and no force (no contact law on the overlap)", math.abs(f[1]) < 1e-9, f[1])
  b.vel = v(0.006 / (1000 * dt)) -- apart by 0.001
  m:cycle(1000)
  b.vel = v(0)
  m:cycle(1)
  check(dim .. "D gone once the balls part", m:bond_count() == 0 and math.abs(b.force[1]) < 1e-9,
        m:bond_count() .. " " .. b.force[1])
  m:close()
end

-- a removed ball takes its joints with it (the broad phase must not list them again)
for _, dim in ipairs{2, 3} do
  local m, a, b = pair(dim)
  local c = m:ball{pos = dim == 3 and {4, 0, 0} or {4, 0}, radius = 1}
  m:bond{kind = "flatjoint", gap = 1e-6, seed = 6, materials = "r"}
  check(dim .. "D two joints", m:bond_count() == 2, m:bond_count())
  m:remove_balls{where = function(x) return x.id == b.id end}
  check(dim .. "D its joints go with a removed ball", m:bond_count() == 0, m:bond_count())
  local p = c.pos:copy(); p[1] = p[1] + 0.5; c.pos = p -- a build
  m:cycle(50)
  check(dim .. "D no joint left", m:flatjoint(a.id, c.id) == nil and m:bond_count() == 0, m:bond_count())
end

-- a gapped face (m:bond{gapped = true}, Potyondy's gapped grains): a pair
-- installed apart by g gets every element open by g; closed by more than
-- g it carries kn A (closure - g); apart by more than 2 g it is gone
do
  local m = seixo.model{dim = 2}
  m:material("r", {density = 1000, kn = 1e9, ks = 1e9, friction = 0.5,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                           cohesion = 2e6, friction = 0.6, elements = 4}})
  local g = 1e-3
  local a = m:ball{pos = {0, 0}, radius = 1}
  local b = m:ball{pos = {2 + g, 0}, radius = 1}
  check("gapped installed", m:bond{kind = "flatjoint", gap = 2 * g, gapped = true} == 1, "")
  local open = true
  for _, e in ipairs(m:flatjoint(a.id, b.id)) do
    open = open and e.state == "unbonded" and math.abs(e.gap - g) < 1e-12
  end
  check("gapped: every element open by the gap", open, "")
  a.fix = "all"
  b.fix = "all"
  b.pos = {2 - 0.5 * g, 0} -- closed by 1.5 g
  m:cycle(1)
  local c = m:contacts()()
  local kn = 1e9 / 2 -- modulus / (RA + RB), per unit area
  check("gapped: compression past the gap", c and math.abs(c.pb_fn - kn * 2 * 0.5 * g) < 1e-9 * kn * g,
        c and c.pb_fn)
  b.pos = {2 + 2.5 * g, 0}
  m:cycle(1)
  check("gapped: gone once apart by more than 2 g", m:bond_count() == 0, m:bond_count())
  local m2 = seixo.model{dim = 2}
  m2:material("r", {density = 1000, kn = 1e9, ks = 1e9, friction = 0.5,
                    bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2.5, tensile_strength = 1e6,
                            cohesion = 2e6, friction = 0.6, elements = 4}})
  m2:ball{pos = {0, 0}, radius = 1}.fix = "all"
  local b2 = m2:ball{pos = {2 + g, 0}, radius = 1}
  b2.fix = "all"
  m2:bond{kind = "flatjoint", gap = 2 * g, gapped = true}
  b2.pos = {2 + 1.5 * g, 0}
  m2:cycle(1)
  check("gapped: apart by less than 2 g, kept", m2:bond_count() == 1, m2:bond_count())
  local ok, err = pcall(m2.bond, m2, {kind = "flatjoint", gap = 1, gapped = 1})
  check("gapped: a boolean", not ok and tostring(err):find("gapped"), err)
end

-- the material's flat-joint parameters survive a save and a load (issue 15 asked)
do
  local m = pair(3)
  local path = os.tmpname()
  m:save(path)
  local r = seixo.load(path)
  os.remove(path)
  local want, got = m:materials().r.bond, r:materials().r.bond
  for _, k in ipairs{"friction_angle", "friction", "elements", "sectors", "unbonded_fraction", "initial_gap",
                     "tensile_strength", "cohesion"} do
    check("saved bond " .. k, got and got[k] == want[k], got and tostring(got[k]) .. " vs " .. tostring(want[k]))
  end
  check("saved hash", r:hash() == m:hash(), "")
end

-- A 0 given in the call is taken, not the material's value: the sd's 0 for
-- equal strengths, an unbonded fraction 0 over a material's 0.5 (a new
-- user's finding: m:bond took a given 0 for "not given", and the strengths
-- still spread, 10 % of the elements still slit).
for _, dim in ipairs{2, 3} do
  local m, a, b = pair(dim, {kind = "flatjoint", gap = 1e-6, seed = 5, tensile_strength_sd = 0, cohesion_sd = 0,
                             unbonded_fraction = 0}, {unbonded_fraction = 0.5})
  local els = m:flatjoint(a.id, b.id)
  local equal, bonded = true, true
  for _, e in ipairs(els) do
    equal = equal and e.tensile_strength == 1e6 and e.cohesion == 2e6
    bonded = bonded and e.state == "bonded"
  end
  check(dim .. "D a given sd of 0: every element at the mean", equal, els[1].tensile_strength)
  check(dim .. "D a given unbonded fraction of 0: every element bonded", bonded, "")
  -- not given: the material's spread and fraction
  local m2, a2, b2 = pair(dim, {kind = "flatjoint", gap = 1e-6, seed = 5}, {unbonded_fraction = 0.5})
  local slit = 0
  for _, e in ipairs(m2:flatjoint(a2.id, b2.id)) do if e.state ~= "bonded" then slit = slit + 1 end end
  check(dim .. "D the material's fraction when the call gives none", slit > 0, slit)
  -- a count given as 0 is the material's (elements 6, sectors 3), as a material's 0 is the default
  local m3, a3, b3 = pair(dim, {kind = "flatjoint", gap = 1e-6, elements = 0, sectors = 0}, {elements = 6})
  check(dim .. "D elements = 0 given: the material's", #m3:flatjoint(a3.id, b3.id) == (dim == 3 and 18 or 6),
        #m3:flatjoint(a3.id, b3.id))
  -- a NaN given is refused (NaN is the core's "not given")
  local ok, err = pcall(pair, dim, {kind = "flatjoint", gap = 1e-6, tensile_strength_sd = 0 / 0})
  check(dim .. "D a NaN given is refused", not ok and tostring(err):find("tensile_strength_sd': a number expected, got nan", 1, true), err)
end

-- a face of unbonded elements only (a frictional joint) on balls that just
-- touch stays a face: pressed by u it carries kn_bar A u, not the material's
-- linear law (it was dropped at its first step, at zero overlap)
for _, dim in ipairs{2, 3} do
  local m, a, b = pair(dim, {kind = "flatjoint", seed = 5}, {unbonded_fraction = 1})
  a.fix, b.fix = "all", "all"
  m:cycle(1)
  check(dim .. "D unbonded face kept", m:bond_count() == 1 and m:flatjoint(a.id, b.id) ~= nil, m:bond_count())
  local u, dt = 1e-7, m:timestep()
  b.vel = dim == 3 and {-u / (100 * dt), 0, 0} or {-u / (100 * dt), 0}
  m:cycle(100)
  b.vel = dim == 3 and {0, 0, 0} or {0, 0}
  m:cycle(1)
  local c = m:contacts()()
  local area = dim == 3 and math.pi or 2 -- radius_multiplier 1, unit radii
  local expect = 1e9 / 2 * area * u
  check(dim .. "D unbonded face carries its stiffness", c.bond == "flatjoint" and math.abs(c.pb_fn - expect) < 1e-6 * expect,
        tostring(c.pb_fn) .. " vs " .. expect)
end

print(string.format("flatjoint: %d passed, %d failed", passed, failed))
if failed > 0 then os.exit(1) end
