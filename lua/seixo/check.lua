-- seixo.check: the option checks, the log and the loops' limits of the lab
-- modules (seixo.lab, seixo.periodic, seixo.joints). Every message starts
-- with the function's name as the user calls it ("lab.triaxial: ..."), and
-- is raised at the level of that function's caller (seixo.caller then puts
-- it at the user's line):
--   local c = require("seixo.check").module("periodic")
--   c.keys(opts, "shear", {"normal", ...}); c.positive(v, "normal", "shear")
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

function check.module(name)
  local c = {}

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
