-- Cycles that go on from the state the last one left scattered (issue 16:
-- under mpirun a cycle ends with each rank's own balls current, and a call
-- that needs more gathers the whole state first), for mpi_same.sh: every
-- rank count must print what the serial run prints, to the bit.
--   servo           a lid held at a stress by a Lua callback at every step
--                   (PFC's FISH servo: it reads the lid's force and sets its
--                   velocity; stopped at every 1000th step, when the bed is
--                   unforced, and made stiffer once): it must not gather,
--                   so nearly every step's cycle goes on from the last
--   events          the same with a bond_break handler (its events come
--                   from the ranks' merged crack logs: no gather), a
--                   history of a ball's height every 25 steps (a fetch)
--                   and a ball stopped every 500 (a gather), and a solve
--                   to a ratio at the end
--   leave           balls poured out of a region, a ball_leave_region
--                   handler printing each event (the balls' motion shared
--                   at each step's delivery: no gather)
--   SCRIPT ARGS...  another test scene (mpi_bonds.lua crush 3, ...) with
--                   every m:cycle(n) cut into runs of 1 to 7 steps
local scene = arg and arg[1] or "servo"
if scene == "leave" then
  local m = seixo.model{dim = 2, gravity = {0, -9.81}}
  m:material("g", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.3})
  m:wall{kind = "box", min = {0, 0}, max = {0.2, 0.2}}
  local upper = {box = {{0, 0.1}, {0.2, 0.2}}}
  m:generate{count = 400, radius = {2e-3, 3e-3}, region = upper, seed = 3}
  local p0 = m:profile{print = false}
  m:cycle(1) -- and the placement's check: each rank's own contacts
  local left, steps, heights = 0, 0, 0
  m:on("ball_leave_region", function(_, e)
    left, steps, heights = left + 1, steps + e.step, heights + e.pos[2] + 1e-3 * e.ball.vel[2]
  end, {region = upper})
  m:cycle(1500)
  local p = m:profile{print = false}
  if m:ranks() > 1 and p.gathers ~= p0.gathers then
    error(string.format("the leave handler's cycles gathered the state %d times", p.gathers - p0.gathers))
  end
  print(string.format("%d left the region, step sum %d, height sum %.17g; hash %s", left, steps, heights, m:hash()))
  io.stderr:write(string.format("ranks %d\n", m:ranks()))
  return
end
if scene ~= "servo" and scene ~= "events" then
  local here = debug.getinfo(1, "S").source:match("^@(.*/)") or "./"
  local methods = getmetatable(seixo.model{dim = 2}).__methods
  local cycle, k = methods.cycle, 0
  methods.cycle = function(m, n)
    local done = 0
    while done < n do
      k = k % 7 + 1
      local run = math.min(k, n - done)
      cycle(m, run)
      done = done + run
    end
  end
  arg = {[0] = here .. scene, table.unpack(arg, 2)}
  dofile(here .. scene)
  return
end

local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("rock", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3})
local w = m:wall{kind = "box", min = {0, 0}, max = {0.5, 0.3}}
m:generate{count = 800, radius = {3e-3, 5e-3}, region = {box = {{0, 0}, {0.5, 0.25}}}, seed = 5}
m:solve{ratio = 1e-3}
m:bond{kind = "parallel", gap = 1e-4, radius_multiplier = 1, modulus = 1e8, stiffness_ratio = 1, tensile_strength = 3e3,
       cohesion = 3e3}
local lid, top = w[4], 0
for b in m:balls() do top = math.max(top, b.pos[2] + b.radius) end
lid.point = {0, top + 5e-4}
local target, gain = 250, 1e-4
m:on("after", function()
  local stress = lid.force[2] / 0.5 -- the balls push the lid up
  local v = stress > 0 and math.max(-0.05, math.min(0.05, gain * (stress - target))) or -0.05
  if m:step() % 1000 == 0 then v = 0 end -- the bed unforced for a step: the guard takes a baseline
  if m:step() == 18000 then lid.kn = 2e6 end -- the timestep rated again
  lid.vel = {0, v}
end)
local broken, first, h = 0, nil, nil
-- histories of the ratio, energies and the timestep: their records gather
-- nothing (the ranks' sums chained, the least rating)
m:history("ratio", "ratio", {every = 50})
for _, name in ipairs{"kinetic", "strain", "bond_strain", "timestep"} do m:history(name, name, {every = 50}) end
-- and of two balls' motion, one through a function: each read fetches its
-- ball's row from its rank
m:history("ball_vy", {ball = 400, field = "vel", component = "y"}, {every = 50})
local watched = m:ball(799)
m:history("ball_x", function() return watched.pos[1] + watched.force[2] end, {every = 50})
if scene == "events" then
  m:on("bond_break", function(_, e)
    broken = broken + 1
    first = first or e.step
  end)
  local probe = m:ball(1)
  m:history("probe_y", function() return probe.pos[2] end, {every = 25})
  m:on("after", function() m:ball(7).vel = {0, 0} end, {every = 500})
end
local p0 = m:profile{print = false}
m:cycle(5000)
local p = m:profile{print = false}
-- the hash of a scattered model is its ranks' digests summed: no gather
local hash = m:hash()
if m:ranks() > 1 and m:profile{print = false}.gathers ~= p.gathers then
  error("m:hash() gathered the scattered state")
end
-- nor its energies and timestep: chained, the ghosts where their owners left them
local e, dt = m:energy(), m:timestep()
if m:ranks() > 1 and m:profile{print = false}.gathers ~= p.gathers then
  error("m:energy() or m:timestep() gathered the scattered state")
end
print(string.format("energy: kinetic %.17g strain %.17g bond strain %.17g; timestep %.17g", e.kinetic, e.strain,
                    e.bond_strain, dt))
print(string.format("lid at %.17g m, force %.17g N, %d bonds, %d broken (first at step %s)", lid.point[2],
                    lid.force[2], m:bond_count(), broken, tostring(first)))
h = m:history("ratio")
print(string.format("ratio %d samples, last %.17g", #h.values, h.values[#h.values]))
for _, name in ipairs{"kinetic", "strain", "bond_strain", "timestep", "ball_vy", "ball_x"} do
  h = m:history(name)
  local sum = 0
  for _, v in ipairs(h.values) do sum = sum + v end
  print(string.format("%s %d samples, sum %.17g, last %.17g", name, #h.values, sum, h.values[#h.values]))
end
if scene == "events" then
  h = m:history("probe_y")
  print(string.format("probe %d samples, last %.17g", #h.values, h.values[#h.values]))
end
print(string.format("step %d hash %s", m:step(), hash))
-- decomposed, the servo's cycles go on from each other (those that build at their start too)
local resumed, cycles = p.resumed - p0.resumed, p.cycles - p0.cycles
if scene == "servo" and m:ranks() > 1 and resumed < 0.9 * cycles then
  error(string.format("%d of %d cycles went on from the last one's scattered state", resumed, cycles))
end
if scene == "events" and m:ranks() > 1 and p.gathers - p0.gathers > 5000 // 500 then -- the stopped ball's alone
  error(string.format("the events' cycle gathered the state %d times", p.gathers - p0.gathers))
end
if scene == "servo" and m:ranks() > 1 and p.gathers ~= p0.gathers then -- the servo and the histories read no ball
  error(string.format("the servo's cycle gathered the state %d times", p.gathers - p0.gathers))
end
-- a loop over many balls' motion fetches 16 balls' rows, then every
-- ball's motion at once (no gather)
if scene == "servo" then
  local before, sum = m:profile{print = false}.gathers, 0
  for id = 1, 40 do
    local b = m:ball(id)
    sum = sum + b.pos[2] + b.vel[1] + b.force[2]
  end
  local gathers = m:profile{print = false}.gathers - before
  if m:ranks() > 1 and gathers ~= 0 then error(string.format("40 balls' motion read with %d gathers", gathers)) end
  print(string.format("40 balls' heights, velocities and forces: %.17g", sum))
end
local why, ratio, steps = m:solve{ratio = 1e-2, steps = 2000}
print(string.format("solve: %s ratio %.17g after %d steps; hash %s", why, ratio, steps, m:hash()))
io.stderr:write(string.format("ranks %d\n", m:ranks()))
-- after a cycle, the sums and selections over the balls share every ball's
-- motion (one exchange, no gather), and what every rank holds (groups,
-- materials, gravity, contact models) is read with no exchange at all
if scene == "servo" then
  m:cycle(500)
  local before = m:profile{print = false}.gathers
  -- the sums first: the predicate below reads every ball, which shares the motion too
  local kinetic, highest, speed, xsum = m:sum("kinetic"), m:max("pos")[2], m:mean("speed"), m:sum("pos")[1]
  local region = {box = {{0.15, 0}, {0.35, 0.2}}} -- across the ranks' cut
  local inside, xs = m:count{region = region}, 0
  for b in m:balls{region = region} do xs = xs + b.pos[1] end
  local rising = m:count{where = function(b) return b.vel[2] > 0 end}
  local mats, groups = 0, 0
  for _ in pairs(m:materials()) do mats = mats + 1 end
  for _ in pairs(m:groups()) do groups = groups + 1 end
  local gathers = m:profile{print = false}.gathers - before
  if m:ranks() > 1 and gathers ~= 0 then error(string.format("the sums and selections gathered %d times", gathers)) end
  print(string.format("kinetic %.17g, highest %.17g, mean speed %.17g, x sum %.17g", kinetic, highest, speed, xsum))
  print(string.format("selected %d (x sum %.17g), %d rising", inside, xs, rising))
  print(string.format("%d materials, %d groups, %d contact models, gravity %.17g, %d clumps", mats, groups,
                      #m:contact_models(), m:gravity()[2], m:clump_count()))
end
