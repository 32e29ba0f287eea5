-- A 3D sample the PFC way: generate, cycle to equilibrium, watch histories.
--   seixo examples/sample3d.lua [count] [ratio] [time]
-- Spheres are generated without overlap in a box of walls and settle under
-- gravity until the mean unbalanced-force ratio falls to `ratio` (or `time`
-- seconds of model time pass); the kinetic energy and the floor's load are
-- recorded and written as CSV to sample3d_histories.csv. Rolling resistance
-- and a normal dashpot settle the bed (without them a ball rolling on its
-- surface feels no force to damp, and the ratio stays near 0.2).
local count = tonumber(arg and arg[1]) or 500
local ratio = tonumber(arg and arg[2]) or 1e-3
local time = tonumber(arg and arg[3]) or 3
local util = require "seixo.util"

local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("granite", {density = 2650, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3,
                       rolling_friction = 0.1})
local size = {0.1, 0.1, 0.3}
local walls = m:wall{kind = "box", min = {0, 0, 0}, max = size}
local floor = walls[5]  -- -x, +x, -y, +y, -z, +z: the floor is the fifth

-- the balls go in a layer just high enough for a solid fraction of 0.3,
-- so that they have little to fall
local height = count * 4 / 3 * math.pi * 125e-9 / 0.3 / (size[1] * size[2])
local n, porosity = m:generate{count = count, radius = {4e-3, 6e-3}, distribution = "uniform",
                               region = {box = {{0, 0, 0}, {size[1], size[2], height}}}, seed = 7}
print(string.format("sample3d: %d balls, porosity %.3f as generated, timestep %.3g s", n, porosity, m:timestep()))

m:history("ke", "kinetic", {every = 100})
m:history("floor", {wall = floor, field = "force", component = "z"}, {every = 100})
m:history("ratio", "ratio", {every = 100})
-- a user variable kept by a callback: the highest ball, every 500 steps
local top = 0
m:on("cycle", function() top = m:max("pos")[3] end, {every = 500})

local t0 = os.clock()
local why, reached, steps = m:solve{ratio = ratio, time = time}
print(string.format("sample3d: stopped on %s (ratio %.2e) after %d steps, %.1f s", why, reached, steps, os.clock() - t0))

-- the floor carries the weight once at rest
local weight = m:sum("mass") * 9.81
print(string.format("sample3d: weight %.4g N, floor load %.4g N, top of the sample %.4f m", weight, -floor.force[3], top))
m:group("bottom", {region = {box = {{0, 0, 0}, {size[1], size[2], 0.02}}}})
print(string.format("sample3d: %d balls in the bottom 2 cm, mean radius %.3g m", m:count{group = "bottom"},
                    m:mean("radius", {group = "bottom"})))
local pressed = 0
for c in m:contacts{kind = "ball-wall", wall = floor} do pressed = pressed + c.fn end
print(string.format("sample3d: %d contacts, floor contacts carry %.4g N", m:contact_count(), pressed))
print(m)

local csv = "sample3d_histories.csv"
m:history_csv(csv)
local h = util.read_csv(csv)
print(string.format("sample3d: %d history rows in %s, last kinetic energy %.3g J", h.rows, csv, h.columns.ke[h.rows]))
