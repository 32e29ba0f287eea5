-- Lua-level tests of files: m:save, seixo.load, m:vars, m:output, seixo.xdmf.
--   build/seixo tests/io/io.lua
local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
local T = dofile(here .. "../lua/harness.lua")

local tmp = os.tmpname()
os.remove(tmp)
local function path(name) return tmp .. "-" .. name end
local made = {}
local function file(name) local p = path(name); made[#made + 1] = p; return p end

local function scene(dim)
  local g = dim == 3 and {0, 0, -9.81} or {0, -9.81}
  local m = seixo.model{dim = dim, gravity = g}
  m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, density = 2600, damping = 0.2})
  m:wall{kind = dim == 3 and "plane" or "line", point = dim == 3 and {0, 0, 0} or {0, 0},
         normal = dim == 3 and {0, 0, 1} or {0, 1}}
  for i = 1, 30 do
    local p = dim == 3 and {0.009 * (i % 5), 0.009 * ((i // 5) % 3), 0.005 + 0.009 * (i // 15)}
                        or {0.009 * (i % 6), 0.005 + 0.009 * (i // 6)}
    local b = m:ball{pos = p, radius = 0.004 + 0.0002 * (i % 3)}
    if i % 4 == 0 then b.group = "top" elseif i % 4 == 1 then b.group = "bottom" end
    if i == 7 then b.extra = {tag = "probe", n = 7} end
  end
  return m
end

T.test("a loaded model continues bit-for-bit, in 2D and 3D", function()
  for _, dim in ipairs{2, 3} do
    local a, b = scene(dim), scene(dim)
    a:cycle(400)
    b:cycle(200)
    b:save(file("restart" .. dim .. ".h5"))
    local c = seixo.load(path("restart" .. dim .. ".h5"))
    T.eq(c:hash(), b:hash())
    T.eq(c:step(), 200)
    T.eq(c:dim(), dim)
    c:cycle(200)
    T.eq(c:hash(), a:hash(), dim .. "D")
  end
end)

T.test("variables, groups and extras come back", function()
  local m = scene(2)
  local v = m:vars()
  v.target = 1.5e6
  v.count = 42
  v.big = math.maxinteger
  v.name = "sample A"
  v.bytes = "a\0b\255"
  v.flag = false
  v.nested = {list = {1, 2.5, "three", {deep = true}}, [true] = "yes", [2.5] = "half"}
  v.nan, v.inf = 0 / 0, math.huge
  v.fn = print                          -- code is not data: skipped
  v.shared = v.nested.list              -- a table met twice: skipped the second time
  local skipped = m:save(file("vars.h5"))
  T.eq(#skipped, 2)
  local all = table.concat(skipped, "; ")
  T.check(all:find("vars.fn (function)", 1, true), all)
  T.check(all:find("already saved", 1, true), all)

  local c = seixo.load(path("vars.h5"))
  local w = c:vars()
  T.eq(w.target, 1.5e6)
  T.eq(math.type(w.target), "float")
  T.eq(w.count, 42)
  T.eq(math.type(w.count), "integer")
  T.eq(w.big, math.maxinteger)
  T.eq(w.name, "sample A")
  T.eq(w.bytes, "a\0b\255")
  T.eq(w.flag, false)
  T.eq(w.nested[true], "yes")
  T.eq(w.nested[2.5], "half")
  T.check(w.nan ~= w.nan and w.inf == math.huge)
  T.eq(w.fn, nil)
  local list = w.nested.list or w.shared
  T.eq(#list, 4)
  T.eq(list[3], "three")
  T.eq(list[4].deep, true)
  -- groups by name, and a ball's extras
  T.eq(c:groups().top, m:groups().top)
  T.eq(c:ball(7).extra.tag, "probe")
  T.eq(c:ball(8).group, "top")
  T.eq(c:count{group = "bottom"}, m:count{group = "bottom"})
end)

T.test("the balls' displacement references come back (an MPI user's finding)", function()
  for _, dim in ipairs{2, 3} do
    local a, b = scene(dim), scene(dim)
    a:reset_disp{group = "top"}
    b:reset_disp{group = "top"}
    a:cycle(300)
    b:cycle(150)
    b:save(file("disp" .. dim .. ".h5"))
    local c = seixo.load(path("disp" .. dim .. ".h5"))
    c:cycle(150)
    -- (the balls outside the reset took theirs when the next cycle began)
    for ball in a:balls() do
      local d = ball.disp
      T.check(d:norm() > 0, "it moved")
      T.eq(c:ball(ball.id).disp, d, dim .. "D ball " .. ball.id)
    end
  end
  -- a model that never reset them: no reference after a load
  local m = scene(3)
  m:save(file("nodisp.h5"))
  local c = seixo.load(path("nodisp.h5"))
  c:cycle(10)
  local ok, err = pcall(function() return c:ball(1).disp end)
  T.check(not ok and err:find("no reference position yet", 1, true), tostring(err))
end)

T.test("bad files give one-line errors naming the file", function()
  local m = scene(2)
  m:save(file("two.h5"))
  T.raises(function() seixo.load(path("missing.h5")) end, path("missing.h5"), "no such file")
  T.raises(function() seixo.load(path("two.h5"), {dim = 3}) end, "holds a 2D model, but a 3D one was asked for")
  local f = io.open(file("text.h5"), "w"); f:write("not a snapshot\n"); f:close()
  T.raises(function() seixo.load(path("text.h5")) end, "not an HDF5 file")
  local whole = io.open(path("two.h5"), "rb"):read("a")
  f = io.open(file("cut.h5"), "wb"); f:write(whole:sub(1, #whole // 2)); f:close()
  T.raises(function() seixo.load(path("cut.h5")) end, "truncated")
  T.raises(function() m:save("/nonexistent-folder/x.h5") end, "cannot create a file in its folder")
  T.raises(function() m:save(path("x.h5"), {compression = 12}) end, "compression")
  T.raises(function() seixo.load(path("two.h5"), {dim = 4}) end, "dim")
  local err = T.raises(function() seixo.load(path("missing.h5")) end)
  T.check(not err:find("\n"), "a multi-line message")
end)

T.test("an output series: every N steps, fields, append, xdmf", function()
  local m = scene(3)
  local o = m:output{path = file("series.h5"), every = 50, fields = {"radius", "velocity", "contacts", "walls"},
                     compression = 3}
  made[#made + 1] = path("series.xmf")
  T.eq(o:count(), 1)                    -- the state when the output starts
  m:cycle(120)
  T.eq(o:count(), 3)                    -- and steps 50, 100
  T.check(tostring(o):find("every 50 steps", 1, true))
  o:close()
  o:close()                             -- closing twice is harmless
  m:cycle(50)                           -- a closed output records nothing more
  local x = io.open(path("series.xmf")):read("a")
  local n = 0
  for _ in x:gmatch("/balls/vertices</DataItem>") do n = n + 1 end  -- the balls' grid of each snapshot
  T.eq(n, 3)
  -- continued after a restart
  m:save(file("mid.h5"))
  local c = seixo.load(path("mid.h5"))
  local o2 = c:output{path = path("series.h5"), every = 50, append = true}
  T.eq(o2:count(), 4)
  c:cycle(100)
  T.eq(o2:count(), 6)
  o2:close()
  seixo.xdmf(path("series.h5"))
  n = 0
  for _ in io.open(path("series.xmf")):read("a"):gmatch("/balls/vertices</DataItem>") do n = n + 1 end
  T.eq(n, 6)
  -- a model from a save older than the series' end (step 170; the series
  -- ends at 250): an error, the series as it was (its snapshots had gone
  -- on at steps 170, 200, ... after that of 250, their times going back)
  local old = seixo.load(path("mid.h5"))
  local bytes = io.open(path("series.h5"), "rb"):read("a")
  T.raises(function() old:output{path = path("series.h5"), every = 50, append = true} end,
           "holds snapshots up to step 250, later than this model's step 170")
  T.check(io.open(path("series.h5"), "rb"):read("a") == bytes, "the refused append changed the file")
  n = 0
  for _ in io.open(path("series.xmf")):read("a"):gmatch("/balls/vertices</DataItem>") do n = n + 1 end
  T.eq(n, 6)
  T.eq(c:output{path = path("series.h5"), every = 50, append = true}:count(), 7) -- the model at its end goes on
  -- a history's samples past the last snapshot count too (written at close)
  local t = seixo.model{dim = 3, timestep = 1e-5}
  t:material("rock")
  t:ball{pos = {0, 0, 0}, radius = 0.01}
  t:history("ke", "kinetic")
  local ot = t:output{path = file("tails.h5"), every = 50}
  made[#made + 1] = path("tails.xmf")
  t:cycle(110)
  t:save(file("tails_110.h5"))
  t:cycle(10)
  ot:close()
  T.raises(function() seixo.load(path("tails_110.h5")):output{path = path("tails.h5"), every = 50, append = true} end,
           "holds histories up to step 120, later than this model's step 110")
  T.raises(function() m:output{path = path("o.h5"), fields = {"colour"}} end, "unknown field 'colour'", "velocity")
  T.raises(function() m:output{every = 5} end, "path")
  T.raises(function() m:output{path = path("o.h5"), every = 0} end, "every")
  do
    local o3 <close> = m:output{path = file("closing.h5"), every = 10}
    made[#made + 1] = path("closing.xmf")
    m:cycle(20)
    T.eq(o3:count(), 3)
  end
end)

-- The values of a dataset or attribute, read by h5dump (nil when h5dump is
-- missing): what any HDF5 tool sees, not what seixo reads back. A series
-- being written is open in this process, and HDF5 1.10 locks a file open
-- for writing: h5dump reads it without taking the lock.
local has_h5dump = os.execute("command -v h5dump > /dev/null 2>&1")
local function h5values(file_path, what, attribute)
  if not has_h5dump then return nil end
  local p = io.popen("HDF5_USE_FILE_LOCKING=FALSE h5dump " .. (attribute and "-a " or "-d ") .. T.quote(what) .. " -y -w 0 -m '%.17g' " .. T.quote(file_path) .. " 2>&1")
  local out = p:read("a")
  p:close()
  local data = out:match("DATA {(.-)}")
  T.check(data, out)
  local v = {}
  for x in data:gsub("%(%d+%):", ""):gmatch("[^,%s]+") do v[#v + 1] = tonumber(x) end
  return v
end

local function same_history(a, b, name)
  local ra, rb = a:history(name), b:history(name)
  T.eq(#rb.steps, #ra.steps, name)
  for i = 1, #ra.steps do
    T.eq(rb.steps[i], ra.steps[i], name)
    T.eq(rb.times[i], ra.times[i], name)
    T.eq(rb.values[i], ra.values[i], name)
  end
end

T.test("histories are saved with the model and keep recording, bit-for-bit", function()
  for _, dim in ipairs{2, 3} do
    local function histories(m)
      m:history("ke", "kinetic", {every = 7})
      m:history("z7", {ball = 7, field = "pos", component = dim}, {every = 5})
      m:history("wall force", {wall = 1, field = "force", component = dim}, {every = 3})
      m:history("twice", function(mm) return 2 * mm:step() end, {every = 10})
    end
    local a, b = scene(dim), scene(dim)
    histories(a)
    histories(b)
    a:cycle(400)
    b:cycle(200)
    local skipped = b:save(file("hist" .. dim .. ".h5"))
    T.eq(#skipped, 1)
    T.check(skipped[1]:find("history 'twice' (its function", 1, true), skipped[1])
    local c = seixo.load(path("hist" .. dim .. ".h5"))
    T.vec_eq(c:histories(), {"ke", "z7", "wall force", "twice"})
    T.eq(c:history("twice").detached, true)
    T.eq(c:history("twice").every, 10)
    T.eq(#c:history("twice").steps, 20)
    T.raises(function() c:history("twice", "time") end, "a history named 'twice' exists")
    local d = seixo.load(path("hist" .. dim .. ".h5"))
    c:history("twice", function(mm) return 2 * mm:step() end)  -- its function again, its every kept
    T.eq(c:history("twice").detached, nil)
    c:cycle(200)
    d:cycle(200)
    T.eq(c:hash(), a:hash())
    for _, name in ipairs{"ke", "z7", "wall force", "twice"} do same_history(a, c, name) end
    -- a detached history records nothing; the others go on
    T.eq(#d:history("twice").steps, 20)
    same_history(a, d, "ke")
  end
end)

T.test("an output series grows the histories as the run goes", function()
  local m = scene(3)
  m:history("ke", "kinetic", {every = 7})
  local o = m:output{path = file("grow.h5"), every = 50}
  made[#made + 1] = path("grow.xmf")
  m:cycle(120)
  local steps = h5values(path("grow.h5"), "/histories/ke/step")
  -- written with the snapshot of step 100: the samples up to it
  if steps then T.vec_eq(steps, {7, 14, 21, 28, 35, 42, 49, 56, 63, 70, 77, 84, 91, 98}) end
  m:history("late", "step", {every = 40})
  m:cycle(40)
  o:close()                              -- the samples since the last snapshot (150) too
  steps = h5values(path("grow.h5"), "/histories/ke/step")
  if steps then
    T.eq(#steps, 22)
    T.eq(steps[22], 154)
    T.vec_eq(h5values(path("grow.h5"), "/histories/late/value"), {160})
    T.vec_eq(h5values(path("grow.h5"), "/histories/ke/value"), m:history("ke").values)
  else
    print("  (h5dump missing: the series' datasets not checked)")
  end
  -- a restart that appends to the series continues its histories
  m:save(file("grow-mid.h5"))
  local c = seixo.load(path("grow-mid.h5"))
  local o2 = c:output{path = path("grow.h5"), every = 50, append = true}
  c:cycle(100)
  o2:close()
  steps = h5values(path("grow.h5"), "/histories/ke/step")
  if steps then
    T.eq(#steps, #c:history("ke").steps)
    for i = 2, #steps do T.check(steps[i] > steps[i - 1], "steps increase") end
    T.vec_eq(h5values(path("grow.h5"), "/histories/ke/value"), c:history("ke").values)
  end
end)

T.test("the seeds of m:generate and m:bond are the files' provenance", function()
  local m = seixo.model{dim = 2}
  m:material("rock", {kn = 1e6, ks = 1e6, friction = 0.5, density = 2600,
                      bond = {radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 2,
                              tensile_strength = 1e6, tensile_strength_sd = 1e5, cohesion = 1e6}})
  m:generate{count = 30, radius = {0.004, 0.005}, region = {box = {{0, 0}, {0.1, 0.1}}}, seed = 7}
  m:generate{count = 10, radius = 0.004, region = {box = {{0.2, 0}, {0.3, 0.1}}}, seed = 7}
  m:generate{count = 10, radius = 0.004, region = {box = {{0.4, 0}, {0.5, 0.1}}}}  -- the default seed, 1
  m:bond{gap = 1e-3, seed = 424242}
  m:save(file("seeds.h5"))
  local o = m:output{path = file("seeds-series.h5")}
  made[#made + 1] = path("seeds-series.xmf")
  o:close()
  local seeds = h5values(path("seeds.h5"), "/seeds", true)
  if seeds then
    T.vec_eq(seeds, {7, 1, 424242})
    T.vec_eq(h5values(path("seeds-series.h5"), "/seeds", true), {7, 1, 424242})
  end
  -- a loaded model keeps them, and adds its own
  local c = seixo.load(path("seeds.h5"))
  c:generate{count = 5, radius = 0.004, region = {box = {{0.6, 0}, {0.7, 0.1}}}, seed = 99}
  c:save(file("seeds2.h5"))
  if seeds then T.vec_eq(h5values(path("seeds2.h5"), "/seeds", true), {7, 1, 424242, 99}) end
end)

T.test("history_csv quotes names, writes under a unique temporary name", function()
  local util = require("seixo.util")
  local m = scene(2)
  m:history('a,"b"', "time", {every = 5})
  m:history("line\nbreak", "step", {every = 10})
  m:cycle(20)
  local csv_path = file("h.csv")
  -- a stale file where an older seixo put its temporary: left alone
  local stale = io.open(csv_path .. ".tmp", "w"); stale:write("stale"); stale:close()
  made[#made + 1] = csv_path .. ".tmp"
  m:history_csv(csv_path)
  local text = io.open(csv_path):read("a")
  T.eq(text:sub(1, #'step,time,"a,""b""","line\nbreak"\n'), 'step,time,"a,""b""","line\nbreak"\n')
  local csv = util.read_csv(csv_path)
  T.vec_eq(csv.header, {"step", "time", 'a,"b"', "line\nbreak"})
  T.vec_eq(csv.columns.step, {5, 10, 15, 20})
  T.eq(csv.columns["line\nbreak"][2], 10)
  T.eq(csv.columns["line\nbreak"][1], nil)
  T.eq(io.open(csv_path .. ".tmp"):read("a"), "stale")
  local dir, base = csv_path:match("^(.*)/([^/]*)$")
  local ls = io.popen("ls -a " .. T.quote(dir)):read("a")
  T.check(not ls:find("." .. base .. ".tmp-", 1, true), "a temporary file left behind")
  T.raises(function() m:history("a/b", "time") end, "without '/'")
  T.raises(function() m:history(".", "time") end, "not \".\"")
end)

-- issue 18: a script that ends with an output still open: its last samples
-- are written while Lua closes, and nothing leaks (the sanitizer run's
-- LeakSanitizer once found the histories handed to the writer: 88 bytes)
T.test("an output left open at the end of the script", function()
  local series = file("left_open.h5")
  file("left_open.xmf")
  local status, out = T.run("-e " .. T.quote([[
    local m = seixo.model{dim = 2} m:material("r") m:ball{pos = {0, 0}, radius = 0.1}
    m:history("ke", "kinetic")
    open_output = m:output{path = ]] .. string.format("%q", series) .. [[, every = 1}
    m:cycle(3)]]))
  T.eq(status, 0, out)
  T.eq(out, "")
  T.check(io.open(series) ~= nil, "the series was written")
end)

for _, p in ipairs(made) do os.remove(p) end
T.done()
