-- Every Lua example of README.md and docs/*.md runs, and prints what its
-- text says it prints. An example is a fenced ```lua block, or in
-- docs/lua-api.md (whose fragments are indented) an indented block.
--
-- The HTML comments right above a block (blank lines between allowed) say
-- how to run it:
--   <!-- example skip: REASON -->      not run (a pattern with `...`, a
--                                      formula, a command line); the reason
--                                      is required
--   <!-- example tested: FILE -->      run and checked by that test file
--                                      (it must exist and name the doc file)
--   <!-- example setup: NAME -->       run after the setup NAME below (the
--                                      model, the variables the fragment
--                                      refers to)
--   <!-- example prints: PATTERN -->   its output must match the Lua PATTERN
--   <!-- example env: VAR=VALUE -->    run with that environment variable
-- A block with no comment runs alone. Each block runs in its own seixo
-- process, in a scratch directory.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq = T.test, T.check, T.eq

-- The contexts a fragment may need: small, so that the whole file runs in
-- well under a minute.
local setups = {
  -- a 2D bed of 60 disks at rest on the floor of a box
  bed2d = [[
m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("sand", {density = 2650, kn = 1e7, ks = 1e7, friction = 0.5, damping = 0.7})
m:wall{kind = "box", min = {0, 0}, max = {0.05, 0.05}}
for i = 0, 59 do m:ball{pos = {2.5e-3 + (i % 10) * 5e-3, 2.5e-3 + (i // 10) * 5e-3}, radius = 2.5e-3} end
m:solve{ratio = 1e-3, steps = 20000}
m:group("top", {where = function(b) return b.pos.y > 0.02 end})
]],
  -- a 3D bed of 27 balls at rest on the floor of a box
  bed3d = [[
m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})
m:wall{kind = "box", min = {0, 0, 0}, max = {0.03, 0.03, 0.03}}
for i = 0, 26 do m:ball{pos = {5e-3 + (i % 3) * 1e-2, 5e-3 + (i // 3 % 3) * 1e-2, 5e-3 + (i // 9) * 1e-2}, radius = 5e-3} end
m:solve{ratio = 1e-3, steps = 20000}
m:group("top", {where = function(b) return b.pos[3] > 0.02 end})
]],
  -- an empty 3D model with a material, and the corners of a box
  model3d = [[
m = seixo.model{dim = 3}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})
lo, hi = {0, 0, 0}, {0.02, 0.02, 0.02}
]],
  -- a 3D model m and a 2D model m2, empty, each with a material
  periodic = [[
m = seixo.model{dim = 3}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6})
m2 = seixo.model{dim = 2}
m2:material("glass", {density = 2500, kn = 1e6, ks = 1e6})
]],
  -- a periodic 3D cell with 30 balls in it
  cell3d = [[
m = seixo.model{dim = 3}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})
m:periodic{min = {0, 0, 0}, max = {0.01, 0.01, 0.01}}
m:generate{count = 30, radius = {1e-3, 1.2e-3}, region = {box = {{0, 0, 0}, {0.01, 0.01, 0.01}}}, seed = 1}
]],
  lab = [[lab = require "seixo.lab"
]],
  -- a 3D model with materials sand and steel, a ball of each, all in group "rock"
  cmodel = [[
m = seixo.model{dim = 3}
m:material("sand", {density = 2650, kn = 1e6, ks = 1e6, friction = 0.5})
m:material("steel", {density = 7800, kn = 1e8, ks = 1e8, friction = 0.2})
m:ball{pos = {0.5, 0.5, 0.05}, radius = 0.01, material = "sand"}
m:ball{pos = {0.5, 0.5, 0.5}, radius = 0.01, material = "steel"}
m:group("rock", {})
]],
}

local function read(path) return assert(io.open(T.root .. path)):read("a") end

-- The examples of one file: {line =, code =, heading =, marks = {kind = value, ...}}.
local function examples(path)
  local lines = {}
  for l in (read(path) .. "\n"):gmatch("(.-)\n") do lines[#lines + 1] = l end
  local out, heading, i = {}, "", 1
  local indented = path == "docs/lua-api.md"
  local function marks_above(at)
    local marks, j = {}, at - 1
    while j >= 1 and lines[j] == "" do j = j - 1 end
    while j >= 1 do
      local kind, value = lines[j]:match("^<!%-%- example (%a+): (.-) %-%->$")
      if not kind then break end
      check(not marks[kind], path .. ":" .. j .. ": two '" .. kind .. "' marks")
      marks[kind] = value
      j = j - 1
      while j >= 1 and lines[j] == "" do j = j - 1 end
    end
    return marks
  end
  local in_fence = false
  while i <= #lines do
    local l = lines[i]
    if l:match("^```") then
      if not in_fence and l == "```lua" then
        local first, code = i, {}
        i = i + 1
        while lines[i] and lines[i] ~= "```" do code[#code + 1] = lines[i]; i = i + 1 end
        out[#out + 1] = {line = first, code = table.concat(code, "\n") .. "\n", heading = heading, marks = marks_above(first)}
      else
        in_fence = not in_fence
      end
    elseif not in_fence and l:match("^#") then
      heading = l:gsub("^#+ *", "")
    elseif not in_fence and indented and l:match("^    ") and (i == 1 or lines[i - 1] == "") then
      local first, code = i, {}
      while lines[i] and (lines[i]:match("^    ") or (lines[i] == "" and lines[i + 1] and lines[i + 1]:match("^    "))) do
        code[#code + 1] = lines[i]:sub(5)
        i = i + 1
      end
      i = i - 1
      out[#out + 1] = {line = first, code = table.concat(code, "\n") .. "\n", heading = heading, marks = marks_above(first)}
    end
    i = i + 1
  end
  return out
end

local files = {"README.md"}
for name in io.popen("ls " .. T.quote(T.root .. "docs")):lines() do
  if name:match("%.md$") then files[#files + 1] = "docs/" .. name end
end

-- the executable by an absolute path: the examples run in a scratch directory
local seixo_exe = T.seixo:sub(1, 1) == "/" and T.seixo or io.popen("pwd"):read("l") .. "/" .. T.seixo

local scratch = os.tmpname()
os.remove(scratch)
assert(os.execute("mkdir " .. T.quote(scratch)))

local counts = {run = 0, skipped = 0, tested = 0}
for _, path in ipairs(files) do
  for _, ex in ipairs(examples(path)) do
    local where = path .. ":" .. ex.line .. " (" .. ex.heading .. ")"
    local m = ex.marks
    if m.skip then
      check(#m.skip > 10, where .. ": a skip needs its reason")
      counts.skipped = counts.skipped + 1
    elseif m.tested then
      test(where .. ": run by " .. m.tested, function()
        local f = io.open(T.root .. m.tested)
        check(f, where .. ": no file " .. m.tested)
        local text = f and f:read("a") or ""
        check(text:find(path, 1, true), m.tested .. " does not name " .. path)
      end)
      counts.tested = counts.tested + 1
    else
      counts.run = counts.run + 1
      test(where .. " runs" .. (m.prints and " and prints what the text says" or ""), function()
        local setup = ""
        if m.setup then
          for name in m.setup:gmatch("[%w_]+") do
            check(setups[name], where .. ": no setup '" .. name .. "'")
            setup = setup .. (setups[name] or "")
          end
        end
        local script = scratch .. "/example.lua"
        local f = assert(io.open(script, "w"))
        -- the setup's globals, then the block as it is written (its locals stay its own)
        f:write(setup, "seixo.progress(false)\n", "do\n", ex.code, "end\n")
        f:close()
        local p = io.popen("cd " .. T.quote(scratch) .. " && timeout 120 env " .. (m.env or "") .. " "
                           .. T.quote(seixo_exe) .. " example.lua 2>&1")
        local out = p:read("a")
        local _, _, status = p:close()
        eq(status, 0, where .. ":\n" .. ex.code .. "--> " .. out)
        if m.prints then  -- \n and \t in the mark stand for a newline and a tab
          local want = m.prints:gsub("\\n", "\n"):gsub("\\t", "\t")
          check(out:find(want), where .. ": prints\n" .. out .. "\nnot " .. m.prints)
        end
      end)
    end
  end
end

test("the examples are found: every file's, and most of them run", function()
  print(string.format("docs examples: %d run, %d run by other tests, %d skipped with a reason",
                      counts.run, counts.tested, counts.skipped))
  check(counts.run >= 8, counts.run)
  check(counts.skipped <= counts.run, "more examples skipped than run")
end)

os.execute("rm -rf " .. T.quote(scratch))
T.done()
