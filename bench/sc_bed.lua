-- The SC-bed of ../shared/BENCH.md as a script, for scripts/bench --mpi:
-- `mpirun -np N seixo bench/sc_bed.lua N_BALLS [STEPS [WARMUP [CHUNK]]]`
-- runs the scene decomposed over the ranks (issue 16), as
-- build/bench/sx-bench (the same scene through the C API, bench/sc_bed.c)
-- runs it on threads; CHUNK cuts the timed steps into cycles of that many
-- (a script cycling in short runs; default one cycle). The last line, from
-- rank 0: "SXBENCH n=... ranks=... steps=... seconds=... hash=...";
-- seconds is the wall time of the timed block, which starts and ends on
-- every rank together (it ends with a query, m:contact_count(), which
-- gathers the state the cycles left on each rank), and the hash lets the
-- caller check that every rank count computed the same bits.
local sizes = {[10000] = {20, 20, 25}, [50000] = {50, 40, 25}, [100000] = {50, 80, 25}, [400000] = {100, 160, 25}}
local n = math.tointeger(tonumber(arg and arg[1]) or 10000)
local steps = math.tointeger(tonumber(arg and arg[2]) or 2000)
local warmup = math.tointeger(tonumber(arg and arg[3]) or 10)
local chunk = math.tointeger(tonumber(arg and arg[4]) or steps)
local size = n and sizes[n]
if not size then error("sc_bed.lua: N must be 10000, 50000, 100000 or 400000 (BENCH.md's lattices), got " .. tostring(arg[1])) end
if not steps or steps < 1 or not warmup or warmup < 0 or not chunk or chunk < 1 or steps % chunk ~= 0 then
  error("sc_bed.lua: STEPS >= 1, WARMUP >= 0 and CHUNK >= 1 dividing STEPS expected")
end
local nx, ny, nz = size[1], size[2], size[3]

-- BENCH.md's constants; seixo's springs are per ball, in series at a
-- contact (4-22): 2e5 N/m on each side is 1e5 N/m per contact. The dashpot
-- is ratio-based: the ball-ball ratio everywhere, as sx-bench does.
local R, delta0, A = 0.01, 1e-5, 2e-6
local s = 2 * R - delta0
local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}, timestep = 1e-5, skin = 0.002}
m:material("bed", {density = 2500, kn = 2e5, ks = 2e5, friction = 0.5, damping = 0, viscous_normal = 0.21545,
                   viscous_shear = 0})
local function perturbation(p, mul, add)
  local u = (p * mul + add) & 0xffffffff
  return A * (2 * (u / 4294967296.0) - 1)
end
for k = 0, nz - 1 do
  for j = 0, ny - 1 do
    for i = 0, nx - 1 do
      local p = i + nx * (j + ny * k)
      m:ball{pos = {R - delta0 / 2 + i * s + perturbation(p, 2654435761, 12345),
                    R - delta0 / 2 + j * s + perturbation(p, 2246822519, 3266489917), R + k * s},
             radius = R, material = "bed"}
    end
  end
end
local lx, ly = nx * s, ny * s
for _, w in ipairs{{{0, 0, 0}, {0, 0, 1}}, {{0, 0, 0}, {1, 0, 0}}, {{lx, 0, 0}, {-1, 0, 0}}, {{0, 0, 0}, {0, 1, 0}},
                   {{0, ly, 0}, {0, -1, 0}}} do
  m:wall{kind = "plane", point = w[1], normal = w[2], kn = 2e5, ks = 2e5, friction = 0.5}
end
m:cycle(warmup)
local t0 = seixo.clock()
for _ = 1, steps // chunk do m:cycle(chunk) end
local contacts = m:contact_count()
local seconds = seixo.clock() - t0
print(string.format("SXBENCH n=%d ranks=%d steps=%d seconds=%.6f contacts=%d kinetic=%.6e hash=%s", n, m:ranks(),
                    steps, seconds, contacts, m:energy().kinetic, m:hash()))
