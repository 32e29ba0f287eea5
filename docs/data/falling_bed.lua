-- A flowing scene for the build's cost (docs/performance.md, "Builds in a
-- flowing scene"): N balls (a multiple of 4,000) on a loose lattice, 50 x 80
-- per layer, falling at 1 m/s with a random sideways velocity into the
-- SC-bed's box, so the Verlet skin is used up every ~90 steps (the SC-bed
-- itself rebuilds once in 2,000). Serially, on threads or under mpirun:
--   build/seixo [--threads T] docs/data/falling_bed.lua [N [STEPS]]
--   mpirun -np R build/seixo docs/data/falling_bed.lua [N [STEPS]]
-- Prints (rank 0) the timed block's seconds, the builds in it, the broad
-- phase's milliseconds per build (m:profile) and the hash, the same for
-- every thread and rank count.
local n = math.tointeger(tonumber(arg and arg[1]) or 100000)
local steps = math.tointeger(tonumber(arg and arg[2]) or 1000)
if not n or n < 4000 or n % 4000 ~= 0 then error("falling_bed.lua: N must be a multiple of 4000, got " .. tostring(arg[1])) end
if not steps or steps < 1 then error("falling_bed.lua: STEPS >= 1 expected") end
local R, s = 0.01, 0.022
local nx, ny, nz = 50, 80, n // 4000
local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}, timestep = 1e-5, skin = 0.002}
m:material("bed", {density = 2500, kn = 2e5, ks = 2e5, friction = 0.5, damping = 0, viscous_normal = 0.2,
                   viscous_shear = 0})
math.randomseed(7)
for k = 0, nz - 1 do
  for j = 0, ny - 1 do
    for i = 0, nx - 1 do
      m:ball{pos = {R + i * s + 1e-4 * math.random(), R + j * s, R + k * s}, radius = R, material = "bed",
             vel = {0.5 * (math.random() - 0.5), 0.5 * (math.random() - 0.5), -1}}
    end
  end
end
local lx, ly = nx * s, ny * s
for _, w in ipairs{{{0, 0, 0}, {0, 0, 1}}, {{0, 0, 0}, {1, 0, 0}}, {{lx, 0, 0}, {-1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}},
                   {{0, ly, 0}, {0, -1, 0}}} do
  m:wall{kind = "plane", point = w[1], normal = w[2], kn = 2e5, ks = 2e5, friction = 0.5}
end
m:cycle(10)
m:profile{print = false, reset = true}
local t0 = seixo.clock()
m:cycle(steps)
local seconds = seixo.clock() - t0
local p = m:profile{print = false}
local builds = p.broad_phase.calls
print(string.format("falling_bed n=%d ranks=%d threads=%d steps=%d seconds=%.3f builds=%d ms_per_build=%.1f " ..
                    "bytes_in_per_step=%.0f hash=%s", n, m:ranks(), seixo.threads or 1, steps, seconds, builds,
                    builds > 0 and 1e3 * p.broad_phase.seconds / builds or 0, p.received / steps, m:hash()))
