-- A pour settling in a box, for the MPI decomposition test (tests/meson.build,
-- lua_mpi_pour): run serially and under mpirun -np 1 ... 4, it prints the
-- same state hash. Arguments: count, steps, dim (default 600, 3000, 3).
local count = tonumber(arg and arg[1]) or 600
local steps = tonumber(arg and arg[2]) or 3000
local dim = tonumber(arg and arg[3]) or 3
local m = seixo.model{dim = dim, gravity = dim == 3 and {0, 0, -9.81} or {0, -9.81}}
-- (softer in 3D: a longer timestep, so the pour lands within the test's steps)
local k = dim == 3 and 1e5 or 1e6
m:material("glass", {density = 2500, kn = k, ks = k, friction = 0.5, damping = 0.7, viscous_normal = 0.3})
local width = dim == 3 and 0.085 or 0.5 * count / 600
local height = dim == 3 and 0.2 or 0.4
local walls
if dim == 3 then
  walls = m:wall{kind = "box", min = {0, 0, 0}, max = {width, width, height}}
else
  walls = m:wall{kind = "box", min = {0, 0}, max = {width, height}}
end
m:generate{count = count, radius = {3e-3, 5e-3}, region = {box = dim == 3 and {{0, 0, 0}, {width, width, 0.3 * height}}
                                                                             or {{0, 0}, {width, 0.5 * height}}},
           seed = 7}
local floor = walls[dim == 3 and 5 or 3]
local half = steps // 2
m:cycle(half)
print(string.format("mid %d %s", m:step(), m:hash()))
m:cycle(steps - half)
print(string.format("end %d contacts %d floor %.17g ratio %.17g kinetic %.17g", m:step(), m:contact_count(),
                    floor.force[dim], m:ratio(), m:energy().kinetic))
print(string.format("hash %s", m:hash()))
-- (on stderr: the serial run's output must equal the decomposed runs')
io.stderr:write(string.format("ranks %d\n", m:ranks()))
