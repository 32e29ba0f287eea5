-- What the fuzzers (tests/fuzz/api.lua, files.lua) check after a case:
-- errors that are clean, and models without a non-finite value.
local checks = {}

-- A failed call's error: one line, a string naming a line of the file
-- `here` ("api.lua:"), and `path` when given.
function checks.clean(err, here, path)
  return type(err) == "string" and err:find(here, 1, true) ~= nil and not err:find("\n", 1, true)
         and (path == nil or err:find(path, 1, true) ~= nil)
end

-- The fuzzers' failure report: fail(case, what) prints the case with the
-- settings that replay it alone; fail.count is how many failed.
function checks.reporter(label, seed)
  return setmetatable({count = 0}, {__call = function(self, case, what)
    self.count = self.count + 1
    io.stderr:write(string.format("FAIL %s %d (FUZZ_SEED=%d FUZZ_FIRST=%d FUZZ_COUNT=1): %s\n", label, case, seed, case,
                                  what))
  end})
end

function checks.finite(v)
  if type(v) == "number" then return v == v and v > -math.huge and v < math.huge end
  if type(v) == "table" then
    for _, x in pairs(v) do if not checks.finite(x) then return false end end
  end
  return true
end

local fields = {
  ball = {"pos", "vel", "spin", "force", "radius", "mass", "inertia", "applied_force", "damping"},
  wall = {"point", "vel", "normal", "axis", "force", "friction"},
  clump = {"pos", "vel", "orientation", "mass"},
  contact = {"normal", "force", "overlap", "pb_fn", "pb_fs", "pb_moment"},
}

-- Where an open model holds a non-finite value (a name), else nil; nil for a closed model.
function checks.nan_in(m)
  local finite = checks.finite
  local ok, t = pcall(function() local t = m:time() return t end)
  if not ok then return nil end
  if not finite(t) then return "time" end
  for name, mat in pairs(m:materials()) do
    if not finite(mat) then return "material " .. name end
  end
  local kinds = {{"ball", m.balls}, {"wall", m.walls}, {"clump", m.clumps}}
  for _, k in ipairs(kinds) do
    for o in k[2](m) do
      for _, f in ipairs(fields[k[1]]) do
        if not finite(o[f]) then return k[1] .. " " .. o.id .. " " .. f end
      end
    end
  end
  local cok, it = pcall(m.contacts, m) -- (a model that cannot be prepared has none to show)
  for c in cok and it or function() end do
    for _, f in ipairs(fields.contact) do
      if not finite(c[f]) then return "contact " .. tostring(c.a.id) .. "-" .. tostring(c.b.id) .. " " .. f end
    end
  end
  for _, cr in ipairs(m:cracks()) do
    if not finite(cr) then return "crack" end
  end
  return nil
end

return checks
