-- Event callbacks: m:on("bond_break" | "contact_create" | "contact_delete" |
-- "ball_leave_region", fn) see every event, in a deterministic order, after
-- the step it happened in, and change no bit of the run.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, raises = T.test, T.check, T.eq, T.raises

-- two bonded rows of balls pulled apart: every bond between the rows breaks
local rows = dofile(T.root .. "tests/io/bonded_rows.lua")

-- balls dropped into a box: contacts made and lost as they bounce
local function pile()
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("glass", {density = 2500, kn = 1e5, ks = 1e5, friction = 0.3, damping = 0.1})
  m:wall{kind = "box", min = {0, 0}, max = {0.05, 0.1}}
  m:generate{count = 40, radius = {1.5e-3, 2.5e-3}, region = {box = {{0, 0.02}, {0.05, 0.1}}}, seed = 3}
  return m
end

local function pair_key(a, b, wall) return (wall and "w" or "b") .. a.id .. "-" .. b.id end

test("bond_break: one event per crack, in the crack log's order, after its step", function()
  local m = rows()
  local seen = {}
  local start = m:step()
  m:on("bond_break", function(mm, e)
    check(mm:step() >= e.step, "delivered after the step it happened in")
    -- at a multiple of 100 steps (or the run's end), wherever the progress display's clock would cut the run
    check(mm:step() % 100 == 0 or mm:step() == start + 1000, "delivered at step " .. mm:step())
    seen[#seen + 1] = e
  end)
  local progress = seixo.progress("log", 1e-3)
  m:cycle(1000)
  seixo.progress(progress, 10)
  local cracks = m:cracks()
  check(#cracks > 0)
  eq(#seen, #cracks)
  for i, c in ipairs(cracks) do
    eq(seen[i].a.id, c.a)
    eq(seen[i].b.id, c.b)
    eq(seen[i].mode, c.mode)
    eq(seen[i].step, c.step)
    eq(seen[i].bond, "parallel")
    check(seen[i].pos.x == c.pos[1] and getmetatable(seen[i].pos) == getmetatable(seixo.vec(0, 0)))
  end
end)

test("contact_create and contact_delete keep an exact copy of the contact list", function()
  local m = pile()
  m:cycle(10)  -- the contacts before the handlers are not created by them
  local live, creates, deletes = {}, 0, 0
  local function key_of(c)
    local a, b = c.a, c.b
    if c.kind ~= "ball-wall" and b.id < a.id then a, b = b, a end
    return pair_key(a, b, c.kind == "ball-wall")
  end
  for c in m:contacts() do live[key_of(c)] = true end
  local last_step = -1
  m:on("contact_create", function(mm, e)
    local k = pair_key(e.a, e.b, e.wall)
    check(not live[k], "created twice: " .. k)
    check(e.overlap >= 0 and e.step == mm:step())
    check(e.step >= last_step)
    last_step = e.step
    live[k] = true
    creates = creates + 1
  end)
  m:on("contact_delete", function(mm, e)
    local k = pair_key(e.a, e.b, e.wall)
    check(live[k], "deleted but not live: " .. k)
    live[k] = nil
    deletes = deletes + 1
  end)
  m:cycle(3000)
  check(creates > 50 and deletes > 20, creates .. " " .. deletes)
  local now, n = {}, 0
  for c in m:contacts() do
    now[key_of(c)] = true
    n = n + 1
  end
  local nlive = 0
  for k in pairs(live) do
    check(now[k], "a live contact the model does not have: " .. k)
    nlive = nlive + 1
  end
  eq(nlive, n)
end)

test("ball_leave_region: once, at the step its centre leaves", function()
  local m = seixo.model{dim = 2, timestep = 1e-3}
  m:material("a")
  local b = m:ball{pos = {0, 0}, radius = 0.1, vel = {1, 0}}
  m:ball{pos = {5, 5}, radius = 0.1}  -- never inside
  local events = {}
  m:on("ball_leave_region", function(_, e) events[#events + 1] = e end, {region = {box = {{-1, -1}, {0.5005, 1}}}})
  m:cycle(1000)
  eq(#events, 1)
  eq(events[1].ball, b)
  eq(events[1].step, 501)  -- x = 0.501 after step 501
  check(events[1].pos.x > 0.5005 and events[1].pos.x < 0.5015, tostring(events[1].pos))
  raises(function() m:on("ball_leave_region", function() end) end, "ball_leave_region needs {region = {...}}")
  raises(function() m:on("bond_brake", function() end) end, "unknown point 'bond_brake'", "contact_create")
end)

test("events change no bit of a run, and m:off removes a handler", function()
  local function run(with)
    local m = pile()
    local r = rows()
    local count = 0
    if with then
      for _, ev in ipairs{"contact_create", "contact_delete"} do m:on(ev, function() count = count + 1 end) end
      m:on("ball_leave_region", function() count = count + 1 end, {region = {box = {{0, 0.05}, {0.05, 0.1}}}})
      r:on("bond_break", function() count = count + 1 end)
    end
    m:cycle(2000)
    r:cycle(1000)
    return m:hash() .. r:hash(), count
  end
  local plain = run(false)
  local with, count = run(true)
  check(count > 50, count)
  eq(with, plain)
  local m = pile()
  local n = 0
  local id = m:on("contact_create", function() n = n + 1 end)
  m:cycle(500)
  check(n > 0)
  eq(m:off(id), true)
  local before = n
  m:cycle(500)
  eq(n, before)
end)

T.done()
