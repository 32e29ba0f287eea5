-- Pouring clumps into a box (3D).
--   seixo examples/clumps_pour.lua [count] [ratio] [output]
-- Two grain shapes made of overlapping pebbles (an elongated "rice" grain
-- of three spheres and a flat "tri" of three), generated at random
-- orientations and sizes in the upper part of a box, fall under gravity
-- and settle; local damping brings them to rest (0.3 while they fall, so
-- they fall briskly, then 0.7). Prints the settled
-- pile's porosity, the clumps' kinetic energy and how the long axes of the
-- rice grains lie (settled grains lie flat: their long axis near
-- horizontal). With an output name, writes a snapshot of the pile.
local count = tonumber(arg and arg[1]) or 200
local ratio = tonumber(arg and arg[2]) or 1e-2
local output = arg and arg[3]

local m = seixo.model{dim = 3, gravity = {0, 0, -9.81}}
m:material("gravel", {density = 2650, kn = 5e5, ks = 5e5, friction = 0.5, damping = 0.3})

-- templates in mm (pebbles of 3 mm, overlapping)
local mm = 1e-3
local rice = m:clump_template("rice", {{-4.2 * mm, 0, 0, 3.0 * mm}, {0, 0, 0, 3.3 * mm}, {4.2 * mm, 0, 0, 3.0 * mm}})
local tri = m:clump_template("tri", {{0, 0, 0, 3.0 * mm}, {4.8 * mm, 0, 0, 3.0 * mm}, {2.4 * mm, 3.9 * mm, 0, 3.0 * mm}})
print(string.format("templates: rice %.3g mm^3 (principal %.3g, %.3g, %.3g, error %.1e), tri %.3g mm^3",
                    rice.volume / mm ^ 3, rice.principal[1], rice.principal[2], rice.principal[3], rice.error,
                    tri.volume / mm ^ 3))

-- the box: its floor fits about seven grains across; they start above its lower third
local width = 72 * mm * math.max(1, (count / 200) ^ (1 / 3))
local height = 2 * width
m:wall{kind = "box", min = {0, 0, 0}, max = {width, width, height}, kn = 5e5, ks = 5e5, friction = 0.5}
local region = {box = {{0, 0, 0.3 * height}, {width, width, height}}}
local n_rice = m:generate{template = "rice", scale = {0.8, 1.2}, count = count // 2, region = region, seed = 1}
local n_tri = m:generate{template = "tri", scale = {0.8, 1.2}, count = count - count // 2, region = region, seed = 2}
print(string.format("clumps_pour: %d rice + %d tri clumps (%d pebbles) in a %.0f mm box", n_rice, n_tri,
                    m:ball_count(), width / mm))

-- the fall first (while grains fly, one impact can make the mean force ratio look small), then
-- settling with PFC's quasi-static damping (the grains rock long under light damping)
m:solve{time = 0.3}
m:material("gravel", {density = 2650, kn = 5e5, ks = 5e5, friction = 0.5, damping = 0.7})
local reason, r, steps = m:solve{ratio = ratio, steps = 200000}
local top = 0
for b in m:balls() do top = math.max(top, b.pos[3] + b.radius) end

-- porosity of the pile: clump volumes (unions of their pebbles) over the box up to the pile's top
local solid, ke, flat, rices = 0, 0, 0, 0
for c in m:clumps() do
  solid = solid + c.volume
  local v, w, I = c.vel, c.spin, c.inertia
  local rot = 0
  for i = 1, 3 do for j = 1, 3 do rot = rot + 0.5 * w[i] * I[i][j] * w[j] end end
  ke = ke + 0.5 * c.mass * (v[1] ^ 2 + v[2] ^ 2 + v[3] ^ 2) + rot
  if c.template == "rice" then
    -- the long axis is the template's x: its vertical component from the orientation
    local q = c.orientation
    local axis_z = 2 * (q[2] * q[4] - q[1] * q[3])
    flat = flat + math.abs(axis_z)
    rices = rices + 1
  end
end
print(string.format("stopped on %s (ratio %.2e) after %d steps, %.3f s", reason, r, steps, m:time()))
print(string.format("pile height %.1f mm, porosity %.3f, clump kinetic energy %.2e J (model: %.2e J)", top / mm,
                    1 - solid / (width * width * top), ke, m:energy().kinetic))
print(string.format("rice grains: mean |sin| of the long axis' tilt %.2f (random orientations: 0.50)", flat / rices))
if output then
  m:save(output)
  print("saved " .. output)
end
print(m)
