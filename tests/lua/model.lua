-- Model-level behaviour: m:solve and its stopping rules, cycling in chunks,
-- timestep and gravity, the summary, lifetime rules while cycling, and the
-- progress display.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "model.lua:"

-- a column of n balls resting above a floor, under gravity
local function column(dim, n)
  local m = T.model(dim, {gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}})
  local r = 0.01
  m:wall{kind = dim == 3 and "plane" or "line", point = T.zero(dim), normal = dim == 3 and {0, 0, 1} or {0, 1}}
  for i = 1, n do
    local pos = T.zero(dim)
    pos[dim] = r + (i - 1) * 2.02 * r
    m:ball{pos = pos, radius = r}
  end
  return m
end

test("solve stops on steps", function()
  local m = column(3, 3)
  local why, ratio, steps = m:solve{steps = 250}
  eq(why, "steps")
  eq(steps, 250)
  eq(m:step(), 250)
  check(ratio > 0, "a ratio is reported")
  why, ratio, steps = m:solve{steps = 0}
  eq(why, "steps")
  eq(steps, 0)
  eq(m:step(), 250)
end)

test("solve stops on time", function()
  local m = column(2, 2)
  m:set_timestep(1e-4)
  local t0 = m:time()
  local why, _, steps = m:solve{time = 0.0123}
  eq(why, "time")
  check(m:time() >= t0 + 0.0123 - 1e-12, "the time is reached")
  check(m:time() < t0 + 0.0123 + 1e-4, "by the first step past it")
  eq(steps, 123)
  eq(m:step(), 123)
end)

-- The model time is a sum of timesteps, off by rounding: a duration that
-- is a whole number of steps takes that many, not one more.
test("solve{time} takes the whole number of steps the time is", function()
  local m = seixo.model{dim = 2, timestep = 1e-5}
  m:material("s", {})
  m:ball{pos = {0, 0}, radius = 0.01}
  local function steps(t)
    local why, _, n = m:solve{time = t}
    eq(why, "time")
    return n
  end
  eq(steps(1.0), 100000)
  eq(steps(0.5), 50000, "from t = 1 s")
  m:set_timestep(0.1)
  eq(steps(0.3), 3, "0.1 + 0.1 + 0.1 < 0.3")
  m:set_timestep(1e-4)
  -- past a boundary by more than rounding: one step more
  eq(steps(0.01235), 124)
  eq(steps(0.0123 + 1e-9), 124)
end)

-- The automatic timestep grows as a burst cluster loses its contacts: a
-- run with a time limit must still stop at the first step past it, and at
-- the same step however it is cut into cycles (one step at a time under a
-- callback, or in one long cycle without a progress display; cut at the
-- start's timestep, it ran to 0.0825 s of 0.05 s, 110 steps instead of 69).
test("solve{time} stops at the first step past the time, however the run is cut", function()
  local progress = seixo.progress(false)
  local function burst()
    local m = seixo.model{dim = 2}
    m:material("s", {kn = 1e5, ks = 1e5, density = 2500})
    for j = 0, 6 do
      for i = 0, 6 do m:ball{pos = {0.0095 * (i + 0.5 * (j % 2)), 0.0095 * 0.866 * j}, radius = 0.005} end
    end
    return m
  end
  local whole = burst()
  eq(whole:solve{time = 0.05}, "time")
  local stepped = burst()
  local lo, hi = math.huge, 0
  stepped:on("after", function()
    local dt = stepped:timestep()
    lo, hi = math.min(lo, dt), math.max(hi, dt)
  end)
  eq(stepped:solve{time = 0.05}, "time")
  seixo.progress(progress)
  check(hi > 1.5 * lo, "the automatic timestep must grow as the cluster bursts")
  eq(whole:step(), stepped:step())
  eq(whole:hash(), stepped:hash())
  check(whole:time() >= 0.05 and whole:time() < 0.05 + hi, "by the first step past it: " .. whole:time())
end)

test("solve stops on the unbalanced-force ratio", function()
  for _, dim in ipairs({2, 3}) do
    local m = column(dim, 4)
    local why, ratio, steps = m:solve{ratio = 1e-4, every = 50, steps = 500000}
    eq(why, "ratio", dim .. "D")
    check(ratio <= 1e-4, "ratio reached: " .. ratio)
    eq(m:ratio(), ratio)
    eq(steps % 50, 0, "the ratio is checked every 50 steps")
    check(steps > 50, "it took cycling to settle")
    -- the settled column: the floor carries the weight
    local weight = m:sum("mass") * 9.81
    local floor
    for w in m:walls() do floor = w end
    near(-floor.force[dim], weight, 1e-3)
  end
end)

test("with no contact force the ratio is settled only when nothing moves", function()
  -- balls afloat (no gravity) and a wall closing on them: solve{ratio} had
  -- stopped at once, at a ratio of 0, before the wall touched them
  local m = seixo.model{dim = 3, gravity = {0, 0, 0}}
  m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})
  for i = 0, 3 do m:ball{pos = {0.02 * i, 0, 0.01}, radius = 0.005} end
  eq(m:ratio(), 0, "a still cloud is settled")
  local why = m:solve{ratio = 1e-3}
  eq(why, "ratio")
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  m:wall{kind = "plane", point = {0, 0, 0.03}, normal = {0, 0, -1}, vel = {0, 0, -0.05}}
  eq(m:ratio(), math.huge, "a wall moves: not settled")
  local steps
  why, _, steps = m:solve{ratio = 1e-2, every = 10, steps = 200000}
  eq(why, "ratio")
  -- the lid squeezes the balls onto the floor: 4 balls, 2 contacts each
  eq(m:contact_count(), 8, "stopped once the lid pressed the balls onto the floor")
  check(steps > 1000, "it cycled until the lid touched: " .. steps)
  -- a moving ball, no contact
  local m2 = seixo.model{dim = 2, gravity = {0, 0}}
  m2:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5})
  m2:ball{pos = {0, 0}, radius = 0.005, vel = {1, 0}}
  eq(m2:ratio(), math.huge)
end)

test("a bond's force is a contact force of the ratio, as PFC counts it", function()
  -- two balls bonded across a 1 nm gap carry a load by the bond alone: the
  -- ratio had no contact force to compare with and never settled
  local R = 1e-3
  local m = seixo.model{dim = 3}
  m:material("g", {density = 2650, kn = 1e6, ks = 1e6, damping = 0.7,
                   bond = {radius_multiplier = 1, modulus = 1e9, stiffness_ratio = 1, tensile_strength = 1e20,
                           cohesion = 1e20}})
  local a = m:ball{pos = {0, 0, 0}, radius = R}
  local b = m:ball{pos = {2 * R + 1e-9, 0, 0}, radius = R}
  eq(m:bond{kind = "parallel", gap = 1e-8}, 1)
  a.fix = "all"
  b.applied_force = {1e-3, 0, 0}
  local why, ratio = m:solve{ratio = 1e-6, steps = 20000}
  eq(why, "ratio")
  check(ratio <= 1e-6, "ratio " .. ratio)
  local c = m:contacts()()
  eq(c.fn, 0)
  -- the mean unbalanced force (b's over the two balls: a's is balanced by
  -- its fixity) over the mean contact force (the bond's 1 mN)
  near(ratio, b.force:norm() / 2 / 1e-3, 1e-6)
  near(-c.pb_fn, 1e-3, 1e-6)
end)

test("solve with no limit uses ratio 1e-5; the first of several limits wins", function()
  local m = column(3, 2)
  local why, ratio = m:solve()
  eq(why, "ratio")
  check(ratio <= 1e-5)
  local m2 = column(3, 2)
  why = m2:solve{ratio = 1e-12, steps = 300}
  eq(why, "steps")
  eq(m2:step(), 300)
end)

test("solve arguments", function()
  local m = column(3, 1)
  raises(function() m:solve{ratoi = 1} end, HERE, "bad argument #1 to 'solve'", "unknown key 'ratoi'", "ratio, steps, time, every")
  raises(function() m:solve{ratio = -1} end, HERE, "field 'ratio'")
  raises(function() m:solve{ratio = 0 / 0} end, HERE, "field 'ratio'")
  raises(function() m:solve{time = 0} end, HERE, "field 'time'")
  raises(function() m:solve{time = math.huge} end, HERE, "field 'time'")
  raises(function() m:solve{steps = -1} end, HERE, "field 'steps'")
  raises(function() m:solve{steps = 1.5} end, HERE, "field 'steps'")
  raises(function() m:solve{every = 0} end, HERE, "field 'every'")
  raises(function() m:solve(5) end, HERE, "table expected")
  eq(m:step(), 0)
end)

test("cycling in pieces equals one cycle, callbacks and histories included", function()
  local function run(pieces)
    local m = column(3, 5)
    local calls = 0
    m:on("cycle", function() calls = calls + 1 end, {every = 7})
    m:history("z", {ball = 5, field = "pos", component = 3}, {every = 13})
    for _, n in ipairs(pieces) do m:cycle(n) end
    return m:hash(), calls, #m:history("z").values
  end
  local h1, c1, n1 = run({200})
  local h2, c2, n2 = run({1, 99, 37, 63})
  eq(h2, h1)
  eq(c1, 200 // 7)
  eq(c2, c1)
  eq(n1, 200 // 13)
  eq(n2, n1)
end)

test("timestep and gravity", function()
  local m = column(3, 2)
  m:set_timestep(2e-5)
  eq(m:timestep(), 2e-5)
  m:set_timestep("auto")
  near(m:timestep(), 0.8 * m:critical_timestep(), 1e-12)
  raises(function() m:set_timestep("fast") end, HERE, "'auto'")
  m:set_gravity({0, 0, -1})
  T.vec_eq(m:gravity(), {0, 0, -1})
  -- an automatic timestep below the user's floor (1e-15 s) is an error: a
  -- stiffness of 1e300 N/m gave 0 s, and cycles counted steps at a standstill
  local stiff = seixo.model{dim = 2}
  stiff:material("s", {kn = 1e300, ks = 1e300})
  stiff:ball{pos = {0, 0}, radius = 0.01}
  raises(function() stiff:cycle(5) end, HERE, "automatic timestep is 0 s, below 1e-15 s")
  eq(stiff:step(), 0)
  raises(function() stiff:timestep() end, HERE, "below 1e-15 s")
end)

test("materials()", function()
  local m = T.model(3)
  m:material("steel", {density = 7800, kn = 2e9, friction = 0.2})
  local all = m:materials()
  eq(all.rock.density, 2000)
  eq(all.rock.ks, 5e5)
  eq(all.steel.kn, 2e9)
  eq(all.steel.friction, 0.2)
  eq(all.steel.model, "linear")
end)

test("print(m) shows a summary", function()
  local m = column(3, 3)
  m:ball(1).group = "bottom"
  m:history("ke", "kinetic")
  m:on("cycle", function() end)
  m:cycle(10)
  local s = tostring(m)
  eq(s, m:summary())
  for _, frag in ipairs({"seixo.model 3D: 3 balls, 1 walls", "step 10", "timestep", "gravity {0.0, 0.0, -9.81} m/s^2",
                         "materials: rock", "groups: bottom", "unbalanced ratio", "kinetic energy", "histories: ke",
                         "callbacks: 1"}) do
    check(s:find(frag, 1, true), "summary lacks " .. frag .. ":\n" .. s)
  end
  local empty = seixo.model{dim = 2}
  check(tostring(empty):find("automatic (no ball yet)", 1, true), tostring(empty))
  empty:close()
  eq(tostring(empty), "seixo.model (closed)")
end)

test("a model cannot be closed or re-cycled from its own callback", function()
  local m = column(2, 2)
  m:on("cycle", function() m:close() end, {every = 5})
  raises(function() m:cycle(10) end, HERE, "cycling")
  eq(m:step(), 5)
  local id = m:on("cycle", function() m:cycle(1) end)
  raises(function() m:cycle(10) end, "already cycling")
  m:off(1)
  m:off(id)
  m:cycle(10)  -- usable again
  eq(m:step(), 16)
  -- another model may cycle from a callback
  local other = column(2, 1)
  m:on("cycle", function() other:cycle(2) end, {every = 2})
  m:cycle(4)
  eq(other:step(), 4)
end)

test("an error in the core leaves the model usable", function()
  local m = T.model(3)
  m:ball{pos = {0, 0, 0}, radius = 0.01}
  m:ball{pos = {0.015, 0, 0}, radius = 0.01}
  m:set_timestep(1)  -- far beyond the critical timestep
  local err = raises(function() m:cycle(100) end, HERE, "unstable")
  check(not err:find("interrupted"), err)
  m:set_timestep(1e-6)
  m:ball(1).pos = {-1, 0, 0}
  m:ball(1).vel = {0, 0, 0}
  m:ball(2).vel = {0, 0, 0}
  m:cycle(3)
end)

test("progress: a log's when stderr is not a terminal, and nothing is printed by a short run", function()
  local slow = [[
    local m = seixo.model{dim = 2, timestep = 1e-4}
    m:material("a")
    m:ball{pos = {0, 0}, radius = 1}
    m:on("cycle", function() local t = os.clock() while os.clock() - t < 0.02 do end end)
    %s
    m:cycle(80)
    print("progress", seixo.progress())]]
  local status, out = T.run("-e " .. T.quote(slow:format("")))
  eq(status, 0, out)
  check(out:find("progress\tlog", 1, true), out)
  check(not out:find("steps/s", 1, true), out)
  -- forced on, the same run shows the line (steps, time, speed, ETA)
  status, out = T.run("-e " .. T.quote(slow:format("seixo.progress(true)")))
  eq(status, 0, out)
  check(out:find("step %d+ of 80"), out)
  check(out:find("steps/s", 1, true) and out:find("ETA", 1, true), out)
  eq(seixo.progress(seixo.progress()), seixo.progress())
  raises(function() seixo.progress("yes") end, HERE, "boolean or 'log' expected")
end)

test("--threads is accepted and recorded", function()
  local status, out = T.run("--threads 3 -e 'print(seixo.threads)'")
  eq(status, 0, out)
  eq(out, "3\n")
  status, out = T.run("-e 'print(seixo.threads)'", nil, "-u OMP_NUM_THREADS")
  eq(out, "1\n")
  -- OMP_NUM_THREADS is read when --threads is not given; a bad one is an error, not 1 thread
  status, out = T.run("-e 'print(seixo.threads)'", nil, "OMP_NUM_THREADS=2")
  eq(out, "2\n")
  status, out = T.run("--threads 3 -e 'print(seixo.threads)'", nil, "OMP_NUM_THREADS=2")
  eq(out, "3\n")
  for _, bad in ipairs({"x", "0", "2000", "1e300"}) do
    status, out = T.run("-e 'print(1)'", nil, "OMP_NUM_THREADS=" .. bad)
    eq(status, 1)
    check(out:find("OMP_NUM_THREADS='" .. bad .. "' is not a whole number", 1, true), out)
  end
  -- seixo.threads set by a script: a thread count, or seixo.model says so
  for _, bad in ipairs({"x", 0 / 0, 0, 2000, 1e300, 1.5}) do
    seixo.threads = bad
    raises(function() seixo.model{dim = 2} end, HERE, "seixo.threads must be a whole number from 1 to 1024")
  end
  seixo.threads = 2
  seixo.model{dim = 2}:close()
  -- a loaded model runs on seixo.threads too, not the saving run's count
  -- (every lab test loads its specimen: --threads did nothing there)
  seixo.threads = 1
  local one = seixo.model{dim = 2}
  eq(one:profile{print = false}.threads, 1)
  local path = os.tmpname()
  one:save(path)
  seixo.threads = 3
  local loaded = seixo.load(path)
  eq(loaded:profile{print = false}.threads, 3)
  seixo.threads = "x"
  raises(function() seixo.load(path) end, HERE, "seixo.load: seixo.threads must be a whole number")
  os.remove(path)
  seixo.threads = nil
  seixo.model{dim = 2}:close()
  seixo.threads = 1
  status, out = T.run("--threads 0 -e 'print(1)'")
  eq(status, 1)
  check(out:find("'--threads' needs a whole number", 1, true), out)
  status, out = T.run("--threads")
  eq(status, 1)
  status, out = T.run("--help")
  check(out:find("--threads N", 1, true), out)
end)

test("the library is on package.path, help is global", function()
  local status, out = T.run("-e " .. T.quote("print(require('seixo.util').norm({3, 4}), type(help))"))
  eq(status, 0, out)
  eq(out, "5.0\tfunction\n")
  -- an override that has no library: require fails with a clear message
  local cmd = "SEIXO_LUA_PATH=/nonexistent timeout 60 " .. T.quote(T.seixo) .. " -e " ..
              T.quote("print(pcall(require, 'seixo.util'))") .. " 2>&1"
  local p = io.popen(cmd)
  out = p:read("a")
  p:close()
  check(out:find("false", 1, true) and out:find("/nonexistent/seixo/util.lua", 1, true), out)
end)

test("m:profile times the stages and counts their calls", function()
  for _, dim in ipairs({2, 3}) do
    local m = column(dim, 4)
    local fired = 0
    m:on("after", function() fired = fired + 1 end, {every = 10})
    m:history("ke", function(mm) return mm:energy().kinetic end, {every = 25})
    m:cycle(200)
    local p = m:profile{print = false}
    eq(p.steps, 200)
    eq(p.integration.calls, 200)
    eq(p.ball_contacts.calls, 200)
    eq(p.wall_contacts.calls, 200)
    eq(p.other.calls, 200)
    check(p.broad_phase.calls >= 1, "the first build is timed")
    eq(fired, 20)
    eq(p.callbacks.calls, 20 + 8, "every callback and history function") -- histories at 25, 50, ..., 200
    local sum = 0
    for _, k in ipairs({"broad_phase", "ball_contacts", "wall_contacts", "integration", "callbacks", "other"}) do
      check(p[k].seconds >= 0, k)
      sum = sum + p[k].seconds
    end
    near(p.total, sum, 1e-12)
    check(p.total - p.callbacks.seconds <= p.cycle_seconds * (1 + 1e-9), "the core's stages run inside its cycles")
    -- printing, and a reset after reading
    local status, out = T.run("-e " .. T.quote("local m = seixo.model{dim = 2}; m:material('r'); " ..
      "m:ball{pos = {0, 0}, radius = 0.1}; m:cycle(10); m:profile()"))
    eq(status, 0, out)
    check(out:find("ball contacts", 1, true) and out:find("integration", 1, true), out)
    m:profile{print = false, reset = true}
    eq(m:profile{print = false}.steps, 0)
    raises(function() m:profile{nope = true} end, "nope")
  end
end)

test("seixo --profile prints each model's profile at the end", function()
  local status, out = T.run("--profile -e " .. T.quote("local m = seixo.model{dim = 3}; m:material('r'); " ..
    "m:ball{pos = {0, 0, 0}, radius = 0.1}; m:cycle(10)"))
  eq(status, 0, out)
  check(out:find("profile of a 3D model of 1 balls at step 10", 1, true) and out:find("broad phase", 1, true), out)
end)

test("m:memory reports bytes per ball and per contact", function()
  local m = column(3, 5)
  m:cycle(50)
  local r = m:memory()
  eq(r.total, m:bytes())
  eq(r.balls + r.contacts + r.bonds + r.work, r.total)
  eq(r.ball_count, 5)
  eq(r.contact_count, m:contact_count())
  check(r.contact_count > 0 and r.pair_count >= r.contact_count)
  near(r.per_ball, r.balls / 5, 1e-12)
  near(r.per_contact, r.contacts / r.contact_count, 1e-12)
  check(r.peak >= r.total)
end)

-- issue 18: a skin (or a bond gap) that makes every pair a candidate is
-- refused before the broad phase runs for minutes beyond Ctrl-C's reach
test("a skin wider than the assembly is refused, quickly", function()
  local t0 = seixo.clock()
  local region = {box = {{0, 0, 0}, {0.2, 0.2, 0.2}}}
  local m = seixo.model{dim = 3, skin = 1e3}
  m:material("r", {bond = {normal_strength = 1, shear_strength = 1}})
  eq(m:generate{method = "lattice", packing = "cubic", radius = 0.005, region = region}, 8000)
  raises(function() m:cycle(1) end, HERE, "a skin of 1000 m makes about", "lower the skin")
  raises(function() m:energy() end, HERE, "m:energy", "lower the skin") -- not a silent zero
  local m2 = seixo.model{dim = 3}
  m2:material("r", {bond = {normal_strength = 1, shear_strength = 1}})
  m2:generate{method = "lattice", packing = "cubic", radius = 0.005, region = region}
  raises(function() m2:bond{kind = "contact", gap = 1} end, HERE, "a skin of 1 m")
  eq(m2:bond_count(), 0)
  check(m2:bond{kind = "contact", gap = 1e-4} > 20000)
  m2:cycle(1)
  check(seixo.clock() - t0 < 60, seixo.clock() - t0)
end)

T.done()
