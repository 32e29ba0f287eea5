-- The README's "A model in Lua" runs as it is written there and prints the
-- line the README says it prints (it settles on the ratio).
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq

local readme = assert(io.open(T.root .. "README.md")):read("a")

test("README: the model in Lua settles on the ratio and prints what the text says", function()
  local code = readme:match("## A model in Lua\n\n[^`]-```lua\n(.-)```")  -- after lua_docs' mark
  check(code, "no Lua block under '## A model in Lua'")
  local promised = readme:match("It prints `([^`]+)`")
  check(promised, "the README does not say what the example prints")
  local dir = os.tmpname()
  os.remove(dir)
  assert(os.execute("mkdir " .. T.quote(dir)))
  local script = dir .. "/model.lua"
  local f = assert(io.open(script, "w"))
  f:write(code)
  f:close()
  os.remove("settled.h5")
  local status, out = T.run("-e " .. T.quote("seixo.progress(false)") .. " " .. T.quote(script))
  eq(status, 0, out)
  eq(out, promised .. "\n")
  local why, ratio = out:match("^(%a+)\t([%d.e-]+)")
  eq(why, "ratio")
  check(tonumber(ratio) <= 1e-3, ratio)
  local saved = io.open("settled.h5", "rb")
  check(saved and saved:read(4) == "\137HDF", "settled.h5 written")
  if saved then saved:close() end
  os.execute("rm -rf " .. T.quote(dir))
end)

T.done()
