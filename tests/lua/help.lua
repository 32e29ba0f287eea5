-- help() and docs/lua-api.md cover every function, method and field the
-- bindings define, and nothing that does not exist.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq

local H = require("seixo.help")
local util = require("seixo.util")
local reg = debug.getregistry()
local classes = {model = "seixo.model", ball = "seixo.ball", wall = "seixo.wall", contact = "seixo.contact",
                 output = "seixo.output", clump = "seixo.clump"}
local letter = {model = "m", ball = "b", wall = "w", contact = "c", output = "o", clump = "cl"}

-- every name the bindings define: "model:cycle", "ball.pos", "seixo.model", "util.add"
local function defined()
  local names = {}
  for kind, tname in pairs(classes) do
    local mt = reg[tname]
    if mt then
      for name in pairs(mt.__methods or {}) do names[kind .. ":" .. name] = true end
      for name in pairs(mt.__getters or {}) do names[kind .. "." .. name] = true end
      for name in pairs(mt.__setters or {}) do names[kind .. "." .. name] = true end
    end
  end
  for name in pairs(seixo) do names["seixo." .. name] = true end
  for name in pairs(util) do names["util." .. name] = true end
  for name in pairs(require("seixo.lab")) do names["lab." .. name] = true end
  for name in pairs(require("seixo.plot")) do names["plot." .. name] = true end
  names.help = true
  return names
end

local doc = assert(io.open(T.root .. "docs/lua-api.md")):read("a")

-- how docs/lua-api.md writes a name: m:cycle(, b.pos, seixo.model, util.add(
local function doc_form(name)
  local kind, sep, member = name:match("^(%w+)([:%.])([%w_]+)$")
  if not kind then return name .. "(" end
  if kind == "seixo" or kind == "util" or kind == "lab" or kind == "plot" then return name end
  return letter[kind] .. sep .. member
end

test("every defined name has a help entry and a place in docs/lua-api.md", function()
  local missing, undocumented = {}, {}
  for name in pairs(defined()) do
    if not H.entries[name] then missing[#missing + 1] = name end
    if not doc:find(doc_form(name), 1, true) then undocumented[#undocumented + 1] = doc_form(name) end
  end
  table.sort(missing)
  table.sort(undocumented)
  eq(#missing, 0, "no help for: " .. table.concat(missing, ", "))
  eq(#undocumented, 0, "not in docs/lua-api.md: " .. table.concat(undocumented, ", "))
end)

test("every help entry names something that exists", function()
  local names = defined()
  local stale = {}
  for name in pairs(H.entries) do
    if not names[name] then stale[#stale + 1] = name end
  end
  table.sort(stale)
  eq(#stale, 0, "help entries for undefined names: " .. table.concat(stale, ", "))
end)

test("help texts", function()
  local m = seixo.model{dim = 2}
  m:material("a")
  local b = m:ball{pos = {0, 0}, radius = 1}
  check(H.text():find("seixo: a DEM simulator", 1, true))
  check(H.text(m.cycle):find("^m:cycle%(n%)"), H.text(m.cycle))
  check(H.text(m.generate):find("m:generate{", 1, true))
  check(H.text(seixo.model):find("^seixo.model{"))
  check(H.text(util.dot):find("^util.dot%(a, b%)"))
  check(H.text(help):find("^help"))
  local methods = H.text(m)
  check(methods:find("model methods", 1, true) and methods:find("  solve ", 1, true), methods)
  local fields = H.text(b)
  check(fields:find("ball fields", 1, true) and fields:find("  radius ", 1, true) and fields:find("[m]", 1, true), fields)
  check(H.text("pos"):find("b.pos", 1, true))
  check(H.text("model:solve"):find("ratio", 1, true))
  check(H.text("ball.fix"):find("'vel'", 1, true))
  check(H.text(seixo):find("model", 1, true))
  check(H.text("util"):find("normalize", 1, true))
  check(H.text("nosuch"):find("no help for 'nosuch'", 1, true))
  check(H.text(42):find("no help for a number", 1, true))
  check(H.text(function() end):find("no help", 1, true))
  for c in m:contacts() do check(H.text(c):find("contact fields", 1, true)) end
end)

test("help is a global of the executable", function()
  local status, out = T.run("-e " .. T.quote("help(seixo.model{dim = 2}.solve)"))
  eq(status, 0, out)
  check(out:find("m:solve{ratio =", 1, true), out)
end)

-- The example session of docs/lua-api.md, typed into `seixo -i`: what it
-- shows after each "> " line is exactly what the REPL prints (stdin is not
-- a terminal, so no prompts are printed, only results and errors).
test("the docs' example session prints what it shows", function()
  local block = (doc .. "\n"):match("An example session.-\n\n<!%-%- example [^\n]*%-%->\n\n(.-)\n\n")
  check(block, "no example session in docs/lua-api.md")
  local input, expected = {}, {}
  for line in (block .. "\n"):gmatch("(.-)\n") do
    local code = line:match("^    > (.*)$")
    if code then
      input[#input + 1] = code
    else
      expected[#expected + 1] = assert(line:match("^    (.*)$"), "not part of the session: " .. line)
    end
  end
  check(#input > 5 and #expected > 3, "the session was read")
  os.remove("ke.csv")
  -- no progress lines in the output, however slow the machine (a sanitized build)
  local status, out = T.run("-e 'seixo.progress(false)' -i", table.concat(input, "\n") .. "\n")
  eq(status, 0, out)
  eq(out, table.concat(expected, "\n") .. "\n")
  check(os.remove("ke.csv"), "the session writes ke.csv")
end)

-- the overview's example runs as printed, and settles on the ratio (it
-- once settled 2,000 spheres without rolling resistance and no step limit,
-- still at ratio 0.58 after 2.35 million steps: a newcomer's finding)
test("help()'s example settles its bed on the ratio", function()
  local text = H.text()
  local lines = {}
  for line in text:gmatch("[^\n]+") do
    if line:match("^  ") then lines[#lines + 1] = line end
  end
  local code = {}
  for _, line in ipairs(lines) do
    local solve = line:match("print%((m:solve%b{})%)")
    if solve then code[#code + 1] = "local why, ratio = " .. solve
    elseif not line:match("^%s*print%(m%)") then code[#code + 1] = line end
  end
  code[#code + 1] = "return why, ratio"
  local chunk = assert(load(table.concat(code, "\n"), "=overview"))
  seixo.progress(false)
  local why, ratio = chunk()
  eq(why, "ratio")
  check(ratio <= 1e-3, ratio)
end)

T.done()
