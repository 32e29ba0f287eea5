-- A 2D granular column collapse (docs/verification.md, "The 2D granular
-- column collapse"): a column of polydisperse disks settled behind a gate
-- on a rough floor (a glued row of fixed grains, or a plain wall), the gate
-- removed, the runout measured three ways when the deposit is at rest.
--   seixo docs/data/column_collapse.lua a mu_r [N] [floor] [seed] [dtfac]
-- a the column's aspect ratio H0/L0 (measured after settling), mu_r the
-- rolling friction, N the disks (2000), floor "glued" or "wall", dtfac the
-- automatic timestep's safety factor (0.8). MU and E in the environment set
-- the grains' friction (0.5) and restitution (0.5). Prints one RESULT line:
-- the normalised runout (L - L0)/L0 by the connected front (conn), the 99th
-- percentile of the grains (p99) and the farthest grain (max), and the
-- energy balance's error relative to the energy released.
local a_target = tonumber(arg[1] or "1")
local mur      = tonumber(arg[2] or "0")
local N        = tonumber(arg[3] or "2000")
local floor    = arg[4] or "glued"
local seed     = tonumber(arg[5] or "1")
local dtfac    = tonumber(arg[6] or "0.8")
seixo.progress(false)

local rmean = 1e-3
local rmin, rmax = 0.8e-3, 1.2e-3
local phi_settled = 0.80
local area = N * math.pi * rmean^2 * (1 + (0.2^2)/3) / phi_settled
local L0 = math.sqrt(area / a_target)
local Hgen = area / L0 * phi_settled / 0.45    -- generate loose (solid fraction 0.45)
local m = seixo.model{dim = 2, gravity = {0, -9.81}, timestep_safety = dtfac}
local kn = 2e6
local MU = tonumber(os.getenv("MU") or "0.5")
local E = tonumber(os.getenv("E") or "0.5")
m:material("g", {density = 2650, kn = kn, ks = 0.5 * kn, friction = MU,
                 restitution = E, damping = 0.7, rolling_friction = mur})
local y0 = 0
local walls = {}
walls.floor = m:wall{kind = "line", point = {0, 0}, normal = {0, 1}, kn = kn, ks = 0.5*kn, friction = MU}
local XMAX = 12 * L0 * math.max(1, a_target) + 0.1
if floor == "glued" then
  -- layer of fixed grains, touching, radius 1 mm, on the floor, spanning the whole run
  local rf = 1e-3
  local x = rf
  while x < XMAX do
    local b = m:ball{pos = {x, rf}, radius = rf, material = "g", group = "floor"}
    b.fix = "all"
    x = x + 2 * rf
  end
  y0 = 2 * rf
end
walls.left = m:wall{kind = "line", point = {0, 0}, normal = {1, 0}, kn = kn, ks = 0.5*kn, friction = 0.5}
walls.gate = m:wall{kind = "segment", p1 = {L0, y0 + 0.5e-3}, p2 = {L0, y0 + 2 * Hgen}, kn = kn, ks = 0.5*kn, friction = 0.0}
m:generate{count = N, radius = {rmin, rmax}, region = {box = {{0, y0 + 1e-4}, {L0, y0 + Hgen}}},
           seed = seed, material = "g", group = "grain"}
local t0 = seixo.clock()
local why, r = m:solve{ratio = 2e-4, time = 3.0}
-- settled column
local ys = {}
for b in m:balls{group = "grain"} do ys[#ys+1] = b.pos[2] + b.radius end
table.sort(ys)
local H0 = ys[math.floor(0.99 * #ys)] - y0   -- top (99th percentile of tops)
local a = H0 / L0
io.stderr:write(string.format("settled (%s ratio %.2g) in %.0f s wall; L0 %.4f H0 %.4f a %.3f dt %.3g\n",
  why, r, seixo.clock() - t0, L0, H0, a, m:timestep()))
-- collapse
m:set{group = "grain", damping = 0, vel = {0, 0}, spin = 0}
m:track_energy(true)
local E0 = m:energy()
walls.gate:remove()
local tstart = m:time()
local T = 0
local function ke() return m:sum("kinetic", {group = "grain"}) end
local PE0 = E0.gravitational
local maxT = 6 * math.sqrt(H0 / 9.81) + 1.0
while true do
  m:solve{time = 0.05}
  T = m:time() - tstart
  local k = ke()
  local mv = m:max("speed", {group = "grain"})
  if (T > 4 * math.sqrt(H0 / 9.81) and mv < 2e-3) or T > maxT then break end
end
local E1 = m:energy()
local function sum(e) return e.kinetic + e.gravitational + e.strain + e.slip + e.local_damping + e.viscous - e.boundary_work end
-- measure
local xs, rs = {}, {}
local bl = {}
for b in m:balls{group = "grain"} do bl[#bl+1] = {b.pos[1], b.radius} end
table.sort(bl, function(p, q) return p[1] < q[1] end)
local n = #bl
local xmax = bl[n][1] + bl[n][2]
local x99 = bl[math.ceil(0.99 * n)][1]
-- connected front: walk in x; a gap > 2*rmax (a full grain missing) between
-- the running right edge and the next grain's left edge ends the deposit
local edge = bl[1][1] + bl[1][2]
local xconn = edge
for i = 2, n do
  local left = bl[i][1] - bl[i][2]
  if left - edge > 2 * rmax then break end
  edge = math.max(edge, bl[i][1] + bl[i][2])
  xconn = edge
end
-- final height at the wall
local hmax = 0
for b in m:balls{group = "grain"} do hmax = math.max(hmax, b.pos[2] + b.radius - y0) end
local released = PE0 - E1.gravitational
print(string.format("RESULT mu="..MU.." e="..E.." a=%.3f mur=%.2f floor=%s N=%d seed=%d dtfac=%.2f L0=%.4f H0=%.4f T=%.2f  "..
  "dL/L0: conn=%.3f p99=%.3f max=%.3f  Hinf/L0=%.3f  Ebal_err=%.2e slip/rel=%.2f visc/rel=%.2f wall=%.0fs",
  a, mur, floor, N, seed, dtfac, L0, H0, T, (xconn - L0)/L0, (x99 - L0)/L0, (xmax - L0)/L0, hmax/L0,
  (sum(E1) - sum(E0)) / released, E1.slip / released, E1.viscous / released, seixo.clock() - t0))
