-- The flat joint's UCS over tensile strength against its installation, and
-- the tensile strength three ways (issue 14; docs/joints.md, "What raises
-- the ratio"):
--   build/seixo docs/data/fj_ratio.lua outdir seeds name ...   (seeds: "1,2,3")
-- For each specimen kind named and each seed: a 2D 10 x 20 mm rectangle and
-- 10 and 20 mm disks (radii 0.2-0.33 mm; one genesis per seed and shape,
-- shared by every kind with the same installation gap), lab.ucs and
-- joints.direct_tension of the rectangle, lab.brazilian of both disks (its
-- peak and joints.split_strength). Appends each run to
-- outdir/fj_ratio_runs.csv; "table" writes the means and sample standard
-- deviations of the runs in that file to outdir/fj_ratio.csv. With
-- FJR_QUICK set in the environment, the UCS and direct tension only, to
-- fj_ratio_quick_runs.csv (table: fj_ratio_quick.csv).
local lab = require("seixo.lab")
local joints = require("seixo.joints")
local dir = (arg and arg[1] or ".") .. "/"
local quick = os.getenv("FJR_QUICK") ~= nil
local file = quick and "fj_ratio_quick" or "fj_ratio"
local RMIN = 0.2e-3

-- name -> {label, model, bond (joints.rock's overrides), gap (installation gap / rmin)}
local kinds = {
  pb = {label = "parallel bond (lab.rock)", model = "parallel"},
  fj = {label = "flat joint (joints.rock)", model = "flatjoint"},
}
-- Potyondy's flat-jointed material: faces at every pair within the
-- installation gap g rmin, each element bonded with probability phi_B, the
-- others slit (unbonded, no gap)
for _, g in ipairs{0.3, 0.5, 1.0} do
  for _, phib in ipairs{1.0, 0.7, 0.5, 0.3} do
    kinds[string.format("g%g_b%g", g, phib)] = {
      label = string.format("flat joint, gap %g rmin, phiB %g", g, phib),
      model = "flatjoint", bond = {unbonded_fraction = 1 - phib}, gap = g}
  end
end

-- g0.5_b0.5 calibrated to the parallel bond's UCS (seeds 1-3: 196.9 MPa
-- against its 162.9 MPa): the elements' strengths and deviations x 1.2
local cal = {unbonded_fraction = 0.5}
for _, key in ipairs{"tensile_strength", "tensile_strength_sd", "cohesion", "cohesion_sd"} do
  cal[key] = 1.2 * joints.rock().bond[key]
end
kinds.g05_b05_cal = {label = "flat joint, gap 0.5 rmin, phiB 0.5, strengths x 1.2",
                     model = "flatjoint", bond = cal, gap = 0.5}

local header = {"kind", "seed", "balls_rect", "faces_per_ball", "ucs_MPa", "direct_tension_MPa", "bts10_peak_MPa",
                "bts10_split_MPa", "bts20_peak_MPa", "bts20_split_MPa", "ucs_over_dt", "ucs_over_bts20_split",
                "ucs_over_bts10_peak", "cracks_tension_at_ucs"}

local stats = require("seixo.util").mean_sd

if arg[2] == "table" then
  local by, order = {}, {}
  for line in io.lines(dir .. file .. "_runs.csv") do
    local f = {}
    for x in (line .. ","):gmatch("([^,]*),") do f[#f + 1] = x end
    if f[1] ~= "kind" then
      if not by[f[1]] then by[f[1]] = {}; order[#order + 1] = f[1] end
      local row = {}
      for k = 3, #f do row[k] = tonumber(f[k]) end
      by[f[1]][#by[f[1]] + 1] = row
    end
  end
  local rows = {}
  for _, name in ipairs(order) do
    local runs = by[name]
    local row = {kinds[name] and kinds[name].label or name, #runs}
    for k = 4, 13 do
      local xs = {}
      for _, r in ipairs(runs) do xs[#xs + 1] = r[k] end -- (nil where a quick run has none)
      row[2 * k - 5], row[2 * k - 4] = stats(xs)
    end
    rows[#rows + 1] = row
  end
  local h = {"specimen", "seeds"}
  for k = 4, 13 do h[#h + 1] = header[k]; h[#h + 1] = header[k] .. "_sd" end
  -- (lab.write_csv writes numbers only: the labels are quoted here)
  local out = io.open(dir .. file .. ".csv", "w")
  out:write(table.concat(h, ",") .. "\n")
  for _, row in ipairs(rows) do
    local cells = {string.format("%q", row[1])}
    for k = 2, #h do cells[k] = row[k] and string.format("%.4g", row[k]) or "" end
    out:write(table.concat(cells, ",") .. "\n")
  end
  out:close()
  return
end

local seeds = {}
for s in (arg[2] or "1"):gmatch("%d+") do seeds[#seeds + 1] = tonumber(s) end
local path = dir .. file .. "_runs.csv"
local fresh = io.open(path, "r") == nil
local runs = io.open(path, "a")
if fresh then runs:write(table.concat(header, ",") .. "\n") end
for i = 3, #arg do
  local name = arg[i]
  local k = kinds[name] or error("fj_ratio.lua: no kind " .. name)
  for _, seed in ipairs(seeds) do
    local mat = k.model == "flatjoint" and joints.rock({bond = k.bond}) or lab.rock()
    local common = {dim = 2, radius = {RMIN, 0.33e-3}, seed = seed, model = k.model, material = mat,
                    gap = (k.gap or 1e-3) * RMIN, log = false}
    local tag = string.format("%sfjr_%s_%d", dir, name, seed)
    local function specimen(t)
      return lab.specimen(setmetatable(t, {__index = common}))
    end
    local spec = specimen{shape = "rect", width = 0.01, height = 0.02, path = tag .. "_rect.h5"}
    local ru = lab.ucs(spec, {log = false})
    local dt = joints.direct_tension(spec).peak
    local bts = {}
    for _, d in ipairs(quick and {} or {0.01, 0.02}) do
      local disk = specimen{shape = "disk", diameter = d, path = tag .. "_disk.h5"}
      local r = lab.brazilian(disk, {log = false})
      bts[#bts + 1] = r.tensile_strength
      bts[#bts + 1] = joints.split_strength(r)
      os.remove(tag .. "_disk.h5")
    end
    local function mpa(x) return x and x / 1e6 end
    local function over(x) return x and ru.peak / x end
    local row = {name, seed, spec.balls, 2 * spec.bonds / spec.balls, ru.peak / 1e6, dt / 1e6, mpa(bts[1]),
                 mpa(bts[2]), mpa(bts[3]), mpa(bts[4]), ru.peak / dt, over(bts[4]), over(bts[1]), ru.cracks.tension}
    for j = 3, #header do row[j] = row[j] and string.format("%.5g", row[j]) or "" end
    runs:write(table.concat(row, ",") .. "\n")
    runs:flush()
    print(table.concat(row, ","))
    os.remove(tag .. "_rect.h5")
  end
end
runs:close()
