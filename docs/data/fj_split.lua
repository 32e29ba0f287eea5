-- The Brazilian strength read at the disk's split against the disk's size,
-- for the parallel bond and the calibrated flat joint of fj_ratio.lua
-- (issue 14; docs/joints.md, "The Brazilian test read at the split"):
--   build/seixo docs/data/fj_split.lua outdir seeds diameters kind ...
--     (seeds "1,2,3", diameters in mm "16,20,24,30", kind pb or cal)
--   build/seixo docs/data/fj_split.lua outdir table
-- For each kind, seed and diameter: a 2D disk of radii 0.2-0.33 mm (the
-- genesis of fj_ratio.lua's disks), lab.brazilian at lab's rate (its peak,
-- its split, and joints.split_strength's first fall of a tenth). The UCS and
-- the direct tension strength of the same seed come from fj_ratio_runs.csv
-- in outdir (the 10 x 20 mm rectangle; kind cal is fj_ratio's g05_b05_cal).
-- Appends each run to outdir/fj_split_runs.csv; "table" writes the means and
-- sample standard deviations over the seeds to outdir/fj_split.csv.
local lab = require("seixo.lab")
local joints = require("seixo.joints")
local util = require("seixo.util")
local dir = (arg and arg[1] or ".") .. "/"
local RMIN, RMAX = 0.2e-3, 0.33e-3

local function read_csv(path)
  local rows, head = {}, nil
  for line in io.lines(path) do
    local f = {}
    for x in (line .. ","):gmatch("([^,]*),") do f[#f + 1] = x end
    if not head then head = f else
      local row = {}
      for k, name in ipairs(head) do row[name] = tonumber(f[k]) or f[k] end
      rows[#rows + 1] = row
    end
  end
  return rows
end

local header = {"kind", "seed", "diameter_mm", "grains_across", "balls", "ucs_MPa", "direct_tension_MPa", "bts_peak_MPa",
                "bts_split_MPa", "bts_drop10_MPa", "ucs_over_split", "ucs_over_peak", "split_over_dt", "peak_over_split"}

if arg[2] == "table" then
  local groups, order = {}, {}
  for _, r in ipairs(read_csv(dir .. "fj_split_runs.csv")) do
    local key = r.kind .. "," .. r.diameter_mm
    if not groups[key] then groups[key] = {}; order[#order + 1] = key end
    table.insert(groups[key], r)
  end
  local out = io.open(dir .. "fj_split.csv", "w")
  local h = {"kind", "diameter_mm", "seeds"}
  for k = 4, #header do h[#h + 1] = header[k]; h[#h + 1] = header[k] .. "_sd" end
  out:write(table.concat(h, ",") .. "\n")
  for _, key in ipairs(order) do
    local runs = groups[key]
    local cells = {runs[1].kind, string.format("%g", runs[1].diameter_mm), #runs}
    for k = 4, #header do
      local xs = {}
      for _, r in ipairs(runs) do
        if type(r[header[k]]) == "number" then xs[#xs + 1] = r[header[k]] end
      end
      local mean, sd = util.mean_sd(xs)
      cells[#cells + 1] = mean and string.format("%.4g", mean) or ""
      cells[#cells + 1] = mean and string.format("%.4g", sd) or ""
    end
    out:write(table.concat(cells, ",") .. "\n")
  end
  out:close()
  return
end

-- the UCS and direct tension of each kind and seed (fj_ratio.lua's names)
local rect = {}
for _, r in ipairs(read_csv(dir .. "fj_ratio_runs.csv")) do
  local kind = r.kind == "g05_b05_cal" and "cal" or r.kind
  rect[kind .. r.seed] = r
end

local function material(kind)
  if kind == "pb" then return lab.rock(), "parallel", 1e-3 * RMIN end
  local cal = {unbonded_fraction = 0.5}
  for _, key in ipairs{"tensile_strength", "tensile_strength_sd", "cohesion", "cohesion_sd"} do
    cal[key] = 1.2 * joints.rock().bond[key]
  end
  return joints.rock({bond = cal}), "flatjoint", 0.5 * RMIN
end

local seeds, diameters = {}, {}
for s in (arg[2] or "1"):gmatch("%d+") do seeds[#seeds + 1] = tonumber(s) end
for d in (arg[3] or "20"):gmatch("[%d.]+") do diameters[#diameters + 1] = tonumber(d) end
local path = dir .. "fj_split_runs.csv"
local fresh = io.open(path, "r") == nil
local runs = io.open(path, "a")
if fresh then runs:write(table.concat(header, ",") .. "\n") end
for i = 4, #arg do
  local kind = arg[i]
  if kind ~= "pb" and kind ~= "cal" then error("fj_split.lua: kind pb or cal, not " .. kind) end
  local mat, model, gap = material(kind)
  for _, seed in ipairs(seeds) do
    local ref = rect[kind .. seed] or error("fj_split.lua: no " .. kind .. " seed " .. seed .. " in fj_ratio_runs.csv")
    for _, dmm in ipairs(diameters) do
      local disk_path = string.format("%sfjs_%s_%d_%g.h5", dir, kind, seed, dmm)
      local disk = lab.specimen{dim = 2, shape = "disk", diameter = dmm * 1e-3, radius = {RMIN, RMAX}, seed = seed,
                                model = model, material = mat, gap = gap, log = false, path = disk_path}
      local r = lab.brazilian(disk, {log = false})
      os.remove(disk_path)
      local split = r.split -- nil (an empty cell) when the halves never parted
      local function of_split(f) return split and f(split) end
      local row = {kind, seed, dmm, dmm * 1e-3 / (RMIN + RMAX), disk.balls, ref.ucs_MPa, ref.direct_tension_MPa,
                   r.tensile_strength / 1e6, of_split(function(s) return s / 1e6 end), joints.split_strength(r) / 1e6,
                   of_split(function(s) return ref.ucs_MPa * 1e6 / s end), ref.ucs_MPa * 1e6 / r.tensile_strength,
                   of_split(function(s) return s / 1e6 / ref.direct_tension_MPa end),
                   of_split(function(s) return r.tensile_strength / s end)}
      for k = 3, #header do row[k] = row[k] and string.format("%.5g", row[k]) or "" end
      runs:write(table.concat(row, ",") .. "\n")
      runs:flush()
      print(table.concat(row, ","))
    end
  end
end
runs:close()
