-- The stresses at the centre of a 2D bonded Brazilian disk against the
-- elastic solution (docs/verification.md, "The Brazilian disk's centre
-- stresses"):
--   build/seixo docs/data/brazilian_centre.lua [seed] [ball_modulus] [D] [rmin] [csv]
-- A disk of diameter D (default 0.03 m) of P&C's 2D granite (lab.rock(),
-- radii rmin to 1.66 rmin, default rmin 0.27 mm: about 1,450 balls) made by
-- lab.specimen and broken by lab.brazilian, unchanged; with ball_modulus
-- (Pa) the ball-ball contacts' modulus is set to it after the genesis (the
-- bonds keep theirs: 1e9 all but turns the contacts off). Every 100 steps
-- the mean stress over centred disk regions of radius 0.1, 0.2 and 0.3 D
-- (m:measure) and over one of 0.6 D (the whole disk), and the platens'
-- contacts. Over the records before the first crack with the force between
-- 0.2 and 0.5 of its peak, the means of sxx/s0 and syy/s0 (tension
-- positive, s0 = 2F/(pi D)) against the exact point-load solution (Hondros)
-- averaged over the same region, and the platens' load-weighted <sin^2 t>,
-- t the angle of a contact from the loaded diameter: point loads in
-- diametral pairs at those angles give the centre sxx the factor
-- 1 - 4 <sin^2 t> of a single pair's. With csv, every record is written
-- there. CPU: 16 s a run (seed 1).
local lab = require "seixo.lab"
local seed = math.tointeger(tonumber(arg[1] or 1))
local ball_modulus = tonumber(arg[2])
local D = tonumber(arg[3]) or 0.03
local rmin = tonumber(arg[4]) or 0.27e-3
local csv = arg[5]
assert(seed, "seed: an integer")
local FRACS = {0.1, 0.2, 0.3, 0.6}

local claim = os.tmpname()
local path = claim .. ".h5"
local spec = lab.specimen{dim = 2, shape = "disk", diameter = D, radius = {rmin, 1.66 * rmin}, seed = seed,
                          path = path, log = false}

-- lab.brazilian opens the specimen with seixo.load: the recorder is added
-- to the model it opens (a callback: it changes no bit of the test)
local recs = {}
local load = seixo.load
seixo.load = function(...)
  local m = load(...)
  if ball_modulus then
    local mat = {}
    for k, v in pairs(spec.material) do mat[k] = v end
    mat.modulus = ball_modulus
    m:material("rock", mat)
  end
  local lo, hi = {math.huge, math.huge}, {-math.huge, -math.huge}
  for b in m:balls() do
    for k = 1, 2 do
      lo[k] = math.min(lo[k], b.pos[k] - b.radius)
      hi[k] = math.max(hi[k], b.pos[k] + b.radius)
    end
  end
  local c = {0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])}
  local d = hi[2] - lo[2]
  m:on("after", function(mm)
    local F, nw, sum, sin2, n, tmax = 0, 0, 0, 0, 0, 0
    for w in mm:walls() do
      F, nw = F + w:load(), nw + 1
      for ct in mm:contacts{wall = w} do
        local t = math.asin(math.max(-1, math.min(1, 2 * (ct.point[1] - c[1]) / d)))
        sum, sin2, n, tmax = sum + ct.fn, sin2 + ct.fn * math.sin(t) ^ 2, n + 1, math.max(tmax, math.abs(t))
      end
    end
    local row = {step = mm:step(), F = F / math.max(nw, 1), cracks = mm:crack_count(), d = d,
                 sin2 = sum > 0 and sin2 / sum or 0, contacts = n / math.max(nw, 1), tmax = tmax}
    for i, f in ipairs(FRACS) do
      local ms = mm:measure{disk = {center = c, radius = f * d}}
      row[i] = {sxx = ms.stress[1][1], syy = ms.stress[2][2], sxy = ms.stress[1][2], balls = ms.balls}
    end
    recs[#recs + 1] = row
  end, {every = 100})
  return m
end
local r = lab.brazilian(spec, {log = false})
seixo.load = load
os.remove(path)
os.remove(claim)
print(string.format("seed %d: %d balls, %d bonds; ball-ball modulus %.4g Pa; peak %.4g N/m, tensile strength %.4g MPa",
                    seed, spec.balls, spec.bonds, ball_modulus or spec.material.modulus, r.peak_force,
                    r.tensile_strength / 1e6))

-- Hondros: point loads F at (0, +-R) on a disk of radius R = 1 (unit
-- thickness), tension positive, over s0 = 2F/(pi D)
local function exact(x, y)
  local R = 1
  local r1, r2 = x * x + (R - y) ^ 2, x * x + (R + y) ^ 2
  local k, s0 = 2 / math.pi, 1 / math.pi
  local sxx = -k * ((R - y) * x * x / r1 ^ 2 + (R + y) * x * x / r2 ^ 2) + s0
  local syy = -k * ((R - y) ^ 3 / r1 ^ 2 + (R + y) ^ 3 / r2 ^ 2) + s0
  return sxx / s0, syy / s0
end
-- its mean over a disk of radius f D about the centre (a 400 x 400 grid)
local function exact_mean(f)
  local a, n = 2 * f, 400
  local sx, sy, w = 0, 0, 0
  for i = 0, n - 1 do
    for j = 0, n - 1 do
      local x, y = -a + (i + 0.5) * 2 * a / n, -a + (j + 0.5) * 2 * a / n
      if x * x + y * y <= a * a then
        local u, v = exact(x, y)
        sx, sy, w = sx + u, sy + v, w + 1
      end
    end
  end
  return sx / w, sy / w
end

local peak = 0
for _, row in ipairs(recs) do peak = math.max(peak, row.F) end
local sel = {}
for _, row in ipairs(recs) do
  if row.cracks == 0 and row.F >= 0.2 * peak and row.F < 0.5 * peak then sel[#sel + 1] = row end
end
assert(#sel > 0, "no record before the first crack between 0.2 and 0.5 of the peak")
print(string.format("%d records before the first crack at 0.2-0.5 of the peak force", #sel))
print("region      balls   sxx/s0  exact   ratio    syy/s0  exact   ratio")
for i, f in ipairs(FRACS) do
  local mx, my = 0, 0
  for _, row in ipairs(sel) do
    local s0 = 2 * row.F / (math.pi * row.d)
    mx, my = mx - row[i].sxx / s0, my - row[i].syy / s0 -- compression positive to tension positive
  end
  mx, my = mx / #sel, my / #sel
  local ex, ey
  if f < 0.5 then
    ex, ey = exact_mean(f)
  else -- the whole disk inside the region: the disk's mean stress over the region's area
    ex, ey = 0, -2 * 0.25 / f ^ 2
  end
  print(string.format("r = %.1f D  %5d  %7.3f %7.3f %7s  %7.3f %7.3f %6.3f", f, sel[#sel][i].balls, mx, ex,
                      ex ~= 0 and string.format("%.3f", mx / ex) or "-", my, ey, my / ey))
end
local sin2, n, tmax = 0, 0, 0
for _, row in ipairs(sel) do sin2, n, tmax = sin2 + row.sin2, n + row.contacts, math.max(tmax, row.tmax) end
sin2, n = sin2 / #sel, n / #sel
print(string.format("platens: %.1f contacts each, within +-%.3f rad of the loaded diameter, <sin^2 t> = %.4f: "
                    .. "centre sxx x %.3f of a point load's", n, tmax, sin2, 1 - 4 * sin2))

if csv then
  local out = assert(io.open(csv, "w"))
  out:write("step,F,cracks,s0,sin2,platen_contacts")
  for i = 1, #FRACS do out:write(string.format(",sxx%d,syy%d,sxy%d,balls%d", i, i, i, i)) end
  out:write("\n")
  for _, row in ipairs(recs) do
    out:write(string.format("%d,%.6g,%d,%.6g,%.5g,%.3g", row.step, row.F, row.cracks, 2 * row.F / (math.pi * row.d),
                            row.sin2, row.contacts))
    for i = 1, #FRACS do
      out:write(string.format(",%.6g,%.6g,%.6g,%d", row[i].sxx, row[i].syy, row[i].sxy, row[i].balls))
    end
    out:write("\n")
  end
  out:close()
end
