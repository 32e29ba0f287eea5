-- Settling spheres in a box under gravity (3D).
--   scripts/run examples/settle3d.lua [count] [steps]
-- Balls start on a jittered lattice with radii uniform in [4, 6] mm and
-- fall into a box of six planes; local damping settles them.
local count = tonumber(arg and arg[1]) or 2000
local steps = tonumber(arg and arg[2]) or 40000

local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("glass", {density = 2500, kn = 1e6, ks = 1e6, friction = 0.5, damping = 0.7})

local rmax = 6e-3
local side = math.ceil((count / 2) ^ (1 / 3))        -- lattice columns per side
local pitch = 2.05 * rmax
local width = side * pitch
m:wall{kind = "box", min = {0, 0, 0}, max = {width, width, 2 * width * (count / side ^ 3) + width}}

-- a small deterministic generator, so the example is reproducible
local seed = 12345
local function random()
  seed = (1103515245 * seed + 12345) % 2147483648
  return seed / 2147483648
end

local placed = 0
local layer = 0
while placed < count do
  for j = 0, side - 1 do
    for i = 0, side - 1 do
      if placed == count then break end
      local r = rmax * (0.8 + 0.4 * random()) / 1.2
      local jitter = 0.02 * rmax
      m:ball{pos = {(i + 0.5) * pitch + jitter * (random() - 0.5),
                    (j + 0.5) * pitch + jitter * (random() - 0.5),
                    (layer + 0.5) * pitch}, radius = r}
      placed = placed + 1
    end
  end
  layer = layer + 1
end

print(string.format("settle3d: %d balls, timestep %.3g s", m:ball_count(), m:timestep()))
local chunk = steps // 10
local t0 = os.clock()
for k = 1, 10 do
  m:cycle(chunk)
  local e = m:energy()
  print(string.format("step %7d  time %.4f s  kinetic %.3e J  contacts %d",
                      m:step(), m:time(), e.kinetic, m:contact_count()))
end
local elapsed = os.clock() - t0
print(string.format("settle3d: %d steps in %.2f s: %.0f steps/s, %.3g ball-steps/s",
                    chunk * 10, elapsed, chunk * 10 / elapsed, count * chunk * 10 / elapsed))
local zmax = 0
for b in m:balls() do
  local z = b.pos[3] + b.radius
  if z > zmax then zmax = z end
end
print(string.format("settle3d: bed height %.4f m", zmax))
