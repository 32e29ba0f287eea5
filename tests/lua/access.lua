-- Access: contacts, groups, bulk operations in C, user extras, filtered
-- iteration and removals (queued while a callback runs).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "access.lua:"

---------------------------------------------------------------- contacts

-- two balls pressed together along x (no gravity), and one on a floor
local function pressed(dim)
  local m = T.model(dim, {timestep = 1e-5})
  local z = T.zero(dim)
  local a = m:ball{pos = z, radius = 0.01}
  local p = T.zero(dim)
  p[1] = 0.019
  local b = m:ball{pos = p, radius = 0.01}
  a.fix, b.fix = "all", "all"
  local floor = m:wall{kind = dim == 3 and "plane" or "line", point = dim == 3 and {0, 0, -0.5} or {0, -0.5},
                       normal = dim == 3 and {0, 0, 1} or {0, 1}}
  local c = T.zero(dim)
  c[dim] = -0.5 + 0.0098
  local on_floor = m:ball{pos = c, radius = 0.01}
  on_floor.fix = "all"
  m:cycle(1)
  return m, a, b, floor, on_floor
end

for _, dim in ipairs({2, 3}) do
  test(dim .. "D contact objects", function()
    local m, a, b, floor, on_floor = pressed(dim)
    local seen = 0
    for c in m:contacts() do
      seen = seen + 1
      check(tostring(c):find("seixo.contact ball", 1, true))
      eq(#c.normal, dim)
      if c.kind == "ball-ball" then
        check(c.a == a and c.b == b, "the pair")
        near(c.overlap, 0.001, 1e-9)
        T.vec_eq(c.normal, dim == 3 and {1, 0, 0} or {1, 0})
        near(c.point[1], 0.0095, 1e-9)
        -- linear springs in series: kn = 1e6 / 2
        near(c.kn, 5e5, 1e-12)
        near(c.fn, 5e5 * 0.001, 1e-9)
        -- the force on b pushes it away from a
        near(c.force[1], c.fn, 1e-12)
        near(b.force[1], c.fn, 1e-9)
        near(a.force[1], -c.fn, 1e-9)
        eq(c.bond, nil)
        eq(c.pb_fn, 0)
      else
        eq(c.kind, "ball-wall")
        check(c.a == on_floor and c.b == floor, "ball, then wall")
        near(c.overlap, 0.0002, 1e-6)
        -- the normal points from the ball to the wall, and so does the force on the wall
        near(c.normal[dim], -1, 1e-12)
        check(c.force[dim] < 0, "the floor is pushed down")
        near(c.force[dim], floor.force[dim], 1e-9)
        near(on_floor.force[dim], -c.force[dim], 1e-9)
      end
    end
    eq(seen, 2)
    eq(m:contact_count(), 2)
  end)
end

test("contact filters and snapshots", function()
  local m, a, b, floor, on_floor = pressed(3)
  local function count(filter)
    local n = 0
    for _ in m:contacts(filter) do n = n + 1 end
    return n
  end
  eq(count{ball = a}, 1)
  eq(count{ball = b.id}, 1)
  eq(count{ball = on_floor}, 1)
  eq(count{wall = floor}, 1)
  eq(count{kind = "ball-ball"}, 1)
  eq(count{kind = "ball-wall"}, 1)
  eq(count{ball = a, kind = "ball-wall"}, 0)
  raises(function() m:contacts{kind = "wall"} end, HERE, "field 'kind'")
  raises(function() m:contacts{ball = "a"} end, HERE, "field 'ball'")
  raises(function() m:contacts{balls = 1} end, HERE, "unknown key 'balls'")
  raises(function() m:contacts{ball = -3} end, HERE, "field 'ball'", "ids are >= 1")
  -- a ball or wall of another model is not taken for its id (the same ids
  -- exist in both models here, so read as ids these would select contacts)
  local other, oa, _, ofloor = pressed(3)
  eq(oa.id, a.id)
  raises(function() m:contacts{ball = oa} end, HERE, "field 'ball'", "ball " .. oa.id .. " belongs to another model")
  raises(function() m:contacts{wall = ofloor} end, HERE, "field 'wall'", "belongs to another model")
  raises(function() m:history("x", {ball = oa, field = "pos", component = 1}) end, HERE, "field 'ball'",
         "belongs to another model")
  raises(function() m:history("f", {wall = ofloor, field = "force", component = 3}) end, HERE, "field 'wall'",
         "belongs to another model")
  other:close()
  -- a contact object outlives the step; its model closing is an error, not a crash
  local it = m:contacts()
  local c = it()
  m:cycle(1)
  check(c.fn > 0)
  m:close()
  raises(function() return c.normal end, HERE, "closed")
  raises(function() it() end, "closed")
  raises(function() return c.nope end, HERE, "contact has no field 'nope'")
end)

---------------------------------------------------------------- groups

local function grid_model(dim, n)
  local m = T.model(dim)
  for i = 1, n do
    local p = T.zero(dim)
    p[1] = i
    p[2] = i % 2
    m:ball{pos = p, radius = 0.1}
  end
  return m
end

test("groups by name, region and predicate", function()
  local m = grid_model(3, 10)
  local b = m:ball(1)
  eq(b.group, nil)
  b.group = "first"
  eq(b.group, "first")
  eq(m:ball(b.id).group, "first")
  b.group = nil
  eq(b.group, nil)
  raises(function() b.group = 3 end, HERE, "field 'group'", "got number")
  raises(function() b.group = "" end, HERE, "empty")
  eq(m:group("low", {region = {box = {{0, -1, -1}, {5.5, 1, 1}}}}), 5)
  eq(m:group("odd", function(ball) return ball.id % 2 == 1 end), 5)
  eq(m:ball(3).group, "odd")  -- one group per ball: the last assignment wins
  eq(m:ball(4).group, "low")
  local groups = m:groups()
  eq(groups.low, 2)
  eq(groups.odd, 5)
  eq(groups.first, 0)
  eq(m:group("top", {group = "odd", region = {box = {{5.5, -1, -1}, {20, 2, 2}}}}), 2)
  eq(m:count{group = "top"}, 2)
  eq(m:count{group = "odd"}, 3)
  eq(m:count(), 10)
  raises(function() m:count{group = "tpo"} end, HERE, "field 'group'", "no group named 'tpo'", "groups: first, low, odd, top")
  raises(function() m:group("x", {regoin = {}}) end, HERE, "unknown key 'regoin'", "group, slot, region, where")
  raises(function() m:group("x") end, HERE, "filter table or predicate function")
  raises(function() m:group("", {}) end, HERE, "empty")
  -- a ball added with a group
  local c = m:ball{pos = {0, 5, 0}, radius = 0.1, group = "top"}
  eq(c.group, "top")
end)

test("balls(filter) iterates over the selection", function()
  local m = grid_model(2, 8)
  m:group("even", function(b) return b.id % 2 == 0 end)
  local ids = {}
  for b in m:balls{group = "even"} do ids[#ids + 1] = b.id end
  T.vec_eq(ids, {2, 4, 6, 8})
  local n = 0
  for _ in m:balls{region = {disk = {center = {0, 0}, radius = 3.5}}} do n = n + 1 end
  eq(n, 3)
  n = 0
  for _ in m:balls{where = function(b) return b.pos[2] > 0.5 end} do n = n + 1 end
  eq(n, 4)
end)

---------------------------------------------------------------- bulk

test("set, sum, mean, min, max, count", function()
  local m = grid_model(3, 6)
  m:group("a", {region = {box = {{0, -1, -1}, {3.5, 2, 2}}}})
  eq(m:set{group = "a", vel = {1, 2, 3}, damping = 0.5, fix = {"vz"}}, 3)
  T.vec_eq(m:ball(2).vel, {1, 2, 3})
  eq(m:ball(2).damping, 0.5)
  T.vec_eq(m:ball(2).fix, {"vz"})
  T.vec_eq(m:ball(5).vel, {0, 0, 0})
  T.vec_eq(m:sum("vel"), {3, 6, 9})
  T.vec_eq(m:sum("vel", {group = "a"}), {3, 6, 9})
  T.vec_eq(m:mean("vel", {group = "a"}), {1, 2, 3})
  near(m:mean("speed", {group = "a"}), math.sqrt(14), 1e-15)
  near(m:sum("radius"), 0.1 * 6, 1e-15)
  near(m:sum("volume"), 6 * 4 / 3 * math.pi * 1e-3, 1e-12)
  local mass = m:ball(1).mass
  near(m:sum("kinetic"), 3 * 0.5 * mass * 14, 1e-12)
  near(m:sum("mass"), 6 * mass, 1e-12)
  eq(m:min("pos")[1], 1)
  eq(m:max("pos")[1], 6)
  T.vec_eq(m:max("pos", {group = "a"}), {3, 1, 0})
  eq(m:mean("radius", {group = "a", region = {sphere = {center = {100, 0, 0}, radius = 1}}}), nil)
  eq(m:sum("radius", {region = {sphere = {center = {100, 0, 0}, radius = 1}}}), 0)
  eq(m:set{fix = {}, spin = {0, 0, 1}}, 6)
  eq(#m:ball(2).fix, 0)
  T.vec_eq(m:sum("spin"), {0, 0, 6})
  m:material("steel", {density = 7800})
  eq(m:set{where = function(b) return b.id > 4 end, material = "steel", radius = 0.2}, 2)
  eq(m:ball(6).material, "steel")
  eq(m:ball(6).radius, 0.2)
  eq(m:ball(1).material, "rock")
  raises(function() m:set{vel = {1, 2}} end, HERE, "bad argument #1 to 'set'", "field 'vel'", "3 components")
  raises(function() m:set{colour = 1} end, HERE, "unknown key 'colour'")
  raises(function() m:set{group = "a"} end, HERE, "nothing to set")
  raises(function() m:set{material = "gold"} end, HERE, "no material named 'gold'")
  raises(function() m:set{damping = 2} end, HERE, "field 'damping'")
  raises(function() m:set{fix = "vq"} end, HERE, "unknown fixity 'vq'")
  raises(function() m:sum("colour") end, HERE, "bad argument #1 to 'sum'", "unknown field 'colour'", "speed, kinetic")
  raises(function() m:mean("radius", {group = 1}) end, HERE, "field 'group'")
  raises(function() m:count{region = {box = 1}} end, HERE, "field 'region'", "box")
  raises(function() m:count{where = 1} end, HERE, "field 'where'", "function expected")
end)

test("2D bulk: spin is a number", function()
  local m = grid_model(2, 4)
  eq(m:set{spin = 2}, 4)
  eq(m:sum("spin"), 8)
  raises(function() m:set{spin = {0, 0, 1}} end, HERE, "field 'spin'")
end)

test("bulk over 100k balls stays fast", function()
  local m = T.model(3)
  m:generate{count = 100000, radius = 1e-3, region = {box = {{0, 0, 0}, {0.15, 0.15, 0.15}}}, seed = 1}
  local t0 = os.clock()
  m:group("bottom", {region = {box = {{0, 0, 0}, {0.15, 0.15, 0.05}}}})
  m:set{group = "bottom", vel = {0, 0, 1}}
  local z = m:mean("pos", {group = "bottom"})[3]
  local n = m:count{group = "bottom"}
  local elapsed = os.clock() - t0
  check(z < 0.05 and n > 20000 and n < 45000, "about a third: " .. n)
  T.vec_eq(m:sum("vel"), {0, 0, n})
  check(elapsed < 2, "took " .. elapsed .. " s")
end)

---------------------------------------------------------------- extras

test("user extras on balls", function()
  local m = grid_model(3, 3)
  local b = m:ball(1)
  eq(next(b.extra), nil)
  b.extra.tag = "marked"
  b.extra[1] = 42
  eq(m:ball(1).extra.tag, "marked")  -- kept with the ball, not the handle
  b:set_extra("n", 7)
  eq(b:get_extra("n"), 7)
  eq(b.extra.n, 7)
  eq(b:get_extra("missing"), nil)
  eq(b:get_extra("missing", 0), 0)
  eq(m:ball(2):get_extra("n"), nil)
  b.extra = {fresh = true}
  eq(b.extra.tag, nil)
  eq(b.extra.fresh, true)
  b.extra = nil
  eq(next(b.extra), nil)
  raises(function() b.extra = 5 end, HERE, "field 'extra'", "table or nil")
  raises(function() b:set_extra(nil, 1) end, HERE, "key")
  -- a removed ball's extras are gone with it
  local c = m:ball(3)
  c.extra.x = 1
  c:remove()
  raises(function() return c.extra end, HERE, "removed")
end)

---------------------------------------------------------------- removal

test("remove_balls and removals queued in callbacks", function()
  local m = grid_model(3, 6)
  m:set_timestep(1e-4)
  local w = m:wall{kind = "plane", point = {0, 0, -5}, normal = {0, 0, 1}}
  m:group("doomed", function(b) return b.id <= 2 end)
  eq(m:remove_balls{group = "doomed"}, 2)
  eq(m:ball_count(), 4)
  eq(m:ball(1), nil)
  -- inside a callback: still there until it returns
  local seen_inside
  m:on("cycle", function()
    local b = m:ball(3)
    if b then
      b:remove()
      seen_inside = {m:ball_count(), b.id, m:remove_balls{where = function(x) return x.id == 4 end}}
      w:remove()
      seen_inside[4] = m:wall_count()
    end
  end, {every = 5})
  m:cycle(5)
  T.vec_eq(seen_inside, {4, 3, 1, 1})
  eq(m:ball_count(), 2)
  eq(m:wall_count(), 0)
  eq(m:ball(3), nil)
  -- an error in a callback still applies what it queued, and queues no more after
  m:on("cycle", function()
    if m:ball(5) then
      m:ball(5):remove()
      error("boom")
    end
  end, {every = 5})
  raises(function() m:cycle(5) end, HERE, "boom")
  eq(m:ball(5), nil)
  m:ball(6):remove()
  eq(m:ball_count(), 0)
end)

T.done()
