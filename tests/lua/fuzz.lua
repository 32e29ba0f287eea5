-- Fuzz: random and malformed arguments (wrong types, NaN, infinities,
-- huge and negative numbers, unknown keys, nested junk, handles of other
-- or closed models) thrown at every function of the seixo module, every
-- method and field of models, balls, walls and contacts, and the pure-Lua
-- library. Every call must either succeed or fail with a clean Lua error:
-- a string carrying this script's position. A crash, a hang or a
-- sanitizer report fails the test (the suite also runs it under
-- -Db_sanitize=address,undefined).
--   FUZZ_SEED=n FUZZ_ROUNDS=n build/seixo tests/lua/fuzz.lua
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local util = require("seixo.util")

local seed = tonumber(os.getenv("FUZZ_SEED")) or 20260101
local rounds = tonumber(os.getenv("FUZZ_ROUNDS")) or 60
math.randomseed(seed)
local function pick(list) return list[math.random(#list)] end

local checks, bad = 0, 0
local function report(what, err)
  bad = bad + 1
  if bad <= 20 then io.stderr:write("FAIL ", what, ": ", tostring(err), "\n") end
end

---------------------------------------------------------------- junk

-- every key the API knows, so that junk tables reach deep into the parsers
local keys = {"dim", "gravity", "timestep", "timestep_safety", "skin", "kn", "ks", "friction", "density", "damping",
              "viscous_normal", "viscous_shear", "model", "shear_modulus", "poisson", "modulus", "stiffness_ratio",
              "bond", "pos", "radius", "vel", "spin", "material", "group", "kind", "point", "normal", "corner",
              "edge1", "edge2", "p1", "p2", "min", "max", "count", "porosity", "distribution", "psd", "mean", "std",
              "region", "seed", "method", "packing", "tries", "relax", "steps", "ratio", "calm", "time", "every",
              "where", "box", "sphere", "cylinder", "disk", "polygon", "center", "fix", "applied_force",
              "applied_moment", "ball", "wall", "field", "component", "gap", "materials", "fricton", "template",
              "scale", "orientation", "axis", "angle", "lines", 1, 2, 3}
local words = {"", "x", "rock", "auto", "cycle", "after", "before", "box", "plane", "line", "rect", "segment",
               "pos", "vel", "radius", "kinetic", "time", "ratio", "uniform", "normal", "lognormal", "random", "distribute",
               "expand", "lattice", "hex", "fcc", "square", "cubic", "vx", "all", "spin", "ball-ball", "top",
               "linear", "hertz", "parallel", "contact", "tension", "pair", string.rep("z", 300), "a,b", "\0"}
local numbers = {0, 1, -1, 2, 3, 7, 0.5, -0.5, 100, 2 ^ 31, 2 ^ 53, 1e300, -1e300, 1e-320, math.huge, -math.huge,
                 0 / 0, -0.0, math.maxinteger, math.mininteger, 1e-3, 0.01, 0.1}

local handles = {}  -- balls, walls, models gathered on the way (some removed or closed)
local function junk_function(level)
  local r = math.random(4)
  if r == 1 then return function() error("junk failure") end end
  if r == 2 then return function() return true end end
  if r == 3 then return function() return 0.5 end end
  return function(...) return pick({nil, 1, "x", {}, false}) end
end

local junk
local function junk_table(level)
  local t = {}
  local shape = math.random(6)
  if shape == 1 then  -- a vector, maybe of the wrong size or type
    for k = 1, math.random(0, 4) do t[k] = math.random(5) == 1 and junk(level + 1) or pick(numbers) end
  elseif shape == 2 then  -- a region-like table
    t[pick({"box", "sphere", "cylinder", "disk", "polygon", "cube"})] = junk(level + 1)
  elseif shape == 3 then  -- a pair of vectors
    t[1] = {pick(numbers), pick(numbers), pick(numbers)}
    t[2] = {pick(numbers), pick(numbers)}
  else  -- known keys with junk values
    for _ = 1, math.random(0, 6) do t[pick(keys)] = junk(level + 1) end
  end
  if math.random(40) == 1 then  -- a metatable whose every access fails
    setmetatable(t, {__index = function() error("junk index") end, __newindex = function() error("junk newindex") end,
                     __len = function() error("junk len") end})
  end
  return t
end

function junk(level)
  level = level or 0
  local r = math.random(level > 2 and 6 or 9)
  if r == 1 then return nil end
  if r == 2 then return math.random(2) == 1 end
  if r <= 4 then return pick(numbers) end
  if r == 5 then return pick(words) end
  if r == 6 then return #handles > 0 and pick(handles) or io.stdout end
  if r == 7 then return junk_function(level) end
  return junk_table(level)
end

local function junk_args()
  local args, n = {}, math.random(0, 4)
  for i = 1, n do args[i] = junk() end
  return args, n
end

---------------------------------------------------------------- calling

-- Calls fn from a Lua frame of this file (not a tail call), so that errors
-- carry this script's position; checks the outcome.
local profile = os.getenv("FUZZ_PROFILE") and {}
local trace = os.getenv("FUZZ_TRACE")
local model_mt = debug.getregistry()["seixo.model"]

local function call(what, fn, args, n)
  if trace then
    local shown = {}
    for i = 1, n do shown[i] = util.show(args[i], 3) end
    io.stderr:write(what, "(", table.concat(shown, ", "), ")\n")
    io.stderr:flush()
  end
  local t0 = profile and os.clock()
  local ok, err = pcall(function()
    local r = fn(table.unpack(args, 1, n))
    return r
  end)
  checks = checks + 1
  if profile then
    local key = what:match("^[%w_.:]+")
    profile[key] = (profile[key] or 0) + os.clock() - t0
  end
  if not ok then
    if type(err) ~= "string" then
      report(what, "non-string error: " .. tostring(err))
    elseif not err:find("fuzz.lua:%d+:") then
      report(what, "no script position: " .. err)
    end
  end
end

-- files go to a scratch directory, never where the test runs
local scratch = os.tmpname()
os.remove(scratch)
assert(os.execute("mkdir -p " .. T.quote(scratch)))
local serial = 0
local function scratch_path()
  serial = serial + 1
  return scratch .. "/f" .. serial .. pick({".h5", ".csv", "", ".xmf"})
end

-- Every function that takes a file name gets a wrapper, for the whole run,
-- that turns any string or number argument, and any `path` key, into a
-- scratch file: however junk reaches them, no file lands elsewhere.
local function scratch_only(tbl, name)
  local f = rawget(tbl, name)
  if type(f) ~= "function" then return end
  rawset(tbl, name, function(...)
    local args = table.pack(...)
    for i = 1, args.n do
      local v = args[i]
      if type(v) == "string" or type(v) == "number" then args[i] = scratch_path() end
      if type(v) == "table" and rawget(v, "path") ~= nil then rawset(v, "path", scratch_path()) end
    end
    local r = table.pack(f(table.unpack(args, 1, args.n)))
    return table.unpack(r, 1, r.n)
  end)
end
local model_class = debug.getregistry()["seixo.model"].__methods
for _, name in ipairs({"save", "history_csv", "output"}) do scratch_only(model_class, name) end
for _, name in ipairs({"load", "xdmf"}) do scratch_only(seixo, name) end

-- bound the methods that run the clock: junk must not start an endless
-- cycle (raw access: a junk table's metatable must not get in the way)
local function tame(name, args, n)
  for i = 1, n do
    local v = args[i]
    local t = type(v) == "table"
    if name == "cycle" or name == "solve" then
      if type(v) == "number" and v > 50 then args[i] = 50 end
      if t then rawset(v, "steps", math.random(0, 50)) end
    elseif name == "generate" and t then
      rawset(v, "relax", false)
      rawset(v, "tries", 20)
      -- at most a few thousand balls (a porosity alone could ask for ten million)
      local count = rawget(v, "count")
      if type(count) == "number" and count > 2000 and count < math.huge then rawset(v, "count", 2000) end
      if count == nil and (rawget(v, "porosity") ~= nil or rawget(v, "method") == "lattice" or rawget(v, "packing") ~= nil) then
        rawset(v, "count", math.random(0, 100))
      end
    end
  end
  if name == "solve" and args[1] == nil then args[1] = {steps = math.random(0, 50)} end  -- solve() waits for a ratio
end

local function fresh_model(dim)
  local m = seixo.model{dim = dim, timestep = 1e-6}
  m:material("rock")
  local z = dim == 3 and {0, 0, 0} or {0, 0}
  local b = m:ball{pos = z, radius = 0.1, group = "top"}
  local b2 = m:ball{pos = dim == 3 and {0.15, 0, 0} or {0.15, 0}, radius = 0.1}
  local box = m:wall{kind = "box", min = dim == 3 and {-1, -1, -1} or {-1, -1}, max = dim == 3 and {1, 1, 1} or {1, 1}}
  m:clump_template("pair", dim == 3 and {{0, 0, 0, 0.05}, {0.06, 0, 0, 0.05}} or {{0, 0, 0.05}, {0.06, 0, 0.05}})
  local cl = m:clump{template = "pair", pos = dim == 3 and {0.5, 0.5, 0.5} or {0.5, 0.5}}
  m:history("ke", "kinetic")
  m:cycle(2)
  handles[#handles + 1] = b
  handles[#handles + 1] = b2
  handles[#handles + 1] = box[1]
  handles[#handles + 1] = cl
  handles[#handles + 1] = m
  if #handles > 200 then table.remove(handles, 1) end
  return m, b, box[1], cl
end

local function class(name) return debug.getregistry()[name] end

local function names(t)
  local list = {}
  for k in pairs(t or {}) do list[#list + 1] = k end
  table.sort(list)
  return list
end

local model_methods = names(class("seixo.model").__methods)
local ball_methods = names(class("seixo.ball").__methods)
local wall_methods = names(class("seixo.wall").__methods)
local clump_methods = names(class("seixo.clump").__methods)
local fields = {
  ball = {get = names(class("seixo.ball").__getters), set = names(class("seixo.ball").__setters)},
  wall = {get = names(class("seixo.wall").__getters), set = names(class("seixo.wall").__setters)},
  contact = {get = names(class("seixo.contact").__getters), set = {}},
  clump = {get = names(class("seixo.clump").__getters), set = names(class("seixo.clump").__setters)},
}
assert(#model_methods > 40 and #fields.ball.set > 8, "the classes are found")

---------------------------------------------------------------- rounds

for round = 1, rounds do
  local dim = round % 2 == 0 and 3 or 2
  local m, b, w, cl = fresh_model(dim)
  -- the module
  for _, name in ipairs(names(seixo)) do
    if type(seixo[name]) == "function" then
      for _ = 1, 3 do
        local args, n = junk_args()
        tame(name, args, n)
        call("seixo." .. name, seixo[name], args, n)
      end
    end
  end
  seixo.progress(false)
  -- model methods, on this model and on junk selves
  for _, name in ipairs(model_methods) do
    for _ = 1, name == "close" and 0 or 4 do
      local args, n = junk_args()
      tame(name, args, n)
      n = math.max(n, #args)
      table.insert(args, 1, m)
      call("model:" .. name, m[name], args, n + 1)
    end
    local args, n = junk_args()
    if getmetatable(args[1]) == model_mt then  -- a real self after all: tame the rest
      local rest = {table.unpack(args, 2, n)}
      tame(name, rest, n - 1)
      n = math.max(n, #rest + 1)
      for i = 2, n do args[i] = rest[i - 1] end
    end
    call("model:" .. name .. " (junk self)", class("seixo.model").__methods[name], args, n)
  end
  -- ball and wall methods and fields
  local objects = {{"ball", b, ball_methods}, {"wall", w, wall_methods}, {"clump", cl, clump_methods}}
  for _, o in ipairs(objects) do
    local kind, obj, methods = o[1], o[2], o[3]
    for _, name in ipairs(methods) do
      local args, n = junk_args()
      table.insert(args, 1, obj)
      if name ~= "remove" or math.random(10) == 1 then call(kind .. ":" .. name, class("seixo." .. kind).__methods[name], args, n + 1) end
    end
    for _, f in ipairs(fields[kind].set) do
      call(kind .. "." .. f .. " =", function(v) obj[f] = v end, {junk()}, 1)
    end
    for _, f in ipairs(fields[kind].get) do call(kind .. "." .. f, function() return obj[f] end, {}, 0) end
    call(kind .. "[junk]", function(k) return obj[k] end, {junk()}, 1)
    call(kind .. "[junk] =", function(k, v) obj[k] = v end, {junk(), junk()}, 2)
  end
  -- contacts
  local ok, it = pcall(m.contacts, m)
  for c in ok and it or function() end do
    for _, f in ipairs(fields.contact.get) do call("contact." .. f, function() return c[f] end, {}, 0) end
    call("contact[junk] =", function(k, v) c[k] = v end, {junk(), junk()}, 2)
  end
  -- callbacks and histories with junk functions, run by a short cycle
  call("m:on junk", m.on, {m, pick({"cycle", "before", "after"}), junk_function(0), {every = math.random(3)}}, 4)
  call("m:history junk", m.history, {m, "h" .. round, junk_function(0)}, 3)
  call("m:cycle with junk callbacks", m.cycle, {m, 4}, 2)
  -- the pure-Lua library
  for _, name in ipairs(names(util)) do
    local args, n = junk_args()
    if name ~= "print" then call("util." .. name, util[name], args, n) end
  end
  -- a closed model: everything is an error, never a crash
  if round % 5 == 0 then
    m:close()
    for _, name in ipairs(model_methods) do
      local args, n = junk_args()
      table.insert(args, 1, m)
      tame(name, args, n + 1)
      call("closed model:" .. name, m[name], args, n + 1)
    end
    for _, f in ipairs(fields.ball.get) do call("closed ball." .. f, function() return b[f] end, {}, 0) end
    call("closed tostring", tostring, {b}, 1)
  end
  if round % 10 == 0 then collectgarbage() end
end

-- the garbage collector finalises models with live handles, callbacks and histories
handles = {}
collectgarbage()
collectgarbage()
os.execute("rm -rf " .. T.quote(scratch))

if profile then
  local list = {}
  for k, v in pairs(profile) do list[#list + 1] = {k, v} end
  table.sort(list, function(a, b) return a[2] > b[2] end)
  for i = 1, math.min(10, #list) do io.stderr:write(string.format("%-30s %.3f s\n", list[i][1], list[i][2])) end
end
print(string.format("%d passed, %d failed", checks - bad, bad))
if bad > 0 then os.exit(1) end
