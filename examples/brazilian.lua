-- Brazilian (indirect tensile) tests: a bonded disc in 3D (axis along y,
-- loaded along z) and a bonded disk in 2D, split between two platens;
-- sigma_t = 2 F / (pi D t).
--   scripts/run examples/brazilian.lua [out_dir]
local lab = require "seixo.lab"
local out = arg and arg[1] or "lab-results-brazilian"
os.execute("mkdir -p '" .. out .. "'")
local disc = lab.specimen{dim = 3, shape = "disc", diameter = 0.03, thickness = 0.015, radius = {1.2e-3, 2.0e-3},
                          seed = 1, path = out .. "/disc.h5"}
local r3 = lab.brazilian(disc, {out = out .. "/disc"})
local disk = lab.specimen{dim = 2, shape = "disk", diameter = 0.03, radius = {0.4e-3, 0.66e-3}, seed = 1,
                          path = out .. "/disk.h5"}
local r2 = lab.brazilian(disk, {out = out .. "/disk"})
print(string.format("3D disc: tensile strength %.4g MPa (%d tensile, %d shear cracks at the peak)",
                    r3.tensile_strength / 1e6, r3.cracks.tension, r3.cracks.shear))
print(string.format("2D disk: tensile strength %.4g MPa (%d tensile, %d shear cracks at the peak)",
                    r2.tensile_strength / 1e6, r2.cracks.tension, r2.cracks.shear))
