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
  for _ in x:gmatch("<Time Value=") do n = n + 1 end
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
  for _ in io.open(path("series.xmf")):read("a"):gmatch("<Time Value=") do n = n + 1 end
  T.eq(n, 6)
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

for _, p in ipairs(made) do os.remove(p) end
T.done()
