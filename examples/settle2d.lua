-- Settling disks in a box under gravity (2D, disks of unit thickness).
--   scripts/run examples/settle2d.lua [count] [steps]
local count = tonumber(arg and arg[1]) or 1000
local steps = tonumber(arg and arg[2]) or 40000

local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})

local rmax = 6e-3
local side = math.ceil(math.sqrt(count / 2))        -- lattice columns
local pitch = 2.05 * rmax
local width = side * pitch
local rows = math.ceil(count / side)
m:wall{kind = "box", min = {0, 0}, max = {width, (rows + 1) * pitch}}

local seed = 12345
local function random()
  seed = (1103515245 * seed + 12345) % 2147483648
  return seed / 2147483648
end

for k = 0, count - 1 do
  local i, j = k % side, k // side
  local r = rmax * (0.8 + 0.4 * random()) / 1.2
  m:ball{pos = {(i + 0.5) * pitch + 0.02 * rmax * (random() - 0.5), (j + 0.5) * pitch}, radius = r}
end

print(string.format("settle2d: %d disks, timestep %.3g s", m:ball_count(), m:timestep()))
local chunk = steps // 10
local t0 = os.clock()
for _ = 1, 10 do
  m:cycle(chunk)
  print(string.format("step %7d  time %.4f s  kinetic %.3e J  contacts %d",
                      m:step(), m:time(), m:energy().kinetic, m:contact_count()))
end
local elapsed = os.clock() - t0
print(string.format("settle2d: %d steps in %.2f s: %.0f steps/s", chunk * 10, elapsed, chunk * 10 / elapsed))
