-- Callbacks (m:on, m:off) and histories (m:history, m:history_csv).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "callbacks.lua:"

-- one ball falling freely (no damping), fixed timestep: exact kinematics
local function falling(dim)
  local m = seixo.model{dim = dim or 3, gravity = (dim or 3) == 3 and {0, 0, -10} or {0, -10}, timestep = 1e-3}
  m:material("rock", {density = 2000})
  local pos = T.zero(dim or 3)
  pos[dim or 3] = 100
  m:ball{pos = pos, radius = 0.1}
  return m
end

---------------------------------------------------------------- callbacks

test("after, before and cycle points at multiples of every", function()
  local m = falling()
  local log = {}
  m:on("after", function(mm) log[#log + 1] = "a" .. mm:step() end, {every = 10})
  m:on("before", function(mm) log[#log + 1] = "b" .. mm:step() end, {every = 10})
  m:on("cycle", function() log[#log + 1] = "c" .. m:step() end, {every = 4})
  m:cycle(25)
  -- at one boundary: "after" callbacks in the order they were added, then "before"
  eq(table.concat(log, " "), "b0 c4 c8 a10 b10 c12 c16 a20 c20 b20 c24")
  log = {}
  m:cycle(5)  -- 26 .. 30: nothing before 30, where the run ends
  eq(table.concat(log, " "), "c28 a30")
  log = {}
  m:cycle(1)  -- before step 31: "before" at 30 has its turn now
  eq(table.concat(log, " "), "b30")
  log = {}
  m:cycle(0)
  eq(#log, 0)
end)

test("callbacks receive the model, see the state after the step, and may change it", function()
  local m = falling()
  local b = m:ball(1)
  local got
  m:on("cycle", function(mm)
    got = mm
    b.vel = {0, 0, 0}  -- a servo: hold the ball still every 3 steps
  end, {every = 3})
  m:cycle(3)
  check(rawequal(got, m), "the model itself")
  T.vec_eq(b.vel, {0, 0, 0})
  m:cycle(1)
  near(b.vel[3], -10 * 1e-3, 1e-12)
end)

test("off, ids, and callbacks added or removed by callbacks", function()
  local m = falling()
  local n1, n2 = 0, 0
  local id1 = m:on("cycle", function() n1 = n1 + 1 end)
  local id2
  id2 = m:on("cycle", function()
    n2 = n2 + 1
    if n2 == 3 then m:off(id1) end  -- takes effect at once
  end)
  check(math.type(id1) == "integer" and id2 ~= id1)
  m:cycle(5)
  eq(n1, 3)  -- it ran before the second at step 3
  eq(n2, 5)
  eq(m:off(id1), false)
  eq(m:off(id2), true)
  m:cycle(2)
  eq(n2, 5)
  raises(function() m:on("cycel", print) end, HERE, "bad argument #1 to 'on'", "unknown point 'cycel' (valid: after, before, cycle; events: bond_break")
  raises(function() m:on("cycle", 5) end, HERE, "function expected")
  raises(function() m:on("cycle", print, {every = 0}) end, HERE, "field 'every'")
  raises(function() m:on("cycle", print, {evry = 2}) end, HERE, "unknown key 'evry'")
  raises(function() m:off("x") end, HERE, "number expected")
end)

test("an error in a callback stops the cycle with its message and position", function()
  local m = falling()
  m:on("cycle", function() if m:step() == 7 then error("servo lost") end end)
  local err = raises(function() m:cycle(20) end, "servo lost")
  check(err:find("callbacks.lua:%d+: servo lost"), err)
  eq(m:step(), 7)
  m:off(1)
  m:cycle(3)
  eq(m:step(), 10)
end)

test("callbacks and solve", function()
  local m = falling()
  local n = 0
  m:on("cycle", function() n = n + 1 end, {every = 2})
  m:solve{steps = 9}
  eq(n, 4)
end)

---------------------------------------------------------------- histories

-- issue 18: a run deeper than the interrupt registry's 16 could not be
-- stopped by Ctrl-C; the 17th model cycling inside the others' callbacks
-- is refused, and every model stays usable
test("more than 16 models cycling inside each other's callbacks are refused", function()
  local models, ids = {}, {}
  for i = 1, 17 do models[i] = falling(2) end
  for i = 1, 16 do ids[i] = models[i]:on("cycle", function() models[i + 1]:cycle(1) end) end
  local ok, err = pcall(models[1].cycle, models[1], 1)
  check(not ok, "the 17th nested run started")
  check(tostring(err):find("m:cycle: more than 16 models cycling inside each other's callbacks", 1, true), err)
  -- 16 deep is allowed
  models[16]:off(ids[16])
  local s16 = models[16]:step()
  models[1]:cycle(1)
  eq(models[16]:step(), s16 + 1)
  for i = 1, 15 do models[i]:off(ids[i]) end
  for i = 1, 17 do models[i]:cycle(1) end
  eq(models[17]:step(), 1)
end)

test("builtin histories record exact values at multiples of every", function()
  local m = falling()
  m:history("t", "time", {every = 10})
  m:history("n", "step", {every = 10})
  m:history("dt", "timestep", {every = 10})
  m:history("ke", "kinetic", {every = 5})
  m:history("z", {ball = m:ball(1), field = "pos", component = "z"}, {every = 10})
  m:history("vz", {ball = 1, field = "vel", component = 3}, {every = 10})
  m:history("r", {ball = 1, field = "radius"}, {every = 20})
  m:history("nb", "balls", {every = 20})
  m:cycle(40)
  local t = m:history("t")
  T.vec_eq(t.steps, {10, 20, 30, 40})
  eq(t.every, 10)
  eq(t.name, "t")
  for i = 1, 4 do
    near(t.values[i], i * 10 * 1e-3, 1e-12)
    eq(t.times[i], t.values[i])
  end
  T.vec_eq(m:history("n").values, {10, 20, 30, 40})
  T.vec_eq(m:history("dt").values, {1e-3, 1e-3, 1e-3, 1e-3})
  T.vec_eq(m:history("ke").steps, {5, 10, 15, 20, 25, 30, 35, 40})
  local mass = m:ball(1).mass
  for i, s in ipairs(m:history("z").steps) do
    -- leapfrog from rest: v_n = -g n dt, z_n = z0 - g dt^2 n(n+1)/2
    near(m:history("z").values[i], 100 - 10 * 1e-6 * s * (s + 1) / 2, 1e-12)
    near(m:history("vz").values[i], -10 * s * 1e-3, 1e-12)
  end
  near(m:history("ke").values[8], 0.5 * mass * (10 * 40 * 1e-3) ^ 2, 1e-9)
  T.vec_eq(m:history("r").values, {0.1, 0.1})
  T.vec_eq(m:history("nb").values, {1, 1})
  -- the record is a copy
  m:history("t").values[1] = -1
  near(m:history("t").values[1], 0.01, 1e-12)
  T.vec_eq(m:histories(), {"t", "n", "dt", "ke", "z", "vz", "r", "nb"})
end)

test("function histories, walls, ratio and removal", function()
  local m = T.model(2, {gravity = {0, -10}})
  local floor = m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
  local b = m:ball{pos = {0, 0.0101}, radius = 0.01}
  m:ball{pos = {1, 0.0101}, radius = 0.01}
  m:history("twice", function(mm) return 2 * mm:step() end, {every = 100})
  m:history("fy", {wall = floor, field = "force", component = "y"}, {every = 100})
  m:history("ratio", "ratio", {every = 100})
  m:history("contacts", "contacts", {every = 100})
  m:cycle(3000)
  T.vec_eq({table.unpack(m:history("twice").values, 1, 3)}, {200, 400, 600})
  local fy = m:history("fy").values
  near(fy[#fy], -2 * b.mass * 10, 1e-3)
  check(m:history("ratio").values[30] < 1e-3, "settled")
  eq(m:history("contacts").values[30], 2)
  m:history_remove("twice")
  T.vec_eq(m:histories(), {"fy", "ratio", "contacts"})
  -- a removed ball records NaN
  m:history("bx", {ball = b, field = "pos", component = 1}, {every = 10})
  b:remove()
  m:cycle(10)
  local v = m:history("bx").values[1]
  check(v ~= v, "NaN after removal")
end)

test("history errors", function()
  local m = falling()
  m:history("ke", "kinetic")
  raises(function() m:history("ke", "kinetic") end, HERE, "bad argument #1 to 'history'", "a history named 'ke' exists")
  raises(function() m:history("x", "kinetik") end, HERE, "unknown builtin 'kinetik'", "kinetic")
  raises(function() m:history("x", {ball = 1, field = "pos"}) end, HERE, "field 'component'", "give a component")
  raises(function() m:history("x", {ball = 1, field = "radius", component = 1}) end, HERE, "no component")
  raises(function() m:history("x", {ball = 1, field = "pos", component = "w"}) end, HERE, "field 'component'")
  raises(function() m:history("x", {ball = 99, field = "pos", component = 1}) end, HERE, "field 'ball'", "existing ball")
  raises(function() m:history("x", {ball = 1, field = "colour"}) end, HERE, "field 'field'", "one of pos")
  raises(function() m:history("x", {ball = 1, wall = 1, field = "pos"}) end, HERE, "one ball or one wall")
  raises(function() m:history("x", {ball = 1, field = "pos", component = 1, every = 2}) end, HERE, "unknown key 'every'")
  raises(function() m:history("x", 5) end, HERE, "function, builtin name")
  raises(function() m:history("a/b", "time") end, HERE, "without '/'")
  -- a file keeps names of up to 65,536 bytes: a longer one saved, and the file would not load
  raises(function() m:history(string.rep("x", 65537), "time") end, HERE, "at most 65536 bytes")
  raises(function() m:history("x", "time", {every = -1}) end, HERE, "field 'every'")
  raises(function() m:history("nothing") end, HERE, "no history named 'nothing'")
  raises(function() m:history_remove("nothing") end, HERE, "no history named 'nothing'")
  m:history("bad", function() return "high" end, {every = 2})
  raises(function() m:cycle(4) end, "history 'bad': the function returned string, a number expected")
  eq(m:step(), 2)
end)

test("history_csv: the union of steps, empty cells, a unique temporary name then rename", function()
  local util = require("seixo.util")
  local m = falling()
  m:history("n", "step", {every = 2})
  m:history("t", "time", {every = 3})
  m:cycle(6)
  local path = os.tmpname()
  m:history_csv(path)
  local f = io.open(path)
  local text = f:read("a")
  f:close()
  eq(text:match("^[^\n]*"), "step,time,n,t")
  local csv = util.read_csv(path)
  eq(csv.rows, 4)  -- steps 2, 3, 4, 6
  T.vec_eq(csv.columns.step, {2, 3, 4, 6})
  eq(csv.columns.n[1], 2)
  eq(csv.columns.n[2], nil)
  near(csv.columns.t[2], 3e-3, 1e-12)
  eq(csv.columns.t[3], nil)
  eq(csv.columns.n[4], 6)
  near(csv.columns.time[4], 6e-3, 1e-12)
  local dir, base = path:match("^(.*)/([^/]*)$")
  check(not io.popen("ls -a " .. T.quote(dir)):read("a"):find("." .. base .. ".tmp-", 1, true),
        "no temporary left behind")
  -- a chosen subset
  m:history_csv(path, {"t"})
  eq(util.read_csv(path).header[3], "t")
  eq(#util.read_csv(path).header, 3)
  os.remove(path)
  raises(function() m:history_csv("/nonexistent/dir/h.csv") end, HERE, "/nonexistent/dir/h.csv", "cannot create a file in its folder")
  raises(function() m:history_csv(path, {"zz"}) end, HERE, "no history named 'zz'")
  raises(function() falling():history_csv(path) end, HERE, "records no history")
end)

test("a cycle that fails inside coroutine.resume gives its model back", function()
  -- Lua closes a failed coroutine's to-be-closed values only at
  -- coroutine.close: the run stayed open, its model cycling for good, and
  -- after 16 of them no model could cycle
  for _ = 1, 17 do
    local m = falling()
    local co = coroutine.create(function()
      m:on("after", function() error("boom") end)
      m:cycle(3)
    end)
    local ok, err = coroutine.resume(co)
    check(not ok and tostring(err):find("boom", 1, true), err)
    eq(coroutine.status(co), "dead")
    m:off(1)
    m:cycle(2)
    eq(m:step(), 3)
    m:close()
  end
  local fresh = falling()
  fresh:cycle(1)
  eq(fresh:step(), 1)
  -- the failed coroutine is left as Lua leaves it: its traceback shows where
  local m = falling()
  local co = coroutine.create(function() m:on("after", function() error("deep") end); m:cycle(3) end)
  local ok, err = coroutine.resume(co)
  check(not ok and debug.traceback(co, err):find("in method 'cycle'", 1, true), debug.traceback(co, err))
  m:off(1)
  m:cycle(1)
  -- a coroutine.wrap's failure
  local g = falling()
  local ok = pcall(coroutine.wrap(function() g:on("after", function() error("x") end); g:cycle(1) end))
  check(not ok)
  g:off(1)
  g:cycle(1)
end)

test("m:save names the callbacks it cannot keep; m:off leaves an output's alone; deep tables are skipped", function()
  local m = falling()
  local cb = m:on("after", function() end)
  local ev = m:on("contact_create", function() end)
  local dir = os.tmpname()
  os.remove(dir)
  assert(os.execute("mkdir " .. T.quote(dir)))
  local o = m:output{path = dir .. "/series.h5", every = 2}
  raises(function() m:off(ev + 1) end, HERE, "m:off: callback " .. (ev + 1) .. " is an output's, not the script's")
  local deep = {}
  local cur = deep
  for _ = 1, 1500 do cur[1] = {}; cur = cur[1] end
  m:vars().deep = deep
  local skipped = m:save(dir .. "/m.h5")
  local said = table.concat(skipped, "\n")
  check(said:find("callback " .. cb .. " (m:on's function", 1, true), said)
  check(said:find("event handler " .. ev .. " (m:on's function", 1, true), said)
  check(said:find("(tables nested deeper than 1000)", 1, true), said)
  eq(#skipped, 3)
  m:cycle(10)
  eq(o:count(), 6) -- the output wrote on
  o:close()
  local l = seixo.load(dir .. "/m.h5")
  local depth, t = 0, l:vars().deep
  while t do depth, t = depth + 1, t[1] end
  check(depth > 900 and depth < 1000, depth)
  os.execute("rm -rf " .. T.quote(dir))
end)

test("m:save in a callback: queued removals refused", function()
  local dir = os.tmpname()
  os.remove(dir)
  assert(os.execute("mkdir " .. T.quote(dir)))
  -- a removal queued in the callback takes effect when it returns: the
  -- file would have held the ball the run removes
  local q = falling()
  q:ball{pos = {1, 0, 100}, radius = 0.1}
  q:on("after", function(mm)
    if mm:step() == 2 then
      mm:ball(2):remove()
      mm:save(dir .. "/q.h5")
    end
  end)
  raises(function() q:cycle(3) end, HERE, "m:save: 1 removal(s) queued in this callback", "save after it")
  os.execute("rm -rf " .. T.quote(dir))
end)

test("m:solve says when the ratio stays infinite, which no ratio limit can end", function()
  -- a free fall: no contact, the ratio infinite; m:solve{ratio =} alone ran for ever, silently
  local script = "seixo.progress(false) local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}} " ..
                 "m:material('s', {kn = 1e6, ks = 1e6}) m:ball{pos = {0, 0, 0}, radius = 0.01} " ..
                 "print(m:solve{ratio = 1e-5, steps = 120000})"
  local status, out = T.run("-e " .. T.quote(script))
  eq(status, 0, out)
  check(out:find("the unbalanced-force ratio has been infinite for 100000 steps", 1, true), out)
  check(out:find("steps\tinf\t120000", 1, true), out)
end)

T.done()
