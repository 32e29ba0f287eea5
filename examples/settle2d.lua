-- Settling disks in a box under gravity (2D, disks of unit thickness).
--   scripts/run examples/settle2d.lua [count] [max_steps] [ratio]
-- Disks with radii uniform in [4, 6] mm are placed at random without
-- overlap in the lower part of a box of four lines (a solid fraction of
-- 0.4) and fall; local damping settles them until PFC's mean
-- unbalanced-force ratio falls to `ratio` (default 1e-2) or max_steps pass.
-- Times are wall-clock (seixo.clock).
local count = tonumber(arg and arg[1]) or 1000
local max_steps = tonumber(arg and arg[2]) or 200000
local ratio = tonumber(arg and arg[3]) or 1e-2

local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7, viscous_normal = 0.3})

local mean_area = math.pi * 5e-3 ^ 2 * (1 + 1 / 75)          -- <r^2> of the uniform radii
local width = 0.3 * math.sqrt(count / 1000)
local height = count * mean_area / 0.4 / width
local walls = m:wall{kind = "box", min = {0, 0}, max = {width, 1.2 * height}}
local floor = walls[3]                                       -- -x +x -y +y
local n = m:generate{count = count, radius = {4e-3, 6e-3}, region = {box = {{0, 0}, {width, height}}}, seed = 12345}
print(string.format("settle2d: %d disks in a %.3f m wide box, timestep %.3g s", n, width, m:timestep()))

local t0 = seixo.clock()
local why, reached
repeat
  why, reached = m:solve{ratio = ratio, steps = math.min(max_steps - m:step(), 10000)}
  print(string.format("step %7d  time %.4f s  kinetic %.3e J  contacts/disk %.2f  ratio %.2e",
                      m:step(), m:time(), m:energy().kinetic, 2 * m:contact_count() / n, reached))
until why ~= "steps" or m:step() >= max_steps
local elapsed = seixo.clock() - t0
print(string.format("settle2d: stopped on %s after %d steps, %.2f s: %.0f steps/s, %.3g disk-steps/s",
                    why, m:step(), elapsed, m:step() / elapsed, n * m:step() / elapsed))
print(string.format("settle2d: bed height %.4f m, floor load %.4g N/m for a weight of %.4g N/m",
                    m:max("pos")[2], -floor.force[2], m:sum("mass") * 9.81))
