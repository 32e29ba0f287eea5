-- The smooth joint (issue 14, item 2; src/core/laws/smoothjoint.h): a pair
-- slides parallel to the joint whatever its centre line; a bonded block on a
-- joint starts to slide when tan(theta) exceeds mu, not before, and slides
-- at g (sin theta - mu cos theta); with dilation psi the joint opens by
-- tan(psi) per unit slip; a bonded joint replaces a parallel bond and breaks
-- at tension x area (crack kind smoothjoint); restarts and threads keep the
-- bits; bad input is named.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

local function v(dim, x, y) return dim == 3 and {x, y, 0} or {x, y} end

-- Ball b pressed on a fixed ball a by P across the plane y = y0 (normal +y),
-- the centre line tilted by `tilt` degrees from the normal, then pushed
-- along x by `push` P (more than mu P). Returns b's slide along x and its
-- move along y during the push, and the contact.
local function pair(dim, tilt, push, joint)
  local m = seixo.model{dim = dim}
  m:material("r", {density = 2600, damping = 0.7, kn = 1e8, ks = 1e8, friction = 0.5})
  local R, t = 0.01, math.rad(tilt)
  local a = m:ball{pos = v(dim, 0, 0), radius = R}
  local b = m:ball{pos = v(dim, 2 * R * math.sin(t), 2 * R * math.cos(t)), radius = R}
  a.fix = "all"
  b.fix = "spin"
  -- the joint's stiffness kn A = 1.6e6 N/m in 2D and 3D
  local area = dim == 3 and math.pi * R * R or 2 * R
  if joint then
    m:joint{point = v(dim, 0, R * math.cos(t)), normal = v(dim, 0, 1), kn = 1.6e6 / area, ks = 1.6e6 / area,
            friction = 0.4}
  end
  local P = 100
  b.applied_force = v(dim, 0, -P)
  m:cycle(3000)
  local x0, y0 = b.pos[1], b.pos[2]
  b.applied_force = v(dim, push * P, -P)
  m:cycle(200)
  local c
  for cc in m:contacts() do c = cc end
  return b.pos[1] - x0, b.pos[2] - y0, c, m
end

for _, dim in ipairs{2, 3} do
  for _, case in ipairs{{0, 1}, {30, -1}, {-45, 1}} do
    local tilt, push = case[1], case[2]
    T.test(dim .. "D pair, centre line at " .. tilt .. " deg: slides parallel to the joint", function()
      local dx, dy, c, m = pair(dim, tilt, push, true)
      T.check(math.abs(dx) > 2e-4, "slid " .. dx)
      T.check(dx * push > 0, "slid the way it was pushed")
      T.check(math.abs(dy) <= 1e-12, "moved across the joint by " .. dy)
      T.check(c and c.joint == 1, "a joint contact")
      T.near(c.fn, 100, 1e-9) -- the normal load, along the joint normal
      T.near(c.fs[1], -push * 0.4 * 100, 1e-9) -- Coulomb, in the plane, against the slide
      T.eq(c.fs[2], 0, "no shear across the plane")
      T.eq(c.normal[2], 1, "the joint's normal")
      m:close()
      if tilt ~= 0 then -- the contact law: the ball rides over or into its neighbour
        local _, dy2, _, m2 = pair(dim, tilt, push, false)
        T.check(math.abs(dy2) > 1e-6, "the contact law's ride " .. dy2)
        m2:close()
      end
    end)
  end
end

-- A bonded block of 2 x 4 balls on a row of 6 fixed balls, the joint y = 0
-- between them; the joint inclined by theta is gravity with a component
-- tan(theta) g along the joint and g across it (the normal load of the
-- settled block, so that tilting sets off no normal oscillation).
-- The joint is soft enough (kn A = 4e5 N/m) that each bottom ball keeps
-- its contact over the slides below (a contact lasts while the balls
-- overlap: sqrt(4 R delta) = 1.2 mm of slip here). The block's balls do
-- not turn (fixed spins take the moment of the friction about each
-- centre), so the four contacts share the load equally: the block is not
-- rocked onto one edge, whose contacts would slip first.
local g, mu, R, alpha = 10, 0.5, 0.01, 0.7
local function block(opts)
  seixo.threads = opts.threads
  local m = seixo.model{dim = 2, gravity = {0, -g}}
  seixo.threads = nil
  m:material("rock", {density = 2600, damping = 0, kn = 2e7, ks = 2e7, friction = 0.5,
                      bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 1, tensile_strength = 1e12,
                              cohesion = 1e12}})
  for k = 0, 5 do m:ball{pos = {(2 * k - 5) * R, -R}, radius = R}.fix = "all" end
  local top = {}
  for row = 0, 1 do
    for k = 0, 3 do top[#top + 1] = m:ball{pos = {(2 * k - 3) * R, R + 2 * row * R}, radius = R} end
  end
  m:bond{kind = "parallel", gap = 1e-6}
  local _, cut = m:joint{point = {0, 0}, normal = {0, 1}, kn = opts.kn or 2e7, ks = opts.kn or 2e7, friction = mu,
                         dilation = opts.dilation}
  -- settle under the normal load, damped
  for _, b in ipairs(top) do b.damping = alpha; b.fix = "spin" end
  m:cycle(4000)
  for _, b in ipairs(top) do b.vel = {0, 0} end
  if opts.tan > 0 then -- the joint tilted by theta: the load along it tan(theta) times the normal load
    for _, b in ipairs(top) do b.damping = 0 end
    m:set_gravity{g * opts.tan, -g}
  end
  return m, top, cut
end

local function centre(top)
  local x, y = 0, 0
  for _, b in ipairs(top) do x, y = x + b.pos[1] / #top, y + b.pos[2] / #top end
  return x, y
end

local function velocity(top)
  local u = 0
  for _, b in ipairs(top) do u = u + b.vel[1] / #top end
  return u
end

T.test("a block on a joint: slides at tan(theta) = 1.1 mu with g (tan(theta) - mu)", function()
  local m, top, cut = block{tan = 1.1 * mu}
  T.eq(cut, 4, "the joint cut the 4 bonds across it")
  m:cycle(1500) -- past the start's elastic transient
  local v1, t1 = velocity(top), m:time()
  m:cycle(1500)
  T.check(v1 > 0, "sliding")
  -- measured -1.3 %: the block rocks (friction at its base, weight at its
  -- centre), undamped, so the normal load beats about its mean
  T.near((velocity(top) - v1) / (m:time() - t1), g * (1.1 * mu - mu), 0.02)
  m:close()
end)

T.test("a block on a joint: held as the joint is tilted to tan(theta) = 0.99 mu", function()
  local m, top = block{tan = 0}
  local x0 = centre(top)
  local tn
  for k = 1, 20 do -- quasi-static, damped: a sudden tilt slips the block during its elastic transient
    tn = 0.99 * mu * k / 20
    m:set_gravity{g * tn, -g}
    m:cycle(300)
  end
  m:cycle(2000)
  local x1 = centre(top)
  m:cycle(1000)
  -- the shear springs' elastic give only: the block's weight along the joint over 4 ks A
  local mass = 8 * math.pi * R * R * 2600
  local give = mass * g * tn / (4 * 2e7 * 2 * R)
  T.near(x1 - x0, give, 0.02)
  T.check(math.abs(centre(top) - x1) < 0.01 * give, "still moving: " .. (centre(top) - x1))
  for c in m:contacts() do
    if c.joint then T.check(math.abs(c.fs[1]) < 0.995 * mu * c.fn, "a contact slips") end
  end
  m:close()
end)

T.test("a block on a dilating joint: opens by tan(psi) per unit slip", function()
  local psi = 10
  local m, top = block{tan = 1.1 * mu, dilation = psi}
  m:cycle(800)
  local x1, y1 = centre(top)
  m:cycle(1600) -- within the contacts' reach (their overlap shrinks as the joint opens)
  local x2, y2 = centre(top)
  T.check(x2 - x1 > 2e-5, "slid " .. (x2 - x1))
  T.near((y2 - y1) / (x2 - x1), math.tan(math.rad(psi)), 0.02)
  m:close()
end)

T.test("energy closes on a sliding block, with and without dilation", function()
  for _, psi in ipairs{0, 10} do
    local m = block{tan = 1.1 * mu, dilation = psi}
    m:track_energy(true)
    local function total()
      local e = m:energy()
      return e.kinetic + e.gravitational + e.strain + e.bond_strain + e.slip + e.local_damping + e.viscous
             + e.bond_released - e.boundary_work, e
    end
    local t0 = total()
    m:cycle(2400)
    local t1, e = total()
    -- measured 6.6e-4 (psi 0) and 5.4e-4 (psi 10) of the slip's dissipation
    T.check(e.slip > 1e-3, "slip " .. e.slip)
    T.check(math.abs(t1 - t0) < 0.01 * e.slip, psi .. " deg: the balance drifts by " .. (t1 - t0) / e.slip)
    m:close()
  end
end)

T.test("restart and threads: the same bits", function()
  local function run(threads)
    local m, top = block{tan = 1.1 * mu, dilation = 5, threads = threads}
    m:cycle(500)
    return m, top
  end
  local m1 = run(1)
  local m2 = run(2)
  T.eq(m1:hash(), m2:hash(), "1 and 2 threads")
  local path = os.tmpname()
  m1:save(path)
  local r = seixo.load(path)
  os.remove(path)
  T.eq(r:hash(), m1:hash(), "as saved")
  T.eq(#r:joints(), 1, "the joint restored")
  T.eq(r:joints()[1].dilation, 5, "its dilation")
  m1:cycle(700)
  r:cycle(700)
  T.eq(r:hash(), m1:hash(), "700 steps later")
  m1:close(); m2:close(); r:close()
end)

-- A bed of about 4,500 disks in a box settling across two joints (one bonded),
-- enough pairs for the contact pass to run in several chunks: 1 and 2
-- threads must give the same bits.
T.test("a bed across joints: 1 and 2 threads the same bits", function()
  local function bed(threads)
    seixo.threads = threads
    local m = seixo.model{dim = 2, gravity = {0, -9.81}}
    seixo.threads = nil
    m:material("r", {density = 2600, kn = 1e7, ks = 1e7, friction = 0.5, damping = 0.2,
                     bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2, tensile_strength = 1e5,
                             cohesion = 1e5}})
    m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
    m:wall{kind = "line", point = {0, 0}, normal = {1, 0}}
    m:wall{kind = "line", point = {0.5, 0}, normal = {-1, 0}}
    m:generate{porosity = 0.3, radius = {0.003, 0.004}, region = {box = {{0, 0}, {0.5, 0.5}}}, method = "distribute",
               seed = 4}
    m:cycle(300)
    m:bond{kind = "parallel", gap = 1e-4}
    m:joint{point = {0.25, 0.1}, dip = 20, kn = 5e8, ks = 5e8, friction = 0.3, dilation = 5}
    m:joint{point = {0.25, 0.2}, dip = -10, kn = 5e8, ks = 5e8, tension = 2e4, cohesion = 2e4, friction_angle = 20}
    m:cycle(400)
    return m
  end
  local m1, m2 = bed(1), bed(2)
  local n = 0
  for c in m1:contacts() do if c.joint then n = n + 1 end end
  T.check(n > 50, "joint contacts: " .. n)
  T.eq(m1:hash(), m2:hash(), "1 and 2 threads")
  m1:close(); m2:close()
end)

-- A parallel-bonded pair across a bonded joint: the joint takes the bond's
-- place, stress free, and breaks in tension at tension x A (A = 2 R in 2D,
-- pi R^2 in 3D), logged as a smooth-joint crack.
for _, dim in ipairs{2, 3} do
  T.test(dim .. "D bonded joint: breaks at tension x area", function()
    local m = seixo.model{dim = dim}
    m:material("r", {density = 2600, damping = 0.7, kn = 1e8, ks = 1e8, friction = 0.5,
                     bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 1, tensile_strength = 1e12,
                             cohesion = 1e12}})
    local a = m:ball{pos = v(dim, 0, 0), radius = R}
    local b = m:ball{pos = v(dim, 0.4 * R, 2 * R * math.cos(math.asin(0.2))), radius = R}
    T.eq(m:bond{kind = "parallel", gap = 1e-6}, 1, "bonded")
    a.fix = "all"
    b.fix = "spin"
    local tension = 1e5
    local _, bonds = m:joint{point = v(dim, 0, R), normal = v(dim, 0, 1), kn = 1e10, ks = 1e10, tension = tension,
                             cohesion = 1e9}
    T.eq(bonds, 1, "the bond replaced")
    local c
    for cc in m:contacts() do c = cc end
    T.eq(c.bond, "smoothjoint")
    local area = dim == 3 and math.pi * R * R or 2 * R
    local limit = tension * area
    for k = 1, 200 do
      b.applied_force = v(dim, 0, limit * k / 100)
      m:cycle(50)
      if m:crack_count() > 0 then break end
    end
    local cr = m:cracks()[1]
    T.check(cr, "broke")
    T.eq(cr.kind, "smoothjoint")
    T.eq(cr.mode, "tension")
    T.near(-cr.fn, limit, 0.02) -- the load ramps by 1 % of the limit per 50 steps
    T.eq(m:bond_count(), 0)
    m:close()
  end)
end

-- A joint of finite radius (a disk about its point; a fracture of a DFN):
-- only the pairs whose centre line meets the plane inside it take the law.
T.test("a joint of finite radius: the bonds its disk cuts, and no others", function()
  local m = seixo.model{dim = 3}
  m:material("r", {density = 2600, damping = 0.7, kn = 1e8, ks = 1e8, friction = 0.5,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 2, tensile_strength = 1e6,
                           cohesion = 1e6}})
  local R = 0.01
  for i = 0, 9 do
    for j = 0, 9 do
      for k = 0, 3 do m:ball{pos = {2 * R * i, 2 * R * j, 2 * R * k}, radius = R} end
    end
  end
  T.eq(m:bond{kind = "parallel", gap = 1e-6}, 2 * 9 * 10 * 4 + 10 * 10 * 3, "bonded lattice")
  -- the plane z = 3R between layers 1 and 2, a disk of radius 4R about (9R, 9R)
  local expected = 0
  for i = 0, 9 do
    for j = 0, 9 do
      if (2 * i - 9) ^ 2 + (2 * j - 9) ^ 2 <= 16 then expected = expected + 1 end
    end
  end
  local n, cut = m:joint{point = {9 * R, 9 * R, 3 * R}, normal = {0, 0, 1}, kn = 1e10, ks = 1e10, radius = 4 * R}
  T.eq(n, 1)
  T.eq(cut, expected, "bonds cut by the disk")
  T.check(expected > 0 and expected < 100, "the disk cuts some of the layer's 100 bonds")
  T.eq(m:bond_count(), 1020 - expected)
  T.eq(m:joints()[1].radius, 4 * R)
  -- a save keeps the extent (format 4) and the bits
  local path = os.tmpname()
  m:save(path)
  local r = seixo.load(path)
  os.remove(path)
  T.eq(r:joints()[1].radius, 4 * R)
  T.eq(r:hash(), m:hash(), "as saved")
  m:close(); r:close()
end)

T.test("a joint of finite radius: contacts that form later take it only inside", function()
  for _, dim in ipairs({2, 3}) do
    local m = seixo.model{dim = dim}
    m:material("r", {density = 2600, damping = 0.7, kn = 1e8, ks = 1e8, friction = 0.5})
    local R = 0.01
    -- two pairs pressed together across y = 0: one at x = 0 (inside the
    -- joint's radius 3R about the origin), one at x = 10R (outside)
    local pairs_ = {}
    for _, x in ipairs({0, 10 * R}) do
      local a = m:ball{pos = v(dim, x, -1.2 * R), radius = R}
      local b = m:ball{pos = v(dim, x, 1.2 * R), radius = R}
      a.fix = "all"
      b.fix = "spin"
      b.applied_force = v(dim, 0, -100)
      pairs_[#pairs_ + 1] = {a = a.id, b = b.id}
    end
    m:joint{point = v(dim, 0, 0), normal = v(dim, 0, 1), kn = 1e10, ks = 1e10, radius = 3 * R}
    m:cycle(2000)
    local joint_of = {}
    for c in m:contacts() do joint_of[c.a.id * 1000 + c.b.id] = c.joint or false end
    local inside, outside = pairs_[1], pairs_[2]
    T.eq(joint_of[inside.a * 1000 + inside.b], 1, dim .. "D: inside, the joint's law")
    T.eq(joint_of[outside.a * 1000 + outside.b], false, dim .. "D: outside, the contact law")
    m:close()
  end
end)

T.test("bad joints are named", function()
  local m = seixo.model{dim = 3}
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 0}, kn = 1, ks = 1} end, "normal")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = -1, ks = 1} end, "kn")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1, ks = 1, dilation = 90} end, "dilation")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1, ks = 1, tension = 1} end, "cohesion")
  T.raises(function() m:joint{point = {0, 0, 0}, kn = 1, ks = 1} end, "normal or dip")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, dip = 30, kn = 1, ks = 1} end, "normal or dip")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1, ks = 1, glue = 1} end, "glue")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1, ks = 1, radius = -1} end, "radius")
  T.raises(function() m:joint{point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1, ks = 1, radius = 0 / 0} end, "radius")
  m:joint{point = {0, 0, 0}, dip = 30, dip_direction = 90, kn = 1, ks = 1}
  local n = m:joints()[1].normal
  T.near(n[1], 0.5, 1e-12); T.near(n[3], math.cos(math.rad(30)), 1e-12)
  local m2 = seixo.model{dim = 2}
  T.raises(function() m2:joint{point = {0, 0}, dip = 10, dip_direction = 5, kn = 1, ks = 1} end, "dip only")
  m2:joint{point = {0, 0}, dip = 30, kn = 1, ks = 1}
  T.near(m2:joints()[1].normal[1], -0.5, 1e-12)
end)

T.done()
