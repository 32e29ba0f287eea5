-- A piston driven from a Lua callback (2D), the FISH way.
--   seixo examples/piston2d.lua [count]
-- Disks are packed on a hexagonal lattice in a box; its lid becomes a
-- piston whose velocity a callback sets every 10 steps so that the load on
-- it approaches a target (a servo written in the script), while histories
-- record the load and the piston's height. Balls that leave through the
-- sides (none should) would be removed by a callback.
local count = tonumber(arg and arg[1]) or 400
local util = require "seixo.util"

local m = seixo.model{dim = 2, gravity = {0, -9.81}}
m:material("sand", {density = 2650, kn = 1e7, ks = 1e7, friction = 0.5, damping = 0.7})
local r = 1e-3
local width = 40 * r
local height = math.ceil(count / 20) * math.sqrt(3) * r + 2 * r
m:wall{kind = "line", point = {0, 0}, normal = {0, 1}}
m:wall{kind = "line", point = {0, 0}, normal = {1, 0}}
m:wall{kind = "line", point = {width, 0}, normal = {-1, 0}}
local lid = m:wall{kind = "line", point = {0, height}, normal = {0, -1}}
local n = m:generate{packing = "hex", radius = r, count = count, region = {box = {{0, 0}, {width, height}}}}
print(string.format("piston2d: %d disks in %d rows", n, math.ceil(n / 20)))

-- the servo: the lid's velocity follows the gap between its load and the target
local target = 50.0  -- N per metre of thickness
local gain = 2e-4    -- m/s per N
m:on("cycle", function()
  local load = lid.force[2]
  local v = math.max(-0.05, math.min(0.05, gain * (load - target)))
  lid.vel = {0, v}
end, {every = 10})
m:on("cycle", function()
  for b in m:balls{where = function(b) return b.pos[1] < 0 or b.pos[1] > width end} do b:remove() end
end, {every = 1000})
m:history("load", {wall = lid, field = "force", component = "y"}, {every = 200})
m:history("lid", {wall = lid, field = "point", component = "y"}, {every = 200})

m:cycle(20000)
local load = m:history("load").values
print(string.format("piston2d: lid at %.5f m (from %.5f), load %.2f N/m for a target of %.0f", lid.point[2], height,
                    load[#load], target))
print(string.format("piston2d: %d disks left, mean speed %.2e m/s", m:ball_count(), m:mean("speed")))
