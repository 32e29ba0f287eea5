-- Settling spheres in a box under gravity (3D).
--   scripts/run examples/settle3d.lua [count] [max_steps] [ratio] [rolling_friction]
-- Spheres with radii uniform in [4, 6] mm are placed at random without
-- overlap in the lower part of a box of six planes (a solid fraction of
-- 0.3) and fall; local damping, a normal dashpot and rolling resistance
-- (mu_r = 0.1) settle them until PFC's mean unbalanced-force ratio falls to
-- `ratio` (default 1e-3) or max_steps pass (default 250,000). Measured:
-- 300 balls stop on the ratio after 125,700 steps, 1,000 after 231,300.
-- Without rolling resistance (rolling_friction 0) a ball rolling on the
-- bed's surface feels no force to damp: 300 balls are still at ratio 0.033
-- after 200,000 steps. Times are wall-clock (seixo.clock).
local count = tonumber(arg and arg[1]) or 1000
local max_steps = tonumber(arg and arg[2]) or 250000
local ratio = tonumber(arg and arg[3]) or 1e-3
local rolling = tonumber(arg and arg[4]) or 0.1

local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3,
                     rolling_friction = rolling})

-- a square box whose width grows with the cube root of the count
local mean_volume = 4 / 3 * math.pi * 5e-3 ^ 3 * 1.08        -- <r^3> of the uniform radii
local width = 0.18 * (count / 1000) ^ (1 / 3)
local height = count * mean_volume / 0.3 / (width * width)
local walls = m:wall{kind = "box", min = {0, 0, 0}, max = {width, width, 1.2 * height}}
local floor = walls[5]                                       -- -x +x -y +y -z +z
local n = m:generate{count = count, radius = {4e-3, 6e-3}, region = {box = {{0, 0, 0}, {width, width, height}}},
                     seed = 12345}
print(string.format("settle3d: %d balls in a %.3f m wide box, timestep %.3g s", n, width, m:timestep()))

local t0 = seixo.clock()
local why, reached
repeat
  why, reached = m:solve{ratio = ratio, steps = math.min(max_steps - m:step(), 10000)}
  print(string.format("step %7d  time %.4f s  kinetic %.3e J  contacts/ball %.2f  ratio %.2e",
                      m:step(), m:time(), m:energy().kinetic, 2 * m:contact_count() / n, reached))
until why ~= "steps" or m:step() >= max_steps
local elapsed = seixo.clock() - t0
print(string.format("settle3d: stopped on %s after %d steps, %.2f s: %.0f steps/s, %.3g ball-steps/s",
                    why, m:step(), elapsed, m:step() / elapsed, n * m:step() / elapsed))
print(string.format("settle3d: bed height %.4f m, floor load %.4g N for a weight of %.4g N",
                    m:max("pos")[3], -floor.force[3], m:sum("mass") * 9.81))
-- at rest the walls together carry the weight; the side walls' friction may
-- point down (locked in when the bed rebounded), so the floor can carry more
local sides = 0
for k = 1, 4 do sides = sides - walls[k].force[3] end
print(string.format("settle3d: the walls carry %.5g N (floor %.5g N, side walls %.3g N) for a weight of %.5g N",
                    -floor.force[3] + sides - walls[6].force[3], -floor.force[3], sides, m:sum("mass") * 9.81))
