-- The contact-model table's rows for ball-wall contacts (issue 12 item 7:
-- a specimen and its platens -- walls in seixo.lab -- under different
-- laws): a row matches a wall with a ball group, a ball material or any
-- ball; a contact takes its row when created and keeps it.
local C = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "cmodel_common.lua")
local T, G, NU, KN, R, hertz, vec = C.T, C.G, C.NU, C.KN, C.R, C.hertz, C.vec

-- The contact of ball id a with a wall, or nil.
local function wall_contact(m, a)
  for c in m:contacts{kind = "ball-wall"} do if c.a.id == a then return c end end
end

-- Balls resting on the floor y = 0 (normal +y), each overlapping it by un,
-- no gravity: a rock ball (sand), a steel ball, an ungrouped sand ball; and
-- one on a second wall x = 1 (normal -x).
local function scene(dim, un)
  local m = C.model(dim)
  local floor = m:wall{kind = dim == 3 and "plane" or "line", point = vec(dim, 0, 0), normal = vec(dim, 0, 1), kn = KN, ks = KN}
  local side = m:wall{kind = dim == 3 and "plane" or "line", point = vec(dim, 1, 0), normal = vec(dim, -1, 0), kn = KN, ks = KN}
  local ids = {}
  local function ball(x, y, group, mat)
    ids[#ids + 1] = m:ball{pos = vec(dim, x, y), radius = R, group = group, material = mat}.id
  end
  ball(0, R - un, "rock", "sand")
  ball(0.1, R - un, nil, "steel")
  ball(0.2, R - un, nil, "sand")
  ball(1 - R + un, 0.5, nil, "sand")
  return m, ids, floor, side
end

for _, dim in ipairs{3, 2} do
  T.test(string.format("%dD: a ball pressed on a wall feels its row's law (Hertz, linear) or the wall's", dim), function()
    local un = 1e-5
    local m, ids, floor, side = scene(dim, un)
    T.eq(m:contact_model{wall = floor, groups = "rock", model = "hertz", shear_modulus = G, poisson = NU}, 1)
    T.eq(m:contact_model{wall = floor, materials = "steel", kn = 4 * KN, ks = 4 * KN}, 2)
    T.eq(m:contact_model{wall = side, kn = 8 * KN, ks = 8 * KN}, 3)
    -- a ball-ball default row governs no wall contact
    T.eq(m:contact_model{default = true, kn = 16 * KN, ks = 16 * KN}, 4)
    m:cycle(1)
    -- Hertz; a ball and a wall of the row's material (springs in series: 2 KN);
    -- no row (the ball's and the wall's springs in series: KN / 2); any ball: 4 KN
    local slope = {nil, 2 * KN, KN / 2, 4 * KN}
    local rows = {1, 2, nil, 3}
    for k, id in ipairs(ids) do
      C.check_force(wall_contact(m, id), "ball " .. k, rows[k], un, k == 1 and hertz or function(o) return slope[k] * o end)
    end
    T.check(math.abs(hertz(un) - KN / 2 * un) > 0.1 * hertz(un), "the laws differ at this overlap")
  end)
end

T.test("a wall contact keeps the row it was created under; a new one takes the newest", function()
  local un = 1e-5
  local m, ids, floor = scene(3, un)
  m:contact_model{wall = floor, groups = "rock", model = "hertz", shear_modulus = G, poisson = NU}
  m:cycle(1)
  T.eq(m:contact_model{wall = floor, groups = "rock", kn = 6 * KN, ks = 6 * KN}, 2)
  m:cycle(1)
  local c = wall_contact(m, ids[1])
  T.eq(c.contact_model, 1)
  T.check(math.abs(c.fn - hertz(c.overlap)) <= 1e-12 * c.fn, "still Hertz: " .. c.fn)
  local b = m:ball(ids[1])
  b.pos = {0, 2 * R, 0}
  m:cycle(1)
  T.check(not wall_contact(m, ids[1]), "parted")
  b.pos = {0, R - un, 0}
  b.vel = {0, 0, 0}
  m:cycle(1)
  c = wall_contact(m, ids[1])
  T.eq(c.contact_model, 2)
  T.check(math.abs(c.fn - 3 * KN * c.overlap) <= 1e-12 * c.fn, "the new row's linear law: " .. c.fn)
  local rows = m:contact_models()
  T.eq(rows[1].wall, floor)
  T.eq(rows[1].groups, "rock")
  T.eq(rows[1].model, "hertz")
end)

T.test("bad wall rows are refused with the reason", function()
  local m, _, floor = scene(3, 1e-5)
  T.raises(function() m:contact_model{wall = floor, default = true} end, "leave out default")
  T.raises(function() m:contact_model{wall = floor, groups = {"a", "b"}} end, "one name")
  T.raises(function() m:contact_model{wall = floor, groups = "a", materials = "sand"} end, "one of groups")
  T.raises(function() m:contact_model{wall = floor, materials = "glass"} end, "no material named 'glass'")
  T.raises(function() m:contact_model{wall = 99} end, "no wall with id 99")
  T.raises(function() m:contact_model{wall = "floor"} end, "wall")
  T.raises(function() m:contact_model{wall = floor, modulus = 1e9} end, "BPM modulus")
  T.eq(#m:contact_models(), 0)
end)

T.test("wall rows are in the state hash; a model without them hashes as before", function()
  local a, b = scene(3, 1e-5), scene(3, 1e-5)
  T.eq(a:hash(), b:hash())
  local wa = a:walls()()
  a:contact_model{wall = wa, kn = KN, ks = KN}
  T.check(a:hash() ~= b:hash(), "a wall row changes the hash")
  local wb = b:walls()()
  b:contact_model{wall = wb, kn = KN, ks = 2 * KN}
  T.check(a:hash() ~= b:hash(), "a parameter changes it")
end)

-- A bed under gravity on a floor and between side walls: a Hertz row for
-- the floor's rock balls, a linear row for any ball on one side wall
-- (gravity tilted towards it).
T.test("1 and 2 threads give the same bits; a restart continues bit for bit", function()
  C.threads_and_restart({-4, 0, -9.81}, function(m)
    for bl in m:balls() do bl.group = (bl.id % 2 == 0) and "rock" or "platen" end
    local floor = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1e6, ks = 1e6}
    local side = m:wall{kind = "plane", point = {0, 0, 0}, normal = {1, 0, 0}, kn = 1e6, ks = 1e6}
    m:contact_model{wall = floor, groups = "rock", model = "hertz", shear_modulus = 2e7, poisson = 0.2}
    m:contact_model{wall = side, kn = 2e5, ks = 1e5, friction = 0.2, rolling_friction = 0.1}
  end, "ball-wall", "cmodel_walls_restart.h5")
end)

T.done()
