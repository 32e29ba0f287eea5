-- The pure-Lua library (lua/seixo/*.lua): seixo.util's vectors, printer and
-- CSV reader, loaded with require through the path the executable sets.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, near, raises = T.test, T.check, T.eq, T.near, T.raises
local HERE = "lualib.lua:"

local util = require("seixo.util")

test("require finds the library", function()
  eq(package.loaded["seixo.util"], util)
  check(package.searchpath("seixo.util", package.path):find("lua/seixo/util.lua", 1, true))
  eq(require("seixo.util"), util)
  eq(type(require("seixo.help").text), "function")
end)

test("vector arithmetic in 2D and 3D", function()
  T.vec_eq(util.add({1, 2, 3}, {4, 5, 6}), {5, 7, 9})
  T.vec_eq(util.sub({1, 2}, {4, 6}), {-3, -4})
  T.vec_eq(util.scale({1, -2, 3}, 2), {2, -4, 6})
  eq(util.dot({1, 2, 3}, {4, 5, 6}), 32)
  T.vec_eq(util.cross({1, 0, 0}, {0, 1, 0}), {0, 0, 1})
  T.vec_eq(util.cross({0, 1, 0}, {1, 0, 0}), {0, 0, -1})
  eq(util.cross({1, 0}, {0, 1}), 1)
  eq(util.cross({2, 3}, {4, 6}), 0)
  eq(util.norm({3, 4}), 5)
  eq(util.norm({2, 3, 6}), 7)
  eq(util.dist({1, 1, 1}, {3, 4, 7}), 7)
  T.vec_eq(util.normalize({0, 3, 4}), {0, 0.6, 0.8})
  T.vec_eq(util.lerp({0, 0}, {10, 20}, 0.25), {2.5, 5})
  local mean, sd = util.mean_sd({2, 4, 9})
  eq(mean, 5)
  eq(sd, math.sqrt((9 + 1 + 16) / 2))
  eq(select(2, util.mean_sd({7})), 0)
  eq(util.mean_sd({}), nil)
  raises(function() util.mean_sd({1, "2"}) end, HERE, "element 2 is a string")
  -- arguments are never changed
  local a, b = {1, 2, 3}, {1, 1, 1}
  util.add(a, b)
  util.scale(a, 3)
  T.vec_eq(a, {1, 2, 3})
  -- a ball's vectors work as they come
  local m = T.model(3)
  local p = m:ball{pos = {1, 2, 3}, radius = 0.1}
  local q = m:ball{pos = {1, 2, 5}, radius = 0.1}
  eq(util.dist(p.pos, q.pos), 2)
end)

test("vector errors name the function, the argument and the caller's line", function()
  raises(function() util.add({1, 2}, {1, 2, 3}) end, HERE, "util.add", "2 and 3 components")
  raises(function() util.add({1, 2, 3}, "x") end, HERE, "bad argument 'b' to 'util.add'", "got string")
  raises(function() util.dot({1, "2"}, {1, 2}) end, HERE, "'a'", "component 2: number expected")
  raises(function() util.scale({1, 2}, "2") end, HERE, "bad argument 's' to 'util.scale'")
  raises(function() util.norm({1, 2, 3, 4}) end, HERE, "vector of 2 or 3 numbers")
  raises(function() util.normalize({0, 0, 0}) end, HERE, "zero vector")
  raises(function() util.lerp({0, 0}, {1, 1}) end, HERE, "bad argument 't'")
end)

test("show prints any value readably", function()
  eq(util.show(1), "1")
  eq(util.show("a\"b"), '"a\\"b"')
  eq(util.show({1, 2, {3}}), "{1, 2, {3}}")
  eq(util.show({b = 1, a = {x = true}, [3] = "c"}), '{[3] = "c", a = {x = true}, b = 1}')
  eq(util.show({["key with space"] = 1}), '{["key with space"] = 1}')
  local t = {}
  t.self = t
  eq(util.show(t), "{self = <cycle>}")
  eq(util.show({{{{{1}}}}}, 2), "{{{...}}}")
  eq(util.show({}), "{}")
  -- long tables break over lines
  local long = {}
  for i = 1, 30 do long["field" .. i] = i end
  local text = util.show(long)
  check(text:find("\n  field1 = 1,", 1, true), text)
  -- objects print as themselves; metamethods are never run
  local m = T.model(2)
  check(util.show({m:ball{pos = {0, 0}, radius = 1}}):find("{seixo.ball 1 {pos = {0, 0}, radius = 1,", 1, true))
  local trap = setmetatable({1}, {__index = function() error("no") end, __len = function() error("no") end,
                                  __pairs = function() error("no") end})
  eq(util.show(trap), "{1}")
  raises(function() util.show({}, 1.5) end, HERE, "integer expected")
  -- a limit cuts each table, saying how long it was
  eq(util.show({1, 2, 3, 4, 5}, 4, 3), "{1, 2, 3, ... (5 entries)}")
  eq(util.show({a = 1, b = 2, c = {1, 2, 3}}, 4, 2), "{a = 1, b = 2, ... (3 entries)}")
  raises(function() util.show({}, 2, "x") end, HERE, "'limit'", "integer expected")
end)

test("read_csv reads what history_csv writes", function()
  local m = seixo.model{dim = 2, timestep = 1e-3, gravity = {0, -10}}
  m:material("a")
  m:ball{pos = {0, 1}, radius = 0.1}
  m:history("y", {ball = 1, field = "pos", component = "y"}, {every = 2})
  m:cycle(6)
  local path = os.tmpname()
  m:history_csv(path)
  local csv = util.read_csv(path)
  os.remove(path)
  T.vec_eq(csv.header, {"step", "time", "y"})
  eq(csv.rows, 3)
  T.vec_eq(csv.columns.step, {2, 4, 6})
  T.vec_eq(csv.columns.y, m:history("y").values)  -- %.17g round-trips exactly
  raises(function() util.read_csv("/nonexistent/file.csv") end, HERE, "util.read_csv")
  raises(function() util.read_csv(3) end, HERE, "string expected")
end)

test("seixo.pool: jobs in processes, the next started as soon as any ends; answers, deaths and errors", function()
  local pool = require("seixo.pool")
  -- exact numbers both ways
  local v = {1 / 3, -0.0, 2 ^ -1074, 7, "a'b\n", true, {x = {1e300}}, 0 / 0, math.huge}
  local back = pool.deserialize(pool.serialize(v))
  for i = 1, 7 do if i ~= 7 then eq(back[i], v[i]) end end
  eq(1 / back[2], -math.huge)
  eq(back[7].x[1], 1e300)
  check(back[8] ~= back[8] and back[9] == math.huge)
  raises(function() pool.serialize({print}) end, "cannot pass between processes")
  eq(pool.can_serve(), true) -- this is the seixo program
  local prefix = os.tmpname()
  -- two workers: job 1 long, 2 and 3 short: 3 starts when 2 ends and ends before 1
  local order, codes = {}, {}
  pool.run{jobs = {{s = 1.5}, {s = 0.05}, {s = 0.05}, {s = 0, code = 3}}, workers = 2, prefix = prefix,
           command = function(job_file)
             local e = pool.take(job_file)
             return string.format("sh -c 'sleep %g; exit %d'", e.job.s, e.job.code or 0)
           end,
           done = function(i, answer, output, code)
             order[#order + 1], codes[i] = i, code
             eq(answer, nil) -- these commands answer nothing
             eq(output, "")
           end}
  eq(table.concat(order, " "), "2 3 4 1")
  eq(codes[4], 3)
  eq(codes[1], 0)
  -- seixo workers calling a module's function: the value, or the error, comes back
  local got = {}
  pool.run{jobs = {{module = "seixo.util", call = "add", args = {{1, 2}, {0.5, 4}}},
                   {module = "seixo.util", call = "add", args = {{1, 2}, "x"}}},
           workers = 2, prefix = prefix, command = pool.serve_command,
           done = function(i, answer) got[i] = answer end}
  eq(got[1].ok, true)
  T.vec_eq(got[1].value, {1.5, 6})
  eq(got[2].ok, false)
  check(got[2].error:find("util.add", 1, true), got[2].error)
  -- a worker's files name this script as their provenance (seixo.script):
  -- a lab.series' test files named none when run in processes
  local script = seixo.script()
  check(script and script:find("lualib.lua", 1, true), tostring(script))
  pool.run{jobs = {{module = "seixo", call = "script", args = {}}}, workers = 1, prefix = prefix,
           command = pool.serve_command, done = function(i, answer) got[i] = answer end}
  eq(got[1].value, script)
  -- a done callback's error comes through, the jobs still running
  -- interrupted (seixo workers, which stop at a SIGINT) and waited for; no file is left
  local busy = pool.quote(seixo.executable()) .. " -e " .. pool.quote("local t = os.time() while os.time() - t < 60 do end")
  local began = os.time()
  raises(function()
    pool.run{jobs = {{s = 0}, {s = 0.2}}, workers = 2, prefix = prefix,
             command = function(job_file) return pool.take(job_file).job.s == 0 and "sleep 0" or busy end,
             done = function() error("stop here") end}
  end, "stop here")
  check(os.time() - began < 30, "the running worker was waited for to its end")
  -- a SIGINT to this process alone (not its group, as a terminal's Ctrl-C
  -- is: a batch scheduler's, `timeout`'s) stops the workers as well
  began = os.time()
  raises(function()
    os.execute("(sleep 1; kill -INT $PPID) &") -- (the shell's parent: this process)
    pool.run{jobs = {{}, {}}, workers = 2, prefix = prefix, command = function() return busy end,
             done = function() end}
  end, "interrupted")
  check(os.time() - began < 30, "the workers ran on after the interrupt")
  os.remove(prefix)
  local left = io.popen("ls " .. pool.quote(prefix) .. ".* 2>/dev/null"):read("a")
  eq(left, "")
end)

T.done()
