-- The Lua tests' shared helpers:
--   local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
--   T.test("name", function() ... end) ... T.done()
-- T.done() prints "N passed, M failed" and exits non-zero on a failure.

local T = {passed = 0, failed = 0}

function T.test(name, fn)
  local ok, err = pcall(fn)
  if ok then
    T.passed = T.passed + 1
  else
    T.failed = T.failed + 1
    io.stderr:write("FAIL ", name, ": ", tostring(err), "\n")
  end
end

function T.check(cond, msg)
  if not cond then error(msg or "check failed", 2) end
end

function T.eq(a, b, context)
  if a ~= b then
    error(string.format("expected %s, got %s%s", tostring(b), tostring(a), context and " (" .. context .. ")" or ""), 2)
  end
end

-- |a - b| <= rel * |b| (or <= rel when b is 0)
function T.near(a, b, rel)
  local tol = rel * (b == 0 and 1 or math.abs(b))
  if not (math.abs(a - b) <= tol) then
    error(string.format("expected %.17g, got %.17g (tolerance %g)", b, a, tol), 2)
  end
end

function T.vec_eq(v, w)
  if type(v) ~= "table" then error("expected a vector, got " .. type(v), 2) end
  if #v ~= #w then error(string.format("expected %d components, got %d", #w, #v), 2) end
  for k = 1, #w do
    if v[k] ~= w[k] then error(string.format("component %d: expected %s, got %s", k, tostring(w[k]), tostring(v[k])), 2) end
  end
end

-- fn must fail with a message containing every given fragment
function T.raises(fn, ...)
  local ok, err = pcall(fn)
  if ok then error("expected an error", 2) end
  err = tostring(err)
  for _, fragment in ipairs({...}) do
    if not err:find(fragment, 1, true) then
      error(string.format("error %q lacks %q", err, fragment), 2)
    end
  end
  return err
end

-- A new temporary path ending in suffix: os.tmpname's file (the name's
-- claim) and the suffix; T.done removes both (a test that failed before
-- its own removal leaves nothing).
local claimed = {}
function T.tmpname(suffix)
  local base = os.tmpname()
  claimed[#claimed + 1] = base
  claimed[#claimed + 1] = base .. suffix
  return base .. suffix
end

function T.done()
  for _, base in ipairs(claimed) do os.remove(base) end
  print(string.format("%d passed, %d failed", T.passed, T.failed))
  if T.failed > 0 then os.exit(1) end
end

-- The directory of the running test script, and the repository root.
T.dir = (debug.getinfo(1, "S").source:match("^@(.*/)") or "./")
T.root = T.dir .. "../../"

-- The seixo executable running the tests.
T.seixo = arg and arg[-1]

local function quote(s) return "'" .. s:gsub("'", "'\\''") .. "'" end
T.quote = quote

-- Runs the seixo executable (under a time limit) with a shell argument
-- string (and `env` arguments before it, "-u VAR" or "VAR=value");
-- returns the exit status and the output (stdout and stderr).
function T.run(args, input, env)
  local cmd = "timeout 120 env " .. (env or "") .. " " .. quote(T.seixo) .. " " .. args .. " 2>&1"
  if input then cmd = "printf '%s' " .. quote(input) .. " | " .. cmd end
  local p = io.popen(cmd)
  local out = p:read("a")
  local _, _, status = p:close()
  return status, out
end

-- A model with one material "rock".
function T.model(dim, opts)
  opts = opts or {}
  opts.dim = dim
  local m = seixo.model(opts)
  m:material("rock", {density = 2000, kn = 1e6, ks = 5e5, friction = 0.4, damping = 0.7})
  return m
end

function T.zero(dim) return dim == 3 and {0, 0, 0} or {0, 0} end

return T
