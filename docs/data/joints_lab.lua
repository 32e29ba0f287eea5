-- Jointed rock (issue 14, item 3): the figures of docs/joints.md.
--   build/seixo docs/data/joints_lab.lua [outdir]
-- A 2D bonded specimen (lab.rock, 10 x 20 mm, radii 0.2-0.33 mm, seed 3),
-- the UCS of the specimen with a bonded smooth joint through its centre at
-- angles beta (its normal from the loading axis) 0-90 degrees, and direct
-- shear tests of the same joint at three normal stresses; writes
-- joints_angle.csv and joints_shear.csv (CPU: about 3 min).
local lab = require("seixo.lab")
local joints = require("seixo.joints")
local dir = (arg and arg[1] or ".") .. "/"
local spec = lab.specimen{dim = 2, shape = "rect", width = 0.01, height = 0.02, radius = {0.2e-3, 0.33e-3}, seed = 3,
                          path = dir .. "joints_rect.h5", log = false}
local joint = {cohesion = 10e6, friction_angle = 30, friction = 0.5}
local series = joints.angle_series(spec, {angles = {0, 15, 30, 40, 45, 50, 55, 60, 65, 70, 75, 80, 90}, joint = joint,
                                          test = {log = false}, out = dir .. "joints_angle", log = print})
print("intact UCS", series.intact)
local rows = {}
for _, sn in ipairs{5e6, 10e6, 20e6} do
  local r = joints.direct_shear(spec, {normal_stress = sn, joint = joint, out = dir .. string.format("joints_shear_%d", sn / 1e6),
                                       log = print})
  rows[#rows + 1] = {sn / 1e6, r.peak / 1e6, r.residual / 1e6}
end
lab.write_csv(dir .. "joints_shear.csv", {"sigma_n_MPa", "peak_MPa", "residual_MPa"}, rows)
