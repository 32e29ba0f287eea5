-- Queries do not change the model (issue 12 item 2). m:timestep(),
-- m:critical_timestep() and m:energy() bring a stale broad phase up to
-- date (the build the next cycle would make from the same positions): the
-- state hash is unchanged by the query, and the cycles that follow give
-- the same bits as cycling with no query at all.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")

-- A 3D bed on a floor, its balls thrown about, with side walls, a Hertz row for
-- the floor and a linear row for one group pair: contacts are made and
-- lost, and the broad phase goes stale every few steps.
local function scene()
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("sand", {kn = 1e5, ks = 1e5, friction = 0.4, density = 2650, damping = 0.1})
  m:generate{region = {box = {{0, 0, 0}, {0.03, 0.03, 0.03}}}, radius = 0.0015, packing = "cubic"}
  for b in m:balls() do
    b.group = b.id % 2 == 0 and "rock" or "platen"
    b.vel = {0.3 * math.sin(b.id), 0.3 * math.cos(b.id), -0.3}
  end
  local floor = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}, kn = 1e6, ks = 1e6}
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {1, 0, 0}, kn = 1e6, ks = 1e6}
  m:contact_model{wall = floor, model = "hertz", shear_modulus = 2e7, poisson = 0.2}
  m:contact_model{groups = {"rock", "platen"}, kn = 2e5, ks = 2e5, friction = 0.3}
  return m
end

local STEPS = 400

T.test("queries before every step leave the hash and the run's bits as without them", function()
  local plain, asked = scene(), scene()
  local most = 0
  for s = 1, STEPS do
    if s == 200 then -- a stale build made by the user: a ball moved by hand
      for _, m in ipairs{plain, asked} do m:ball(1).pos = {0.015, 0.015, 0.06} end
    end
    local h = asked:hash()
    local dt, crit, e = asked:timestep(), asked:critical_timestep(), asked:energy()
    T.check(dt > 0 and crit > dt and e.kinetic > 0, "the queries answer")
    asked:contact_count()
    for _ in asked:contacts() do end
    T.eq(asked:hash(), h, "step " .. s .. ": the queries left the hash alone")
    plain:cycle(1)
    asked:cycle(1)
    T.eq(asked:hash(), plain:hash(), "step " .. s)
    most = math.max(most, plain:contact_count())
  end
  local p, a = plain:profile{print = false}.broad_phase.calls, asked:profile{print = false}.broad_phase.calls
  -- every build of the asked run was made by a query (its cycles built nothing): the
  -- queries met a stale broad phase p times, and the runs stayed equal
  T.check(p >= 2 and a == 0, string.format("builds in the cycles: %d without queries, %d with", p, a))
  -- contacts were made and lost on the way (the bed flies apart)
  T.check(most > 100 and plain:contact_count() < most / 2,
          string.format("contacts: %d at most, %d at the end", most, plain:contact_count()))
  print(string.format("%d steps, %d builds (each done by a query in the asked run), %d contacts at most, %d at the end",
                      STEPS, p, most, plain:contact_count()))
end)

T.done()
