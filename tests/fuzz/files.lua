-- File fuzzer: a 2D and a 3D snapshot and a 3D series holding every kind
-- of state (bonds, cracks, clumps, servo walls, a cylinder, histories,
-- variables, extras) are damaged one dataset or attribute at a time by
-- h5mutate (a value made NaN, infinite, -0, huge, negative or denormal;
-- the object deleted, shortened, lengthened or retyped; a string made
-- variable-length or empty). Case k damages target k / 3 of its file
-- (k % 3 picks the file), so consecutive cases sweep every dataset and
-- attribute of all three. Each damaged file is loaded (seixo.load; the
-- series also through seixo.xdmf and m:output{append = true}): the load
-- must fail with one clean line naming the file, or give a model with no
-- non-finite value that cycles or refuses to with a clean error.
--   FUZZ_H5MUTATE=path FUZZ_SEED=s FUZZ_FIRST=k FUZZ_COUNT=n [FUZZ_LOG=file] seixo tests/fuzz/files.lua
-- Run it from a scratch folder; tests/fuzz/driver.lua runs it in batches.
local seed = tonumber(os.getenv("FUZZ_SEED")) or 1
local first = tonumber(os.getenv("FUZZ_FIRST")) or 1
local count = tonumber(os.getenv("FUZZ_COUNT")) or 50
local mutator = assert(os.getenv("FUZZ_H5MUTATE"), "FUZZ_H5MUTATE: the h5mutate program")
local log = os.getenv("FUZZ_LOG") and assert(io.open(os.getenv("FUZZ_LOG"), "a"))
local limit = tonumber(os.getenv("FUZZ_LIMIT")) or 30
local HERE = "files.lua:"
seixo.progress(false)

local function quote(s) return "'" .. s:gsub("'", "'\\''") .. "'" end
local dir = "fuzz-files"
os.execute("mkdir -p " .. dir)

---------------------------------------------------------------- the files

local function V(dim, x, y, z) return dim == 3 and {x, y, z} or {x, y} end

local function scene(dim)
  local m = seixo.model{dim = dim, gravity = V(dim, 0, -9.81, 0), timestep = 1e-5}
  m:material("rock", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3, viscous_normal = 0.1,
                      bond = {normal_strength = 50, shear_strength = 50, tensile_strength = 1e5, cohesion = 1e5,
                              modulus = 1e7, radius_multiplier = 1, stiffness_ratio = 1}})
  m:material("soft", {density = 1000, kn = 1e5, ks = 1e5, viscous_shear = 0.2, shear_modulus = 1e7, poisson = 0.2})
  m:generate{count = 20, radius = {0.004, 0.006}, region = {box = {V(dim, -0.05, -0.05, -0.05), V(dim, 0.05, 0, 0.05)}},
             seed = 2, material = "rock"}
  m:ball{pos = V(dim, 0.08, 0.08, 0.08), radius = 0.005, material = "soft", vel = V(dim, 0.1, 0, 0)}
  m:group("top", {region = {box = {V(dim, -1, -0.02, -1), V(dim, 1, 1, 1)}}})
  for b in m:balls() do b.applied_force = V(dim, 0, -0.01, 0) b:set_extra("k", b.id) break end
  local walls = m:wall{kind = "box", min = V(dim, -0.1, -0.1, -0.1), max = V(dim, 0.1, 0.1, 0.1)}
  walls[#walls]:servo{target = 1e3, area = 0.01}
  walls[1]:set_extra("name", "left")
  if dim == 3 then m:wall{kind = "cylinder", point = {0, 0, -0.1}, axis = {0, 0, 1}, height = 0.2, radius = 0.2} end
  m:clump_template("pair", dim == 3 and {{0, 0, 0, 0.005}, {0.006, 0, 0, 0.005}} or {{0, 0, 0.005}, {0.006, 0, 0.005}})
  m:clump{template = "pair", pos = V(dim, 0.07, -0.07, 0.07), material = "rock"}
  m:bond{kind = "parallel", gap = 1e-3, materials = "rock"}
  m:bond{kind = "contact", gap = 1e-3, materials = "rock"}
  m:history("ke", "kinetic")
  m:history("t", function(mm) return mm:time() end)
  m:vars().note = {1, 2, "x", nested = {true}}
  m:track_energy(true)
  m:cycle(60)
  return m
end

local bases = {}
for i, spec in ipairs({{2, "snapshot"}, {3, "snapshot"}, {3, "series"}}) do
  local dim, kind = spec[1], spec[2]
  local m = scene(dim)
  local p = dir .. "/base" .. i .. ".h5"
  if kind == "snapshot" then
    m:save(p)
  else
    local o = m:output{path = p, every = 20}
    m:cycle(45)
    o:close()
  end
  m:close()
  local targets = {}
  local list = io.popen(quote(mutator) .. " list " .. quote(p))
  for line in list:lines() do targets[#targets + 1] = line end
  list:close()
  assert(#targets > 10, "the file lists its datasets and attributes")
  bases[i] = {dim = dim, kind = kind, path = p, targets = targets}
end

---------------------------------------------------------------- checks

local checks = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "checks.lua")
local fail = checks.reporter("file case", seed)
local nan_in = checks.nan_in
local function clean(err, path) return checks.clean(err, HERE, path) end

local function load(p, dim) local m = seixo.load(p, {dim = dim}) return m end
local function cycle(m, n) m:cycle(n) end
local function xdmf(p) seixo.xdmf(p) end
-- a small model continues the damaged series (its histories are read back)
local function append(p, dim)
  local m = seixo.model{dim = dim, timestep = 1e-5}
  m:material("rock")
  m:ball{pos = V(dim, 0, 0, 0), radius = 0.01}
  m:history("ke", "kinetic")
  m:cycle(150) -- past the series' end (its histories reach step 105), or appending is refused
  local o = m:output{path = p, every = 10, append = true}
  m:cycle(25)
  o:close()
  m:close()
end

---------------------------------------------------------------- cases

local function run_case(k)
  math.randomseed(seed, k)
  local base = bases[k % #bases + 1]
  local t = (k // #bases) % #base.targets
  local kind, elem = math.random(0, 13), math.random(0, 1 << 30)
  local p = dir .. "/case.h5"
  if log then
    log:write(string.format("file case %d FUZZ_SEED=%d FUZZ_FIRST=%d FUZZ_COUNT=1: %s %s\n", k, seed, k, base.kind,
                            base.targets[t + 1]))
    log:flush()
  end
  local t0 = seixo.clock()
  local cmd = string.format("%s apply %s %s %d %d %d", quote(mutator), quote(base.path), quote(p), t, kind, elem)
  local h = io.popen(cmd)
  local what = h:read("l") or "?"
  h:close()
  local desc = base.kind .. " " .. base.dim .. "D " .. what
  if log then log:write("  ", desc, "\n") log:flush() end
  local ok, m = pcall(load, p, base.dim)
  if ok then
    if base.kind == "series" then fail(k, desc .. ": a series loaded as a snapshot") end
    local where = nan_in(m)
    if where then fail(k, desc .. ": loaded with a non-finite value: " .. where) end
    local cok, cerr = pcall(cycle, m, 5)
    if cok then
      where = nan_in(m)
      if where then fail(k, desc .. ": silent NaN after a cycle: " .. where) end
    elseif not clean(cerr) then
      fail(k, desc .. ": the next cycle failed uncleanly: " .. tostring(cerr))
    end
    m:close()
  elseif not clean(m, p) then
    fail(k, desc .. ": unclean error: " .. tostring(m))
  end
  if base.kind == "series" then
    local xok, xerr = pcall(xdmf, p)
    if not xok and not clean(xerr, p) then fail(k, desc .. ": seixo.xdmf: unclean error: " .. tostring(xerr)) end
    local aok, aerr = pcall(append, p, base.dim)
    if not aok and not clean(aerr, p) then fail(k, desc .. ": output append: unclean error: " .. tostring(aerr)) end
  end
  local dt = seixo.clock() - t0
  if dt > limit then fail(k, string.format("%s: took %.1f s (limit %g s)", desc, dt, limit)) end
end

for k = first, first + count - 1 do
  run_case(k)
  if k % 20 == 0 then collectgarbage() end
end
collectgarbage()
os.execute("rm -rf " .. dir)
local targets = 0
for _, b in ipairs(bases) do targets = targets + #b.targets end
print(string.format("files: %d cases from %d (seed %d) over %d datasets and attributes, %d failed", count, first, seed,
                    targets, fail.count))
if fail.count > 0 then os.exit(1) end
