-- The contact-model table (issue 12 item 7, PFC's contact model
-- assignment table): rows that give the ball-ball contacts of a pair of
-- groups, of a pair of materials, or any other, their own law; each
-- contact keeps the row it took when it was created.
local C = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "cmodel_common.lua")
local T, G, NU, KN, R, hertz, vec = C.T, C.G, C.NU, C.KN, C.R, C.hertz, C.vec

-- The contact of balls a and b (ids), or nil.
local function contact(m, a, b)
  for c in m:contacts() do
    if c.kind == "ball-ball" and ((c.a.id == a and c.b.id == b) or (c.a.id == b and c.b.id == a)) then return c end
  end
end

-- Four pairs far apart, each overlapping by un and at rest, no gravity:
-- rock-rock (the materials' linear law: two springs KN in series),
-- rock-platen (a Hertz row), steel-steel (a linear material row, kn = 4 KN)
-- and a pair of ungrouped sand balls (no row).
local function scene(dim, un)
  local m = C.model(dim)
  local ids = {}
  local function pair(x, ga, gb, mat)
    local a = m:ball{pos = vec(dim, x), radius = R, group = ga, material = mat}
    local b = m:ball{pos = vec(dim, x + 2 * R - un), radius = R, group = gb, material = mat}
    ids[#ids + 1] = {a.id, b.id}
  end
  pair(0, "rock", "rock", "sand")
  pair(0.1, "rock", "platen", "sand")
  pair(0.2, nil, nil, "steel")
  pair(0.3, nil, nil, "sand")
  return m, ids
end

for _, dim in ipairs{3, 2} do
  T.test(string.format("%dD: each pair feels exactly the force of its row's law", dim), function()
    local un = 1e-5
    local m, ids = scene(dim, un)
    T.eq(m:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}, 1)
    T.eq(m:contact_model{materials = {"steel", "steel"}, kn = 4 * KN, ks = 4 * KN}, 2)
    m:cycle(1)
    local want = {KN / 2 * un, hertz(un), 2 * KN * un, KN / 2 * un}
    local rows = {nil, 1, 2, nil}
    for k, p in ipairs(ids) do
      C.check_force(contact(m, p[1], p[2]), "pair " .. k, rows[k], un,
                    k == 2 and hertz or function(o) return want[k] / un * o end)
    end
    -- the Hertz force is not the linear one: the table did change the law
    T.check(math.abs(hertz(un) - KN / 2 * un) > 0.1 * hertz(un), "the two laws differ at this overlap")
  end)
end

T.test("a default row governs the contacts no other row matches", function()
  local un = 1e-5
  local m, ids = scene(3, un)
  m:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}
  m:contact_model{default = true, kn = 8 * KN, ks = 8 * KN}
  m:cycle(1)
  local rows = {2, 1, 2, 2}
  for k, p in ipairs(ids) do
    local c = contact(m, p[1], p[2])
    T.eq(c.contact_model, rows[k], "pair " .. k)
    if k ~= 2 then T.check(math.abs(c.fn - 4 * KN * c.overlap) <= 1e-12 * c.fn, "pair " .. k .. " fn " .. c.fn) end
  end
end)

T.test("a contact keeps the row it was created under; a new contact takes the newest", function()
  local un = 1e-5
  local m, ids = scene(3, un)
  m:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}
  m:cycle(20)
  local p = ids[2]
  -- a newer row for the same groups: the contact that exists keeps Hertz
  T.eq(m:contact_model{groups = {"platen", "rock"}, kn = 6 * KN, ks = 6 * KN}, 2)
  m:cycle(20)
  local c = contact(m, p[1], p[2])
  T.eq(c.contact_model, 1)
  T.check(math.abs(c.fn - hertz(c.overlap)) <= 1e-12 * c.fn, "still Hertz: " .. c.fn)
  -- parted and brought back: a new contact, under the newest row
  local b = m:ball(p[2])
  local x = b.pos
  b.pos = vec(3, x[1] + 0.01)
  m:cycle(1)
  T.check(not contact(m, p[1], p[2]), "parted")
  b.pos = x
  b.vel = vec(3, 0)
  m:cycle(1)
  c = contact(m, p[1], p[2])
  T.eq(c.contact_model, 2)
  T.check(math.abs(c.fn - 3 * KN * c.overlap) <= 1e-12 * c.fn, "the new row's linear law: " .. c.fn)
  T.eq(#m:contact_models(), 2)
  T.eq(m:contact_models()[1].model, "hertz")
  T.eq(m:contact_models()[2].groups[1], "platen")
end)

T.test("bad rows are refused with the reason", function()
  local m = scene(3, 1e-5)
  T.raises(function() m:contact_model{model = "hertz"} end, "exactly one of groups")
  T.raises(function() m:contact_model{groups = {"a", "b"}, default = true} end, "exactly one of groups")
  T.raises(function() m:contact_model{materials = {"sand", "glass"}} end, "no material named 'glass'")
  T.raises(function() m:contact_model{groups = {"a", "b"}, model = "hooke"} end, "'linear', 'hertz'")
  T.raises(function() m:contact_model{groups = {"a", "b"}, model = "hertz", poisson = 0.6} end, "Poisson")
  T.raises(function() m:contact_model{groups = {"a", "b", "c"}} end, "two names")
  T.raises(function() m:contact_model{groups = {"a", "b"}, colour = 1} end, "colour")
  T.eq(#m:contact_models(), 0)
  -- seed 4.3.3: bonds join only laws that take them
  local b = seixo.model{dim = 3}
  b:material("s", {kn = KN, ks = KN})
  b:ball{pos = {0, 0, 0}, radius = R, group = "rock"}
  b:ball{pos = {2 * R - 1e-6, 0, 0}, radius = R, group = "rock"}
  b:contact_model{groups = {"rock", "rock"}, model = "hertz", shear_modulus = G, poisson = NU}
  b:bond{kind = "contact", gap = 1e-4, normal_strength = 1, shear_strength = 1}
  T.raises(function() b:cycle(1) end, "bonded", "seed 4.3.3")
end)

T.test("a bonded specimen keeps its law and bonds; its platen balls press it under a Hertz row", function()
  local m = seixo.model{dim = 2, timestep = 1e-7}
  m:material("rock", {kn = KN, ks = KN, friction = 0.5, density = 2650, damping = 0.7,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2, tensile_strength = 1e9,
                              cohesion = 1e9}})
  for j = 0, 3 do
    for i = 0, 5 do m:ball{pos = {(2 * i + (j % 2) + 1) * R, (1 + j * math.sqrt(3)) * R}, radius = R, group = "rock"} end
  end
  T.check(m:bond{gap = 1e-9} > 0, "bonds installed")
  local top = (1 + 3 * math.sqrt(3)) * R
  local platen = {}
  for i = 0, 5 do
    local b = m:ball{pos = {(2 * i + 2) * R, top + 2 * R + 1e-6}, radius = R, group = "platen"}
    b.fix = "vel"
    b.vel = {0, -0.1}
    platen[#platen + 1] = b
  end
  m:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}
  local bonds = m:bond_count()
  m:cycle(400)
  local pressed, bonded = 0, 0
  for c in m:contacts() do
    local ga, gb = c.a.group, c.b.group
    if ga ~= gb then
      pressed = pressed + 1
      T.eq(c.contact_model, 1)
      T.check(math.abs(c.fn - hertz(c.overlap)) <= 1e-9 * c.fn, string.format("Hertz: %.17g vs %.17g", c.fn, hertz(c.overlap)))
    elseif c.bond then
      bonded = bonded + 1
      T.eq(c.contact_model, nil, "a bonded contact keeps its materials' law")
    end
  end
  T.check(pressed > 0 and bonded > 0, string.format("%d platen contacts, %d bonded", pressed, bonded))
  print(string.format("bonded specimen: %d platen contacts under the Hertz row, %d bonded contacts under the materials' law", pressed, bonded))
  T.eq(m:bond_count(), bonds)
end)

T.test("the table is part of the state hash, and nothing else changes without it", function()
  local a, b = scene(3, 1e-5), scene(3, 1e-5)
  T.eq(a:hash(), b:hash())
  a:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}
  T.check(a:hash() ~= b:hash(), "a row changes the hash")
  b:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU, rolling_friction = 0.1}
  T.check(a:hash() ~= b:hash(), "a row's parameter (rolling_friction) changes the hash")
  local c = scene(3, 1e-5)
  c:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = G, poisson = NU}
  T.eq(c:hash(), a:hash(), "equal tables")
end)

-- A bed under gravity in two groups, a Hertz row between them: enough
-- pairs (> 4096) for the ball-ball pass to run in several chunks.
T.test("1 and 2 threads give the same bits; a restart continues bit for bit", function()
  local one = C.threads_and_restart({0, 0, -9.81}, function(m)
    for bl in m:balls() do bl.group = bl.pos[3] < 0.0225 and "rock" or "platen" end
    m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1e6, ks = 1e6}
    m:contact_model{groups = {"rock", "platen"}, model = "hertz", shear_modulus = 2e7, poisson = 0.2}
    m:contact_model{groups = {"platen", "platen"}, kn = 2e5, ks = 1e5, friction = 0.2, rolling_friction = 0.1}
  end, "ball-ball", "cmodel_restart.h5", function(l, one)
    -- a row added after the load governs new contacts only, in both alike
    l:contact_model{default = true, kn = 3e5, ks = 3e5}
    one:contact_model{default = true, kn = 3e5, ks = 3e5}
  end)
  T.check(one:contact_count() > 1000, "contacts " .. one:contact_count())
end)

T.done()
