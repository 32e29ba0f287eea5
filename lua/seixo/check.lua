-- seixo.check: the option checks, the specimen tables' checks, the log and
-- the loops' limits of the lab modules (seixo.lab, seixo.periodic,
-- seixo.joints). Every message starts
-- with the function's name as the user calls it ("lab.triaxial: ..."), and
-- is raised at the level of that function's caller (seixo.caller then puts
-- it at the user's line):
--   local c = require("seixo.check").module("periodic")
--   c.keys(opts, "shear", {"normal", ...}); c.positive(v, "normal", "shear")
local seixo = require "seixo"  -- a global in the executable, not under a stock lua5.4
local check = {}

-- a value in a message: NaN as "nan" (tostring says "-nan" on x86 Linux)
function check.show(v)
  if v ~= v then return "nan" end
  return tostring(v)
end
local show = check.show

-- a value of the wrong type in a message: its type, and a string quoted (a
-- stress given as the string '5e6' was "not a stress >= 0 Pa (got 5e6)")
function check.got(v)
  if type(v) == "string" then return string.format("string '%s'", v) end
  if type(v) == "number" or type(v) == "boolean" then return type(v) .. " " .. show(v) end
  return type(v)
end
local got = check.got

-- The shapes of lab.specimen, by dimension.
check.shapes = {
  [3] = {cylinder = true, prism = true, disc = true},
  [2] = {rect = true, disk = true},
}

-- Why mat is not a material m:material takes (its first fault, as
-- seixo.check_material words it), or nil.
function check.material_error(mat)
  local ok, why = pcall(seixo.check_material, mat)
  if ok then return nil end
  return (tostring(why):gsub("^.-bad argument #%d+ to '[^']*' %((.*)%)$", "%1"):gsub("^.-seixo.check_material: ", ""))
end

-- The fields of a specimen table (lab.specimen's, periodic.specimen's or
-- joints.jointed's, as lab.open reads them back) that the tests read: what
-- each must be, and whether v is that in the table spec (false and why,
-- when the value alone does not say). Each test checks those it reads
-- before it starts: a table changed by hand was used as it came (without
-- wall_kn a UCS ran against platens of no stiffness, 23 MPa instead of
-- 154; a string for it failed in an internal m:wall call). A shape is
-- checked against dim once the file has said which dim is right (c.load).
local function bounded(v) return type(v) == "number" and v > 0 and v < math.huge end
local function shown(v) return type(v) == "number" and show(v) or check.got(v) end
local function corner(v, spec)
  if type(v) ~= "table" then return false end
  for k = 1, spec.dim do
    if type(v[k]) ~= "number" or not (v[k] > -math.huge and v[k] < math.huge) then return false end
  end
  return true
end
local specimen_fields = {
  path = {"a string, its file's path", function(v) return type(v) == "string" end},
  dim = {"2 or 3", function(v) return v == 2 or v == 3 end},
  shape = {"rect or disk (2D), cylinder, prism or disc (3D)",
           function(v) return check.shapes[2][v] or check.shapes[3][v] or false end},
  wall_kn = {"a number > 0, N/m", bounded},
  sigma0 = {"a stress > 0, Pa", bounded},
  radius = {"{rmin, rmax}, 0 < rmin <= rmax, m",
            function(v) return type(v) == "table" and bounded(v[1]) and bounded(v[2]) and v[1] <= v[2] end},
  lo = {"its box's lower corner, dim numbers, m", corner},
  hi = {"its box's upper corner, dim numbers, m", corner},
  material = {"a material table with a density > 0", function(v)
    if type(v) ~= "table" then return false end
    if v.density == nil then return false, "it has no density" end
    if not bounded(v.density) then return false, "its density is " .. shown(v.density) end
    local why = check.material_error(v)
    return why == nil, why
  end},
  granular = {"true or false", function(v) return type(v) == "boolean" end, optional = true},
}

-- Why out, the path prefix of a function's files (out.csv, out.h5, ...),
-- is a folder's name, or nil: lab.ucs(s, {out = 'dir/'}) wrote the hidden
-- files dir/.csv and dir/.h5. stem: a file's name for the example.
function check.prefix_error(out, stem)
  local folder = out == "" or out:sub(-1) == "/"
  local f = not folder and io.open(out, "r") -- (a folder opens, and reads as one)
  if f then
    local _, _, code = f:read(0)
    f:close()
    folder = code == 21
  end
  if not folder then return nil end
  local dir = (out == "" or out:sub(-1) == "/") and out or out .. "/"
  return string.format("out must be a path prefix, the files' names without their endings (.csv, .h5, ...), not a "
                       .. "folder (got '%s'): give one such as '%s%s1'", out, dir, stem)
end

-- An options' checker for a module's functions. from: the functions whose
-- specimen tables its tests take (default: name.specimen or lab.open).
function check.module(name, from)
  local c = {}
  from = from or name .. ".specimen or lab.open"

  -- an error at the caller of the function that calls fail
  function c.fail(fmt, ...) error(string.format(fmt, ...), 3) end

  -- a log option: false (silent), nil (print) or a function; checked up
  -- front, not at the first line said (after a genesis or a whole test)
  local function check_log(v, fn)
    if v == nil or v == false or type(v) == "function" then return end
    error(string.format("%s.%s: log must be false, nil or a function (got %s)", name, fn, got(v)), 4)
  end

  function c.log(v, fn) check_log(v, fn) end

  -- the options' names, and the log among them (every function that takes
  -- one calls keys first)
  function c.keys(t, fn, allowed)
    if type(t) ~= "table" then error(string.format("%s.%s: a table of options expected, got %s", name, fn, type(t)), 3) end
    local set = {}
    for _, k in ipairs(allowed) do set[k] = true end
    for k in pairs(t) do
      if not set[k] then
        table.sort(allowed)
        error(string.format("%s.%s: unknown option '%s' (valid: %s)", name, fn, tostring(k), table.concat(allowed, ", ")), 3)
      end
    end
    if set.log then check_log(t.log, fn) end
  end

  -- What is wrong with v, an option that must be a number for which ok(v)
  -- holds (rule says which), or nil; a value of another type is named as
  -- one, not compared with the rule.
  local function wrong_number(v, what, fn, rule, ok)
    if type(v) ~= "number" then
      return string.format("%s.%s: %s must be a number, got %s (%s)", name, fn, what, got(v), rule)
    end
    if not ok(v) then return string.format("%s.%s: %s must be %s (got %s)", name, fn, what, rule, show(v)) end
  end

  -- v, a number for which ok(v) holds (rule: what that is, in words)
  function c.number(v, what, fn, rule, ok)
    local why = wrong_number(v, what, fn, rule, ok)
    if why then error(why, 3) end
    return v
  end

  -- A check of a kind of number: function(v, what, fn) -> v (as convert
  -- makes it); NaN fails every comparison, so each rule is written to fail
  -- it (it passed the old `v < 0` checks and failed later under another name).
  local function number_check(rule, ok, convert)
    return function(v, what, fn)
      local why = wrong_number(v, what, fn, rule, ok)
      if why then error(why, 3) end
      return convert and convert(v) or v
    end
  end

  -- a stress >= 0 Pa, finite
  c.stress = number_check("a stress >= 0 Pa", function(v) return v >= 0 and v < math.huge end)

  c.positive = number_check("a positive number", function(v) return v > 0 and v < math.huge end)

  -- a number of steps: a whole number >= 1 (0 or NaN would cycle nothing, forever)
  c.steps = number_check("a whole number of steps >= 1",
                         function(v) return v >= 1 and v < math.huge and v == math.floor(v) end, math.tointeger)

  -- Warns of a stress far outside DEM's usual range, most likely a slip of
  -- the unit (sigma0 = 0.1 meant in MPa), as the core warns of a servo's
  -- target (lab.triaxial's confining): its range and words, at the user's
  -- line, by rank 0 alone when the ranks share the models.
  function c.warn_stress(v, what, fn)
    if v == 0 or (v >= 1e3 and v <= 1e10) then return end
    if seixo.ranks() > 1 and seixo.decompose() and seixo.rank() > 0 then return end
    io.stderr:write(string.format("seixo: warning: %s%s.%s: %s %g is outside the usual range for DEM, %g ... %g Pa "
                                  .. "(seixo's unit is Pa)\n", require("seixo.caller").where() or "", name, fn, what, v,
                                  1e3, 1e10))
  end

  -- Fails unless spec is a specimen table whose fields (specimen_fields'
  -- names, in the order given: dim before the corners) are what the
  -- function fn reads, naming the first that is not.
  function c.specimen(spec, fn, fields)
    if type(spec) ~= "table" then
      error(string.format("%s.%s: a specimen (from %s) expected, got %s", name, fn, from, got(spec)), 3)
    end
    for _, field in ipairs(fields) do
      local f, v = specimen_fields[field], spec[field]
      if v == nil and not f.optional then
        error(string.format("%s.%s: the specimen has no %s (%s): give the table %s returned", name, fn, field, f[1],
                            from), 3)
      end
      local ok, why = true, nil
      if v ~= nil then ok, why = f[2](v, spec) end
      if not ok then
        error(string.format("%s.%s: the specimen's %s must be %s%s: give the table %s returned", name, fn, field,
                            f[1], why and ": " .. why or " (got " .. shown(v) .. ")", from), 3)
      end
    end
  end

  -- The model of a checked specimen, from its file, whose dimension must
  -- be the table's (a 2D file tested as dim = 3 failed in arithmetic on
  -- nil), as its shape's.
  function c.load(spec, fn)
    local m = seixo.load(spec.path)
    local dim = m:dim()
    local why
    if dim ~= spec.dim then
      why = string.format("the specimen's dim is %d but its file %s holds a %dD model", spec.dim, spec.path, dim)
    elseif spec.shape ~= nil and not check.shapes[dim][spec.shape] then
      why = string.format("the specimen's shape %s is not a %dD shape, as its file %s is", spec.shape, dim, spec.path)
    end
    if why then
      m:close()
      error(string.format("%s.%s: %s: give the table %s returned", name, fn, why, from), 3)
    end
    return m
  end

  -- out, a path prefix (a string naming no folder: check.prefix_error)
  function c.prefix(out, fn)
    if type(out) ~= "string" then
      error(string.format("%s.%s: out must be a path prefix (a string; got %s)", name, fn, type(out)), 3)
    end
    local why = check.prefix_error(out, fn)
    if why then error(string.format("%s.%s: %s", name, fn, why), 3) end
  end

  -- Fails unless a file can be made at path (an output's, checked before
  -- the work that would end by writing it).
  function c.writable(path, what, fn)
    if type(path) ~= "string" then
      error(string.format("%s.%s: %s must be a path (a string; got %s)", name, fn, what, type(path)), 3)
    end
    local ok, why = require("seixo.pool").writable(path)
    if not ok then error(string.format("%s.%s: cannot write %s (%s): %s", name, fn, path, what, why), 3) end
  end

  -- a progress line: opts.log false (silent), a function, or print
  function c.say(opts, fmt, ...)
    local log = opts.log
    if log == false then return end
    (log or print)(string.format(fmt, ...))
  end

  return c
end

-- A loading's quasi-static warnings: its largest inertial number (nil when
-- the test has none) above 1e-3, or its mean unbalanced-force ratio above
-- 1e-2 (the lab's tests and the periodic cell's share them).
function check.balance_warnings(mean_ratio, inertial)
  local w = {}
  if inertial and inertial > 1e-3 then
    w[#w + 1] = string.format("inertial number %.2g > 1e-3: the loading is too fast to be quasi-static; lower "
                              .. "strain_rate", inertial)
  end
  if mean_ratio > 0.01 then
    w[#w + 1] = string.format("mean unbalanced-force ratio %.2g during loading: the specimen is not near equilibrium; "
                              .. "lower strain_rate", mean_ratio)
  end
  return w
end

-- The steps to the next record: every, or fewer where the test ends sooner
-- -- left steps to max_steps, or strain_left to max_strain at
-- strain_per_step -- so that max_steps is exact and max_strain is not
-- overshot by more than the automatic timestep's drift over the record,
-- whatever every is (both were checked only at the records: with every =
-- 1e9 a UCS ran 13.6 million steps of its max_steps 5000).
function check.record_steps(every, left, strain_left, strain_per_step)
  local n = math.min(every, left)
  if strain_per_step > 0 and strain_left > 0 then
    local to_strain = math.ceil(strain_left / strain_per_step)
    if to_strain < n then n = math.max(1, to_strain) end
  end
  return math.tointeger(math.max(1, n))
end

return check
