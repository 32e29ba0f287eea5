-- One specimen of the comparison with Potyondy & Cundall (2004)
-- (docs/potyondy-cundall.md): Lac du Bonnet micro-parameters
-- (lab.rock{dim = dim}: P&C's PFC2D set in 2D, seixo's 3D calibration in
-- 3D; with "2d-set", the PFC2D set in 3D too), radii uniform in [Rmin,
-- 1.66 Rmin], a 31.7 x 63.4 mm rectangle (2D) or
-- cylinder (3D), its genesis and a UCS test, or with "bts" a 31.7 mm disk
-- (2D) or disc 15.85 mm thick (3D) and a Brazilian test. Appends a line to
-- the CSV (its header when the file is new).
--   scripts/run docs/data/potyondy_cundall.lua dim rmin seed out.csv [ucs|bts] [2d-set]
local lab = require "seixo.lab"
local dim, rmin, seed, csv, kind = tonumber(arg[1]), tonumber(arg[2]), tonumber(arg[3]) or 1, arg[4], arg[5] or "ucs"
if not (dim and rmin and csv) or (kind ~= "ucs" and kind ~= "bts") or (arg[6] and arg[6] ~= "2d-set") then
  error("usage: potyondy_cundall.lua dim rmin seed out.csv [ucs|bts] [2d-set]")
end
local set = arg[6] and 2 or dim
local material = lab.rock{dim = set}
local w = 0.0317
local radius = {rmin, 1.66 * rmin}
local tag = string.format("%s_d%d_r%g_s%d_%s", csv:gsub("%.csv$", ""), dim, rmin * 1e3, seed, kind)
local t0 = seixo.clock()
local spec, r, values
local common = {dim = dim, radius = radius, seed = seed, material = material, path = tag .. "_specimen.h5"}
local function with(t)
  for k, v in pairs(common) do t[k] = v end
  return t
end
if kind == "bts" then
  spec = lab.specimen(dim == 2 and with{shape = "disk", diameter = w}
                      or with{shape = "disc", diameter = w, thickness = w / 2})
  r = lab.brazilian(spec, {out = tag, plot = false})
  values = {tensile_strength = r.tensile_strength}
else
  spec = lab.specimen(dim == 2 and with{shape = "rect", width = w, height = 2 * w}
                      or with{shape = "cylinder", diameter = w, height = 2 * w})
  r = lab.ucs(spec, {out = tag, plot = false})
  values = {young = r.young, poisson = r.poisson, ucs = r.peak}
end
local g = spec.genesis
local header = {"dim", "set", "rmin", "seed", "test", "balls", "across", "young", "poisson", "ucs", "tensile_strength",
                "core_porosity", "core_coordination", "locked_in", "sigma0_ratio", "peak_strain", "test_steps",
                "genesis_seconds", "test_seconds"}
local row = {dim, set .. "d", rmin, seed, kind, spec.balls, w / (radius[1] + radius[2]), values.young or "",
             values.poisson or "",
             values.ucs or "", values.tensile_strength or "", g.core_porosity, g.core_coordination, g.locked_in,
             g.sigma / spec.sigma0, r.peak_strain or "", r.steps, spec.genesis_time,
             seixo.clock() - t0 - spec.genesis_time}
local f = io.open(csv, "r")
local new = f == nil
if f then f:close() end
f = assert(io.open(csv, "a"))
if new then f:write(table.concat(header, ","), "\n") end
for i, v in ipairs(row) do row[i] = type(v) == "number" and string.format("%.6g", v) or v end
f:write(table.concat(row, ","), "\n")
f:close()
print(table.concat(header, ","))
print(table.concat(row, ","))
