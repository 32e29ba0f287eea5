-- A new user's first session: the REPL and -i keep a chunk's top-level
-- locals, seixo.models() lists the open models, objects print what they
-- are, tables print readably, a typo is answered with the name meant,
-- help() covers seixo.lab, a callback's error names the callback and the
-- step, and progress written to a log is plain lines.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, raises = T.test, T.check, T.eq, T.raises
local HERE = debug.getinfo(1, "S").short_src

local function tmpfile(text)
  local path = os.tmpname()
  local f = assert(io.open(path, "w"))
  f:write(text)
  f:close()
  return path
end

test("seixo -: the script read from standard input, its #! line a comment, its arguments passed", function()
  local status, out = T.run("- 7 x", "#!/usr/bin/env seixo\nprint(select('#', ...), arg[1], arg[2], arg[0])\nerror('on line 3')\n")
  check(status ~= 0, out)
  check(out:find("2\t7\tx\t-\n", 1, true), out)
  check(out:find("stdin:3: on line 3", 1, true), out)
end)

test("-i: the script's top-level locals are globals of the session", function()
  local script = tmpfile([[
local m = seixo.model{dim = 2}
local n = 42
m:material("a")
local function helper() local hidden = 1 return hidden end
helper()
]])
  local status, out = T.run("-i " .. T.quote(script), "print(n, m:dim(), type(helper), hidden)\n")
  os.remove(script)
  eq(status, 0, out)
  eq(out, "42\t2\tfunction\tnil\n")
  -- without -i nothing is copied: the script's locals stay local
  status, out = T.run("-e " .. T.quote("local z = 1") .. " -e 'print(z)'")
  eq(out, "nil\n")
end)

test("the REPL keeps a line's locals for the next lines", function()
  local status, out = T.run("-i", "local m = seixo.model{dim = 2}\nlocal a, b = 1, 2\nprint(m:dim(), a + b)\n")
  eq(status, 0, out)
  eq(out, "2\t3\n")
  -- a line that fails keeps nothing
  status, out = T.run("-i", "local q = 5; error('no')\nprint(q)\n")
  check(out:find("no\nnil\n", 1, true), out)
end)

test("seixo.models() lists the open models in order", function()
  local before = #seixo.models()
  local a = seixo.model{dim = 2}
  local b = seixo.model{dim = 3}
  local list = seixo.models()
  eq(#list, before + 2)
  check(rawequal(list[#list - 1], a) and rawequal(list[#list], b))
  a:close()
  list = seixo.models()
  eq(#list, before + 1)
  check(rawequal(list[#list], b))
  b:close()
end)

test("objects print what they are", function()
  local m = seixo.model{dim = 3}
  m:material("glass", {density = 2500, kn = 1e5, ks = 1e5})
  local b = m:ball{pos = {0, 0, 0.5e-3}, radius = 1e-3, group = "top"}
  eq(tostring(b), "seixo.ball 1 {pos = {0, 0, 0.0005}, radius = 0.001, vel = {0, 0, 0}, material = glass, group = top}")
  local w = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  eq(tostring(w), "seixo.wall 1 {kind = plane, point = {0, 0, 0}, normal = {0, 0, 1}, vel = {0, 0, 0}, force = {0, 0, 0}}")
  m:cycle(1)
  for c in m:contacts() do check(tostring(c):find("^seixo.contact ball 1 %- wall 1 %(fn [%d.e-]+ N")) end
  m:clump_template("pair", {{-1e-3, 0, 0, 1e-3}, {1e-3, 0, 0, 1e-3}})
  local cl = m:clump{template = "pair", pos = {0, 0, 0.01}}
  check(tostring(cl):find("^seixo.clump 1 {pos = {0, 0, 0.01}, mass = [%d.e-]+, vel = {0, 0, 0}, template = pair}$"), tostring(cl))
  b:remove()
  eq(tostring(b), "seixo.ball 1 (removed)")
  m:close()
  eq(tostring(w), "seixo.wall 1 (model closed)")
end)

test("the REPL prints tables of tables one entry a line, long arrays cut", function()
  local status, out = T.run("-i", [[
m = seixo.model{dim = 2, timestep = 1e-3}
m:material("a", {density = 2000})
m:materials()
m:history("t", "time")
m:cycle(20)
m:history("t").steps
]])
  eq(status, 0, out)
  check(out:find('{\n  a = {\n    damping = 0.0,\n    density = 2000.0,', 1, true), out)
  check(out:find("{1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, ... (20 entries)}", 1, true), out)
end)

test("a typo is answered with the name meant", function()
  local m = seixo.model{dim = 2}
  m:material("a")
  local b = m:ball{pos = {0, 0}, radius = 1}
  raises(function() return m:slove() end, "model has no field 'slove' (did you mean 'solve'?)")
  raises(function() return b.radisu end, "ball has no field 'radisu' (did you mean 'radius'?)", "(fields: id, pos")
  raises(function() b.raduis = 2 end, "ball has no writable field 'raduis' (did you mean 'radius'?)")
  local err = raises(function() return m:frobnicate() end, "model has no field 'frobnicate'", 'help("model")')
  check(not err:find("did you mean", 1, true), err)
  m:close()
end)

test("help covers seixo.lab", function()
  local H = require("seixo.help")
  local lab = require("seixo.lab")
  local text = H.text(lab)
  for _, name in ipairs{"triaxial", "ucs", "brazilian", "specimen", "series", "mohr_coulomb"} do
    check(text:find("  " .. name .. " ", 1, true), text)
  end
  check(H.text(lab.ucs):find("^lab.ucs%(spec"), H.text(lab.ucs))
  check(H.text("lab"):find("seixo.lab", 1, true))
end)

test("an error in a callback names the callback's file:line and the step", function()
  local m = seixo.model{dim = 2}
  m:material("a")
  m:ball{pos = {0, 0}, radius = 1}
  local line = debug.getinfo(1, "l").currentline + 1
  m:on("cycle", function(mm) if mm:step() == 7 then error("boom") end end)
  raises(function() m:cycle(10) end,
         string.format("the callback defined at %s:%d failed at step 7: %s:%d: boom", HERE, line, HERE, line))
  eq(m:step(), 7)
  -- a history function too
  local m2 = seixo.model{dim = 2, timestep = 1e-3}
  m2:material("a")
  line = debug.getinfo(1, "l").currentline + 1
  m2:history("bad", function() return nil + 1 end)
  raises(function() m2:cycle(1) end, string.format("the callback defined at %s:%d failed at step 1", HERE, line))
  m:close()
  m2:close()
end)

test("progress to a log: plain lines, no carriage return nor escape code", function()
  local slow = [[
    local m = seixo.model{dim = 2, timestep = 1e-4}
    m:material("a")
    m:ball{pos = {0, 0}, radius = 1}
    m:on("cycle", function() local t = os.clock() while os.clock() - t < 0.01 do end end)
    print(seixo.progress("log", 0.2))
    m:solve{steps = 60}]]
  local status, out = T.run("-e " .. T.quote(slow))
  eq(status, 0, out)
  check(out:find("^log\n"), out)  -- the executable's default when stderr is not a terminal
  local lines = 0
  for line in out:gmatch("seixo: m:solve: step %d+ of 60[^\n]*ETA %d+ s\n") do lines = lines + 1 end
  check(lines >= 2, out)
  check(not out:find("[\r\27]"), out)
  raises(function() seixo.progress("yes") end, "boolean or 'log' expected")
  raises(function() seixo.progress("log", -1) end, "seconds between log lines")
end)

test("a live plot of histories is redrawn while the model cycles, and changes no bit", function()
  local plot = require("seixo.plot")
  local function run(with_plot, out)
    local m = seixo.model{dim = 2, gravity = {0, -9.81}}
    m:material("a", {density = 2000, kn = 1e6, ks = 1e6, damping = 0.7})
    m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
    m:ball{pos = {0, 0.01}, radius = 0.005}
    m:history("kinetic energy", "kinetic", {every = 10})
    local p
    if with_plot then p = plot.live(m, "kinetic energy", {every = 100, terminal = "dumb", output = out}) end
    m:cycle(500)
    local hash = m:hash()
    if p then
      eq(p.draws, 6)  -- at once, then at steps 100, ..., 500
      check(tostring(p):find("seixo.plot of kinetic energy (6 draws)", 1, true), tostring(p))
      p:close()
      check(tostring(p):find("closed", 1, true))
      raises(function() p:draw() end, "the plot has been closed")
    end
    m:cycle(100)  -- no refresh once closed
    m:close()
    return hash
  end
  local out = os.tmpname()
  local with = run(true, out)
  eq(with, run(false))
  local text = assert(io.open(out)):read("a")
  os.remove(out)
  check(text:find("kinetic energy", 1, true) and text:find("step", 1, true), text)
  raises(function() plot.live(seixo.model{dim = 2}, "nope") end, "no history named 'nope'")
  raises(function() plot.live(seixo.model{dim = 2}, {}) end, "names of histories expected")
  -- issue 18's fuzzer: a file handle (userdata indexing to nil) is no model
  raises(function() plot.live(io.stdout, "kinetic energy") end, "plot.live: a model expected, got file")
  raises(function() plot.live(42, "kinetic energy") end, "plot.live: a model expected, got number")
  -- a file terminal without a file: refused (it wrote a PNG to the standard output)
  local mp = seixo.model{dim = 2}
  mp:history("ke", "kinetic")
  raises(function() plot.live(mp, "ke", {terminal = "pngcairo"}) end, "terminal 'pngcairo' writes a file: give output")
end)

test("a ball placed behind a wall or overlapping one is an error naming the wall", function()
  local m = seixo.model{dim = 3}
  m:material("glass", {density = 2500, kn = 1e5, ks = 1e5})
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  raises(function() m:ball{pos = {0, 0, -1e-3}, radius = 1e-3} end, "m:ball: the ball of radius 0.001 m lies behind wall 1")
  raises(function() m:ball{pos = {0, 0, 0.2e-3}, radius = 1e-3} end,
         "would overlap wall 1 by 0.0008 m, 80% of its radius (more than the 50% of seixo.model{overlap_limit})")
  eq(m:ball_count(), 0)
  m:ball{pos = {0, 0, 0.6e-3}, radius = 1e-3}  -- 40%: accepted
  -- the limit is the model's
  local loose = seixo.model{dim = 3, overlap_limit = 0.9}
  loose:material("glass", {density = 2500, kn = 1e5, ks = 1e5})
  loose:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  loose:ball{pos = {0, 0, 0.2e-3}, radius = 1e-3}
  raises(function() seixo.model{overlap_limit = 2} end, "overlap_limit", "[0.0, 1.0]")
  m:close()
  loose:close()
end)

test("balls placed overlapping are named at the first step, not blamed on the timestep", function()
  local function two(dx, opts)
    local m = seixo.model(opts or {dim = 3})
    m:material("glass", {density = 2500, kn = 1e5, ks = 1e5})
    m:ball{pos = {0, 0, 0}, radius = 1e-3}
    m:ball{pos = {dx, 0, 0}, radius = 1e-3}
    return m
  end
  -- 60 %: the step succeeds, its contacts show the overlap
  local m = two(1.4e-3)
  raises(function() m:cycle(10) end, "m:cycle: balls 1 and 2 overlap by 0.0006 m, 60% of the smaller radius 0.001 m",
         "the timestep is not the cause")
  eq(m:step(), 1)
  -- 180 %: the first step fails as unstable; the placement is still what is named
  m = two(0.2e-3)
  local err = raises(function() m:solve{steps = 10} end, "m:solve: balls 1 and 2 overlap by 0.0018 m, 180%")
  check(not err:find("lower the timestep", 1, true), err)
  -- 40 %, or a looser limit: no error, and the same bits as with no check
  m = two(1.6e-3)
  m:cycle(50)
  local h = m:hash()
  m = two(1.6e-3, {dim = 3, overlap_limit = 1})
  m:cycle(50)
  eq(m:hash(), h)
  -- a wall added over a placed ball
  m = seixo.model{dim = 2}
  m:material("a", {density = 2650, kn = 1e6, ks = 1e6})
  m:ball{pos = {0, 0.5e-3}, radius = 1e-3}
  m:wall{kind = "box", min = {-0.01, 1e-3}, max = {0.01, 0.02}}
  raises(function() m:cycle(10) end, "ball 1 overlaps wall 3 by 0.0015 m, 150% of its radius 0.001 m (its centre is behind the wall)")
  -- balls generated (distribute, which moves only its own) over balls
  -- that have cycled: named before any is added, not blamed on the
  -- timestep; its own balls' overlaps are its relaxation's, not checked
  m = seixo.model{dim = 2}
  m:material("a", {kn = 1e6, ks = 1e6, damping = 0.5})
  m:wall{kind = "box", min = {0, 0}, max = {0.05, 0.05}}
  m:generate{count = 100, radius = {0.8e-3, 1e-3}, region = {box = {{0, 0}, {0.05, 0.05}}}, seed = 2}
  m:cycle(10)
  err = raises(function()
    m:generate{method = "distribute", porosity = 0.5, radius = {0.5e-3, 0.6e-3}, region = {box = {{0, 0}, {0.05, 0.05}}},
               seed = 4}
  end, "m:generate: a ball it places (at 0.048884218094219, 0.043980682039162) would overlap ball 28 by",
         "250% of the smaller radius", "distribute moves only the balls it makes")
  check(not err:find("lower the timestep", 1, true), err)
  eq(m:ball_count(), 100, "none added")
  for _, wall in ipairs{false, true} do -- a wall first: the relaxation's first step is checked
    local tight = seixo.model{dim = 2, overlap_limit = 0.02}
    tight:material("a", {kn = 1e6, ks = 1e6})
    if wall then tight:wall{kind = "box", min = {0, 0}, max = {0.01, 0.01}} end
    eq(tight:generate{method = "distribute", porosity = 0.2, radius = {0.5e-3, 0.6e-3},
                      region = {box = {{0, 0}, {0.01, 0.01}}}, seed = 4} > 0, true)
  end
  -- a lattice over a ball that has cycled: the next step names the placement
  m = seixo.model{dim = 2}
  m:material("a", {kn = 1e6, ks = 1e6, damping = 0.5})
  m:ball{pos = {0.0051, 0.0052}, radius = 1e-3}
  m:cycle(1)
  m:generate{method = "lattice", radius = 0.5e-3, region = {box = {{0, 0}, {0.01, 0.01}}}}
  err = raises(function() m:cycle(10) end, "m:cycle: balls 1 and", "as they were placed")
  check(not err:find("lower the timestep", 1, true), err)
end)

test("an unstable run's advice holds: after it, the automatic timestep is not blamed again", function()
  -- a robustness tester followed "use the automatic one" and got the same
  -- "timestep too large" error: the model still held the blown-up state
  local m = seixo.model{dim = 2, gravity = {0, -9.81}, timestep = 1e-2}
  m:material("s", {density = 2650, kn = 1e7, ks = 1e7, friction = 0.5})
  m:wall{kind = "box", min = {0, 0}, max = {0.1, 0.1}}
  m:generate{count = 300, radius = {1.5e-3, 2.5e-3}, region = {box = {{0, 0}, {0.1, 0.1}}}, seed = 7}
  raises(function() m:cycle(100) end, "unstable at step", "is too large for the contact stiffness", "from a save")
  m:set_timestep("auto")
  local err = raises(function() m:cycle(100) end, "unstable at step", "within the critical one",
                     "the overlap came from before this step", "load a save")
  check(not err:find("too large", 1, true), err)
end)

test("values outside a material's physical range warn once, with the unit expected", function()
  local status, out = T.run("-e " .. T.quote([[
m = seixo.model{dim = 3}
m:material("glass", {density = 2.5, kn = 1e5, ks = 1e5})
m:material("glass2", {density = 2.6})
m:material("rock", {modulus = 40, stiffness_ratio = 2})
m:material("fine", {density = 2650, modulus = 40e9})
w = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
w:servo{target = 10, area = 1}
m:material("sand", {friction = 30})
m:material("sand2", {friction = 0.5})
print("done")]]))
  eq(status, 0, out)
  check(out:find("seixo: warning: (command line):2: density 2.5 is outside the usual range for DEM, 100 ... 30000 kg/m^3 (seixo's unit is kg/m^3)", 1, true), out)
  local _, count = out:gsub("density", "")
  eq(count, 1, "once per model")
  check(out:find("(command line):4: modulus 40 is outside the usual range for DEM, 100000 ... 1e+12 Pa", 1, true), out)
  check(out:find("(command line):7: servo target stress 10 is outside the usual range for DEM, 1000 ... 1e+10 Pa (seixo's unit is Pa)", 1, true), out)
  -- a friction angle given for the coefficient
  check(out:find("(command line):8: friction 30 is a coefficient, the tangent of the friction angle", 1, true), out)
  check(not out:find("(command line):9:", 1, true), "the coefficient 0.5 is usual: " .. out)
  check(out:find("done\n$"), out)
end)

test("a fixed timestep far below the critical one warns once, given before or after the balls", function()
  -- a timestep in the wrong unit (1e-9 for 1e-6 s) ran a thousand times the
  -- steps needed with no word (a new user's first day)
  local status, out = T.run("-e " .. T.quote([[
m = seixo.model{dim = 2, timestep = 1e-11}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6})
m:generate{count = 50, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.03, 0.03}}}, seed = 2}
m:cycle(3)
m:cycle(3)
n = seixo.model{dim = 2}
n:material("g", {density = 2500, kn = 1e6, ks = 1e6})
n:generate{count = 50, radius = {1e-3, 1.5e-3}, region = {box = {{0, 0}, {0.03, 0.03}}}, seed = 2}
n:set_timestep(0.5 * n:critical_timestep())
n:cycle(3)
n:set_timestep(1e-3 * n:critical_timestep() / 2)
n:cycle(2)
print("done")]]))
  eq(status, 0, out)
  check(out:find("seixo: warning: %(command line%):4: the timestep 1e%-11 s is 1/[0-9]+ of the critical estimate [0-9.e-]+ s: "
                 .. "every run takes that many times the steps it needs %(m:set_timestep%('auto'%) sets the automatic one%)"), out)
  local _, count = out:gsub("the timestep 1e%-11", "")
  eq(count, 1, "once per model")
  check(not out:find(":9:", 1, true), "half the critical timestep is usual: " .. out)
  check(out:find("%(command line%):12: the timestep [0-9.e-]+ s is 1/[0-9]+ of the critical estimate"), out)
  check(out:find("done\n$"), out)
end)

test("clumps of a size outside the usual range warn, as balls do", function()
  -- a sieve curve in m given as clumps' scales (dimensionless) made pebbles
  -- of 0.25 um with no word, where a ball that small is warned of
  local status, out = T.run("-e " .. T.quote([[
m = seixo.model{dim = 3}
m:material("s", {})
m:clump_template("dimer", {{-0.25e-3, 0, 0, 0.5e-3}, {0.25e-3, 0, 0, 0.5e-3}})
m:generate{template = "dimer", count = 3, region = {box = {{0, 0, 0}, {0.1, 0.1, 0.1}}}}
print("scale 1")
m:generate{template = "dimer", psd = {{0.5e-3, 0}, {1.5e-3, 1}}, count = 3, region = {box = {{1, 1, 1}, {2, 2, 2}}}}
print("done")]]))
  eq(status, 0, out)
  check(not out:sub(1, out:find("scale 1", 1, true)):find("warning", 1, true), out)
  check(out:find("clump size (equivalent radius) 8.9", 1, true) and out:find("outside the usual range", 1, true), out)
end)

test("m:generate says when count and porosity together scaled the radii asked for", function()
  local status, out = T.run("-e " .. T.quote([[
m = seixo.model{dim = 2}
m:material("g", {density = 2500, kn = 1e6, ks = 1e6})
m:generate{count = 100, porosity = 0.3, radius = {0.5e-3, 0.8e-3}, region = {box = {{0, 0}, {0.05, 0.05}}}, method = "distribute"}
m:generate{count = 10, radius = {0.5e-3, 0.8e-3}, region = {box = {{0, 0.06}, {0.05, 0.1}}}}
print("done")]]))
  eq(status, 0, out)
  check(out:find("seixo: warning: (command line):3: m:generate: the radii were scaled by 3.519 to reach porosity 0.3 " ..
                 "with 100 balls: 0.0017597 ... 0.00281553 m instead of 0.0005 ... 0.0008 m", 1, true), out)
  local _, count = out:gsub("warning", "")
  eq(count, 1, "the count alone keeps the radii: no warning")
end)

test("an invalid value is an error with no range warning before it; a valid, unusual one warns", function()
  local status, out = T.run("-e " .. T.quote([[
m = seixo.model{dim = 3}
print(pcall(m.material, m, "a", {density = -1}))
print(pcall(m.material, m, "b", {modulus = -5}))
print(pcall(m.material, m, "c", {density = 2.5, kn = -1}))
print(pcall(m.material, m, "d", {shear_modulus = 0/0, modulus = 1e9}))
w = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
print(pcall(w.servo, w, {target = 0/0, area = 1}))
print(pcall(w.servo, w, {target = 10, area = -1}))
print("valid")
m:material("e", {density = 2.5})
print("done")]]))
  eq(status, 0, out)
  check(out:find("density must be > 0 kg/m^3 (got -1)", 1, true), out)
  check(out:find("modulus must be >= 0 Pa", 1, true), out)
  check(out:find("kn must be > 0 N/m (got -1)", 1, true), out)
  check(out:find("w:servo: the target stress must be finite", 1, true), out)
  check(out:find("w:servo: the area must be > 0 (got -1)", 1, true), out)
  -- no warning before "valid": the invalid values only failed (material c's density 2.5 included)
  local before = out:sub(1, out:find("valid", 1, true))
  check(not before:find("warning", 1, true), out)
  check(out:find("valid\nseixo: warning: (command line):10: density 2.5 is outside the usual range", 1, true), out)
  check(out:find("done\n$"), out)
end)

test("vectors: arithmetic, accepted wherever {x, y, z} is, returned by the API", function()
  local v, w = seixo.vec(1, 2, 3), seixo.vec{0, 1, 0}
  eq(tostring(v + w), "{1.0, 3.0, 3.0}")
  eq(tostring(v - w), "{1.0, 1.0, 3.0}")
  eq(tostring(-v), "{-1.0, -2.0, -3.0}")
  eq(tostring(v * 2), "{2.0, 4.0, 6.0}")
  eq(tostring(2 * v), "{2.0, 4.0, 6.0}")
  eq(tostring(v / 2), "{0.5, 1.0, 1.5}")
  check(v == seixo.vec(1, 2, 3) and v ~= w)
  eq(v:dot(w), 2.0)
  eq(tostring(v:cross(w)), "{-3.0, 0.0, 1.0}")
  eq(seixo.vec(3, 4):norm(), 5.0)
  eq(seixo.vec(1, 0):cross(seixo.vec(0, 1)), 1.0)
  eq(tostring(seixo.vec(0, 3, 4):unit()), "{0.0, 0.6, 0.8}")
  eq(v.x + v.y + v.z, 6.0)
  eq(#v, 3)
  raises(function() return v + seixo.vec(1, 2) end, "the two vectors differ in length")
  raises(function() return v * w end, "a vector times a number expected")
  raises(function() return seixo.vec(0, 0):unit() end, "the zero vector has no direction")
  raises(function() return v.w end, "vector has no field 'w'")
  -- a plain array past its components: nil, so ipairs stops (it raised "no field '4'")
  eq(v[4], nil)
  local seen = 0
  for i, x in ipairs(v) do seen = seen + 1; eq(x, v[i]) end
  eq(seen, 3)
  eq(seixo.model{dim = 2}:gravity()[3], nil)
  local m = seixo.model{dim = 3, gravity = {0, 0, -10}}
  m:material("a")
  local b = m:ball{pos = seixo.vec(0, 0, 1), radius = 0.1, vel = v}
  eq(getmetatable(b.pos:copy()), getmetatable(v))
  b.pos = b.pos + b.vel * 0.5
  eq(tostring(b.pos), "{0.5, 1.0, 2.5}")
  eq(tostring(m:gravity()), "{0.0, 0.0, -10.0}")
  -- a field's vector is a read-only copy: setting a component says how to set the field
  raises(function() b.pos[1] = 5 end, "ball.pos is a copy of the field: setting its component 1 would not change "
         .. "the object; assign the whole vector (local v = ball.pos:copy(); v[1] = ...; ball.pos = v)")
  raises(function() b.vel.x = 5 end, "ball.vel is a copy of the field: setting its component x")
  raises(function() b.force[2] = 0 end, "ball.force is a copy of a read-only field: its component 2 cannot be set")
  local w = m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  raises(function() w.point[3] = 1 end, "wall.point is a copy of the field")
  eq(b.pos.x, 0.5)
  local copy = b.pos:copy()
  copy[1] = 5
  eq(b.pos.x, 0.5, "a copy is a copy")
  b.pos = copy
  eq(tostring(b.pos), "{5.0, 1.0, 2.5}")
  -- a field vector reads like a vector: length, components, pairs, ipairs, unpack, arithmetic, == and the API
  local p = b.pos
  eq(#p, 3)
  eq(p[1] + p.y + p[3], 8.5)
  local n = 0
  for k, x in pairs(p) do n = n + k * x end
  eq(n, 5 + 2 + 7.5)
  n = 0
  for k, x in ipairs(p) do n = n + k * x end
  eq(n, 14.5)
  eq(select("#", table.unpack(p)), 3)
  check(p == seixo.vec(5, 1, 2.5) and p:norm() == seixo.vec(5, 1, 2.5):norm())
  eq(tostring(p - seixo.vec(5, 1, 2.5)), "{0.0, 0.0, 0.0}")
  local b2 = m:ball{pos = p + seixo.vec(1, 0, 0), radius = 0.1}
  eq(tostring(b2.pos), "{6.0, 1.0, 2.5}")
  -- kept in m:vars(), it is saved as its components
  m:vars().where = b.pos
  local file = T.tmpname(".h5")
  eq(#m:save(file), 0, "nothing skipped")
  local loaded = seixo.load(file)
  eq(loaded:vars().where[1], 5.0)
  eq(#loaded:vars().where, 3)
  loaded:close()
  os.remove(file)
  m:close()
end)

test("b.disp: the displacement since m:reset_disp, for balls added later since their first cycle", function()
  local m = seixo.model{dim = 2, timestep = 1e-3}
  m:material("a")
  local b = m:ball{pos = {0, 0}, radius = 0.1, vel = {1, 0}}
  raises(function() return b.disp end, "ball field 'disp': no reference position yet; m:reset_disp() starts")
  m:cycle(10)
  eq(m:reset_disp(), 1)
  eq(tostring(b.disp), "{0.0, 0.0}")
  m:cycle(100)
  T.near(b.disp.x, 0.1, 1e-12)
  local c = m:ball{pos = {5, 5}, radius = 0.1, vel = {0, 2}}
  eq(tostring(c.disp), "{0.0, 0.0}")  -- measured from the next cycle on
  m:cycle(100)
  T.near(b.disp.x, 0.2, 1e-12)
  T.near(c.disp.y, 0.2, 1e-12)
  -- a filter resets some balls only
  eq(m:reset_disp{where = function(x) return x.id == 1 end}, 1)
  eq(b.disp.x, 0.0)
  T.near(c.disp.y, 0.2, 1e-12)
  check(tostring(b):find("seixo.ball 1", 1, true))
  m:close()
end)

test("group slots: a ball in several groups, filters by any slot or one", function()
  local m = seixo.model{dim = 2}
  m:material("a")
  for i = 1, 6 do m:ball{pos = {i, 0}, radius = 0.1} end
  eq(m:group("left", {where = function(b) return b.pos.x < 3.5 end}), 3)       -- slot 1: b.group
  eq(m:group("even", function(b) return b.id % 2 == 0 end, 2), 3)              -- slot 2
  local b = m:ball(2)
  eq(b.group, "left")
  eq(b.groups[1], "left")
  eq(b.groups[2], "even")
  b:set_group("special", 5)
  eq(b.groups[5], "special")
  eq(m:count{group = "even"}, 3)
  eq(m:count{group = "even", slot = 1}, 0)
  eq(m:count{group = "even", slot = 2}, 3)
  eq(m:count{group = "left", region = {box = {{1.5, -1}, {7, 1}}}}, 2)
  local g = m:groups()
  eq(g.left, 3)
  eq(g.even, 3)
  eq(g.special, 1)
  b:set_group(nil, 2)
  eq(b.groups[2], nil)
  eq(m:count{group = "even"}, 2)
  raises(function() m:group("x", {}, 9) end, "a group slot from 1 to 8 expected")
  raises(function() m:count{group = "left", slot = 0} end, "a group slot from 1 to 8 expected")
  raises(function() b:set_group("x", 9) end, "a group slot from 1 to 8 expected")
  m:close()
end)

test("group slots 2 to 8: saved by m:save, restored by seixo.load, in m:hash(), dropped with their ball", function()
  local m = seixo.model{dim = 3}
  m:material("a")
  for i = 1, 8 do m:ball{pos = {i, 0, 0}, radius = 0.1} end
  local plain = m:hash()
  m:group("left", {where = function(b) return b.pos.x < 4.5 end})
  m:group("even", function(b) return b.id % 2 == 0 end, 2)
  m:ball(3):set_group("odd", 8)
  m:ball(5):set_group("special", 5)
  local h = m:hash()
  check(h ~= plain, "slot 1 is in the core's hash")
  -- a group in slot 2 changes the hash; taken away, the hash is back
  m:ball(7):set_group("even", 2)
  local h7 = m:hash()
  check(h7 ~= h, "a slot-2 group changes the hash")
  m:ball(7):set_group(nil, 2)
  eq(m:hash(), h)
  m:ball(7):set_group("even", 2)
  local path = T.tmpname(".h5")
  m:save(path)
  local r = seixo.load(path)
  eq(r:hash(), h7, "same hash after the load")
  eq(r:ball(2).groups[2], "even")
  eq(r:ball(7).groups[2], "even")
  eq(r:ball(3).groups[8], "odd")
  eq(r:ball(5).groups[5], "special")
  eq(r:ball(1).groups[2], nil)
  eq(r:count{group = "even", slot = 2}, 5)
  eq(r:count{group = "odd"}, 1)
  eq(r:groups().even, 5)
  -- the two continue alike
  m:cycle(20)
  r:cycle(20)
  eq(r:hash(), m:hash())
  -- a removed ball leaves its slots; the hash sees it
  local before = r:hash()
  r:ball(2):remove()
  eq(r:count{group = "even", slot = 2}, 4)
  check(r:hash() ~= before)
  r:save(path)
  local r2 = seixo.load(path)
  eq(r2:count{group = "even", slot = 2}, 4)
  eq(r2:hash(), r:hash())
  -- a model without slots 2 to 8 keeps the core's hash
  local q = seixo.model{dim = 3}
  q:material("a")
  q:ball{pos = {0, 0, 0}, radius = 0.1}
  local hq = q:hash()
  q:ball(1):set_group("x", 3)
  q:ball(1):set_group(nil, 3)
  eq(q:hash(), hq)
  os.remove(path)
  for _, x in ipairs{m, r, r2, q} do x:close() end
end)

test("m:save writes a table's keys in a fixed order: two runs save the same file data", function()
  -- Lua seeds its string hash per run, so the keys' order in a table
  -- differs from run to run; the file must not
  local script = tmpfile([[
local m = seixo.model{dim = 2}
m:material("a")
local v = m:vars()
for i = 1, 40 do v["k" .. i] = i end
v[1.5], v[3], v[true], v[false] = "f", "i", 1, 0
v.t = {x = 1, y = 2, [2] = 3, z = {w = "deep"}}
m:save(arg[1])
]])
  local a, b = T.tmpname(".h5"), T.tmpname(".h5")
  for _, f in ipairs{a, b} do eq(T.run(T.quote(script) .. " " .. T.quote(f)), 0) end
  check(os.execute("h5diff -q " .. T.quote(a) .. " " .. T.quote(b) .. " /lua"), "two runs' /lua groups differ")
  local m = seixo.load(a)
  eq(m:vars().k17, 17)
  eq(m:vars()[1.5], "f")
  eq(m:vars()[true], 1)
  eq(m:vars().t.z.w, "deep")
  m:close()
  for _, f in ipairs{script, a, b} do os.remove(f) end
end)

T.done()
