-- Clumps from Lua: templates (tables and files), clump objects and their
-- fields, pebble guards, generation in a region, save/load, removal, 2D.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "clumps.lua:"

local function model(dim)
  local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}}
  m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
  return m
end

-- the largest overlap between pebbles of different clumps (and free balls), over the smaller radius
local function worst_overlap(m)
  local list = {}
  for b in m:balls() do
    local c = b.clump
    list[#list + 1] = {pos = b.pos, r = b.radius, clump = c and c.id or -b.id}
  end
  local worst = 0
  for i = 1, #list do
    for j = i + 1, #list do
      local a, b = list[i], list[j]
      if a.clump ~= b.clump then
        local d2 = 0
        for k = 1, #a.pos do d2 = d2 + (a.pos[k] - b.pos[k]) ^ 2 end
        worst = math.max(worst, (a.r + b.r - math.sqrt(d2)) / math.min(a.r, b.r))
      end
    end
  end
  return worst
end

test("a template from a table, and its properties", function()
  local m = model(3)
  local r, a = 0.01, 0.015
  local t = m:clump_template("dumbbell", {{-a, 0, 0, r}, {pos = {a, 0, 0}, radius = r}})
  eq(t.name, "dumbbell")
  eq(#t.pebbles, 2)
  eq(t.overlapping, false)
  eq(t.error, 0)
  local v = 4 / 3 * math.pi * r ^ 3
  near(t.volume, 2 * v, 1e-14)
  near(t.principal[1], 2 * 0.4 * v * r ^ 2, 1e-12)
  near(t.principal[3], 2 * (0.4 * v * r ^ 2 + v * a ^ 2), 1e-12)
  near(t.inertia[2][2], t.principal[3], 1e-12)
  eq(m:clump_template("dumbbell").volume, t.volume)
  eq(m:clump_template("nothing"), nil)
  check(m:clump_templates().dumbbell)
  raises(function() m:clump_template("dumbbell", {{0, 0, 0, r}}) end, HERE, "exists")
  raises(function() m:clump_template("x", {{0, 0, 0, -1}}) end, HERE, "pebble 1")
  raises(function() m:clump_template("x", {{0, 0, 0}}) end, HERE, "pebble 1")
  raises(function() m:clump_template("x", {}) end, HERE, "1 to 1000000 pebbles")
  raises(function() m:clump_template("x", {{0, 0, 0, 1}}, {lines = 3}) end, HERE, "lines")
  -- issue 18: 1e6 x 1e6 lines would integrate for days, uninterruptibly
  raises(function() m:clump_template("x", {{0, 0, 0, 1}, {0.5, 0, 0, 1}}, {lines = 1000000}) end, HERE, "in 16..2048")
  raises(function() m:clump_template("x", 42) end, HERE, "table of pebbles or file name")
end)

test("a template from a file of spheres", function()
  local m = model(3)
  local path = os.tmpname()
  local f = assert(io.open(path, "w"))
  f:write("# x y z r\n0 0 0 0.01\n\n0.012, 0, 0, 0.008   # overlapping the first\n")
  f:close()
  local t = m:clump_template("pair", path)
  eq(#t.pebbles, 2)
  eq(t.overlapping, true)
  check(t.error > 0 and t.error < 1e-4, t.error)
  check(t.volume < 4 / 3 * math.pi * (0.01 ^ 3 + 0.008 ^ 3))
  f = assert(io.open(path, "w"))
  f:write("0 0 0 0.01\n1 2\n")
  f:close()
  raises(function() m:clump_template("bad", path) end, ":2:", "4 numbers")
  -- a line longer than the reader's buffer was read as two lines' numbers
  f = assert(io.open(path, "w"))
  f:write("0 0 0 0.01\n0.012 0 0" .. string.rep(" ", 5000) .. "0.008\n")
  f:close()
  raises(function() m:clump_template("long", path) end, ":2:", "a line longer than")
  os.remove(path)
  raises(function() m:clump_template("none", path) end, "cannot open")
end)

test("clump objects: fields, orientation, pebbles", function()
  local m = model(3)
  m:clump_template("ell", {{0, 0, 0, 0.01}, {0.026, 0, 0, 0.01}, {0, 0.026, 0, 0.01}})
  local c = m:clump{template = "ell", pos = {0.1, 0.2, 0.3}, orientation = {axis = {0, 0, 1}, angle = math.pi / 2},
                    scale = 2, vel = {1, 0, 0}, spin = {0, 0, 3}, group = "g"}
  check(tostring(c):find("^seixo.clump " .. c.id .. " {pos = {0.1, 0.2, 0.3}, mass = [%d.]+, vel = {1, 0, 0}, template = ell}$"),
        tostring(c))
  eq(c, m:clump(c.id))
  eq(m:clump_count(), 1)
  eq(m:ball_count(), 3)
  T.vec_eq(c.pos, {0.1, 0.2, 0.3})
  near(c.orientation[1], math.cos(math.pi / 4), 1e-14)
  near(c.orientation[4], math.sin(math.pi / 4), 1e-14)
  eq(c.scale, 2)
  eq(c.template, "ell")
  eq(c.material, "rock")
  near(c.mass, 2650 * 8 * 3 * 4 / 3 * math.pi * 0.01 ^ 3, 1e-12)
  near(c.volume, 8 * 3 * 4 / 3 * math.pi * 0.01 ^ 3, 1e-12)
  eq(#c.principal, 3)
  eq(#c.inertia, 3)
  near(c.angular_momentum[3], c.inertia[3][3] * 3, 1e-12)
  local peb = c.pebbles
  eq(#peb, 3)
  for _, b in ipairs(peb) do
    eq(b.clump, c)
    eq(b.group, "g")
    near(b.radius, 0.02, 1e-15)
    near(b.mass, c.mass, 1e-15)
  end
  -- the template's second pebble (along x) turned a quarter about z: along y from the centroid
  local t = m:clump_template("ell")
  local p2 = peb[2].pos
  near(p2[1] - 0.1, -2 * (0 - t.centroid[2]), 1e-12)
  near(p2[2] - 0.2, 2 * (0.026 - t.centroid[1]), 1e-12)
  -- a pebble's velocity is the body's v + w x r
  local r = {p2[1] - 0.1, p2[2] - 0.2, p2[3] - 0.3}
  near(peb[2].vel[1], 1 - 3 * r[2], 1e-12)
  near(peb[2].vel[2], 3 * r[1], 1e-12)
  T.vec_eq(peb[2].spin, {0, 0, 3})
  -- writes
  c.pos = {0, 0, 1}
  T.vec_eq(c.pos, {0, 0, 1})
  c.orientation = {1, 0, 0, 0}
  T.vec_eq(c.orientation, {1, 0, 0, 0})
  c.spin = {0, 0, 0}
  c.damping = 0.5
  eq(c.damping, 0.5)
  c.fix = "vel"
  T.vec_eq(c.fix, {"vx", "vy", "vz"})
  c.fix = nil
  raises(function() c.fix = "wx" end, HERE, "as a whole")
  raises(function() c.mass = 1 end, HERE, "mass")
  raises(function() c.nothing = 1 end, HERE, "nothing")
  -- the pebbles' guards
  raises(function() peb[1].pos = {0, 0, 0} end, HERE, "pebble of clump")
  raises(function() peb[1].radius = 0.1 end, HERE, "pebble of clump")
  raises(function() peb[1]:remove() end, HERE, "remove the clump")
  -- a cycle in free fall: the body falls, its pebbles with it
  m:set_timestep(1e-4)
  m:cycle(100)
  -- local damping 0.5 takes half the weight while falling (not in the first step, from rest)
  near(c.vel[3], -9.81 * 1e-4 * (1 + 99 * 0.5), 1e-9)
  near(peb[1].pos[3] - c.pos[3], 0 - 2 * t.centroid[3], 1e-9)
  c:remove()
  eq(m:clump_count(), 0)
  eq(m:ball_count(), 0)
  raises(function() return c.pos end, HERE, "removed")
  raises(function() m:clump{template = "nothing", pos = {0, 0, 0}} end, HERE, "no clump template named 'nothing'")
  raises(function() m:clump{template = "ell"} end, HERE, "pos")
  raises(function() m:clump{template = "ell", pos = {0, 0, 0}, orientation = {0, 0, 0, 0}} end, HERE, "zero")
  raises(function() m:clump{template = "ell", pos = {0, 0, 0}, scale = -1} end, HERE, "scale")
  local d = m:clump{template = "ell", pos = {0, 0, 0}}
  raises(function() d.orientation = {1, 2} end, HERE, "clump field 'orientation': quaternion", "got 2")
end)

test("a clump's pebbles keep one density: a material redefined apart from its clump's is refused", function()
  local m = model(3)
  local rho = m:materials().rock.density
  m:material("same", {density = rho, kn = 1e6, ks = 1e6, friction = 0.2})
  m:clump_template("pair", {{0, 0, 0, 0.01}, {0.012, 0, 0, 0.01}})
  local c = m:clump{template = "pair", pos = {0, 0, 0}, material = "rock"}
  local mass = c.mass
  local peb = c.pebbles
  peb[2].material = "same" -- another material of the clump's density: its friction
  raises(function() m:material("same", {density = 8000, kn = 1e6, ks = 1e6}) end, HERE,
         "material 'same': a density of 8000 kg/m^3 would part pebble " .. peb[2].id .. " of clump " .. c.id)
  eq(m:materials().same.density, rho)
  eq(c.mass, mass)
  m:material("same", {density = rho, kn = 2e6, ks = 2e6}) -- the same density: taken
  eq(m:materials().same.kn, 2e6)
end)

test("generation: count, sizes, inside the region, no overlaps, reproducible", function()
  local function make(seed)
    local m = model(3)
    m:clump_template("tri", {{0, 0, 0, 0.004}, {0.006, 0, 0, 0.004}, {0.003, 0.005, 0, 0.003}})
    m:ball{pos = {0.05, 0.05, 0.05}, radius = 0.01}
    local n, por = m:generate{template = "tri", scale = {0.8, 1.2}, count = 80, seed = seed,
                              region = {box = {{0, 0, 0}, {0.1, 0.1, 0.1}}}}
    return m, n, por
  end
  local m, n, por = make(5)
  eq(n, 80)
  eq(m:clump_count(), 80)
  eq(m:ball_count(), 80 * 3 + 1)
  local solid = 0
  for c in m:clumps() do
    check(c.scale >= 0.8 and c.scale <= 1.2, c.scale)
    solid = solid + c.volume
    for _, b in ipairs(c.pebbles) do
      for k = 1, 3 do check(b.pos[k] - b.radius >= -1e-12 and b.pos[k] + b.radius <= 0.1 + 1e-12, "outside") end
    end
  end
  near(por, 1 - solid / 1e-3, 1e-12)
  check(worst_overlap(m) <= 1e-12, "overlap " .. worst_overlap(m))
  local m2 = make(5)
  eq(m2:hash(), m:hash())
  check(make(6):hash() ~= m:hash())
  -- orientations are spread: the mean of the first quaternion component is well below 1
  local sum = 0
  for c in m:clumps() do sum = sum + math.abs(c.orientation[1]) end
  check(sum / 80 < 0.8, sum / 80)
  -- by porosity
  local m3 = model(3)
  m3:clump_template("tri", {{0, 0, 0, 0.004}, {0.006, 0, 0, 0.004}, {0.003, 0.005, 0, 0.003}})
  local n3, por3 = m3:generate{template = "tri", porosity = 0.9, region = {box = {{0, 0, 0}, {0.1, 0.1, 0.1}}}}
  check(n3 > 0 and por3 <= 0.9 and por3 > 0.88, por3)
  -- errors
  raises(function() m3:generate{template = "tri", radius = 1, count = 1, region = {box = {{0, 0, 0}, {1, 1, 1}}}} end,
         HERE, "scale")
  raises(function() m3:generate{template = "tri", method = "distribute", porosity = 0.5,
                                region = {box = {{0, 0, 0}, {1, 1, 1}}}} end, HERE, "'random'")
  raises(function() m3:generate{radius = 0.01, scale = 1, count = 1, region = {box = {{0, 0, 0}, {1, 1, 1}}}} end,
         HERE, "only with 'template'")
  raises(function() m3:generate{template = "tri", scale = 100, count = 1, region = {box = {{0, 0, 0}, {0.1, 0.1, 0.1}}}} end,
         HERE, "does not fit")
  raises(function() m3:generate{template = "tri", count = 100000, tries = 5, region = {box = {{0, 0, 0}, {0.02, 0.02, 0.02}}}} end,
         HERE, "no room")
end)

test("2D: templates, clumps, orientation as an angle, generation", function()
  local m = model(2)
  local t = m:clump_template("bar", {{-0.01, 0, 0.008}, {0.01, 0, 0.008}})
  eq(type(t.inertia), "number")
  -- a 3D pebble in a 2D model: the message names the model's dimension
  raises(function() m:clump_template("x", {{0, 0, 0, 1e-3}}) end, HERE, "{x, y, r}: 3 numbers expected in a 2D model, got 4")
  local c = m:clump{template = "bar", pos = {0.5, 0.5}, orientation = 0.3, spin = 2}
  near(c.orientation, 0.3, 1e-14)
  eq(c.spin, 2)
  eq(type(c.principal), "number")
  local n = m:generate{template = "bar", scale = {0.5, 1}, count = 30, region = {box = {{0, 0}, {0.3, 0.3}}}, seed = 2}
  eq(n, 30)
  check(worst_overlap(m) <= 1e-12)
  raises(function() m:clump{template = "bar", pos = {0, 0}, orientation = {1, 0, 0, 0}} end, HERE, "angle")
  m:set_timestep(1e-4)
  m:cycle(10)
  near(c.orientation, 0.3 + 2 * 10 * 1e-4, 1e-12)
end)

test("save and load continue bit-for-bit", function()
  local m = model(3)
  m:clump_template("tri", {{0, 0, 0, 0.004}, {0.006, 0, 0, 0.004}, {0.003, 0.005, 0, 0.003}})
  m:wall{kind = "box", min = {0, 0, 0}, max = {0.05, 0.05, 0.1}}
  m:generate{template = "tri", count = 40, region = {box = {{0, 0, 0}, {0.05, 0.05, 0.1}}}, seed = 1}
  m:cycle(40000) -- the pile has formed by then
  check(m:contact_count() > 0)
  local path = T.tmpname(".h5")
  m:save(path)
  local l = seixo.load(path)
  os.remove(path)
  eq(l:hash(), m:hash())
  eq(l:clump_count(), 40)
  m:cycle(1000)
  l:cycle(1000)
  eq(l:hash(), m:hash())
  local c = l:clump(1)
  eq(c.template, "tri")
  eq(#c.pebbles, 3)
end)

test("help knows clumps", function()
  local H = require("seixo.help")
  local m = model(3)
  m:clump_template("one", {{0, 0, 0, 0.01}})
  local c = m:clump{template = "one", pos = {0, 0, 0}}
  local text = H.text(c)
  check(text:find("clump fields (cl.name)", 1, true) and text:find("orientation", 1, true), text)
  check(H.text(m.clump):find("m:clump{template", 1, true))
end)

T.done()
