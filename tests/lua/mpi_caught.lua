-- Errors a decomposed cycle meets, caught with pcall under mpirun
-- (issue 16; test lua_mpi_caught through mpi_same.sh: every rank count
-- prints what the serial run prints). An instability one rank finds in its
-- own part of a step, or one every rank finds alike, ends the cycle on
-- every rank at the same step with the serial run's error, which the
-- script catches on every rank, and goes on: here from a save made before.
--   overlap D   a settled bed of D dimensions given a timestep far above
--               the critical one: balls overlap by more than a radius (or
--               move by a non-finite amount) on some rank; the error's
--               step and cause, up to the critical estimate (the ranks'
--               least, made after the others' balls went on: see cause)
--   guard       an unforced bed given four times the critical timestep
--               (mpi_energy.lua guard 3 4): the energy guard, every rank's
--               decision, trips after a whole step; its whole message, and
--               the state it left, hash and all
--   periodic D  a granular gas compressed in a periodic cell, likewise (a rank also
--               runs the pairs of its balls' ghosts, whose errors are their
--               owners' to report)
--   radius      a bed in a cylinder with energy tracking, the cylinder
--               set to close through a zero radius in one step: every rank
--               refuses the step before any ball moves; the state and the
--               energies are the serial run's, then and after going on
--   clumps      a pour of clumps at a hundred times the critical timestep
--               (mpi_clumps.lua ... unstable): the clumps' exchanges with a
--               rank that failed
--   cause       a bed grown into contact, one ball swollen to six times
--               its radius and the timestep set 1.3 times the critical one:
--               its whole message, critical estimate included, which
--               decides the cause it names (the estimate was the failing
--               rank's own, 1.31e-5 s at 3 ranks against the serial
--               7.00e-6 s, and the message said the timestep was within
--               the critical one: a review's finding)
--   mesh        a row of balls rolling onto a mesh too fine for them (a
--               ball near more facets than a step lists), on the first
--               rank's side: the error is that rank's alone (its wall
--               blocks), and stopped the whole job instead of being caught
--               (a review's finding); the run goes on once the ball is gone
--   checks      errors of checks every rank makes alike, from what all
--               hold alike, before the steps (no ball to rate the
--               timestep from; two laws in one model, after a cycle that
--               left the state scattered too; a skin that lists too many
--               pairs) or at a build inside a cycle (a cell shrunk below
--               twice the contact reach): caught on every rank, as
--               serially (they stopped the job from rank 0, as if that
--               rank had met them alone: a user's finding), and the run
--               goes on to the serial hash
local scene = arg and arg[1] or "overlap"
local dim = tonumber(arg and arg[2]) or 2
local dir = (debug.getinfo(1, "S").source:match("^@(.*/)") or "./")

-- the error's step and cause
local function cause(err)
  return tostring(err):match("unstable at step %d+: [^;,(]*") or ("not an instability: " .. tostring(err))
end

if scene == "clumps" then
  arg = {"3", "8000", "unstable"}
  local ok, err = pcall(dofile, dir .. "mpi_clumps.lua")
  print("caught", not ok, cause(err))
  return
elseif scene == "guard" then
  arg = {"guard", "3", "4"}
  local ok, err = pcall(dofile, dir .. "mpi_energy.lua")
  print("caught", not ok, tostring(err):match("unstable at step .*") or tostring(err))
  local m = seixo.models()[1]
  print("left", m:step(), m:hash())
  return
end

if scene == "cause" then
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("g", {density = 2500, kn = 1e5, ks = 1e5, friction = 0.5, damping = 0.3})
  m:generate{count = 300, radius = 1e-3, seed = 4, region = {box = {{0, 0, 0}, {0.04, 0.01, 0.02}}}, material = "g"}
  m:wall{kind = "box", min = {0, 0, 0}, max = {0.04, 0.01, 0.05}}
  m:cycle(500)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  for k = 1, 10 do m:set{radius = 1e-3 * (1 + 0.06 * k)}; m:cycle(300) end
  m:ball(150).radius = 6e-3
  m:set_timestep(9e-6)
  local ok, err = pcall(m.cycle, m, 300)
  print("caught", not ok, string.format("critical %.6g s", m:critical_timestep()))
  print((tostring(err):gsub(" %(under mpirun the state is .*$", ""))) -- the rank's note aside
  return
end

if scene == "checks" then
  local function try(what, f, ...)
    local ok, err = pcall(f, ...)
    print(what, ok, (tostring(err):gsub("^.-: m:", "m:")))
  end
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("a", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.5})
  -- a query of the whole model one rank makes alone is no collective call,
  -- its error neither (compared between the ranks, it left rank 0 waiting)
  if seixo.rank() == 0 then try("alone", m.timestep, m) end
  try("empty", m.cycle, m, 10)
  m:wall{kind = "box", min = {0, 0}, max = {0.1, 0.1}}
  m:generate{count = 60, radius = {1.5e-3, 2.5e-3}, region = {box = {{0, 0}, {0.1, 0.1}}}, seed = 1, material = "a"}
  m:material("b", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.5})
  m:generate{count = 60, radius = {1.5e-3, 2.5e-3}, region = {box = {{0, 0}, {0.1, 0.1}}}, seed = 2, material = "b"}
  m:cycle(300) -- under mpirun, the state is left scattered
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  m:material("b", {density = 2650, model = "hertz", shear_modulus = 1e8, poisson = 0.2, friction = 0.5})
  try("laws", m.cycle, m, 10)
  m:material("b", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.5})
  m:cycle(100)
  print("on", m:step(), m:hash())
  local wide = seixo.model{dim = 2, skin = 0.5}
  wide:material("a", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.5})
  wide:generate{count = 3000, radius = {1e-3, 1e-3}, region = {box = {{0, 0}, {1, 1}}}, seed = 3}
  try("skin", wide.cycle, wide, 10)
  local c = seixo.model{dim = 2}
  c:material("s", {density = 2650, kn = 1e5, ks = 1e5, friction = 0.5, damping = 0.5})
  c:periodic{min = {0, 0}, max = {0.012, 0.05}}
  c:generate{count = 30, radius = {1e-3, 1e-3}, region = {box = {{0, 0}, {0.012, 0.05}}}, seed = 1}
  c:cell_control{xx = {rate = -1}}
  try("cell", c.cycle, c, 400000)
  print("cell left", c:step(), c:hash())
  c:cell_control{xx = {rate = 0}}
  c:periodic{min = {0, 0}, max = {0.02, 0.05}}
  c:cycle(100)
  print("cell again", c:step(), c:hash())
  return
end

if scene == "mesh" then
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("g", {density = 2500, kn = 1e5, ks = 1e5, friction = 0.5})
  for i = 0, 39 do m:ball{pos = {0.004 * i, 0.004 * (i % 3), 0.0012}, radius = 1e-3} end
  local tris, h = {}, 1e-4 -- 0.1 mm facets around the first ball
  for i = -15, 14 do for j = -15, 14 do
    local x0, y0 = i * h, j * h
    tris[#tris + 1] = {{x0, y0, 0}, {x0 + h, y0, 0}, {x0 + h, y0 + h, 0}}
    tris[#tris + 1] = {{x0, y0, 0}, {x0 + h, y0 + h, 0}, {x0, y0 + h, 0}}
  end end
  m:wall{kind = "mesh", triangles = tris}
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  local ok, err = pcall(m.cycle, m, 2000)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  print("caught", not ok, tostring(err):match("ball %d+ is near %d+ facets of mesh wall %d+"), m:step())
  m:ball(1):remove()
  m:cycle(200)
  print("again", m:step(), m:hash())
  return
end

if scene == "radius" then -- a bed in a cylinder, energy tracked; the cylinder set to close through 0 at once
  local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
  m:material("bead", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.2, viscous_normal = 0.1})
  local cyl = m:wall{kind = "cylinder", point = {0, 0, 0}, axis = {0, 0, 1}, radius = 0.03, height = 0.1}
  m:wall{kind = "plane", point = {0, 0, 0}, normal = {0, 0, 1}}
  m:generate{count = 1200, radius = {1.5e-3, 2.5e-3}, region = {cylinder = {p1 = {0, 0, 0.002}, p2 = {0, 0, 0.06}, radius = 0.026}},
             seed = 5}
  for b in m:balls() do -- thrown about: contacts, slip and dashpots from the start
    local k = b.id
    b.vel = {(k * 7 % 11 - 5) * 0.2, (k * 5 % 13 - 6) * 0.2, (k * 3 % 7 - 3) * 0.2}
  end
  m:track_energy(true)
  m:cycle(400)
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  cyl:set_radial_vel(-1e4)
  local ok, err = pcall(m.cycle, m, 100)
  print("caught", not ok, tostring(err):match("cylinder .*"))
  -- decided alike on every rank before any ball moved: the serial state, energies and all
  local function report(what)
    local e = m:energy()
    print(what, m:step(), m:hash(), string.format("%a %a %a %a", e.slip, e.viscous, e.local_damping, e.boundary_work))
  end
  report("left")
  cyl:set_radial_vel(0)
  m:cycle(300)
  report("again")
  return
end

local m
if scene == "periodic" then -- a granular gas in a cell periodic on every axis
  m = seixo.model{dim = dim}
  m:material("grain", {density = 2000, kn = 1e7, ks = 5e6, friction = 0.5, damping = 0.7})
  local L = dim == 3 and 0.06 or 0.2
  local zero, size = dim == 3 and {0, 0, 0} or {0, 0}, dim == 3 and {L, L, L} or {L, L}
  m:periodic{min = zero, max = size}
  m:generate{count = dim == 3 and 700 or 900, radius = {2.2e-3, 3.3e-3}, region = {box = {zero, size}}, seed = 7}
  local target = dim == 3 and 2e5 or 4e3 -- compressed into contact
  local servo = {xx = {stress = target}, yy = {stress = target}, max_rate = dim == 3 and 80 or 30}
  if dim == 3 then servo.zz = {stress = target} end
  m:cell_control(servo)
else
  m = dofile(dir .. "mpi_stack.lua")(dim, dim == 3 and 6 or 24, dim == 3 and 6 or 16, 8)
end
m:cycle(640)
io.stderr:write(string.format("ranks %d\n", m:ranks()))
local saved = os.tmpname()
m:save(saved)
print("settled", m:step(), m:hash())
m:set_timestep(300 * m:timestep())
local ok, err = pcall(m.cycle, m, 6400)
print("caught", not ok, cause(err))
print("left", m:step())
-- the ranks go on together: from the save, with the automatic timestep
m = seixo.load(saved)
os.remove(saved)
m:cycle(300)
print("again", m:step(), m:hash())
