-- One specimen of the comparison with Potyondy & Cundall (2004)
-- (docs/potyondy-cundall.md): Lac du Bonnet micro-parameters (lab.rock()),
-- radii uniform in [Rmin, 1.66 Rmin], a 31.7 x 63.4 mm rectangle (2D) or
-- cylinder (3D), its genesis and a UCS test, or with "bts" a 31.7 mm disk
-- (2D) or disc 15.85 mm thick (3D) and a Brazilian test. Appends a line to
-- the CSV (its header when the file is new).
--   scripts/run docs/data/potyondy_cundall.lua dim rmin seed out.csv [bts]
local lab = require "seixo.lab"
local dim, rmin, seed, csv, kind = tonumber(arg[1]), tonumber(arg[2]), tonumber(arg[3]) or 1, arg[4], arg[5] or "ucs"
if not (dim and rmin and csv) then error("usage: potyondy_cundall.lua dim rmin seed out.csv [bts]") end
local w = 0.0317
local radius = {rmin, 1.66 * rmin}
local tag = string.format("%s_d%d_r%g_s%d_%s", csv:gsub("%.csv$", ""), dim, rmin * 1e3, seed, kind)
local t0 = seixo.clock()
local spec, r, values
if kind == "bts" then
  spec = dim == 2 and lab.specimen{dim = 2, shape = "disk", diameter = w, radius = radius, seed = seed,
                                   path = tag .. ".h5"}
    or lab.specimen{dim = 3, shape = "disc", diameter = w, thickness = w / 2, radius = radius, seed = seed,
                    path = tag .. ".h5"}
  r = lab.brazilian(spec, {out = tag, plot = false})
  values = {tensile_strength = r.tensile_strength}
else
  spec = dim == 2 and lab.specimen{dim = 2, shape = "rect", width = w, height = 2 * w, radius = radius, seed = seed,
                                   path = tag .. ".h5"}
    or lab.specimen{dim = 3, shape = "cylinder", diameter = w, height = 2 * w, radius = radius, seed = seed,
                    path = tag .. ".h5"}
  r = lab.ucs(spec, {out = tag, plot = false})
  values = {young = r.young, poisson = r.poisson, ucs = r.peak}
end
local g = spec.genesis
local header = {"dim", "rmin", "seed", "test", "balls", "across", "young", "poisson", "ucs", "tensile_strength",
                "core_porosity", "core_coordination", "locked_in", "sigma0_ratio", "peak_strain", "test_steps",
                "genesis_seconds", "test_seconds"}
local row = {dim, rmin, seed, kind, spec.balls, w / (radius[1] + radius[2]), values.young or "", values.poisson or "",
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
