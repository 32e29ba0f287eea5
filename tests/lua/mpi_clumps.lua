-- Clumps under the MPI decomposition (issue 16; test lua_mpi_clumps through
-- mpi_same.sh): a pour of clumps (overlapping three-pebble grains and
-- dumbbells) among free balls settling in a box, run serially and under
-- mpirun -np 1 ... 4, prints the same state hash at mid-run and at the end,
-- and the same contact count, floor force, ratio and kinetic energy, to the
-- bit. The clumps' pebbles lie on several ranks: a clump's owner steps it
-- from its pebbles' forces, the other ranks' sent to it. Arguments: dim (3), steps (8000), with
-- the automatic timestep (rated from the clumps' pebbles), or a fixed one
-- with a third argument "fixed". With "unstable" instead, a timestep a
-- hundred times the critical one: the cycle must stop on every rank with
-- the serial run's instability (mpi_stops.sh), not hang.
local dim = tonumber(arg and arg[1]) or 3
local steps = tonumber(arg and arg[2]) or 8000
local fixed = arg and arg[3] == "fixed"
local unstable = arg and arg[3] == "unstable"
local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81},
                      timestep = unstable and 3e-3 or fixed and 2e-5 or 0}
io.stderr:write(string.format("ranks %d\n", m:ranks()))
m:material("grain", {density = 2500, kn = 2e4, ks = 2e4, friction = 0.5, damping = 0.3, viscous_normal = 0.2})
local r = 3e-3
if dim == 3 then
  m:clump_template("tri", {{-r, 0, 0, r}, {r, 0, 0, r}, {0, 1.2 * r, 0.5 * r, 0.9 * r}})
  m:clump_template("pair", {{-0.8 * r, 0, 0, r}, {0.8 * r, 0, 0, 0.8 * r}})
else
  m:clump_template("tri", {{-r, 0, r}, {r, 0, r}, {0, 1.2 * r, 0.9 * r}})
  m:clump_template("pair", {{-0.8 * r, 0, r}, {0.8 * r, 0, 0.8 * r}})
end
local width = dim == 3 and 0.06 or 0.2
local height = dim == 3 and 0.2 or 0.3
local walls
if dim == 3 then
  walls = m:wall{kind = "box", min = {0, 0, 0}, max = {width, width, height}}
else
  walls = m:wall{kind = "box", min = {0, 0}, max = {width, height}}
end
local function box(lo, hi)
  return dim == 3 and {{0, 0, lo}, {width, width, hi}} or {{0, lo}, {width, hi}}
end
m:generate{template = "tri", count = dim == 3 and 150 or 100, scale = {0.9, 1.1}, region = {box = box(0, 0.3 * height)},
           seed = 11}
m:generate{template = "pair", count = dim == 3 and 100 or 80, region = {box = box(0.3 * height, 0.5 * height)},
           seed = 12}
m:generate{count = dim == 3 and 150 or 150, radius = {2e-3, 3e-3}, region = {box = box(0.5 * height, 0.7 * height)},
           seed = 13}
local floor = walls[dim == 3 and 5 or 3]
local half = steps // 2
m:cycle(half)
print(string.format("mid %d clumps %d balls %d dt %.17g %s", m:step(), m:clump_count(), m:ball_count(), m:timestep(),
                    m:hash()))
m:cycle(steps - half)
print(string.format("end %d contacts %d floor %.17g ratio %.17g kinetic %.17g", m:step(), m:contact_count(),
                    floor.force[dim], m:ratio(), m:energy().kinetic))
print(string.format("hash %s", m:hash()))
