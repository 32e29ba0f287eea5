-- API fuzzer: every function, method and field documented in
-- docs/lua-api.md has a valid call below (the check at the start fails when
-- a documented one has none); each case takes one, made from a fresh small
-- scene, swaps one hostile value into it (an argument, a table field, a
-- vector component, a region's corner: NaN, infinities, -0, huge, tiny,
-- wrong types, failing or NaN-returning functions, nil) or none, and runs
-- it directly, inside a cycle's callback, or inside a history's function.
-- A case passes when the call succeeds or fails with a clean error (a
-- string naming this file's line), when no model is left with a non-finite
-- value (no silent NaN) and still cycles or refuses to with a clean error,
-- and when it ends within FUZZ_LIMIT seconds. A crash, a hang (the driver's
-- time limit), a leak or a sanitizer report fails the driver's run.
--   FUZZ_SEED=s FUZZ_FIRST=k FUZZ_COUNT=n [FUZZ_LOG=file] [FUZZ_LIMIT=s] seixo tests/fuzz/api.lua
-- Case k of seed s is made from (s, k) alone: FUZZ_FIRST=k FUZZ_COUNT=1
-- replays it. Run it from a scratch folder: hostile paths are relative.
-- tests/fuzz/driver.lua runs it in batches under a time limit.
local lab = require("seixo.lab")
local util = require("seixo.util")

local seed = tonumber(os.getenv("FUZZ_SEED")) or 1
local first = tonumber(os.getenv("FUZZ_FIRST")) or 1
local count = tonumber(os.getenv("FUZZ_COUNT")) or 100
local limit = tonumber(os.getenv("FUZZ_LIMIT")) or 30
local log = os.getenv("FUZZ_LOG") and assert(io.open(os.getenv("FUZZ_LOG"), "a"))
local docs = os.getenv("FUZZ_DOCS")
local HERE = "api.lua:"
seixo.progress(false)

local function pick(list) return list[math.random(#list)] end

---------------------------------------------------------------- the scene

local function V(c, x, y, z) return c.dim == 3 and {x, y, z} or {x, y} end
local function R(c, w) return c.dim == 3 and {w, 0, 0} or w end -- a rotational quantity

-- A small scene with everything an entry may need: two materials, touching
-- balls, a box, a clump, a group, a history, bonds, a few steps taken.
local function scene(dim)
  local c = {dim = dim, models = {}}
  local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}, timestep = 1e-5}
  c.m = m
  c.models[1] = m
  m:material("rock", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3,
                      bond = {normal_strength = 1e3, shear_strength = 1e3, tensile_strength = 1e6, cohesion = 1e6,
                              modulus = 1e8, radius_multiplier = 1, stiffness_ratio = 1}})
  m:material("soft", {density = 1000, kn = 1e5, ks = 1e5})
  c.b = m:ball{pos = V(c, 0, 0, 0), radius = 0.01, group = "top", material = "rock"}
  c.b2 = m:ball{pos = V(c, 0.019, 0, 0), radius = 0.01, material = "rock"}
  c.b3 = m:ball{pos = V(c, 0.05, 0.05, 0.05), radius = 0.008, material = "soft"}
  c.walls = m:wall{kind = "box", min = V(c, -0.1, -0.1, -0.1), max = V(c, 0.1, 0.1, 0.1)}
  c.w = c.walls[1]
  m:clump_template("pair", dim == 3 and {{0, 0, 0, 0.006}, {0.008, 0, 0, 0.006}} or {{0, 0, 0.006}, {0.008, 0, 0.006}})
  c.cl = m:clump{template = "pair", pos = V(c, -0.05, -0.05, -0.05), material = "rock"}
  m:history("ke", "kinetic")
  m:bond{kind = "parallel", gap = 1e-3}
  m:cycle(3)
  -- a step budget: m:cycle(2^63 - 1) is valid (and a Ctrl-C stops it), not a hang
  m:on("cycle", function(mm) if mm:step() > 20000 then error("fuzz: step budget spent") end end, {every = 1000})
  for k in m:contacts() do c.c = k break end
  return c
end

local scratch = "fuzz-scratch"
os.execute("mkdir -p " .. scratch)
local serial = 0
local function path(ext)
  serial = serial + 1
  return scratch .. "/f" .. serial .. (ext or ".h5")
end

---------------------------------------------------------------- the entries

-- name = the documented name; make(c) -> receiver (nil for functions), the
-- function, the arguments; or a field entry: {get = obj, field} / {set = obj, field, value}.
local entries = {}
local function E(name, make) entries[#entries + 1] = {name = name, make = make} end

local function method(obj, name, ...) return {self = obj, fn = obj[name], args = {...}} end
local function fn(f, ...) return {fn = f, args = {...}} end

-- the module
E("seixo.model", function(c)
  return fn(seixo.model, {dim = c.dim, gravity = V(c, 0, -1, 0), timestep = 1e-5, timestep_safety = 0.5, skin = 1e-3})
end)
E("seixo.version", function() return {get = seixo, field = "version"} end)
E("seixo.progress", function() return fn(seixo.progress, false) end)
E("seixo.clock", function() return fn(seixo.clock) end)
E("seixo.interrupts", function() return fn(seixo.interrupts) end)
E("seixo.threads", function() return {set = seixo, field = "threads", value = 2, restore = 1} end)
E("seixo.load", function(c)
  local p = path()
  c.m:save(p)
  return fn(seixo.load, p, {dim = c.dim})
end)
E("seixo.xdmf", function(c)
  local p = path()
  c.m:output{path = p, every = 2}:close()
  return fn(seixo.xdmf, p)
end)
-- models
E("m:material", function(c)
  return method(c.m, "material", "rock2", {density = 2600, kn = 1e7, ks = 1e7, friction = 0.4, damping = 0.5,
                viscous_normal = 0.1, viscous_shear = 0.1, model = "linear", shear_modulus = 1e9, poisson = 0.2,
                modulus = 0, stiffness_ratio = 1})
end)
E("m:materials", function(c) return method(c.m, "materials") end)
E("m:contact_model", function(c)
  return method(c.m, "contact_model", {groups = {"top", "g"}, model = "linear", kn = 1e7, ks = 1e7, friction = 0.3,
                name = "top-g", material = "rock"})
end)
E("m:contact_model{wall}", function(c)
  return method(c.m, "contact_model", {wall = c.w, groups = "top", model = "linear", kn = 1e7, ks = 1e7, friction = 0.3,
                material = "rock"})
end)
E("m:contact_models", function(c) return method(c.m, "contact_models") end)
E("m:summary", function(c) return method(c.m, "summary") end)
E("m:close", function(c) return method(c.m, "close") end)
for _, name in ipairs({"dim", "time", "step", "timestep", "critical_timestep", "gravity", "ratio", "energy",
                       "contact_count", "hash", "ranks", "bytes", "memory"}) do
  E("m:" .. name, function(c) return method(c.m, name) end)
end
E("m:set_timestep", function(c) return method(c.m, "set_timestep", 2e-5) end)
E("m:set_gravity", function(c) return method(c.m, "set_gravity", V(c, 0, -5, 0)) end)
E("m:profile", function(c) return method(c.m, "profile", {print = false, reset = false}) end)
E("m:cycle", function(c) return method(c.m, "cycle", 5) end)
E("m:solve", function(c) return method(c.m, "solve", {ratio = 1e-2, steps = 20, every = 5}) end)
E("m:on", function(c)
  return method(c.m, "on", pick({"after", "before", "cycle"}), function(m) m:cycle(0) end, {every = 2})
end)
E("m:off", function(c) return method(c.m, "off", c.m:on("cycle", function() end)) end)
E("m:history", function(c) return method(c.m, "history", "h2", pick({"kinetic", "time", "ratio"}), {every = 2}) end)
E("m:history", function(c) return method(c.m, "history", "h3", function(m) return m:time() end, {every = 1}) end)
E("m:history", function(c) return method(c.m, "history", "ke") end)
E("m:histories", function(c) return method(c.m, "histories") end)
E("m:history_remove", function(c) return method(c.m, "history_remove", "ke") end)
E("m:history_csv", function(c) return method(c.m, "history_csv", path(".csv"), {"ke"}) end)
E("m:generate", function(c)
  local method_name = pick({"random", "distribute", "expand", "lattice"})
  local spec = {count = math.random(0, 30), radius = method_name == "lattice" and 0.005 or {0.004, 0.006},
                region = {box = {V(c, -0.09, -0.09, -0.09), V(c, -0.02, -0.02, -0.02)}}, seed = math.random(100),
                method = method_name, relax = false}
  if method_name == "distribute" or method_name == "expand" then spec.porosity = 0.6 end
  if method_name == "lattice" then spec.packing = c.dim == 3 and "cubic" or "square" end
  return method(c.m, "generate", spec)
end)
E("m:generate", function(c)
  return method(c.m, "generate", {template = "pair", count = 5, region = {sphere = c.dim == 3 and {center = {0.05, 0.05, 0.05}, radius = 0.04} or nil,
                                   disk = c.dim == 2 and {center = {0.05, 0.05}, radius = 0.04} or nil}})
end)
E("m:ball", function(c)
  return method(c.m, "ball", {pos = V(c, 0.06, -0.06, 0), radius = 0.005, vel = V(c, 0.1, 0, 0), spin = R(c, 1),
                              material = "rock", group = "g"})
end)
E("m:ball", function(c) return method(c.m, "ball", c.b.id) end)
E("m:balls", function(c)
  return {self = c.m, fn = function(m, f) local n = 0 for _ in m:balls(f) do n = n + 1 end return n end,
          args = {{group = "top"}}}
end)
E("m:ball_count", function(c) return method(c.m, "ball_count") end)
E("b:remove", function(c) return method(c.b, "remove") end)
E("b:set_extra", function(c) return method(c.b, "set_extra", "k", {1, "x"}) end)
E("b:get_extra", function(c) return method(c.b, "get_extra", "k", 0) end)
E("m:clump_template", function(c)
  return method(c.m, "clump_template", "t2", c.dim == 3 and {{0, 0, 0, 0.005}, {0.004, 0, 0, 0.005}, {0, 0.004, 0, 0.003}}
                or {{0, 0, 0.005}, {0.004, 0, 0.005}}, {lines = 64})
end)
E("m:clump_template", function(c) return method(c.m, "clump_template", "pair") end)
E("m:clump_templates", function(c) return method(c.m, "clump_templates") end)
E("m:clump", function(c)
  return method(c.m, "clump", {template = "pair", pos = V(c, 0.06, 0.06, 0.06), orientation = c.dim == 3 and {1, 0, 0, 0} or 0.3,
                               scale = 1, vel = V(c, 0, 0, 0), spin = R(c, 0), material = "rock", group = "g"})
end)
E("m:clump", function(c) return method(c.m, "clump", c.cl.id) end)
E("m:clumps", function(c)
  return {self = c.m, fn = function(m) local n = 0 for _ in m:clumps() do n = n + 1 end return n end, args = {}}
end)
E("m:clump_count", function(c) return method(c.m, "clump_count") end)
E("cl:remove", function(c) return method(c.cl, "remove") end)
E("m:wall", function(c)
  if c.dim == 3 then
    return method(c.m, "wall", pick({{kind = "plane", point = {0, 0, -0.05}, normal = {0, 0, 1}, kn = 1e6, friction = 0.3},
                                     {kind = "rect", corner = {0, 0, -0.05}, edge1 = {0.05, 0, 0}, edge2 = {0, 0.05, 0}},
                                     {kind = "cylinder", point = {0, 0, -0.1}, axis = {0, 0, 1}, radius = 0.2}}))
  end
  return method(c.m, "wall", pick({{kind = "line", point = {0, -0.05}, normal = {0, 1}, kn = 1e6},
                                   {kind = "segment", p1 = {-0.05, -0.05}, p2 = {0.05, -0.04}}}))
end)
E("m:walls", function(c)
  return {self = c.m, fn = function(m) local n = 0 for _ in m:walls() do n = n + 1 end return n end, args = {}}
end)
E("m:wall_count", function(c) return method(c.m, "wall_count") end)
E("w:remove", function(c) return method(c.w, "remove") end)
E("w:set_extra", function(c) return method(c.w, "set_extra", "k", "v") end)
E("w:get_extra", function(c) return method(c.w, "get_extra", "k") end)
E("w:servo", function(c) return method(c.w, "servo", {target = 1e3, area = 0.01, alpha = 0.5, max_speed = 0.1}) end)
E("w:load", function(c) return method(c.w, "load") end)
local function cylinder(c)
  if c.dim == 2 then return c.w end
  return c.m:wall{kind = "cylinder", point = {0, 0, -0.1}, axis = {0, 0, 1}, height = 0.2, radius = 0.3}
end
E("w:radius", function(c) return method(cylinder(c), "radius") end)
E("w:set_radial_vel", function(c) return method(cylinder(c), "set_radial_vel", -0.01) end)
E("w:set_radius", function(c) return method(cylinder(c), "set_radius", 0.25) end)
E("m:measure", function(c)
  return method(c.m, "measure", pick({{box = {min = V(c, -0.05, -0.05, -0.05), max = V(c, 0.05, 0.05, 0.05)}},
                                      c.dim == 3 and {sphere = {center = {0, 0, 0}, radius = 0.05}} or {disk = {center = {0, 0}, radius = 0.05}}}))
end)
E("m:contacts", function(c)
  return {self = c.m, fn = function(m, f) local n = 0 for k in m:contacts(f) do n = n + 1 local _ = k.force end return n end,
          args = {{ball = c.b.id, kind = "ball"}}}
end)
E("m:group", function(c) return method(c.m, "group", "g2", {region = {box = {V(c, -1, -1, -1), V(c, 1, 1, 1)}}}) end)
E("m:group", function(c) return method(c.m, "group", "g3", function(b) return b.radius > 0.009 end) end)
E("m:groups", function(c) return method(c.m, "groups") end)
E("m:set", function(c) return method(c.m, "set", {group = "top", vel = V(c, 0, 0, 0), fix = "vel", damping = 0.2}) end)
for _, name in ipairs({"sum", "mean", "min", "max"}) do
  E("m:" .. name, function(c)
    return method(c.m, name, pick({"pos", "vel", "radius", "mass", "kinetic", "speed", "volume"}), {group = "top"})
  end)
end
E("m:count", function(c) return method(c.m, "count", {where = function(b) return b.id % 2 == 0 end}) end)
E("m:remove_balls", function(c) return method(c.m, "remove_balls", {group = "top"}) end)
E("m:bond", function(c)
  return method(c.m, "bond", {kind = pick({"parallel", "contact"}), gap = 2e-3, seed = 3, materials = "rock",
                              normal_strength = 1e3, shear_strength = 1e3, tensile_strength = 1e6, cohesion = 1e6,
                              modulus = 1e8, radius_multiplier = 1, stiffness_ratio = 1})
end)
E("m:bond_count", function(c) return method(c.m, "bond_count") end)
E("m:cracks", function(c) return method(c.m, "cracks") end)
E("m:crack_count", function(c) return method(c.m, "crack_count", "tension") end)
E("m:track_energy", function(c) return method(c.m, "track_energy", true) end)
E("m:save", function(c) return method(c.m, "save", path(), {compression = 1}) end)
E("m:vars", function(c) return {self = c.m, fn = function(m, v) m:vars().x = v return m:vars() end, args = {{1, 2, "x"}}} end)
E("m:output", function(c) return method(c.m, "output", {path = path(), every = 2, compression = 0, append = false}) end)
local function output(c) return c.m:output{path = path(), every = 2} end
E("o:write", function(c) return method(output(c), "write") end)
E("o:close", function(c) return method(output(c), "close") end)
E("o:count", function(c) return method(output(c), "count") end)
E("o:path", function(c) return method(output(c), "path") end)
-- the ball, clump, wall and contact fields, read and written
local fields = {
  b = {"id", "pos", "vel", "spin", "force", "moment", "applied_force", "applied_moment", "radius", "mass", "inertia",
       "material", "fix", "damping", "group", "extra", "clump"},
  cl = {"id", "pos", "vel", "spin", "orientation", "force", "moment", "angular_momentum", "mass", "volume", "inertia",
        "principal", "scale", "template", "material", "damping", "fix", "pebbles"},
  w = {"id", "kind", "force", "moment", "vel", "point", "normal", "axis", "edge1", "edge2", "friction", "extra", "material",
       "rigid"},
  c = {"a", "b", "kind", "normal", "point", "overlap", "fn", "fs", "force", "bond", "pb_fn", "pb_fs", "pb_moment",
       "pb_radius", "contact_model"},
}
local writable = {
  b = {pos = "v", vel = "v", spin = "r", applied_force = "v", applied_moment = "r", radius = 0.012, material = "soft",
       fix = "vel", damping = 0.1, group = "g", extra = {a = 1}},
  cl = {pos = "v", vel = "v", spin = "r", orientation = "q", scale = 1.1, material = "soft", damping = 0.2, fix = "spin"},
  w = {vel = "v", point = "v", normal = "v", friction = 0.2, extra = "x", material = "soft", rigid = true},
}
-- (in a fixed order: pairs' order over string keys differs from one process
-- to the next, so a case's number would name another entry when replayed,
-- or on another MPI rank)
for _, kind in ipairs{"b", "cl", "w", "c"} do
  for _, f in ipairs(fields[kind]) do
    E(kind .. "." .. f, function(c)
      local obj = kind == "b" and c.b or kind == "cl" and c.cl or kind == "w" and c.w or c.c
      local value = writable[kind] and writable[kind][f]
      if value == nil then return {get = obj, field = f} end
      if value == "v" then value = V(c, 0.01, 0.02, 0.03) end
      if value == "r" then value = R(c, 0.5) end
      if value == "q" then value = c.dim == 3 and {0.6, 0.8, 0, 0} or 0.7 end
      return {set = obj, field = f, value = value}
    end)
  end
end
-- seixo.util
E("util.add", function(c) return fn(util.add, V(c, 1, 2, 3), V(c, 3, 2, 1)) end)
E("util.sub", function(c) return fn(util.sub, V(c, 1, 2, 3), V(c, 3, 2, 1)) end)
E("util.scale", function(c) return fn(util.scale, V(c, 1, 2, 3), 2) end)
E("util.dot", function(c) return fn(util.dot, V(c, 1, 2, 3), V(c, 3, 2, 1)) end)
E("util.cross", function() return fn(util.cross, {1, 0, 0}, {0, 1, 0}) end)
E("util.norm", function(c) return fn(util.norm, V(c, 3, 4, 0)) end)
E("util.normalize", function(c) return fn(util.normalize, V(c, 3, 4, 0)) end)
E("util.lerp", function(c) return fn(util.lerp, V(c, 0, 0, 0), V(c, 1, 1, 1), 0.5) end)
E("util.mean_sd", function() return fn(util.mean_sd, {1, 2, 4}) end)
E("util.show", function() return fn(util.show, {1, {2, x = "y"}}, 3) end)
E("util.print", function() return fn(util.show, {1, 2}) end) -- print's text is show's: no output flood
E("util.read_csv", function(c)
  local p = path(".csv")
  c.m:history_csv(p, {"ke"})
  return fn(util.read_csv, p)
end)
-- seixo.lab: the cheap functions run; the tests (minutes each) get hostile specimens, which fail at once
local junk_spec = {dim = 2, shape = "rect"}
E("lab.rock", function() return fn(lab.rock, {density = 2700, kn = 1e8}) end)
-- (refused twice over, so that one swap never makes a specimen of minutes)
E("lab.specimen", function() return fn(lab.specimen, {dim = 4, shape = "rect", size = {1, 2, 3}}) end)
E("lab.open", function() return fn(lab.open, path(".lua")) end)
E("lab.triaxial", function() return fn(lab.triaxial, junk_spec, {confining = -1}) end)
E("lab.ucs", function() return fn(lab.ucs, junk_spec, {every = 0}) end)
E("lab.brazilian", function() return fn(lab.brazilian, junk_spec, {}) end)
E("lab.lateral_strain", function(c) return fn(lab.lateral_strain, c.m, c.dim) end)
E("lab.mohr_coulomb", function() return fn(lab.mohr_coulomb, {{sigma3 = 0, sigma1 = 10e6}, {sigma3 = 1e6, sigma1 = 14e6}}) end)
E("lab.series", function() return fn(lab.series, junk_spec, {confining = {1}}) end)
E("lab.write_csv", function() return fn(lab.write_csv, path(".csv"), {"a", "b"}, {{1, 2}, {3, 4}}) end)
E("lab.have_gnuplot", function() return fn(lab.have_gnuplot) end)
-- the functions of issues 13, 14, 15 and 17
local plot = require("seixo.plot")
local function cube(c) return {min = V(c, -0.1, -0.1, -0.1), max = V(c, 0.1, 0.1, 0.1)} end
E("seixo.vec", function() return fn(seixo.vec, 1, 2, 3) end)
E("seixo.models", function() return fn(seixo.models) end)
E("seixo.check_material", function() return fn(seixo.check_material, {modulus = 62e9, bond = {tensile_strength = 1e8}}) end)
E("seixo.optimize", function()
  return fn(seixo.optimize, function(x) return (x[1] - 1) ^ 2 end, {x0 = {0}, lower = {-2}, upper = {2}, maxeval = 20})
end)
E("seixo.cores", function() return fn(seixo.cores) end)
E("seixo.executable", function() return fn(seixo.executable) end)
E("seixo.script", function() return fn(seixo.script) end)
E("seixo.rank", function() return fn(seixo.rank) end)
E("seixo.decompose", function() return fn(seixo.decompose, true) end)
E("seixo.barrier", function() return fn(seixo.barrier) end)
E("seixo.send", function() return fn(seixo.send, 0, "text") end)
E("m:reset_disp", function(c) return method(c.m, "reset_disp", {group = "top"}) end)
E("b.disp", function(c)
  c.m:reset_disp()
  return {get = c.b, field = "disp"}
end)
E("b.groups", function(c) return {get = c.b, field = "groups"} end)
E("b:set_group", function(c) return method(c.b, "set_group", "second", 2) end)
E("w.spin", function(c) return {get = c.w, field = "spin"} end)
local function mesh(c)
  if c.dim ~= 3 then return c.w end
  return c.m:wall{kind = "mesh", triangles = {{{0.5, 0.5, 0.5}, {0.6, 0.5, 0.5}, {0.5, 0.6, 0.5}}}}
end
E("w.vertices", function(c) return {get = mesh(c), field = "vertices"} end)
E("w.triangles", function(c) return {get = mesh(c), field = "triangles"} end)
E("m:periodic", function(c) return method(c.m, "periodic", cube(c)) end)
E("m:cell_control", function(c)
  c.m:periodic(cube(c))
  return method(c.m, "cell_control", {xx = {rate = -0.01}, yy = {stress = 1e3}})
end)
E("m:cell_stress", function(c)
  c.m:periodic(cube(c))
  return method(c.m, "cell_stress")
end)
E("c.shift", function(c) return {get = c.c, field = "shift"} end)
E("m:flatjoint", function(c) return method(c.m, "flatjoint", c.b.id, c.b2.id) end)
E("m:flatjoint_unbond", function(c) return method(c.m, "flatjoint_unbond", c.b.id, c.b2.id, 1) end)
E("m:joint", function(c)
  return method(c.m, "joint", {point = V(c, 0.5, 0.5, 0.5), normal = V(c, 0, 1, 0), kn = 1e9, ks = 1e9, friction = 0.4,
                               dilation = 5, tension = 1e5, cohesion = 1e5, friction_angle = 20})
end)
E("m:joints", function(c)
  c.m:joint{point = V(c, 0.5, 0.5, 0.5), dip = 30, kn = 1e9, ks = 1e9}
  return method(c.m, "joints")
end)
E("c.joint", function(c) return {get = c.c, field = "joint"} end)
E("plot.live", function(c) return fn(plot.live, c.m, "ke", {every = 1000, terminal = "dumb", output = path(".txt")}) end)
E("lab.calibrate", function()
  return fn(lab.calibrate, {targets = {E = 2e9}, parameters = {modulus = {1e9, 1e10}}, workers = 1, maxeval = 3,
                            seeds = 1, out = path(""), plot = false, print = false,
                            evaluate = function(mat) return {E = mat.modulus or 1e9} end})
end)
E("help", function() return fn(function(x) local ok = pcall(help, x) return ok end, seixo.clock) end)

-- every documented function, method and field has an entry
if docs then
  local have = {}
  for _, e in ipairs(entries) do have[e.name] = true end
  local missing = {}
  for line in io.lines(docs) do
    local name = line:match("^### ([%w_.:]+)")
    if name and not name:match("^[A-Z]") and not have[name] then missing[#missing + 1] = name end
    local field = line:match("^| `(%a+%.[%w_]+)` |")
    if field and not have[field] then missing[#missing + 1] = field end
  end
  if #missing > 0 then
    io.stderr:write("documented but not fuzzed: ", table.concat(missing, ", "), "\n")
    os.exit(1)
  end
end

---------------------------------------------------------------- mutation

local hostile = {0 / 0, math.huge, -math.huge, -0.0, 0, -1, 1e300, -1e300, 4.9e-324, 2 ^ 63, math.mininteger,
                 math.maxinteger, 0.5, 1.5, "", "x", string.rep("z", 300), "a\0b", true, false, {}, {0 / 0, 0 / 0, 0 / 0},
                 {1}, {1, 2, 3, 4}, {x = 1}, {{}}, "nil"}
local function hostile_value()
  local v = pick(hostile)
  if v == "nil" then return nil end
  local r = math.random(12)
  if r == 1 then return function() error("hostile") end end
  if r == 2 then return function() return 0 / 0 end end
  if r == 3 then return io.stdout end
  return v
end

-- Swaps one hostile value somewhere into t (an argument list or a table
-- in it), `depth` levels deep at most; returns a description.
local function swap(t, depth, where)
  local keys = {}
  for k in pairs(t) do keys[#keys + 1] = k end
  table.sort(keys, function(a, b) return tostring(a) < tostring(b) end)
  local n = #t
  if #keys == 0 or math.random(8) == 1 then -- a key of its own: an extra argument or an unknown field
    local k = n > 0 and n + 1 or pick({"bogus", 1, n + 1})
    t[k] = hostile_value()
    return where .. "[" .. tostring(k) .. "] added"
  end
  local k = pick(keys)
  if type(t[k]) == "table" and depth > 0 and math.random(3) > 1 then
    return swap(t[k], depth - 1, where .. "." .. tostring(k))
  end
  local v = hostile_value()
  t[k] = v
  return where .. "." .. tostring(k) .. " = " .. util.show(v, 2)
end

---------------------------------------------------------------- a case

local checks = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "checks.lua")
local fail = checks.reporter("case", seed)
local nan_in = checks.nan_in
local function clean(err) return checks.clean(err, HERE) end

-- (no tail calls: an error must find this file's frame as its caller's)
local function run_call(call)
  if call.get then
    local v = call.get[call.field]
    return v
  end
  if call.set then
    call.set[call.field] = call.value
    return true
  end
  local r
  if call.self ~= nil then r = table.pack(call.fn(call.self, table.unpack(call.args, 1, call.n or #call.args)))
  else r = table.pack(call.fn(table.unpack(call.args, 1, call.n or #call.args))) end
  return table.unpack(r, 1, r.n)
end

local function cycle(m, n) m:cycle(n) end

local modes = {"direct", "direct", "direct", "callback", "history"}

local function run_case(k)
  math.randomseed(seed, k)
  local entry = entries[math.random(#entries)]
  local dim = math.random(2) + 1
  local mode = pick(modes)
  local mutate = math.random(5) > 1
  local desc = string.format("%s %dD %s", entry.name, dim, mode)
  if log then
    log:write(string.format("case %d FUZZ_SEED=%d FUZZ_FIRST=%d FUZZ_COUNT=1: %s\n", k, seed, k, desc))
    log:flush()
  end
  local t0 = seixo.clock()
  local c = scene(dim)
  local ok, call = pcall(entry.make, c)
  if not ok then
    fail(k, desc .. ": the valid call could not be made: " .. tostring(call))
    return
  end
  local saved_threads = seixo.threads
  if mutate then
    if call.set then
      local v = {call.value}
      desc = desc .. " " .. swap(v, 2, "value")
      call.value = v[1]
    elseif call.args then
      desc = desc .. " " .. swap(call.args, 3, "args")
      call.n = 0
      for i in pairs(call.args) do if math.type(i) == "integer" and i > call.n then call.n = i end end
    end
  end
  if log then log:write("  ", desc, "\n") log:flush() end
  local results
  if mode == "direct" then
    results = table.pack(pcall(run_call, call))
  else
    -- inside the model's own cycle: a callback, or a history's function
    local m = c.m
    local inner
    local function body() inner = table.pack(pcall(run_call, call)) return 0 end
    local id
    if mode == "callback" then id = m:on("cycle", body) else m:history("fuzz", body) end
    local cok, cerr = pcall(cycle, m, 2)
    if not cok and not clean(cerr) then fail(k, desc .. ": the cycle around it failed uncleanly: " .. tostring(cerr)) end
    pcall(function() if id then m:off(id) else m:history_remove("fuzz") end end)
    results = inner or table.pack(true)
  end
  seixo.threads = saved_threads
  if not results[1] and not clean(results[2]) then
    fail(k, desc .. ": unclean error: " .. tostring(results[2]))
  end
  -- models made by the call are checked too
  for i = 2, results.n do
    if getmetatable(results[i]) == getmetatable(c.m) then c.models[#c.models + 1] = results[i] end
  end
  for _, m in ipairs(c.models) do
    local where = nan_in(m)
    if where then fail(k, desc .. ": silent NaN: " .. where .. (results[1] and " (the call succeeded)" or "")) end
    local cok, cerr = pcall(cycle, m, 3)
    if cok then
      where = nan_in(m)
      if where then fail(k, desc .. ": silent NaN after a cycle: " .. where) end
    elseif not clean(cerr) and not tostring(cerr):find("closed", 1, true) then
      fail(k, desc .. ": the next cycle failed uncleanly: " .. tostring(cerr))
    end
    pcall(m.close, m)
  end
  local dt = seixo.clock() - t0
  if dt > limit then fail(k, string.format("%s: took %.1f s (limit %g s)", desc, dt, limit)) end
end

for k = first, first + count - 1 do
  run_case(k)
  if k % 50 == 0 then collectgarbage() end
end
collectgarbage()
collectgarbage()
os.execute("rm -rf " .. scratch)
print(string.format("api: %d cases from %d (seed %d), %d failed", count, first, seed, fail.count))
if fail.count > 0 then os.exit(1) end
