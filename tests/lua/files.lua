-- What a write does to what the user has at its path (a robustness
-- tester's findings): every file is written under a temporary name and
-- renamed over the old one, so a path that is not a regular file is
-- refused, not replaced; the device, the pipe, the link and its target
-- are left as they were.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local test, check, eq, raises = T.test, T.check, T.eq, T.raises

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p '" .. dir .. "'")

local function kind(path) -- "file", "link", "fifo", "char" or "missing", by the shell's test
  for _, k in ipairs{{"-L", "link"}, {"-p", "fifo"}, {"-c", "char"}, {"-d", "folder"}, {"-f", "file"}} do
    if os.execute("test " .. k[1] .. " '" .. path .. "'") then return k[2] end
  end
  return "missing"
end

local function small_model()
  local m = seixo.model{dim = 2}
  m:material("s", {kn = 1e6})
  m:ball{pos = {0, 0}, radius = 0.01}
  m:history("kinetic", "kinetic")
  m:cycle(3)
  return m
end

test("a path that is not a regular file is refused, and left as it was", function()
  local m = small_model()
  local target, link, fifo = dir .. "/target.h5", dir .. "/link.h5", dir .. "/fifo"
  m:save(target)
  local before = io.open(target, "rb"):read("a")
  os.execute("ln -s '" .. target .. "' '" .. link .. "' && mkfifo '" .. fifo .. "'")
  -- as root, m:save("/dev/null") had replaced the system's /dev/null by a file
  raises(function() m:save("/dev/null") end, "'/dev/null'", "not a regular file")
  eq(kind("/dev/null"), "char")
  raises(function() m:save(link) end, "is a symbolic link", "give the target's path")
  eq(kind(link), "link")
  eq(io.open(target, "rb"):read("a"), before)
  raises(function() m:save(fifo) end, "not a regular file")
  eq(kind(fifo), "fifo")
  raises(function() m:save(dir) end, "is a folder")
  raises(function() m:history_csv(link) end, "is a symbolic link")
  raises(function() m:output{path = fifo} end, "not a regular file")
  eq(kind(fifo), "fifo")
  -- the lab library's files: checked before the work, as m:save checks
  local ok, why = seixo.replaceable("/dev/null")
  check(ok == false and why:find("not a regular file", 1, true), tostring(why))
  eq(seixo.replaceable(dir .. "/new.csv"), true)
  local pool = require "seixo.pool"
  raises(function() pool.write_file(link, "x") end, "cannot write " .. link, "symbolic link")
  eq(io.open(target, "rb"):read("a"), before)
  local lab = require "seixo.lab"
  raises(function() lab.specimen{dim = 2, width = 0.01, height = 0.02, path = "/dev/null", log = false} end,
         "lab.specimen: cannot write /dev/null", "not a regular file")
  -- a regular file is replaced as before
  m:save(dir .. "/plain.h5")
  m:save(dir .. "/plain.h5")
  eq(kind(dir .. "/plain.h5"), "file")
  m:close()
end)

test("an open output series' file is not taken by another writer", function()
  local m, other = small_model(), small_model()
  local path = dir .. "/series.h5"
  local o = m:output{path = path}
  o:write()
  m:cycle(2)
  o:write()
  -- a second output on the path (this model's or another's), or a save to
  -- it, replaced the file while the first went on counting snapshots lost
  raises(function() other:output{path = path} end, "an output series open in this session writes this file")
  -- a path ending .xmf put the HDF5 data in a.xmf and the XDMF in a.xmf.xmf
  raises(function() other:output{path = dir .. "/a.xmf"} end, "give the series' .h5 path")
  raises(function() m:output{path = path, append = true} end, "close it first")
  raises(function() other:save(path) end, "an output series open in this session writes this file")
  raises(function() m:history_csv(path) end, "an output series open")
  os.execute("ln -s series.h5 '" .. dir .. "/alias.h5'")
  raises(function() other:save(dir .. "/alias.h5") end, "symbolic link")
  -- another spelling of the same file, and a hard link to it: the same file
  raises(function() other:save(dir .. "/./series.h5") end, "an output series open in this session writes this file")
  -- its .xmf, rewritten at each write, by any spelling; and another series that would share it
  raises(function() other:save(dir .. "/series.xmf") end, "an output series open in this session writes this file")
  raises(function() other:history_csv(dir .. "/./series.xmf") end, "an output series open")
  raises(function() other:output{path = dir .. "/series.hdf5"} end, "is another open output series'")
  os.execute("ln '" .. path .. "' '" .. dir .. "/hard.h5'")
  raises(function() other:save(dir .. "/hard.h5") end, "an output series open in this session writes this file")
  o:write()
  eq(o:count(), 4) -- m:output's own first snapshot and three writes: none lost
  o:close()
  -- closed, the file is the user's to replace or to append to
  -- appended at the step of its last snapshot (a restart from a save made
  -- there): that snapshot is not written twice (its time came twice in the .xmf)
  local again = m:output{path = path, append = true}
  eq(again:count(), 4)
  m:cycle(1)
  again:write()
  eq(again:count(), 5)
  again:close()
  other:save(path)
  m:close()
  other:close()
end)

test("a run stops before a state that could not be saved and loaded", function()
  -- a cylinder shrinking through a zero radius: saved, then refused as damaged
  local m = seixo.model{dim = 3}
  m:material("s", {kn = 1e6})
  local w = m:wall{kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}, radius = 0.01, height = 0.1}
  m:ball{pos = {0, 0, 0.05}, radius = 0.002}
  w:set_radial_vel(-100)
  raises(function() m:cycle(1000) end, "cylinder 1: its radius", "a radius must stay > 0")
  check(w:radius() > 0, "radius " .. w:radius())
  local at = m:step()
  m:save(dir .. "/cylinder.h5")
  local back = seixo.load(dir .. "/cylinder.h5")
  eq(back:step(), at)
  eq(back:hash(), m:hash())
  back:close()
  w:set_radial_vel(0)
  m:cycle(2) -- and it goes on once stopped
  -- a servo closing the cylinder on nothing (its speed set within the step)
  local s = seixo.model{dim = 3}
  s:material("s", {kn = 1e6})
  local sw = s:wall{kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}, radius = 0.01, height = 0.1}
  s:ball{pos = {0, 0, 0.5}, radius = 0.002} -- above the cylinder: it pushes on nothing
  sw:servo{target = 1e5, area = 1e-3, max_speed = 1e4}
  raises(function() s:cycle(10) end, "cylinder 1: its radius", "its servo closes it on nothing")
  check(sw:radius() > 0, "radius " .. sw:radius())
  s:save(dir .. "/servo.h5")
  eq(seixo.load(dir .. "/servo.h5"):step(), s:step())
  s:close()
  -- gravity whose step velocity overflows its square (the run's state then loaded as damaged)
  raises(function() m:set_gravity{0, 0, 1e308} end, "below 1e100")
  raises(function() seixo.model{dim = 3, gravity = {0, 0, 1e200}} end, "below 1e100")
  m:close()
  -- a cell driven inside out (no ball to meet the contact-reach check)
  local p = seixo.model{dim = 2}
  p:material("s", {kn = 1e6})
  p:periodic{min = {0, 0}, max = {1, 1}}
  p:set_timestep(1e-3)
  p:cell_control{xx = {rate = -1e6}}
  raises(function() p:cycle(10) end, "would make it", "thick across axis x", "lower the rate")
  check(p:periodic().size[1] > 0, "width " .. p:periodic().size[1])
  p:save(dir .. "/cell.h5")
  local q = seixo.load(dir .. "/cell.h5")
  eq(q:periodic().size[1], p:periodic().size[1])
  q:close()
  p:close()
  -- with a ball moving: the refused step is undone whole (the ball had
  -- moved a step while the clock had not)
  local c = seixo.model{dim = 2, timestep = 1e-3}
  c:material("s", {kn = 1e6})
  c:periodic{min = {0, 0}, max = {1, 1}}
  local b = c:ball{pos = {0.5, 0.5}, radius = 0.01, vel = {1, 0}}
  c:cycle(3)
  local x, t = b.pos[1], c:time()
  c:cell_control{xx = {rate = -1e6}}
  raises(function() c:cycle(5) end, "would make it")
  eq(c:time(), t)
  eq(b.pos[1], x)
  c:close()
end)

test("Lua source only: a precompiled chunk is refused by name, never run", function()
  -- a damaged precompiled chunk crashed seixo (SIGSEGV or abort in 30 of 300
  -- mutated files): Lua does not check bytecode
  local path = dir .. "/chunk.luac"
  local f = assert(io.open(path, "wb"))
  f:write(string.dump(function() return 42 end))
  f:close()
  raises(function() dofile(path) end, path .. ": a precompiled (luac) chunk", "Lua source only")
  local fn, why = loadfile(path)
  check(fn == nil and why:find(path .. ": a precompiled", 1, true), tostring(why))
  fn, why = load(string.dump(function() end), "dumped", "b")
  check(fn == nil and why:find("dumped: a precompiled", 1, true), tostring(why))
  -- as the executable's script
  local out = io.popen("'" .. seixo.executable() .. "' '" .. path .. "' 2>&1; echo \"exit $?\"")
  local text = out:read("a")
  out:close()
  check(text:find("a precompiled (luac) chunk", 1, true) and text:find("exit 1", 1, true), text)
  -- source runs as before: arguments, environments, results
  f = assert(io.open(dir .. "/source.lua", "w"))
  f:write("return (x or 40) + 2")
  f:close()
  eq(dofile(dir .. "/source.lua"), 42)
  eq(loadfile(dir .. "/source.lua", "t", {x = 1})(), 3)
  eq(load("return ...", "args")(7), 7)
  -- the wrappers' argument errors name the function (Lua's own, called from C, said '?')
  raises(function() load(nil) end, "bad argument #1 to 'load'")
  raises(function() loadfile({}) end, "bad argument #1 to 'loadfile'")
  local env = {}
  load("y = 5", "env", "t", env)()
  eq(env.y, 5)
end)

test("a name or a path with a zero byte is refused (C cut it there)", function()
  local m = seixo.model{dim = 2}
  -- "sand\0wet" and "sand\0dry" were one material, the second redefining the first
  raises(function() m:material("sand\0wet", {density = 2000}) end, "zero byte")
  m:material("sand", {density = 2000})
  raises(function() m:ball{pos = {0, 0}, radius = 0.01, material = "sand\0dry"} end, "field 'material'", "zero byte")
  local b = m:ball{pos = {0, 0}, radius = 0.01}
  raises(function() b.group = "top\0x" end, "zero byte")
  raises(function() b.material = "sand\0x" end, "zero byte")
  raises(function() m:save(dir .. "/x.h5\0junk") end, "zero byte")
  raises(function() seixo.load(dir .. "/x.h5\0junk") end, "zero byte")
  raises(function() m:output{path = dir .. "/s.h5\0junk"} end, "field 'path'", "zero byte")
  eq(b.group, nil)
  m:close()
end)

test("a SIGTERM (a batch scheduler's, timeout's) interrupts a run as Ctrl-C does: the script saves its state", function()
  -- it had ended seixo at once: the state since the last save lost, and a
  -- save under way left its temporary file
  local path = dir .. "/term.h5"
  local script = string.format([[
m = seixo.model{dim = 2}
m:material("r", {kn = 1e7, density = 2600, damping = 0.7})
m:wall{kind = "box", min = {0, 0}, max = {0.1, 0.1}}
m:generate{count = 300, radius = {1.5e-3, 2.5e-3}, region = {box = {{0, 0}, {0.1, 0.1}}}, seed = 3}
m:set_gravity{0, -9.81}
print("cycling") io.stdout:flush()
-- a SIGTERM to this process a moment after the loop begins, whatever the machine's speed
local ok, e = pcall(function()
  os.execute("(sleep 0.5; kill -TERM $PPID) &") -- (the shell's parent: this process)
  while true do m:cycle(100) end
end)
print(ok, e)
m:save(%q)
print("saved at step", m:step())]], path)
  local shell = string.format("%s -e %s; echo status $?", T.quote(T.seixo), T.quote(script))
  local h = io.popen(shell .. " 2>&1")
  local out = h:read("a")
  h:close()
  check(out:find("false\t[^\n]*interrupted"), out)
  check(out:find("saved at step\t%d+"), out)
  check(out:find("status 0\n"), out)
  local m = seixo.load(path)
  eq(tostring(m:step()), out:match("saved at step\t(%d+)"))
  eq(io.popen("ls -a '" .. dir .. "' | grep -c tmp"):read("a"), "0\n")
end)

os.execute("rm -rf '" .. dir .. "'")
T.done()
