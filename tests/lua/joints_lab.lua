-- Jointed specimens in seixo.joints (issue 14, item 3): Jaeger's single
-- plane of weakness in closed form, a smooth joint through a bonded
-- specimen at an angle, and the direct-shear test of an unbonded joint,
-- whose residual shear stress is Coulomb's mu sigma_n.
local T = dofile((debug.getinfo(1, "S").source:match("^@(.*/)") or "./") .. "harness.lua")
local lab = require("seixo.lab")
local joints = require("seixo.joints")

T.test("Jaeger's single plane of weakness", function()
  local mu = math.tan(math.rad(30))
  -- beta = 60: sin 2 beta = sqrt(3)/2, 1 - mu cot beta = 2/3
  T.near(joints.jaeger(60, 10e6, mu), 2 * 10e6 / (2 / 3 * math.sqrt(3) / 2), 1e-12)
  T.near(joints.jaeger(60, 10e6, mu, 5e6), 5e6 + 2 * (10e6 + mu * 5e6) / (2 / 3 * math.sqrt(3) / 2), 1e-12)
  T.eq(joints.jaeger(30, 10e6, mu), nil, "no slip at beta = phi")
  T.eq(joints.jaeger(20, 10e6, mu), nil, "no slip below phi")
  T.eq(joints.jaeger(90, 10e6, mu), nil, "no slip along sigma1")
  -- the minimum at 45 + phi / 2
  local best, at = math.huge, nil
  for b = 31, 89 do
    local s = joints.jaeger(b, 10e6, mu)
    if s < best then best, at = s, b end
  end
  T.eq(at, 60, "the weakest angle")
end)

local dir = os.tmpname()
os.remove(dir)
os.execute("mkdir -p " .. T.quote(dir))
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.004, height = 0.008, radius = {0.2e-3, 0.33e-3}, seed = 2,
                          path = dir .. "/rect.h5", log = false}

T.test("a jointed specimen: the joint cuts the bonds across it", function()
  local js = joints.jointed(spec, {angle = 45, cohesion = 10e6, friction_angle = 30, path = dir .. "/j45.h5"})
  T.check(js.joint.bonds > 5, "bonds replaced: " .. js.joint.bonds)
  T.eq(js.bonds, spec.bonds, "bonded: every bond kept, those across as the joint's")
  local m = seixo.load(js.path)
  local j = m:joints()[1]
  T.near(j.normal[1], math.sqrt(0.5), 1e-12)
  T.near(j.point[2], 0.5 * (spec.lo[2] + spec.hi[2]), 1e-12)
  local n = 0
  for c in m:contacts() do if c.bond == "smoothjoint" then n = n + 1 end end
  T.eq(n, js.joint.bonds, "the joint's bonds")
  m:close()
  local cut = joints.jointed(spec, {angle = 45, path = dir .. "/c45.h5"})
  T.eq(cut.bonds, spec.bonds - cut.joint.bonds, "unbonded: the bonds across are cut")
  T.raises(function() joints.jointed(spec, {angle = 100, path = dir .. "/x.h5"}) end, "angle")
  T.raises(function() joints.jointed(spec, {angle = 10, path = dir .. "/x.h5", glue = 1}) end, "glue")
end)

T.test("direct shear of an unbonded joint: residual mu sigma_n", function()
  local r = joints.direct_shear(spec, {normal_stress = 5e6, joint = {friction = 0.4}, speed = 0.1, displacement = 5e-5,
                                       log = false, out = dir .. "/ds"})
  T.near(r.residual, 0.4 * 5e6, 0.02)
  T.check(r.peak >= r.residual, "peak " .. r.peak)
end)

T.test("direct tension: the grips pull equally before the peak, the specimen breaks", function()
  local r = joints.direct_tension(spec)
  T.eq(r.stopped, "post_peak")
  T.check(r.peak > 1e6, "peak " .. r.peak)
  T.check(r.cracks.tension > 0, "tensile cracks at the peak: " .. r.cracks.tension)
  -- quasi-static below the peak: the bottom grip's pull is the top's
  local half
  for _, row in ipairs(r.rows) do if not half and row[2] > 0.5 * r.peak then half = row end end
  T.near(half[3], half[2], 0.01)
  T.check(r.rows[#r.rows][2] < 0.5 * r.peak, "broken")
  T.raises(function() joints.direct_tension(spec, {rate = 1}) end, "rate")
end)

T.test("the splitting strength: the load at the first fall of a tenth", function()
  local rows = {}
  for _, s in ipairs{1, 5, 10, 20, 17, 25, 30, 10} do rows[#rows + 1] = {0, s} end
  local r = {columns = {"step", "tensile_stress"}, rows = rows, tensile_strength = 30}
  T.eq(joints.split_strength(r), 20, "split at 20 (a fall of 15 %)")
  T.eq(joints.split_strength(r, 0.2), 30, "no fall of 20 % before the peak")
  rows[5][2] = 18.5 -- a fall of 7.5 %: not a split
  T.eq(joints.split_strength(r), 30)
end)

T.test("a flat-jointed Brazilian disk splits below its peak", function()
  -- Potyondy's installation (faces within 0.5 rmin, half the elements slit):
  -- after the diametral crack the halves part and, pressed by the platens,
  -- carry a later, higher peak; lab.brazilian's split is the load before
  -- they parted
  local disk = lab.specimen{dim = 2, shape = "disk", diameter = 0.006, radius = {0.2e-3, 0.33e-3}, seed = 3,
                            model = "flatjoint", material = joints.rock({bond = {unbonded_fraction = 0.5}}), gap = 1e-4,
                            path = dir .. "/disk.h5", log = false}
  local r = lab.brazilian(disk, {log = false})
  T.check(r.split and r.split < 0.8 * r.tensile_strength,
          string.format("split %s, peak %g", tostring(r.split), r.tensile_strength))
  local c0, split_row, peak_row, first_crack
  for i, row in ipairs(r.rows) do
    if row[6] + row[7] == 0 then c0 = row[9] / row[5] elseif not first_crack then first_crack = i end
    if row[5] == r.split and not split_row then split_row = i end
    if row[5] == r.tensile_strength then peak_row = i end
  end
  T.check(split_row >= first_crack and split_row < peak_row, "split after the first crack, before the peak")
  local function parted(row) return row[9] > 2 * c0 * row[5] end
  T.check(not parted(r.rows[split_row]), "together at the split")
  T.check(parted(r.rows[split_row + 1]) or r.rows[split_row + 1][5] < r.split, "parted or unloading just after")
  T.check(parted(r.rows[peak_row]), "parted at the peak")
end)

os.execute("rm -rf " .. T.quote(dir))
T.done()
